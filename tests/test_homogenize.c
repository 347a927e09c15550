/* Periodic cells: the periodic wrapper's derivatives, the average stress, and the laminate's
 * exact effective tensor. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "test_rng.h"
#include "plume_tree.h"
#include "../micro/homogenize.h"
#include "../micro/layout.h"
#include "../micro/layout_json.h"
#include "../micro/periodic.h"

/* Exact plane-stress tensor of a laminate of isotropic layers normal to y (fields are constant
 * in each layer): with t = {xx} continuous strain, n = {yy, xy} continuous stress, and each layer's
 * C split as [A B; B^T D], D_eff = <D^-1>^-1, C_nt = D_eff <D^-1 B^T>,
 * C_tt = <A - B D^-1 B^T> + <B D^-1> D_eff <D^-1 B^T>. */
static void laminate_exact(const double *E, const double *nu, const double *frac, int nl, double C[9])
{
    double Dinv_avg[4] = {0}, DinvBt_avg[2] = {0}, schur_avg = 0.0;
    for (int i = 0; i < nl; i++) {
        double c = E[i] / (1.0 - nu[i] * nu[i]), G = E[i] / (2.0 * (1.0 + nu[i]));
        double A = c, B[2] = {c * nu[i], 0.0}, D[4] = {c, 0.0, 0.0, G};
        double det = D[0] * D[3] - D[1] * D[2];
        double Di[4] = {D[3] / det, -D[1] / det, -D[2] / det, D[0] / det};
        double DiBt[2] = {Di[0] * B[0] + Di[1] * B[1], Di[2] * B[0] + Di[3] * B[1]};
        for (int k = 0; k < 4; k++)
            Dinv_avg[k] += frac[i] * Di[k];
        DinvBt_avg[0] += frac[i] * DiBt[0];
        DinvBt_avg[1] += frac[i] * DiBt[1];
        schur_avg += frac[i] * (A - (B[0] * DiBt[0] + B[1] * DiBt[1]));
    }
    double det = Dinv_avg[0] * Dinv_avg[3] - Dinv_avg[1] * Dinv_avg[2];
    double De[4] = {Dinv_avg[3] / det, -Dinv_avg[1] / det, -Dinv_avg[2] / det, Dinv_avg[0] / det};
    double Cnt[2] = {De[0] * DinvBt_avg[0] + De[1] * DinvBt_avg[1], De[2] * DinvBt_avg[0] + De[3] * DinvBt_avg[1]};
    double Ctt = schur_avg + DinvBt_avg[0] * Cnt[0] + DinvBt_avg[1] * Cnt[1];
    double out[9] = {Ctt, Cnt[0], Cnt[1], Cnt[0], De[0], De[1], Cnt[1], De[2], De[3]};
    memcpy(C, out, sizeof out);
}

/* The small-strain tensor of the laminate layout matches the exact answer to 1e-6 relative, for
 * several fractions, contrasts and Poisson ratios (the paper's contrast 1e-6 included), with linear
 * and quadratic elements, and the convergence estimate says it is converged. */
void test_homogenize_laminate_exact(void)
{
    const double phis[] = {0.16, 0.5, 0.8}, ratios[] = {1e-6, 1e-2, 0.3}, nub[] = {0.3, 0.0, 0.45},
                 nuB[] = {0.3, 0.4, 0.1};
    for (int run = 0; run < 6; run++) {
        const int k = run % 3;
        plume_layout l;
        plume_layout_default(&l);
        l.order = run < 3 ? 2 : 1;
        l.phi = phis[k];
        l.ratio = ratios[k];
        l.nu_b = nub[k];
        l.nu_B = nuB[k];
        l.e_rel = 0.7;
        plume_homog_opts o;
        plume_homog_opts_default(&o);
        o.strain_max = 0.0; /* tensor only */
        plume_homog_result r;
        plume_err err = {{0}};
        plume_status st = plume_homogenize(&l, &o, &r, &err);
        CHECK(st == PLUME_OK);
        if (st != PLUME_OK) {
            fprintf(stderr, "    %s\n", err.msg);
            continue;
        }
        double E[2] = {l.E_b, l.ratio * l.E_b}, nu[2] = {l.nu_b, l.nu_B}, frac[2] = {l.phi, 1.0 - l.phi}, C[9];
        laminate_exact(E, nu, frac, 2, C);
        double scale = sqrt(C[0] * C[4]);
        for (int i = 0; i < 9; i++) {
            /* relative per entry, with an absolute floor for entries that vanish */
            double floor = (i == 2 || i == 5 || i == 6 || i == 7) ? 1e-3 * scale : 0.0; /* abs 1e-9 */
            CHECK_REL(r.C[i], C[i], 1e-6, floor);
        }
        plume_ortho m;
        CHECK(plume_ortho_from_tensor(C, &m, &err) == PLUME_OK);
        CHECK_REL(r.moduli.E_xx, m.E_xx, 1e-6, 0.0);
        CHECK_REL(r.moduli.E_yy, m.E_yy, 1e-6, 0.0);
        CHECK_REL(r.moduli.G_xy, m.G_xy, 1e-6, 0.0);
        CHECK_REL(r.moduli.nu_xy, m.nu_xy, 1e-6, 1e-12);
        CHECK(r.coupling < 1e-9);
        CHECK(r.refinement_change >= 0.0 && r.refinement_change < 1e-6);
        plume_homog_result_free(&r);
    }
}

