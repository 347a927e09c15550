/* The separation law of a barb line from the periodic cell held by hooks
 * (plume_separation_law_of; docs/unzipping.md, "The macro law"): at 90 degrees one hooklet per
 * period gives strength / period exactly, the opening at the strength is the hook's opening plus
 * the bonded cell's stretch (its C22 from plume_homogenize, a computation without hooks), the
 * energy is the triangle under that line, and the line catches again at the capture distance; a
 * slide adds its plateau; the law written with the moduli reads back; bad input is named. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hdf5.h>

#include "harness.h"
#include "../include/plume/curves.h"
#include "../include/plume/homogenize.h"
#include "../micro/cell_linear.h"
#include "../micro/cell_mesh.h"
#include "../micro/hooked_cell.h"

#define DEG (3.14159265358979323846 / 180.0)

/* The bonded cell's traction per opening strain (N/m): C22 h at no stretch along the barbs, from
 * the exact linearised cell problem (micro/cell_linear.h), which knows nothing of hooks. */
static double bonded_stiffness(const plume_layout *hooked)
{
    plume_layout l = *hooked;
    l.hooks.strength = 0.0;
    plume_cell *cell = NULL;
    plume_membrane_material mats[2];
    plume_layout_materials(&l, mats);
    double C[9] = {0};
    plume_err err = {{0}};
    if (plume_cell_mesh(&l, &cell, &err) != PLUME_OK ||
        plume_cell_linear_tensor(cell, mats, 2, l.h, C, NULL, &err) != PLUME_OK)
        fprintf(stderr, "    bonded cell: %s\n", err.msg);
    plume_cell_destroy(&cell);
    return C[4] * l.h;
}

void test_micro_separation_law_kovalev(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {{0}};
    CHECK(plume_layout_load_json("../data/layout_kovalev.json", &l, &err) == PLUME_OK);
    /* elements of 13.5 um (a third of the default's cost), and a hook opening of 20 nm so that the
     * cell's own stretch, which the bonded cell checks, is more than half of the peak opening */
    l.e_rel = 0.3;
    l.hooks.opening = 2e-8;
    plume_separation_law s;
    CHECK(plume_separation_law_of(&l, &s, &err) == PLUME_OK);
    if (err.msg[0])
        fprintf(stderr, "    %s\n", err.msg);
    printf("    strength %.6g N/m, energy %.6g J/m^2, peak opening %.6g m, opening %.6g m, capture %.6g m, "
           "%d solves, %d Newton iterations\n", s.strength, s.energy, s.peak_opening, s.opening, s.capture, s.solves,
           s.newton_iterations);
    /* one hooklet of 14 uN per 12 um of barb, pulled straight across */
    CHECK(s.cell_hooks == 1);
    CHECK_REL(s.cell_length, l.barbule_spacing, 1e-12, 0.0);
    CHECK(s.strength <= l.hooks.strength / l.barbule_spacing * (1.0 + 1e-4));
    CHECK_REL(s.strength, l.hooks.strength / l.barbule_spacing, 2e-4, 0.0);
    /* compliance in series: the hook's own opening, then the bonded cell's stretch */
    const double K = bonded_stiffness(&l);
    printf("    bonded C22 h %.6g N/m: elastic stretch %.6g m + hook opening %.6g m\n", K,
           s.strength / K * l.d_B, l.hooks.opening);
    CHECK(s.strength / K * l.d_B > 0.5 * s.peak_opening);
    CHECK_REL(s.peak_opening, l.hooks.opening + s.strength / K * l.d_B, 0.01, 0.0);
    /* the line's own stiffness: the hook's, strength over its opening, per period */
    CHECK_REL(s.stiffness, s.strength / l.hooks.opening, 1e-3, 0.0);
    /* brittle: the traction is gone at the strength's opening; the energy is the triangle */
    CHECK_REL(s.opening, s.peak_opening, 1e-12, 0.0);
    CHECK_REL(s.energy * l.h, 0.5 * s.strength * s.peak_opening, 0.01, 0.0);
    /* it catches again at the capture distance, to the bisection's 1/1000 */
    CHECK(s.capture <= l.hooks.capture * (1.0 + 1e-9));
    CHECK(s.capture >= l.hooks.capture * (1.0 - 2e-3));
}

