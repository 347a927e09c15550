/* apps/homogenize and apps/fit as a user runs them. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hdf5.h>
#include <jansson.h>

#include "app_runner.h"
#include "harness.h"
#include "../lib/io/curves.h"
#include "../lib/io/vtu.h"
#include "../include/plume/homogenize.h"

void test_app_homogenize_and_fit(void)
{
    char scratch[64] = "/tmp/plume-hom-XXXXXX", args[1024], path[256], out[16384], err[8192];
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/m.h5", scratch);
    snprintf(args, sizeof args, "--phi 0.16 --ratio 1e-6 --Eb 2.5e9 --nu-barb 0.3 --nu-barbule 0.3 --thickness 1e-4 "
                                "--steps 2 --strain-max 0.01 -o %s --json", path);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (j) {
        const char *keys[] = {"E_xx", "E_yy", "nu_xy", "G_xy", "seconds", "element_edge", "refinement_edge"};
        for (int k = 0; k < 7; k++)
            CHECK(json_is_number(json_object_get(j, keys[k])));
        /* the strips cell is exact at any mesh, and says so */
        double change = json_number_value(json_object_get(j, "refinement_change"));
        CHECK(change >= 0.0 && change < 1e-6);
        CHECK(json_integer_value(json_object_get(j, "order")) == 2);
        CHECK(json_is_number(json_object_get(json_object_get(j, "moduli_change"), "E_yy")));
        json_decref(j);
    }
    /* ... and so does /moduli */
    hid_t hf = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    double attr = -2.0;
    CHECK(hf >= 0 && H5Aexists_by_name(hf, "/moduli", "refinement_change", H5P_DEFAULT) > 0);
    if (hf >= 0) {
        hid_t a = H5Aopen_by_name(hf, "/moduli", "refinement_change", H5P_DEFAULT, H5P_DEFAULT);
        CHECK(a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, &attr) >= 0 && attr >= 0.0 && attr < 1e-6);
        if (a >= 0)
            H5Aclose(a);
        H5Fclose(hf);
    }
    plume_ortho m;
    plume_err e;
    CHECK(plume_moduli_read(path, &m, &e) == PLUME_OK);
    CHECK(m.E_xx > 1e5 * m.E_yy); /* barbs ~1e5 times stiffer than the vane across them */
    plume_curve c;
    CHECK(plume_curve_read(path, "cell", "shear", &c, &e) == PLUME_OK);
    plume_curve_free(&c);
    /* the moduli file drives a macro traction run */
    snprintf(args, sizeof args, "--moduli %s --steps 2 --quiet --json", path);
    CHECK(app_run(scratch, "traction", args, out, sizeof out, err, sizeof err) == 0);
    /* a curve file as a fit target */
    snprintf(args, sizeof args, "--moduli %s --steps 3 --quiet -o %s", path, path);
    CHECK(app_run(scratch, "traction", args, out, sizeof out, err, sizeof err) == 0);
    snprintf(args, sizeof args, "--target %s:macro/tilted --angle 45 --Exx %g --Eyy %g --Gxy %g --steps 3 --json", path,
             m.E_xx, 2.0 * m.E_yy, 0.5 * m.G_xy);
    CHECK(app_run(scratch, "fit", args, out, sizeof out, err, sizeof err) == 0);
    j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (j) {
        CHECK_REL(json_real_value(json_object_get(j, "G_xy")), m.G_xy, 1e-3, 0.0);
        json_decref(j);
    } else {
        fprintf(stderr, "    fit output: %s\n    stderr: %s\n", out, err);
    }
    /* bad inputs */
    const char *bad[][2] = {{"--phi 0", "phi"}, {"--phi 1", "phi"}, {"--ratio -2", "ratio"},
                            {"--e-rel 6", "narrower than an element"},
                            {"--layout barbules --barbule-spacing 1e-4", "barbule"},
                            {"--config /nonexistent.json", "/nonexistent.json"}, {"--phi x", "--phi"},
                            {"--order 3", "order must be 1 (linear) or 2"}, {"--order x", "--order"}};
    for (int k = 0; k < 9; k++) {
        CHECK(app_run(scratch, "homogenize", bad[k][0], out, sizeof out, err, sizeof err) != 0);
        if (!strstr(err, bad[k][1])) {
            plume_test_failures++;
            fprintf(stderr, "    homogenize %s: expected '%s' in: %s\n", bad[k][0], bad[k][1], err);
        }
    }
    snprintf(path, sizeof path, "%s/bad.json", scratch);
    FILE *f = fopen(path, "w");
    fputs("{\n  \"phi\": 0.2,\n  \"ratoi\": 1e-6\n}\n", f);
    fclose(f);
    snprintf(args, sizeof args, "--config %s", path);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 2);
    CHECK(strstr(err, "unknown key \"ratoi\"") != NULL);
    f = fopen(path, "w"); /* the element order is 1 or 2, in a file too */
    fputs("{\n  \"order\": 1.5\n}\n", f);
    fclose(f);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 2);
    CHECK(strstr(err, "key \"order\" must be 1 or 2 (got 1.5)") != NULL);
    CHECK(app_run(scratch, "fit", "--target /nonexistent.txt", out, sizeof out, err, sizeof err) != 0);
    CHECK(strstr(err, "/nonexistent.txt") != NULL);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}