/* The finite-strain cell curves start with the slopes of the small-strain tensor: the periodic
 * wrapper, the average stress and the lateral-stress iteration agree with the linear problem. */
void test_homogenize_curves_match_tensor(void)
{
    const double ratios[] = {1e-3, 1e-6};
    for (int k = 0; k < 2; k++) {
        plume_layout l;
        plume_layout_default(&l);
        l.ratio = ratios[k];
        plume_homog_opts o;
        plume_homog_opts_default(&o);
        o.strain_max = 0.002;
        o.steps = 2;
        plume_homog_result r;
        plume_err err = {{0}};
        plume_status st = plume_homogenize(&l, &o, &r, &err);
        CHECK(st == PLUME_OK);
        if (st != PLUME_OK) {
            fprintf(stderr, "    %s\n", err.msg);
            continue;
        }
        CHECK(r.uniaxial_x.n == 3 && r.uniaxial_y.n == 3 && r.shear.n == 3);
        double e = r.uniaxial_x.strain[1];
        CHECK_REL(r.uniaxial_x.stress[1] / e, r.moduli.E_xx, 5e-3, 0.0);
        CHECK_REL(r.uniaxial_y.stress[1] / e, r.moduli.E_yy, 5e-3, 0.0);
        CHECK_REL(r.shear.stress[1] / e, r.moduli.G_xy, 5e-3, 0.0);
        /* lateral strain of the uniaxial test along the barbs: -nu_xy eps */
        CHECK_REL(r.uniaxial_x.wbar[1], -r.moduli.nu_xy * e, 1e-2, 1e-9);
        CHECK(r.uniaxial_x.stress[2] > r.uniaxial_x.stress[1]);
        plume_homog_result_free(&r);
    }
}

/* The periodic wrapper is an energy term: its gradient and Hessian (on the masters) against
 * central differences, and the average stress against the derivative in Fbar at fixed masters. */