/* A slide holds the strength over its length: the energy gains its plateau. */
void test_micro_separation_law_slide(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {{0}};
    CHECK(plume_layout_load_json("../data/layout_kovalev.json", &l, &err) == PLUME_OK);
    l.e_rel = 0.3; /* elements 13.5 um: the slide's 40 steps on a coarser cell */
    plume_separation_law brittle, s;
    CHECK(plume_separation_law_of(&l, &brittle, &err) == PLUME_OK);
    l.hooks.slide = 3e-6;
    CHECK(plume_separation_law_of(&l, &s, &err) == PLUME_OK);
    printf("    slide %g m: strength %.6g N/m, energy %.6g J/m^2 (brittle %.6g), opening %.6g m (brittle %.6g)\n",
           l.hooks.slide, s.strength, s.energy, brittle.energy, s.opening, brittle.opening);
    CHECK_REL(s.strength, brittle.strength, 1e-3, 0.0);
    CHECK_REL(s.opening, brittle.opening + l.hooks.slide, 0.02, 0.0); /* a step is 1/40 of the slide */
    CHECK_REL(s.energy * l.h, brittle.energy * l.h + s.strength * l.hooks.slide, 0.02, 0.0);
}

/* The shipped layout with hooks (barbules at an angle): the hook is pulled askew, with a shear
 * traction half the normal one, yet only the hook crosses the line, so the traction's magnitude
 * at the release is one hook's strength per period; the law is written and read back. */
void test_micro_separation_law_file(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {{0}};
    CHECK(plume_layout_load_json("../data/layout_hooks.json", &l, &err) == PLUME_OK);
    plume_separation_law s, back;
    CHECK(plume_separation_law_of(&l, &s, &err) == PLUME_OK);
    printf("    layout_hooks: strength %.6g N/m (one hook per period %.6g), energy %.6g J/m^2, opening %.6g m, "
           "capture %.6g m\n", s.strength, l.hooks.strength / l.barbule_spacing, s.energy, s.opening, s.capture);
    CHECK(s.strength <= l.hooks.strength / l.barbule_spacing * (1.0 + 1e-4));
    CHECK_REL(s.strength, l.hooks.strength / l.barbule_spacing, 2e-4, 0.0);
    CHECK(s.energy > 0.0 && s.opening >= s.peak_opening && s.capture > 0.0);
    plume_homog_result r;
    memset(&r, 0, sizeof r);
    r.moduli = (plume_ortho){1e9, 1e8, 0.3, 1e7};
    r.order = 2;
    char path[] = "/tmp/plume_separation_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    unlink(path);
    CHECK(plume_homog_write_separation(path, &l, &r, &s, &err) == PLUME_OK);
    CHECK(plume_separation_read(path, &back, &err) == PLUME_OK);
    CHECK(back.strength == s.strength && back.energy == s.energy && back.opening == s.opening &&
          back.capture == s.capture && back.stiffness == s.stiffness && back.peak_opening == s.peak_opening);
    /* a file written before separation_peak_opening: read as brittle (the peak at the opening) */
    {
        hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
        CHECK(f >= 0 && H5Adelete_by_name(f, "/moduli", "separation_peak_opening", H5P_DEFAULT) >= 0);
        H5Fclose(f);
        CHECK(plume_separation_read(path, &back, &err) == PLUME_OK);
        CHECK(back.peak_opening == back.opening && back.opening == s.opening);
        /* a peak opening beyond the opening: refused, named */
        f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
        hid_t g = f >= 0 ? H5Gopen2(f, "/moduli", H5P_DEFAULT) : -1, sp = H5Screate(H5S_SCALAR);
        hid_t a = g >= 0 ? H5Acreate2(g, "separation_peak_opening", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT) : -1;
        const double beyond = 2.0 * s.opening;
        CHECK(a >= 0 && H5Awrite(a, H5T_NATIVE_DOUBLE, &beyond) >= 0);
        H5Aclose(a);
        H5Sclose(sp);
        H5Gclose(g);
        H5Fclose(f);
        CHECK(plume_separation_read(path, &back, &err) == PLUME_EINVAL && strstr(err.msg, "separation_peak_opening") &&
              strstr(err.msg, path));
    }
    /* moduli without hooks: the law's absence is named */
    CHECK(plume_homog_write(path, &l, &r, &err) == PLUME_OK);
    CHECK(plume_separation_read(path, &back, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "separation_strength") && strstr(err.msg, path));
    unlink(path);
}

