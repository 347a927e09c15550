/* apps/fit --bending as a user runs it: traction --bending writes the curves of a small strip
 * layout, fit --bending gives back bending moduli; bad input is refused naming the flag or the
 * file. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "app_runner.h"
#include "harness.h"
#include "../lib/io/curves.h"

static char scratch[64];

static int run(const char *app, const char *args, char *out, size_t nout, char *err, size_t nerr)
{
    return app_run(scratch, app, args, out, nout, err, nerr);
}

static void expect_fit_error(const char *args, const char *needle)
{
    char out[8192], err[8192];
    const int rc = run("fit", args, out, sizeof out, err, sizeof err);
    CHECK(rc == 2);
    if (!strstr(err, needle)) {
        plume_test_failures++;
        fprintf(stderr, "    fit %s: expected '%s' in: %s\n", args, needle, err);
    }
}

/* a number of a JSON object printed on stdout (NaN when missing) */
static double json_num(const char *text, const char *key)
{
    json_t *j = json_loads(text, 0, NULL);
    json_t *v = j ? json_object_get(j, key) : NULL;
    const double x = v ? json_number_value(v) : NAN;
    json_decref(j);
    return x;
}

static int make_scratch(void)
{
    strcpy(scratch, "/tmp/plume-fitb-XXXXXX");
    return mkdtemp(scratch) != NULL;
}

static void remove_scratch(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", scratch);
    CHECK(system(cmd) == 0);
}

/* Each bad input: exit 2 and a message naming the flag or the file. */
void test_app_fit_bending_bad_input(void)
{
    if (!make_scratch()) {
        CHECK(0);
        return;
    }
    char args[1024], path[256], out[8192], err[8192];
    /* the flags of the two fits do not mix */
    expect_fit_error("--bending x.h5 --target y.h5:micro/tilted", "--bending cannot be combined with --target");
    expect_fit_error("--bending x.h5 --Eyy 3", "--bending cannot be combined with --Eyy");
    expect_fit_error("--bending x.h5 --angle 45", "--bending cannot be combined with --angle");
    expect_fit_error("--bending x.h5 --plot p.png", "--bending cannot be combined with --plot");
    expect_fit_error("--target y.h5:micro/tilted --D-twist 1e-5", "--D-twist is a start value of a bending fit");
    expect_fit_error("--bending x.h5 --free Eyy", "--free: 'Eyy' is not a bending modulus");
    expect_fit_error("--bending x.h5 --D-long -1", "--D-long must be finite and > 0");
    /* files: missing, not HDF5, without bending curves */
    snprintf(args, sizeof args, "--bending %s/none.h5", scratch);
    expect_fit_error(args, "none.h5");
    snprintf(path, sizeof path, "%s/text.h5", scratch);
    FILE *f = fopen(path, "w");
    fputs("not hdf5\n", f);
    fclose(f);
    snprintf(args, sizeof args, "--bending %s", path);
    expect_fit_error(args, "is not an HDF5 file");
    /* a membrane curves file: no bending curves */
    snprintf(path, sizeof path, "%s/membrane.h5", scratch);
    snprintf(args, sizeof args, "--edge 0.2 --steps 2 --strain-max 0.01 --quiet -o %s", path);
    CHECK(run("traction", args, out, sizeof out, err, sizeof err) == 0);
    snprintf(args, sizeof args, "--bending %s", path);
    expect_fit_error(args, "no bending curves");
    /* one macro curve cannot determine four moduli; a scale the file does not have */
    snprintf(path, sizeof path, "%s/one.h5", scratch);
    snprintf(args, sizeof args, "--bending cylinder --model macro --phi 0.3 --ratio 0.05 --edge 0.002 --quiet -o %s",
             path);
    CHECK(run("traction", args, out, sizeof out, err, sizeof err) == 0);
    snprintf(args, sizeof args, "--bending %s:macro", path);
    expect_fit_error(args, "1 distinct curve(s) (load, angle) cannot determine 4 moduli");
    snprintf(args, sizeof args, "--bending %s", path);
    expect_fit_error(args, "/curves/bending/micro");
    remove_scratch();
}