void test_homogenize_periodic_fd(void)
{
    plume_layout l;
    plume_layout_default(&l);
    l.ratio = 0.1;
    l.e_rel = 1.5;
    plume_err err = {{0}};
    plume_cell *cell = NULL;
    CHECK(plume_cell_mesh(&l, &cell, &err) == PLUME_OK);
    if (!cell)
        return;
    plume_membrane_material mats[2];
    plume_layout_materials(&l, mats);
    mats[0].kappa = mats[1].kappa = 1e6;
    plume_term mem, t;
    plume_periodic *per = NULL;
    CHECK(plume_membrane_term_create(cell->mesh, 2, mats, 2, &mem, &err) == PLUME_OK);
    CHECK(plume_periodic_term_create(cell, &mem, &per, &t, &err) == PLUME_OK);
    const double F[4] = {1.03, 0.02, -0.01, 0.97};
    plume_periodic_set_macro(per, F);
    plume_index nv = cell->mesh->nv, k = t.arity * 2;
    rng64 rng = {0x5EEDCE11ULL};
    double *x = malloc((size_t)(2 * nv) * sizeof *x), *g = calloc((size_t)(2 * nv), sizeof *g);
    double *gp = calloc((size_t)(2 * nv), sizeof *gp), *gm = calloc((size_t)(2 * nv), sizeof *gm);
    double *H = malloc((size_t)(t.nstencil * k * k) * sizeof *H);
    for (plume_index v = 0; v < nv; v++) {
        x[2 * v] = F[0] * cell->mesh->X[2 * v] + F[1] * cell->mesh->X[2 * v + 1] + 1e-3 * l.d_B * urange(&rng, -1, 1);
        x[2 * v + 1] = F[2] * cell->mesh->X[2 * v] + F[3] * cell->mesh->X[2 * v + 1] + 1e-3 * l.d_B * urange(&rng, -1, 1);
    }
    double f = 0.0;
    CHECK(t.eval(t.ctx, 2, x, &f, g, H, 0) == PLUME_OK);
    double P[4];
    plume_periodic_average_stress(per, P);
    /* gradient: every master coordinate */
    double worst_g = 0.0, gscale = 0.0, hstep = 1e-7 * l.d_B;
    for (plume_index i = 0; i < 2 * nv; i++)
        gscale = fmax(gscale, fabs(g[i]));
    for (plume_index v = 0; v < nv; v++) {
        if (cell->master[v] != v)
            continue;
        for (int a = 0; a < 2; a++) {
            double fp = 0.0, fm = 0.0, x0 = x[2 * v + a];
            x[2 * v + a] = x0 + hstep;
            t.eval(t.ctx, 2, x, &fp, NULL, NULL, 0);
            x[2 * v + a] = x0 - hstep;
            t.eval(t.ctx, 2, x, &fm, NULL, NULL, 0);
            x[2 * v + a] = x0;
            worst_g = fmax(worst_g, fabs((fp - fm) / (2 * hstep) - g[2 * v + a]));
        }
    }
    CHECK(worst_g <= 1e-6 * gscale);
    /* Hessian: the sum of the blocks applied to a random direction against gradient differences */
    double *dir = calloc((size_t)(2 * nv), sizeof *dir), *Hd = calloc((size_t)(2 * nv), sizeof *Hd);
    for (plume_index v = 0; v < nv; v++)
        if (cell->master[v] == v)
            dir[2 * v] = urange(&rng, -1, 1), dir[2 * v + 1] = urange(&rng, -1, 1);
    for (plume_index s = 0; s < t.nstencil; s++)
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++)
                Hd[2 * t.stencil[s * 3 + a / 2] + a % 2] += H[(s * k + a) * k + b] * dir[2 * t.stencil[s * 3 + b / 2] + b % 2];
    for (plume_index i = 0; i < 2 * nv; i++)
        gp[i] = x[i] + hstep * dir[i], gm[i] = x[i] - hstep * dir[i];
    double *g1 = calloc((size_t)(2 * nv), sizeof *g1), *g2 = calloc((size_t)(2 * nv), sizeof *g2);
    double e1 = 0, e2 = 0;
    t.eval(t.ctx, 2, gp, &e1, g1, NULL, 0);
    t.eval(t.ctx, 2, gm, &e2, g2, NULL, 0);
    double worst_h = 0.0, hscale = 0.0;
    for (plume_index i = 0; i < 2 * nv; i++) {
        worst_h = fmax(worst_h, fabs((g1[i] - g2[i]) / (2 * hstep) - Hd[i]));
        hscale = fmax(hscale, fabs(Hd[i]));
    }
    CHECK(worst_h <= 1e-5 * hscale);
    /* average stress: (1/A) dW/dFbar at fixed masters */
    double Fd[4], area = cell->a * cell->b, eps = 1e-7;
    for (int c = 0; c < 4; c++) {
        double fp = 0.0, fm = 0.0;
        memcpy(Fd, F, sizeof Fd);
        Fd[c] += eps;
        plume_periodic_set_macro(per, Fd);
        t.eval(t.ctx, 2, x, &fp, NULL, NULL, 0);
        Fd[c] -= 2 * eps;
        plume_periodic_set_macro(per, Fd);
        t.eval(t.ctx, 2, x, &fm, NULL, NULL, 0);
        CHECK_REL(P[c], (fp - fm) / (2 * eps) / area, 1e-6, 1e-6 * fabs(P[0]));
    }
    t.destroy(t.ctx);
    free(x), free(g), free(gp), free(gm), free(H), free(dir), free(Hd), free(g1), free(g2);
    plume_cell_destroy(&cell);
}