/* --vtk: one series per load case from the rest state; the deformed cell is a periodic tile of
 * the macroscopic gradient, so its area (the area-weighted mean of J) is det F exactly (under
 * shear, whose normal stretches are free, det F read from the deformed cell's corners). A load case at rest has J = 1 and zero strain. */
void test_app_homogenize_vtk(void)
{
    char scratch[64] = "/tmp/plume-hvtk-XXXXXX", args[512], out[8192], err[8192], path[512];
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "--steps 2 --vtk %s/v", scratch);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    const char *cases[3] = {"uniaxial_x", "uniaxial_y", "shear"};
    for (int c = 0; c < 3; c++) {
        plume_pvd_entries e;
        plume_err pe = {{0}};
        snprintf(path, sizeof path, "%s/v/%s/steps.pvd", scratch, cases[c]);
        CHECK(plume_pvd_read(path, &e, &pe) == PLUME_OK && e.n == 3);
        for (int i = 0; i < e.n; i++) {
            plume_vtu_data d;
            snprintf(path, sizeof path, "%s/v/%s/%s", scratch, cases[c], e.files[i]);
            CHECK(plume_vtu_read(path, &d, &pe) == PLUME_OK);
            const plume_vtu_array *J = plume_vtu_find(&d, 0, "J"), *E = plume_vtu_find(&d, 0, "green_strain_barb");
            if (!J || !E || !d.points) {
                CHECK(0);
                plume_vtu_data_free(&d);
                continue;
            }
            /* reference areas from the rest frame's points: frame 0 is the rest state */
            double area = 0.0, jarea = 0.0, emax = 0.0;
            plume_vtu_data rest;
            snprintf(path, sizeof path, "%s/v/%s/%s", scratch, cases[c], e.files[0]);
            CHECK(plume_vtu_read(path, &rest, &pe) == PLUME_OK);
            for (plume_index t = 0; rest.points && t < d.ncells; t++) {
                const plume_index *v = d.connectivity + 3 * t;
                const double *a = rest.points + 3 * v[0], *b = rest.points + 3 * v[1], *q = rest.points + 3 * v[2];
                double A = 0.5 * fabs((b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]));
                area += A, jarea += J->values[t] * A;
                emax = fmax(emax, fabs(E->values[3 * t]) + fabs(E->values[3 * t + 1]) + fabs(E->values[3 * t + 2]));
            }
            /* det Fbar from the deformed lattice vectors: the corners (0, 0), (a, 0), (0, b) */
            double detF = 1.0;
            if (rest.points && d.npoints == rest.npoints) {
                plume_index o0 = 0, ox = 0, oy = 0;
                for (plume_index v = 0; v < rest.npoints; v++) {
                    const double *p = rest.points + 3 * v, *q0 = rest.points + 3 * o0;
                    const double *qx = rest.points + 3 * ox, *qy = rest.points + 3 * oy;
                    if (p[0] + p[1] < q0[0] + q0[1])
                        o0 = v;
                    if (p[0] - p[1] > qx[0] - qx[1])
                        ox = v;
                    if (p[1] - p[0] > qy[1] - qy[0])
                        oy = v;
                }
                const double *r0 = rest.points + 3 * o0, *rx = rest.points + 3 * ox, *ry = rest.points + 3 * oy;
                const double *x0 = d.points + 3 * o0, *xx = d.points + 3 * ox, *xy = d.points + 3 * oy;
                double A0 = (rx[0] - r0[0]) * (ry[1] - r0[1]) - (rx[1] - r0[1]) * (ry[0] - r0[0]);
                detF = ((xx[0] - x0[0]) * (xy[1] - x0[1]) - (xx[1] - x0[1]) * (xy[0] - x0[0])) / A0;
            }
            plume_vtu_data_free(&rest);
            if (i == 0)
                CHECK(fabs(jarea / area - 1.0) < 1e-14 && emax < 1e-14);
            else if (c == 2) /* shear at free normal stretches: a periodic tile of Fbar, area det Fbar */
                CHECK(fabs(jarea / area - detF) < 1e-12 && fabs(detF - 1.0) < 0.01 && emax > 1e-3);
            else
                CHECK(jarea / area > 1.0 + 0.01 * i); /* stretched by 2.5 % a step, contracting less */
            if (c == 2 && i == 2)
                fprintf(stderr, "    shear 0.05: cell area ratio - 1 = %.2g\n", jarea / area - 1.0);
            plume_vtu_data_free(&d);
        }
        plume_pvd_entries_free(&e);
    }
    CHECK(app_run(scratch, "homogenize", "--strain-max 0 --vtk x", out, sizeof out, err, sizeof err) == 2);
    CHECK(strstr(err, "--vtk") != NULL);
    snprintf(path, sizeof path, "rm -rf '%s'", scratch);
    CHECK(system(path) == 0);
}