/* The hooked cell's small-strain tensor (plume_separation_tensor). Hooks a thousand times stiffer
 * than the barbule weld the cell shut: the bonded cell's tensor from the exact linearised problem,
 * which knows nothing of hooks. The shipped hooks: a hook holds a leaning barbule's end by its
 * position only, so the cell is softer across the barbs and in shear than the bonded cell plus the
 * hooks' own opening in series (the line's compliance h / (k d_B) on S22 and S33), and the
 * stretch-shear coupling stays strong. */
void test_micro_separation_tensor(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {{0}};
    CHECK(plume_layout_load_json("../data/layout_hooks.json", &l, &err) == PLUME_OK);
    double Cb[9] = {0}, Ch[9], Cs[9];
    {
        plume_layout b = l;
        b.hooks.strength = 0.0;
        plume_cell *cell = NULL;
        plume_membrane_material mats[2];
        plume_layout_materials(&b, mats);
        CHECK(plume_cell_mesh(&b, &cell, &err) == PLUME_OK &&
              plume_cell_linear_tensor(cell, mats, 2, b.h, Cb, NULL, &err) == PLUME_OK);
        plume_cell_destroy(&cell);
    }
    plume_layout stiff = l;
    stiff.hooks.opening = 1e-13; /* 9.3e9 N/m a hook */
    CHECK(plume_separation_tensor(&stiff, Cs, &err) == PLUME_OK);
    CHECK(plume_separation_tensor(&l, Ch, &err) == PLUME_OK);
    printf("    bonded C22 %.6g C33 %.6g C23 %.6g; stiff hooks %.6g %.6g %.6g; shipped hooks %.6g %.6g %.6g (Pa)\n", Cb[4],
           Cb[8], Cb[5], Cs[4], Cs[8], Cs[5], Ch[4], Ch[8], Ch[5]);
    for (int k = 0; k < 9; k++) /* each entry to 1e-4 of the diagonal entries it couples */
        CHECK_REL(Cs[k], Cb[k], 1e-4, sqrt(Cb[4 * (k / 3)] * Cb[4 * (k % 3)]));
    /* compliances S22 and S33 of the 2x2 block (E22, 2E12) at held E11 */
    const double det_b = Cb[4] * Cb[8] - Cb[5] * Cb[5], det_h = Ch[4] * Ch[8] - Ch[5] * Ch[5];
    const double series = l.h / (5.8125e5 * l.d_B); /* the line's compliance (1/Pa), the law's stiffness */
    CHECK(det_h > 0.0);
    CHECK(Ch[8] / det_h > Cb[8] / det_b + 2.0 * series); /* S22 */
    CHECK(Ch[4] / det_h > Cb[4] / det_b + 2.0 * series); /* S33 */
    CHECK(Ch[5] / sqrt(Ch[4] * Ch[8]) > 0.8);
    CHECK_REL(Ch[0], Cb[0], 1e-2, 0.0); /* along the barbs the hooks change nothing */
    l.hooks.strength = 0.0;
    CHECK(plume_separation_tensor(&l, Ch, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "hook_strength") != NULL);
}

/* The cell of data/layout_hooks.json opened in mixed mode, F = [1 s cos(psi); 0 1 + s sin(psi)],
 * from shear (psi = 0) through pure opening (90 deg) to shear the other way (180 deg), s found
 * where the hook reaches its strength by secant steps. The hook lets go at its strength whatever
 * its pull's direction, so the traction's magnitude at the release is the law's strength in every
 * mode. The energy stored at the release (all of which a brittle hook lets go) depends on the mode
 * through the hooked cell's compliance alone: its small-strain tensor (plume_separation_tensor,
 * which the macro vane C carries) predicts, at |t| = strength, the traction's direction to a
 * degree and the energy to 1 % in every mode but the one across the leaning barbule (150 deg),
 * where the cell is nearly a mechanism, opens ten times further and stores 15 times more. Within
 * 60 deg of the barbule's lean the energy stays within 12 % of pure opening's, the law's energy. */