/* A cell with empty space (explicit barbules) gives moduli per unit area of vane: along the barbs
 * the small-strain tensor's E_xx is the uniaxial curve's initial slope (whose stress the periodic
 * wrapper averages over the whole cell), not that over the material's area (0.4 of the cell). */
void test_homogenize_barbule_cell_area(void)
{
    plume_layout l;
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES, l.phi = 0.3, l.ratio = 1.0, l.barbule_width = 1e-4, l.barbule_spacing = 8e-4;
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.strain_max = 1e-4, o.steps = 1, o.convergence = 0;
    plume_homog_result r;
    plume_err err = {{0}};
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    if (r.uniaxial_x.n < 2)
        return;
    CHECK_REL(r.moduli.E_xx, r.uniaxial_x.stress[1] / r.uniaxial_x.strain[1], 0.01, 0.0);
    /* the barbs alone carry 0.3 E_b along them; the barbules add little */
    CHECK(r.moduli.E_xx > 0.3 * l.E_b && r.moduli.E_xx < 0.32 * l.E_b);
    plume_homog_result_free(&r);
}

/* The small-strain tensor's compliance moduli (E_xx = 1/S11, E_yy = 1/S22, G_xy = 1/S33, nu_xy)
 * are what the cell curves start at: each curve is stress-controlled (the other stresses vanish,
 * also the shear in the uniaxial tests and the normal stresses in shear), so a cell whose normal
 * stresses and shear are coupled (barbules at 60 degrees: C26 / sqrt(C22 C66) = 0.95) gives the
 * same initial slopes as an orthotropic one. The curves' shear used to be held at zero, which
 * measured C22 - C12^2 / C11 and C66: 11 times E_yy and G_xy for data/layout_barbules.json.
 * Tolerance 1e-3: both solves share the mesh and order, the step (1e-6, or 1e-4 where the strips'
 * 1e-6 contrast sets the free stresses' tolerance to 1e-4 of the drive) makes the finite-strain
 * part that small, and the defect was a factor of 11. */
static void check_slopes(const plume_homog_result *r, const char *name)
{
    double e = r->uniaxial_x.strain[1];
    fprintf(stderr, "    %s: E_xx %.5g / %.5g, E_yy %.5g / %.5g, G_xy %.5g / %.5g, nu_xy %.4g / %.4g (tensor / curves)\n",
            name, r->moduli.E_xx, r->uniaxial_x.stress[1] / e, r->moduli.E_yy, r->uniaxial_y.stress[1] / e,
            r->moduli.G_xy, r->shear.stress[1] / e, r->moduli.nu_xy, -r->uniaxial_x.wbar[1] / e);
    CHECK_REL(r->uniaxial_x.stress[1] / e, r->moduli.E_xx, 1e-3, 0.0);
    CHECK_REL(r->uniaxial_y.stress[1] / e, r->moduli.E_yy, 1e-3, 0.0);
    CHECK_REL(r->shear.stress[1] / e, r->moduli.G_xy, 1e-3, 0.0);
    CHECK_REL(-r->uniaxial_x.wbar[1] / e, r->moduli.nu_xy, 1e-2, 0.0);
}