/* A layout with hooks: the moduli as before, and the barb line's separation law in the summary,
 * in --json and in the file, where plume_separation_read finds it. */
void test_app_homogenize_separation(void)
{
    char scratch[64] = "/tmp/plume-hom-XXXXXX", args[1024], path[256], out[16384], err[8192];
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/m.h5", scratch);
    snprintf(args, sizeof args, "--config ../data/layout_kovalev.json --e-rel 0.3 --no-convergence --strain-max 0 "
                                "-o %s --json", path);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    json_t *j = json_loads(out, 0, NULL), *s = json_object_get(j, "separation");
    CHECK(json_is_object(s));
    const double strength = json_real_value(json_object_get(s, "strength"));
    CHECK_REL(strength, 1.4e-5 / 1.2e-5, 2e-4, 0.0); /* one 14 uN hooklet per 12 um, pulled straight */
    CHECK(json_real_value(json_object_get(s, "energy")) > 0.0);
    plume_separation_law law;
    plume_err e = {{0}};
    CHECK(plume_separation_read(path, &law, &e) == PLUME_OK);
    CHECK_REL(law.strength, strength, 1e-10, 0.0); /* --json prints 12 digits */
    CHECK(law.capture > 0.0 && law.opening > 0.0);
    json_decref(j);
    /* without --json: the summary names the law */
    snprintf(args, sizeof args, "--config ../data/layout_kovalev.json --e-rel 0.3 --no-convergence --strain-max 0");
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    CHECK(strstr(out, "separation of a barb line (hooks): strength 1.1667") != NULL);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}
