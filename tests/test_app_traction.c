/* apps/traction as a user runs it: bad inputs give a clear message and a non-zero exit without
 * leaving an output file; a good run writes HDF5 and a JSON summary with the documented keys. */
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

static char scratch[64];

static int run_app(const char *args, char *out, size_t nout, char *errtxt, size_t nerr)
{
    return app_run(scratch, "traction", args, out, nout, errtxt, nerr);
}

static void expect_error(const char *args, const char *needle)
{
    char out[8192], err[8192];
    int rc = run_app(args, out, sizeof out, err, sizeof err);
    CHECK(rc != 0);
    if (!strstr(err, needle)) {
        plume_test_failures++;
        fprintf(stderr, "    traction %s: expected '%s' in: %s\n", args, needle, err);
    }
}

void test_app_traction_bad_inputs(void)
{
    strcpy(scratch, "/tmp/plume-app-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    char args[1024], path[256];
    expect_error("--Eyy -1 --quiet", "E_yy");
    expect_error("--Gxy nan --quiet", "--Gxy expects a finite number");
    expect_error("--Exx 1e4 --nu 200 --quiet", "nu");
    expect_error("--angle 200 --quiet", "angle");
    expect_error("--lx 0 --quiet", "zero-area");
    expect_error("--steps 0 --quiet", "--steps");
    expect_error("--solver magic --quiet", "newton|ipopt|linearized");
    expect_error("--frobnicate", "unknown option");
    expect_error("--moduli /nonexistent/moduli.h5 --quiet", "/nonexistent/moduli.h5");
    /* load paths and hooks: a strain that is not a number, a leg that does not move, a negative
     * strength, a capture beyond the barbule spacing, hooks on a strips layout */
    expect_error("--path 0.01,x --quiet", "--path: strain 2 of '0.01,x' is not a number");
    expect_error("--path 0.01,0.01 --quiet", "--path: strain 2 (0.01) must be > -1 and differ from the one before");
    expect_error("--peel 2 --quiet", "--peel must be in [0, 1] (got 2)");
    expect_error("--top-grip-free 1 --quiet", "--top-grip-free must be in [0, 1) (got 1)");
    expect_error("--model micro --layout-config ../data/layout_hooks.json --lx 4e-3 --ly 5.2e-3 --hook-strength -1 "
                 "--quiet", "hook_strength must be finite and >= 0");
    expect_error("--model micro --layout-config ../data/layout_hooks.json --lx 4e-3 --ly 5.2e-3 --hook-capture 1e-3 "
                 "--quiet", "hook_capture = 0.001 m must be less than barbule_spacing = 0.0008 m");
    expect_error("--model micro --layout strips --hook-strength 1e-3 --quiet", "needs the layout \"barbules\"");
    /* malformed sample file: the message names the file and the line */
    snprintf(path, sizeof path, "%s/bad.json", scratch);
    FILE *f = fopen(path, "w");
    fputs("{\"samples\": [\n  {\"id\": \"L01\", \"scenario\": \"longitudinal\",\n   \"lx_mm\": 9,, }\n]}\n", f);
    fclose(f);
    snprintf(args, sizeof args, "--sample L01 --samples %s --quiet", path);
    expect_error(args, ":3:");
    expect_error("--sample Z99 --samples ../data/samples.json --quiet", "Z99");
    /* constrained barbs spanning both grips: clear message, non-zero exit, no file left behind */
    snprintf(path, sizeof path, "%s/span.h5", scratch);
    snprintf(args, sizeof args, "--scenario longitudinal --edge 0.2 -o %s --quiet", path);
    expect_error(args, "span both grips");
    CHECK(access(path, F_OK) != 0);
}

void test_app_traction_run(void)
{
    char args[1024], path[256], out[16384], err[8192];
    snprintf(path, sizeof path, "%s/run.h5", scratch);
    /* a sample of Table 1, transverse, with the default vane moduli */
    snprintf(args, sizeof args, "--sample T01 --samples ../data/samples.json --edge 0.002 --steps 3 -o %s --json --quiet", path);
    int rc = run_app(args, out, sizeof out, err, sizeof err);
    CHECK(rc == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (!j) {
        fprintf(stderr, "    output: %s\n    stderr: %s\n", out, err);
        return;
    }
    const char *keys[] = {"initial_slope", "stress_at_max_strain", "wbar_at_max_strain", "elements", "vertices",
                          "newton_iterations", "max_constraint_violation", "converged", "solver", "seconds"};
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
        CHECK(json_object_get(j, keys[k]) != NULL);
    CHECK(json_is_true(json_object_get(j, "converged")));
    CHECK(strcmp(json_string_value(json_object_get(j, "scenario")), "transverse") == 0);
    double slope = json_real_value(json_object_get(j, "initial_slope"));
    /* transverse pull with nu = 0: nominal stress F / (lx h) over strain = E_yy = 1 Pa */
    CHECK_REL(slope, 1.0, 2e-3, 0.0);
    json_decref(j);
    plume_curve c;
    plume_err e;
    CHECK(plume_curve_read(path, "macro", "transverse", &c, &e) == PLUME_OK);
    CHECK(c.n == 4);
    if (c.n == 4) {
        CHECK(c.stress[3] > c.stress[1]);
        CHECK_REL(c.strain[3], 0.05, 1e-14, 0.0);
    }
    plume_curve_free(&c);
    /* a second scenario into the same file keeps the first one */
    snprintf(args, sizeof args, "--scenario tilted --edge 0.1 --steps 2 -o %s --quiet --plot %s/run.png", path, scratch);
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
    CHECK(plume_curve_read(path, "macro", "transverse", &c, &e) == PLUME_OK);
    plume_curve_free(&c);
    CHECK(plume_curve_read(path, "macro", "tilted", &c, &e) == PLUME_OK);
    plume_curve_free(&c);
    snprintf(path, sizeof path, "%s/run.svg", scratch);
    CHECK(access(path, F_OK) == 0);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}

/* The shipped hooked layout (data/layout_hooks.json) loaded, unloaded and reloaded: hooks let go
 * and catch again, the summary's energy balance closes. */
void test_app_traction_hooks(void)
{
    strcpy(scratch, "/tmp/plume-app-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    char out[16384], err[8192], args[1024];
    snprintf(args, sizeof args, "--model micro --layout-config ../data/layout_hooks.json --lx 4e-3 --ly 5.2e-3 "
             "--thickness 1e-4 --steps 4 --path 0.003,0,0.003 --no-convergence --json --quiet --vtk %s/vtk "
             "-o %s/hooks.h5", scratch, scratch);
    int rc = run_app(args, out, sizeof out, err, sizeof err);
    CHECK(rc == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (j) {
        const long released = (long)json_integer_value(json_object_get(j, "hooks_released"));
        const long caught = (long)json_integer_value(json_object_get(j, "hooks_reengaged"));
        const double W = json_real_value(json_object_get(j, "work")),
                     D = json_real_value(json_object_get(j, "dissipated_energy")),
                     E = json_real_value(json_object_get(j, "stored_energy")),
                     bal = json_real_value(json_object_get(j, "energy_balance_error"));
        printf("    %ld hooks let go, %ld caught again; work %.4g J, dissipated %.4g J, stored %.4g J, balance %.2e\n",
               released, caught, W, D, E, bal);
        CHECK(json_is_true(json_object_get(j, "converged")));
        CHECK(released > 0 && caught > 0 && D > 0.0 && W > 0.0);
        CHECK(fabs(bal) < 1e-2);
        CHECK(json_integer_value(json_object_get(j, "largest_cascade")) >= 1);
        json_decref(j);
    } else
        fprintf(stderr, "    output: %s\n    stderr: %s\n", out, err);
    /* -o: the hooks' pairs' states at every point of the curve, /curves/micro/tilted/hooks */
    long rows = 0, cols = 0;
    int *table = NULL;
    {
        char path[256];
        snprintf(path, sizeof path, "%s/hooks.h5", scratch);
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        hid_t ds = f >= 0 ? H5Dopen2(f, "/curves/micro/tilted/hooks", H5P_DEFAULT) : -1;
        hid_t sp = ds >= 0 ? H5Dget_space(ds) : -1;
        hsize_t dims[2] = {0, 0};
        if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == 2 && H5Sget_simple_extent_dims(sp, dims, NULL) == 2) {
            rows = (long)dims[0], cols = (long)dims[1];
            table = malloc((size_t)(rows * cols) * sizeof *table);
            if (table && H5Dread(ds, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, table) < 0) {
                free(table);
                table = NULL;
            }
        }
        if (sp >= 0)
            H5Sclose(sp);
        if (ds >= 0)
            H5Dclose(ds);
        if (f >= 0)
            H5Fclose(f);
    }
    CHECK(table != NULL && rows == 13 && cols > 0); /* the rest state and 3 legs of 4 steps */
    /* --vtk: each step's hooks as lines, their state 1 at rest and some 0 at the top of the first load;
     * the table's rows the same */
    for (int step = 0; step <= 4; step += 4) {
        char path[256];
        snprintf(path, sizeof path, "%s/vtk/micro/step_hooks_%05d.vtu", scratch, step);
        plume_vtu_data d;
        plume_err e = {{0}};
        CHECK(plume_vtu_read(path, &d, &e) == PLUME_OK);
        const plume_vtu_array *s = plume_vtu_find(&d, 0, "state");
        CHECK(s != NULL && s->ntuples > 0);
        double engaged = 0.0;
        for (plume_index i = 0; s && i < s->ntuples; i++)
            engaged += s->values[i];
        long in_table = 0;
        for (long c = 0; table && c < cols; c++)
            in_table += table[step * cols + c];
        printf("    step %d: %.0f of %ld hook pairs engaged (the -o table: %ld of %ld)\n", step, engaged,
               s ? (long)s->ntuples : 0L, in_table, cols);
        CHECK(s && (step == 0 ? engaged == s->ntuples : engaged < s->ntuples));
        CHECK(s && cols == (long)s->ntuples && in_table == (long)engaged);
        plume_vtu_data_free(&d);
    }
    free(table);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}

/* --model both: micro and macro curves in one file, their difference in the JSON summary. */
void test_app_traction_both_models(void)
{
    char args[1024], path[256], out[16384], err[8192];
    strcpy(scratch, "/tmp/plume-both-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/both.h5", scratch);
    snprintf(args, sizeof args, "--model both --dB-rel 0.17 --steps 2 -o %s --plot %s/both.png --json --quiet", path,
             scratch);
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (j) {
        json_t *d = json_object_get(j, "relative_difference");
        CHECK(json_is_number(json_object_get(d, "stress_at_max_strain_relative")));
        CHECK(json_is_object(json_object_get(j, "micro")) && json_is_object(json_object_get(j, "macro")));
        CHECK(strcmp(json_string_value(json_object_get(json_object_get(j, "moduli"), "source")), "homogenised") == 0);
        CHECK(json_is_true(json_object_get(j, "converged")));
        /* the micro curve says how converged it is: quadratic elements, within 2 % of a mesh twice as coarse */
        json_t *micro = json_object_get(j, "micro");
        double change = json_number_value(json_object_get(micro, "refinement_change"));
        CHECK(json_integer_value(json_object_get(micro, "order")) == 2 && change >= 0.0 && change < 0.02);
        CHECK(json_is_true(json_object_get(json_object_get(micro, "refinement"), "converged")));
        CHECK(json_object_get(json_object_get(j, "macro"), "refinement_change") == NULL);
        json_decref(j);
    } else {
        fprintf(stderr, "    output: %s\n    stderr: %s\n", out, err);
    }
    plume_curve c;
    plume_err e;
    CHECK(plume_curve_read(path, "micro", "tilted", &c, &e) == PLUME_OK);
    plume_curve_free(&c);
    CHECK(plume_curve_read(path, "macro", "tilted", &c, &e) == PLUME_OK);
    plume_curve_free(&c);
    /* a bad layout is refused with the field named */
    snprintf(args, sizeof args, "--model micro --phi 1.5 --quiet");
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 2);
    CHECK(strstr(err, "phi") != NULL);
    snprintf(args, sizeof args, "--model micro --order 3 --quiet");
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 2);
    CHECK(strstr(err, "order must be 1 (linear) or 2") != NULL);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}

/* --size-effect: the micro specimen at finer barb spacings approaches the macro curve, which is
 * its limit (docs/micro-convergence.md): halving d_B from 0.086 l_y brings the end stress closer
 * to the macro one from above (coarser spacings swing with the barbs' phase against the corners:
 * 0.17 -> 0.085 goes +27 % -> +64 %); the family lands in /curves/micro_dB<V>/ and on the chart; bad lists are
 * refused with the flag named. */
void test_app_traction_size_effect(void)
{
    char args[1024], path[256], out[16384], err[8192];
    strcpy(scratch, "/tmp/plume-size-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/size.h5", scratch);
    snprintf(args, sizeof args,
             "--model both --dB-rel 0.086 --size-effect 0.043 --steps 2 --no-convergence -o %s --plot %s/size.png "
             "--json --quiet", path, scratch);
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    json_t *fam = j ? json_object_get(j, "size_effect") : NULL;
    CHECK(json_array_size(fam) == 2);
    if (json_array_size(fam) == 2) {
        double d0 = json_number_value(json_object_get(json_array_get(fam, 0), "relative_to_macro"));
        double d1 = json_number_value(json_object_get(json_array_get(fam, 1), "relative_to_macro"));
        /* stiffer than the limit, and closer to it at the finer spacing */
        CHECK(d0 > 0.0 && d1 > 0.0 && d1 < d0);
        CHECK(fabs(json_number_value(json_object_get(json_array_get(fam, 1), "dB_rel")) - 0.043) < 1e-12);
        if (!(d1 < d0))
            fprintf(stderr, "    micro - macro: %g at 0.086, %g at 0.043\n", d0, d1);
    } else
        fprintf(stderr, "    output: %s\n    stderr: %s\n", out, err);
    json_decref(j);
    plume_curve c;
    plume_err e;
    CHECK(plume_curve_read(path, "micro_dB0.043", "tilted", &c, &e) == PLUME_OK);
    plume_curve_free(&c);
    snprintf(args, sizeof args, "%s/size.png", scratch);
    CHECK(access(args, R_OK) == 0);
    expect_error("--model both --size-effect 0.2", "--size-effect expects spacings");
    expect_error("--model both --size-effect 0.05,0.06", "each finer than the one before");
    expect_error("--model macro --size-effect 0.05", "--size-effect needs --model micro or both");
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}

/* --vtk: both models' deformed samples as ParaView series at the nominal strains; the macro
 * barbs keep their length (constraint) and so does the barb-direction Green strain of every
 * triangle of the aligned mesh, while the sample stretches to ly (1 + strain). */
void test_app_traction_vtk(void)
{
    char args[1024], path[512], out[16384], err[8192];
    strcpy(scratch, "/tmp/plume-tvtk-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "--model both --dB-rel 0.17 --steps 2 --vtk %s/v --quiet", scratch);
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
    const char *scales[2] = {"macro", "micro"};
    for (int s = 0; s < 2; s++) {
        plume_pvd_entries e;
        plume_err pe = {{0}};
        snprintf(path, sizeof path, "%s/v/%s/steps.pvd", scratch, scales[s]);
        CHECK(plume_pvd_read(path, &e, &pe) == PLUME_OK);
        int tri = 0, barbs = 0;
        const char *last = NULL, *last_barbs = NULL;
        for (int i = 0; i < e.n; i++) {
            if (e.parts[i] == 1) {
                barbs++, last_barbs = e.files[i];
                continue;
            }
            CHECK(fabs(e.times[i] - 0.025 * tri) < 1e-15);
            tri++, last = e.files[i];
        }
        CHECK(tri == 3 && barbs == (s == 0 ? 3 : 0));
        plume_vtu_data d;
        snprintf(path, sizeof path, "%s/v/%s/%s", scratch, scales[s], last ? last : "none");
        CHECK(plume_vtu_read(path, &d, &pe) == PLUME_OK);
        if (d.points) {
            double ymax = -1.0;
            for (plume_index v = 0; v < d.npoints; v++)
                ymax = fmax(ymax, d.points[3 * v + 1]);
            CHECK(fabs(ymax - 1.3 * 1.05) < 1e-12);
            const plume_vtu_array *E = plume_vtu_find(&d, 0, "green_strain_barb"), *m = plume_vtu_find(&d, 0, "material");
            CHECK(E && m);
            double ebb = 0.0, ett = 0.0, mmax = 0.0;
            for (plume_index c = 0; E && m && c < d.ncells; c++)
                ebb = fmax(ebb, fabs(E->values[3 * c])), ett = fmax(ett, E->values[3 * c + 1]), mmax = fmax(mmax, m->values[c]);
            if (s == 0)
                CHECK(ebb < 1e-8 && ett > 1e-3); /* inextensible barbs, stretched matrix */
            else
                CHECK(mmax == 1.0); /* barbs and barbules */
            fprintf(stderr, "    %s: largest barb-direction strain %.2g, transverse %.3g\n", scales[s], ebb, ett);
        }
        plume_vtu_data_free(&d);
        if (last_barbs) {
            snprintf(path, sizeof path, "%s/v/%s/%s", scratch, scales[s], last_barbs);
            CHECK(plume_vtu_read(path, &d, &pe) == PLUME_OK);
            const plume_vtu_array *b = plume_vtu_find(&d, 0, "barb_strain");
            double bmax = 0.0;
            for (plume_index c = 0; b && c < b->ntuples; c++)
                bmax = fmax(bmax, fabs(b->values[c]));
            CHECK(b && b->ntuples > 10 && bmax < 1e-8);
            plume_vtu_data_free(&d);
        }
        plume_pvd_entries_free(&e);
    }
    expect_error("--steps 1 --vtk /dev/null/x --quiet", "--vtk /dev/null/x: cannot create the directory");
    snprintf(path, sizeof path, "rm -rf '%s'", scratch);
    CHECK(system(path) == 0);
}

/* --bending: the macro plate's curve in /curves/bending/macro/cylinder_90 at the curvature asked
 * for (the plate's own prediction), the plate at the default contrast, and each bad input refused
 * naming its flag. */
void test_app_traction_bending(void)
{
    strcpy(scratch, "/tmp/plume-app-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    expect_error("--bending roll", "--bending expects cylinder|twist");
    expect_error("--bending twist --curvature -0.01", "--curvature must be finite and > 0");
    expect_error("--bending cylinder --strain-max 0.1", "--bending cannot be combined with --strain-max");
    expect_error("--bending cylinder --vtk out", "--bending cannot be combined with --vtk");
    expect_error("--bending cylinder --curvature 100", "beyond linear plate theory");
    expect_error("--bending cylinder --layout barbules --phi 0.3 --ratio 1", "couples bending and twist");
    char out[8192], err[8192], path[128];
    snprintf(path, sizeof path, "%s/b.h5", scratch);
    char args[256];
    snprintf(args, sizeof args, "--bending cylinder --angle 90 --model macro --phi 0.3 --ratio 0.05 --curvature 0.02 -o %s", path);
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
    plume_bend_curve c;
    plume_err e = {{0}};
    CHECK(plume_bend_curve_read(path, "macro", "cylinder_90", &c, &e) == PLUME_OK);
    if (c.n == 3)
        CHECK_REL(c.curvature[2], 0.02, 0.03, 0.0);
    CHECK(c.n == 3);
    CHECK(strstr(err, "warning") == NULL);
    plume_bend_curve_free(&c);
    unlink(path);
    /* at the default contrast (1e-6, D_trans = 8e-6 D_long) the plate reproduces plate theory
     * along and across the barbs, without the departure warning */
    const char *defaults[2] = {"--bending cylinder --model macro --json", "--bending cylinder --angle 90 --model macro --json"};
    for (int k = 0; k < 2; k++) {
        CHECK(run_app(defaults[k], out, sizeof out, err, sizeof err) == 0);
        CHECK(strstr(err, "warning") == NULL);
        double pred = NAN, macro = NAN;
        const char *a = strstr(out, "\"predicted_stiffness\": "), *b = strstr(out, "\"macro_stiffness\": ");
        if (a && b) {
            pred = strtod(a + strlen("\"predicted_stiffness\": "), NULL);
            macro = strtod(b + strlen("\"macro_stiffness\": "), NULL);
        }
        CHECK_REL(macro, pred, 0.01, 0.0);
    }
    rmdir(scratch);
}

/* --bending --size-effect: the micro specimen again at a finer spacing, written as
 * /curves/bending/micro_dB<V>/..., summarised in the JSON (the finer spacing nearer macro, at 45 deg
 * where the size effect is largest) and charted; the twist, gripped by the uniform-curvature
 * loads, within 2 % at every spacing; bad spacings refused naming the flag. Spacings lx/2 and lx/4
 * on an element edge of 0.7 barb widths (about 1 s). */
void test_app_traction_bending_size_effect(void)
{
    strcpy(scratch, "/tmp/plume-app-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    expect_error("--bending cylinder --model macro --size-effect 0.05", "--size-effect needs --model micro or both");
    expect_error("--bending cylinder --model both --dB-rel 0.1 --size-effect 0.2", "--size-effect expects spacings");
    char out[8192], err[8192], path[128], png[128], args[512];
    snprintf(path, sizeof path, "%s/b.h5", scratch);
    snprintf(png, sizeof png, "%s/b.png", scratch);
    const char *loads[2] = {"cylinder --angle 45", "twist"};
    for (int k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "--bending %s --model both --phi 0.3 --ratio 0.05 --e-rel 0.7 --dB-rel 0.25 "
                 "--size-effect 0.125 --json --quiet -o %s --plot %s", loads[k], path, png);
        CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
        const char *a = strstr(out, "\"size_effect\": ");
        double rel[2] = {NAN, NAN};
        for (int i = 0; i < 2 && a; i++)
            if ((a = strstr(a + 1, "\"relative_to_macro\": ")))
                rel[i] = strtod(a + strlen("\"relative_to_macro\": "), NULL);
        fprintf(stderr, "    %s: micro - macro %+.2f %% (d_B lx/2), %+.2f %% (lx/4)\n", loads[k], 100.0 * rel[0],
                100.0 * rel[1]);
        if (k == 0)
            CHECK(fabs(rel[1]) < fabs(rel[0]));
        else
            CHECK(fabs(rel[0]) < 0.02 && fabs(rel[1]) < 0.02 && strstr(out, "\"loads\": \"uniform curvature\""));
        CHECK(access(png, R_OK) == 0);
        plume_bend_curve c;
        plume_err e = {{0}};
        CHECK(plume_bend_curve_read(path, "micro_dB0.125", k ? "twist_0" : "cylinder_45", &c, &e) == PLUME_OK);
        CHECK(c.n == 3);
        plume_bend_curve_free(&c);
        unlink(path), unlink(png);
        snprintf(png, sizeof png, "%s/b.svg", scratch);
        unlink(png);
        snprintf(png, sizeof png, "%s/b.png", scratch);
    }
    rmdir(scratch);
}

/* --split-lines: a barb line of the macro sample with the separation law apps/homogenize wrote for
 * a layout with hooks lets go at its strength, zips again when the grip comes back within the
 * capture distance (5 um) and lets go again on the reload; the .vtu series holds its pairs'
 * states; bad combinations are named. */
void test_app_traction_splits(void)
{
    strcpy(scratch, "/tmp/plume-app-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    char out[16384], err[8192], args[1024], law_path[256];
    snprintf(law_path, sizeof law_path, "%s/cell.h5", scratch);
    snprintf(args, sizeof args, "--config ../data/layout_kovalev.json --e-rel 0.3 --no-convergence --strain-max 0 -o %s",
             law_path);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    plume_separation_law law;
    plume_err e = {{0}};
    CHECK(plume_separation_read(law_path, &law, &e) == PLUME_OK);
    snprintf(args, sizeof args, "--moduli %s --scenario transverse --lx 1e-3 --ly 1e-3 --thickness 1e-4 "
             "--split-lines 1 --path 0.008,0.0045,0.008 --steps 10 --quiet --json --vtk %s/vtk", law_path, scratch);
    CHECK(run_app(args, out, sizeof out, err, sizeof err) == 0);
    json_t *j = json_loads(out, 0, NULL);
    CHECK(j != NULL);
    if (j) {
        const long pairs = (long)json_integer_value(json_object_get(j, "split_pairs"));
        const long released = (long)json_integer_value(json_object_get(j, "hooks_released"));
        const long caught = (long)json_integer_value(json_object_get(j, "hooks_reengaged"));
        const double peak = json_real_value(json_object_get(j, "peak_stress")) * 1e-4; /* N/m */
        printf("    %ld pairs: %ld let go, %ld caught again; peak traction %.5g N/m (strength %.5g N/m)\n", pairs,
               released, caught, peak, law.strength);
        CHECK(json_is_true(json_object_get(j, "converged")));
        CHECK(pairs > 10 && released == 2 * pairs && caught == pairs);
        CHECK(peak >= law.strength * (1.0 - 1e-3) && peak <= law.strength * 1.02);
        CHECK(fabs(json_real_value(json_object_get(j, "energy_balance_error"))) < 1e-2);
        json_decref(j);
    } else
        fprintf(stderr, "    output: %s\n    stderr: %s\n", out, err);
    /* let go at the top of the first load (step 10), caught again at 4.5 um (step 20) */
    for (int step = 10; step <= 20; step += 10) {
        char path[256];
        snprintf(path, sizeof path, "%s/vtk/macro/step_splits_%05d.vtu", scratch, step);
        plume_vtu_data d;
        CHECK(plume_vtu_read(path, &d, &e) == PLUME_OK);
        const plume_vtu_array *s = plume_vtu_find(&d, 0, "state");
        double engaged = 0.0;
        for (plume_index i = 0; s && i < s->ntuples; i++)
            engaged += s->values[i];
        printf("    step %d: %.0f of %ld pairs engaged\n", step, engaged, s ? (long)s->ntuples : 0L);
        CHECK(s && s->ntuples > 0 && engaged == (step == 10 ? 0.0 : (double)s->ntuples));
        plume_vtu_data_free(&d);
    }
    snprintf(args, sizeof args, "--moduli %s --split-lines 1 --mesh unaligned --quiet", law_path);
    expect_error(args, "--split-lines needs --mesh aligned");
    expect_error("--split-lines 1 --quiet", "--split-lines needs a separation law");
    char plain[256];
    snprintf(plain, sizeof plain, "%s/plain.h5", scratch);
    snprintf(args, sizeof args, "--strain-max 0 --no-convergence -o %s", plain);
    CHECK(app_run(scratch, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    snprintf(args, sizeof args, "--moduli %s --split-lines 1 --quiet", plain);
    expect_error(args, "separation_strength missing");
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}