void test_homogenize_curve_slopes(void)
{
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.steps = 1, o.convergence = 0;
    plume_err err = {{0}};
    plume_homog_result r;
    /* data/layout_barbules.json */
    plume_layout l;
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES, l.phi = 0.3, l.ratio = 1.0, l.barbule_width = 1e-4, l.barbule_spacing = 8e-4;
    l.barbule_angle = 60.0;
    o.strain_max = 1e-6;
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    if (r.uniaxial_x.n == 2) {
        CHECK(r.coupling > 0.1); /* the case that needs the free shear */
        check_slopes(&r, "barbules at 60 deg");
        /* Bounds: the true field's energy is at most that of a field affine in each layer across y
         * (the barb, then the barbule layer), whose tensor is the laminate of the layers' Voigt
         * averages (the barbule layer: f_b C, f_b its solid fraction); below the plain Voigt bound
         * f C of the solid fraction f; the Reuss bound is 0 (there is empty space). A compliance
         * modulus 1/S_ii is monotone in the tensor, so each bound holds for it. */
        double fb = l.barbule_width / (l.barbule_spacing * sin(l.barbule_angle * (3.14159265358979323846 / 180.0)));
        double f = l.phi + (1.0 - l.phi) * fb;
        double E[2] = {l.E_b, fb * l.E_b}, nu[2] = {l.nu_b, l.nu_b}, frac[2] = {l.phi, 1.0 - l.phi}, Cl[9];
        laminate_exact(E, nu, frac, 2, Cl);
        plume_ortho lam;
        CHECK(plume_ortho_from_tensor(Cl, &lam, &err) == PLUME_OK);
        const double G_b = l.E_b / (2.0 * (1.0 + l.nu_b));
        const double m[3] = {r.moduli.E_xx, r.moduli.E_yy, r.moduli.G_xy};
        const double lam_m[3] = {lam.E_xx, lam.E_yy, lam.G_xy}, voigt[3] = {f * l.E_b, f * l.E_b, f * G_b};
        const double slope[3] = {r.uniaxial_x.stress[1] / 1e-6, r.uniaxial_y.stress[1] / 1e-6, r.shear.stress[1] / 1e-6};
        for (int k = 0; k < 3; k++) {
            CHECK(m[k] > 0.0 && m[k] <= lam_m[k] && lam_m[k] <= voigt[k] * (1.0 + 1e-12));
            CHECK(slope[k] > 0.0 && slope[k] <= lam_m[k]);
        }
        fprintf(stderr, "    bounds: layer-Voigt laminate E_xx %.4g E_yy %.4g G_xy %.4g; Voigt f = %.3f: %.4g %.4g\n",
                lam.E_xx, lam.E_yy, lam.G_xy, f, f * l.E_b, f * G_b);
    }
    plume_homog_result_free(&r);
    /* a hand-made orthotropic barbule cell: barbules across the barbs, a rectangular grid */
    l.barbule_angle = 90.0;
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    if (r.uniaxial_x.n == 2) {
        CHECK(r.coupling < 1e-3); /* mirror-symmetric up to the mesh */
        fprintf(stderr, "    90 deg coupling %.2g\n", r.coupling);
        check_slopes(&r, "barbules at 90 deg");
    }
    plume_homog_result_free(&r);
    /* strips (the default layout): orthotropic, the laminate */
    plume_layout_default(&l);
    o.strain_max = 1e-4;
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    if (r.uniaxial_x.n == 2)
        check_slopes(&r, "strips");
    plume_homog_result_free(&r);
}

/* The shipped real-scale layout (data/layout_feather_si.json): its cell is the exact laminate, so
 * E_xx lies between the Reuss and Voigt bounds of the barb fraction, and the bending moduli are of
 * a real feather's order (the paper's hand-set vane: D_long 2.5e-4 N m; the non-dimensional Figure
 * 10 sample, 1 m thick: 3.3e7), the strips' plate bounds holding too. */