static plume_status open_to_strength(const plume_layout *l, double psi, double *traction, double *angle,
                                     double *energy, double *opening, plume_err *err)
{
    plume_hooked_cell c;
    plume_status st = plume_hooked_cell_init(&c, l, "mixed mode", err);
    const double b = st == PLUME_OK ? c.oc.cell.b : 1.0;
    double s = 1e-3 * l->hooks.opening / b, sprev = 0.0, load = 0.0, lprev = 0.0, P[4] = {0}, E = 0.0;
    for (int it = 0; st == PLUME_OK; it++) {
        const double F[4] = {1.0, s * cos(psi), 0.0, 1.0 + s * sin(psi)};
        if ((st = plume_hooked_cell_solve_F(&c, F, P, &E, err)) != PLUME_OK)
            break;
        load = plume_hooked_cell_load(&c);
        if (fabs(load - 1.0) < 1e-6)
            break;
        if (it == 50 || !((load - lprev) / (s - sprev) > 0.0)) {
            st = plume_err_set(err, PLUME_EINFEASIBLE, "the hook's load %g does not reach 1 (psi %g rad)", load, psi);
            break;
        }
        const double next = s + (1.0 - load) * (s - sprev) / (load - lprev);
        sprev = s, lprev = load, s = next;
    }
    if (st == PLUME_OK) {
        *traction = hypot(P[1], P[3]);
        *angle = atan2(P[3], P[1]) / DEG;
        *energy = E / c.oc.cell.a / l->h;
        *opening = s * b;
    }
    plume_hooked_cell_free(&c);
    return st;
}

void test_micro_separation_law_modes(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {{0}};
    CHECK(plume_layout_load_json("../data/layout_hooks.json", &l, &err) == PLUME_OK);
    plume_separation_law law;
    CHECK(plume_separation_law_of(&l, &law, &err) == PLUME_OK);
    double C[9];
    CHECK(plume_separation_tensor(&l, C, &err) == PLUME_OK);
    double G[7] = {0}, d[7] = {0}, G_tensor[7] = {0};
    for (int k = 0; k < 7; k++) {
        const double psi = (30.0 * k) * DEG;
        double t = 0.0, angle = 0.0;
        CHECK(open_to_strength(&l, psi, &t, &angle, &G[k], &d[k], &err) == PLUME_OK);
        if (err.msg[0])
            fprintf(stderr, "    %s\n", err.msg);
        /* the tensor's prediction: strain (E22, 2E12) = s (sin psi, cos psi), scaled to |t| = strength */
        const double e22 = sin(psi), g12 = cos(psi), P22 = C[4] * e22 + C[5] * g12, P12 = C[5] * e22 + C[8] * g12;
        const double scale = law.strength / (l.h * hypot(P22, P12)), angle_tensor = atan2(P22, P12) / DEG;
        G_tensor[k] = 0.5 * scale * scale * (P22 * e22 + P12 * g12) * l.d_B;
        printf("    psi %3d deg: opening %.4g m, traction %.6g N/m at %.1f deg (tensor %.1f), energy %.5g J/m^2, "
               "%.3f of pure opening's (tensor %.5g J/m^2)\n", 30 * k, d[k], t, angle, angle_tensor, G[k],
               G[k] / law.energy, G_tensor[k]);
        CHECK_REL(t, law.strength, 1e-4, 0.0);
        if (k != 5) {
            CHECK(fabs(angle - angle_tensor) < 1.0);
            CHECK_REL(G[k], G_tensor[k], 0.01, 0.0);
        }
        if (k <= 4)
            CHECK(G[k] > 0.98 * law.energy && G[k] < 1.12 * law.energy);
    }
    CHECK_REL(G[3], law.energy, 1e-2, 0.0); /* pure opening: the law's energy, integrated on another path */
    CHECK(G[5] > 5.0 * law.energy && d[5] > 5.0 * d[3]);
}

void test_micro_separation_law_bad_input(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_separation_law s;
    plume_err err = {{0}};
    CHECK(plume_separation_law_of(&l, &s, &err) == PLUME_EINVAL); /* strips */
    CHECK(strstr(err.msg, "hook_strength") != NULL);
    CHECK(plume_layout_load_json("../data/layout_kovalev.json", &l, &err) == PLUME_OK);
    l.hooks.strength = 0.0; /* bonded barbules */
    CHECK(plume_separation_law_of(&l, &s, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "hook_strength") != NULL);
    l.hooks.strength = -1.0;
    CHECK(plume_separation_law_of(&l, &s, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "strength") != NULL);
    CHECK(plume_separation_read("/nonexistent/moduli.h5", &s, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, "/nonexistent/moduli.h5") != NULL);
}