/* End to end: a strip layout (barbs 0.3 of the spacing, matrix 20 times softer, d_B = lx / 4 on
 * the 10 x 20 mm specimen) bent along the barbs at curvature 0.01 1/m and twisted at 0.02 1/m,
 * both scales (traction --bending --model both); fit --bending on the micro curves frees D_long and
 * D_twist (two curves, two moduli; D_trans and D_coupling keep the cell's values) from a start
 * twice too stiff and half too soft.
 *
 * What the fit can promise: it inverts the plate test, so the fitted moduli make the plate
 * reproduce the micro curves, and they differ from the cell's D by the micro/macro stiffness
 * ratio that traction reports (the size effect of the specimen, 0.3 % and 3.4 % here); the model
 * mesh (edge lx/10 against traction's lx/20, for speed) does not change the plate, which the edge
 * moments make exact on any mesh (tests/test_plate_bending.c). Asserted: each fitted
 * modulus over the cell's is the micro/macro ratio to 2 %, D_long within 3 % of the cell's, and
 * the misfit below 1e-3 (two moduli for two linear curves: an exact fit up to the tolerance). The
 * macro curves, fitted with the model on traction's own mesh, give back the cell's D_long and
 * D_twist to 2 %: measured 1.0 % and 1e-5 from this start (the misfit barely changes along a
 * valley in D_long in which BOBYQA stops, "xtol reached"). -o writes /moduli with the fitted D. */
void test_app_fit_bending_end_to_end(void)
{
    if (!make_scratch()) {
        CHECK(0);
        return;
    }
    char args[1024], path[256], out[8192], err[8192];
    snprintf(path, sizeof path, "%s/bend.h5", scratch);
    double ratio[2] = {NAN, NAN}, D[2] = {NAN, NAN};
    const char *loads[2] = {"cylinder --curvature 0.01", "twist --curvature 0.02"};
    for (int k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "--bending %s --angle 0 --model both --phi 0.3 --ratio 0.05 --dB-rel 0.125 --json "
                 "--quiet -o %s", loads[k], path);
        CHECK(run("traction", args, out, sizeof out, err, sizeof err) == 0);
        ratio[k] = json_num(out, "micro_stiffness") / json_num(out, "macro_stiffness");
    }
    plume_err e = {{0}};
    CHECK(plume_bend_curve_param(path, "micro", "cylinder_0", "D_long", &D[0], &e) == PLUME_OK);
    CHECK(plume_bend_curve_param(path, "micro", "twist_0", "D_twist", &D[1], &e) == PLUME_OK);

    char mod[256];
    snprintf(mod, sizeof mod, "%s/fitted.h5", scratch);
    snprintf(args, sizeof args, "--bending %s --free D_long,D_twist --D-long %.6g --D-twist %.6g --edge 0.001 --json "
             "-o %s", path, 2.0 * D[0], 0.5 * D[1], mod);
    CHECK(run("fit", args, out, sizeof out, err, sizeof err) == 0);
    const double fl = json_num(out, "D_long"), ft = json_num(out, "D_twist"), res = json_num(out, "residual");
    fprintf(stderr, "    micro: D_long %.5g (cell %.5g, micro/macro %.4f), D_twist %.5g (cell %.5g, micro/macro %.4f); "
            "misfit %.2g, %g evaluations\n", fl, D[0], ratio[0], ft, D[1], ratio[1], res, json_num(out, "evaluations"));
    CHECK_REL(fl / D[0], ratio[0], 0.02, 0.0);
    CHECK_REL(ft / D[1], ratio[1], 0.02, 0.0);
    CHECK_REL(fl, D[0], 0.03, 0.0);
    CHECK(res < 1e-3);
    double w;
    CHECK(plume_moduli_read_param(mod, "D_long", &w, &e) == PLUME_OK);
    CHECK_REL(w, fl, 1e-10, 0.0); /* --json prints 12 digits */
    CHECK(plume_moduli_read_param(mod, "D_16", &w, &e) == PLUME_OK && w == 0.0);

    /* the macro curves against the model on the same mesh: the cell's D back */
    snprintf(args, sizeof args, "--bending %s:macro --free D_long,D_twist --D-long %.6g --D-twist %.6g --json", path,
             2.0 * D[0], 0.5 * D[1]);
    CHECK(run("fit", args, out, sizeof out, err, sizeof err) == 0);
    fprintf(stderr, "    macro: D_long %.6g (cell %.6g), D_twist %.6g (cell %.6g); misfit %.2g\n", json_num(out, "D_long"),
            D[0], json_num(out, "D_twist"), D[1], json_num(out, "residual"));
    CHECK_REL(json_num(out, "D_long"), D[0], 0.02, 0.0);
    CHECK_REL(json_num(out, "D_twist"), D[1], 0.02, 0.0);
    remove_scratch();
}