void test_homogenize_feather_si_layout(void)
{
    plume_layout l;
    plume_err err = {{0}};
    plume_layout_default(&l);
    CHECK(plume_layout_load_json("../data/layout_feather_si.json", &l, &err) == PLUME_OK);
    CHECK(plume_layout_check(&l, &err) == PLUME_OK);
    CHECK(l.kind == PLUME_LAYOUT_STRIPS && l.E_b == 2.5e9 && l.h == 1.2e-4 && l.d_B == 4e-4);
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.strain_max = 0.0;
    plume_homog_result r;
    plume_status st = plume_homogenize(&l, &o, &r, &err);
    CHECK(st == PLUME_OK);
    if (st != PLUME_OK) {
        fprintf(stderr, "    %s\n", err.msg);
        return;
    }
    double E_B = l.ratio * l.E_b, voigt = l.phi * l.E_b + (1.0 - l.phi) * E_B,
           reuss = 1.0 / (l.phi / l.E_b + (1.0 - l.phi) / E_B);
    CHECK(r.moduli.E_xx <= voigt * (1.0 + 1e-9) && r.moduli.E_xx >= reuss);
    CHECK(r.moduli.E_yy <= voigt && r.moduli.E_yy >= reuss * (1.0 - 1e-6));
    double E[2] = {l.E_b, E_B}, nu[2] = {l.nu_b, l.nu_B}, frac[2] = {l.phi, 1.0 - l.phi}, C[9];
    laminate_exact(E, nu, frac, 2, C);
    plume_ortho m;
    CHECK(plume_ortho_from_tensor(C, &m, &err) == PLUME_OK);
    CHECK_REL(r.moduli.E_xx, m.E_xx, 1e-6, 0.0);
    CHECK_REL(r.moduli.E_yy, m.E_yy, 1e-6, 0.0);
    CHECK_REL(r.moduli.G_xy, m.G_xy, 1e-6, 0.0);
    /* plate: D_long between the plate Voigt and Reuss bounds of E t^3 / (12 (1 - nu^2)) */
    double t3 = l.h * l.h * l.h / 12.0, Db = l.E_b * t3 / (1.0 - l.nu_b * l.nu_b), DB = E_B * t3 / (1.0 - l.nu_B * l.nu_B);
    double Dv = l.phi * Db + (1.0 - l.phi) * DB, Dr = 1.0 / (l.phi / Db + (1.0 - l.phi) / DB);
    CHECK(r.bending.D_long <= Dv * (1.0 + 1e-6) && r.bending.D_long >= Dr);
    CHECK(r.bending.D_trans <= Dv && r.bending.D_trans >= Dr * (1.0 - 1e-6));
    CHECK(r.bending.D_long > 1e-5 && r.bending.D_long < 1e-3);
    fprintf(stderr, "    data/layout_feather_si.json: E_xx %.4g (Reuss %.4g, Voigt %.4g), E_yy %.4g, G_xy %.4g Pa; "
                    "D_long %.4g, D_trans %.4g N m\n", r.moduli.E_xx, reuss, voigt, r.moduli.E_yy, r.moduli.G_xy,
            r.bending.D_long, r.bending.D_trans);
    plume_homog_result_free(&r);
}

/* plume_homog_write: what it wrote reads back as the moduli; bad arguments and an unwritable path
 * are errors naming what is wrong */
void test_homogenize_write_errors(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.strain_max = 0.0;
    o.convergence = 0;
    plume_homog_result r;
    plume_err err = {{0}};
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    CHECK(plume_homog_write(NULL, &l, &r, &err) == PLUME_EINVAL && strstr(err.msg, "path"));
    err.msg[0] = '\0';
    CHECK(plume_homog_write("/nonexistent-dir/m.h5", &l, &r, &err) != PLUME_OK &&
          strstr(err.msg, "/nonexistent-dir/m.h5"));
    char path[] = "/tmp/plume-homog-write-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd >= 0) {
        close(fd);
        remove(path);
        plume_ortho back;
        CHECK(plume_homog_write(path, &l, &r, &err) == PLUME_OK && plume_moduli_read(path, &back, &err) == PLUME_OK &&
              back.E_xx == r.moduli.E_xx && back.G_xy == r.moduli.G_xy);
        remove(path);
    }
    plume_homog_result_free(&r);
}

/* plume_homogenize_bending is plume_homogenize's bending part alone: the same D bit for bit, its
 * moduli those of D; an invalid layout is refused naming the field. */
void test_homogenize_bending_alone(void)
{
    plume_layout l;
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES;
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.strain_max = 0.0; /* no curves */
    o.convergence = 0;
    plume_homog_result r;
    plume_err err = {{0}};
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    double D[9];
    plume_plate_moduli m;
    CHECK(plume_homogenize_bending(&l, D, &m, &err) == PLUME_OK);
    CHECK(memcmp(D, r.D, sizeof D) == 0);
    CHECK(m.D_long == r.bending.D_long && m.D_trans == r.bending.D_trans && m.D_twist == r.bending.D_twist &&
          m.D_coupling == r.bending.D_coupling);
    fprintf(stderr, "    barbule cell: D_long %.6g, D_trans %.6g, D_twist %.6g N m, the same alone and in full\n",
            m.D_long, m.D_trans, m.D_twist);
    plume_homog_result_free(&r);
    l.phi = 1.2;
    CHECK(plume_homogenize_bending(&l, D, NULL, &err) == PLUME_EINVAL && strstr(err.msg, "phi"));
    CHECK(plume_homogenize_bending(NULL, D, NULL, &err) == PLUME_EINVAL);
}
