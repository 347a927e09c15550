/* Bending moduli from the microstructure end to end: apps/homogenize writes them (--json, /moduli
 * attributes with units), a scene material reads them ("bending": {"from_moduli": ...}), and the
 * per-phase thickness keys and flags refuse bad values. */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app_runner.h"
#include "h5_units.h"
#include "harness.h"
#include "plume_tree.h"
#include "../macro/scene.h"
#include "../micro/layout.h"
#include "../micro/layout_json.h"

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* a scene of one material whose bending is `bending` (JSON), in dir/scene.json */
static plume_status load_scene(const char *dir, const char *bending, plume_scene **s, plume_err *err)
{
    char path[256], text[1024];
    snprintf(path, sizeof path, "%s/scene.json", dir);
    snprintf(text, sizeof text,
             "{\"mesh\": {\"rectangle\": [0.01, 0.01], \"edge\": 0.0025},\n"
             " \"materials\": [{\"membrane\": {\"E\": 1e6, \"nu\": 0, \"thickness\": 1e-4},\n"
             "                 \"bending\": %s, \"density\": 0.026}],\n"
             " \"dt\": 0.01, \"duration\": 0.1}\n",
             bending);
    write_text(path, text);
    return plume_scene_load(path, s, err);
}

static double jnum(json_t *j, const char *key)
{
    json_t *v = json_object_get(j, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

/* homogenize --json -o: the bending moduli on stdout and in /moduli (with their unit); a scene
 * material takes them from the file (relative to the scene), and a cell with tilted barbules has
 * bending-twist couplings the scene refuses unless told to drop them. */
void test_bending_moduli_app_to_scene(void)
{
    char dir[64] = "/tmp/plume-bend-XXXXXX", args[1024], path[256], out[16384], errs[8192];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/strips.h5", dir);
    snprintf(args, sizeof args, "--strain-max 0 --no-convergence --thickness-barbule 5e-5 --json -o %s", path);
    CHECK(app_run(dir, "homogenize", args, out, sizeof out, errs, sizeof errs) == 0);
    json_t *j = json_loads(out, 0, NULL);
    CHECK(j != NULL);
    const char *names[4] = {"D_long", "D_trans", "D_coupling", "D_twist"};
    double D[4];
    for (int k = 0; k < 4; k++) {
        D[k] = jnum(j, names[k]);
        CHECK(isfinite(D[k]));
        double v = NAN;
        plume_err err = {{0}};
        CHECK(plume_moduli_read_param(path, names[k], &v, &err) == PLUME_OK);
        CHECK_REL(v, D[k], 1e-11, 0.0);
    }
    /* strips: twist is the area average of G t^3 / 12 (barbs 1e-4 m thick, barbules 5e-5 m) */
    double G = 2.5e9 / 2.6, Gs = 1e-6 * G;
    CHECK_REL(D[3], (0.16 * G * 1e-12 + 0.84 * Gs * 1.25e-13) / 12.0, 1e-9, 0.0);
    json_decref(j);
    char units[1024] = "";
    CHECK(h5_units(path, "/moduli", units, sizeof units) == 0);
    CHECK(strstr(units, "E_xx, E_yy, G_xy: Pa") && strstr(units, "D_long: N m") && strstr(units, "D_twist: N m") &&
          strstr(units, "thickness_barbule: m"));

    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(load_scene(dir, "{\"from_moduli\": \"strips.h5\"}", &s, &err) == PLUME_OK);
    if (s) {
        const plume_bending_material *b = &s->mats[0].bending;
        CHECK_REL(b->D_long, D[0], 1e-11, 0.0);
        CHECK_REL(b->D_trans, D[1], 1e-11, 0.0);
        CHECK_REL(b->D_coupling, D[2], 1e-11, 0.0);
        CHECK_REL(b->D_twist, D[3], 1e-11, 0.0);
        plume_scene_destroy(&s);
    } else {
        fprintf(stderr, "    %s\n", err.msg);
    }

    /* the explicit-barbule cell (barbules at 60 deg): D_16, D_26 of about 10 % */
    snprintf(path, sizeof path, "%s/barbules.h5", dir);
    snprintf(args, sizeof args, "--config ../data/layout_barbules.json --strain-max 0 --no-convergence --e-rel 0.3 -o %s",
             path);
    CHECK(app_run(dir, "homogenize", args, out, sizeof out, errs, sizeof errs) == 0);
    CHECK(strstr(out, "bending: D_long") != NULL);
    CHECK(load_scene(dir, "{\"from_moduli\": \"barbules.h5\"}", &s, &err) == PLUME_EINVAL &&
          strstr(err.msg, "materials[0].bending.from_moduli") && strstr(err.msg, "drop_couplings"));
    CHECK(load_scene(dir, "{\"from_moduli\": \"barbules.h5\", \"drop_couplings\": true}", &s, &err) == PLUME_OK);
    if (s) {
        double v = NAN;
        CHECK(plume_moduli_read_param(path, "D_trans", &v, &err) == PLUME_OK && s->mats[0].bending.D_trans == v);
        plume_scene_destroy(&s);
    }
    snprintf(args, sizeof args, "rm -rf %s", dir);
    CHECK(system(args) == 0);
}

/* Bad input: the thickness keys and flags (zero, negative, non-finite), the layout check, and the
 * scene's "from_moduli" (not a string, a missing file, a file without bending moduli, unknown
 * keys, a non-boolean drop_couplings). */
void test_bending_moduli_bad_input(void)
{
    plume_layout l;
    plume_err err = {{0}};
    const char *bad_keys[][2] = {{"{\"thickness_barb\": 0}", "\"thickness_barb\" must be a finite thickness > 0"},
                                 {"{\"thickness_barbule\": -1e-5}", "\"thickness_barbule\" must be a finite thickness"},
                                 {"{\"thickness_barb\": \"thin\"}", "\"thickness_barb\" must be a number"}};
    for (int k = 0; k < 3; k++) {
        plume_layout_default(&l);
        CHECK(plume_layout_apply_json(bad_keys[k][0], "test", &l, &err) == PLUME_EFORMAT && strstr(err.msg, bad_keys[k][1]));
    }
    plume_layout_default(&l);
    CHECK(plume_layout_apply_json("{\"thickness_barb\": 2e-4, \"thickness_barbule\": 3e-4}", "test", &l, &err) == PLUME_OK);
    CHECK(plume_layout_check(&l, &err) == PLUME_OK); /* thicker barbules are allowed */
    CHECK(plume_layout_thickness(&l, PLUME_MAT_BARB) == 2e-4 && plume_layout_thickness(&l, PLUME_MAT_BARBULE) == 3e-4);
    l.h_barb = -1.0;
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "thickness_barb"));
    l.h_barb = 0.0, l.h_barbule = NAN;
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "thickness_barbule"));
    l.h_barbule = INFINITY;
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "thickness_barbule"));
    l.h_barbule = 0.0;
    CHECK(plume_layout_check(&l, &err) == PLUME_OK && plume_layout_thickness(&l, PLUME_MAT_BARBULE) == l.h);

    char dir[64] = "/tmp/plume-bendbad-XXXXXX", out[4096], errs[4096], cmd[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    const char *flags[][2] = {{"--thickness-barb 0", "--thickness-barb must be a finite thickness > 0"},
                              {"--thickness-barbule -1e-4", "--thickness-barbule must be a finite thickness > 0"},
                              {"--thickness-barb nan", "--thickness-barb expects a finite number"},
                              {"--thickness-barbule inf", "--thickness-barbule expects a finite number"},
                              {"--thickness-barb", "--thickness-barb needs a value"}};
    for (int k = 0; k < 5; k++) {
        CHECK(app_run(dir, "homogenize", flags[k][0], out, sizeof out, errs, sizeof errs) == 2);
        CHECK(strstr(errs, flags[k][1]) != NULL);
        if (!strstr(errs, flags[k][1]))
            fprintf(stderr, "    %s -> %s\n", flags[k][0], errs);
    }
    plume_scene *s = NULL;
    CHECK(load_scene(dir, "{\"from_moduli\": 3}", &s, &err) == PLUME_EFORMAT && strstr(err.msg, "bending.from_moduli must be"));
    CHECK(load_scene(dir, "{\"from_moduli\": \"none.h5\"}", &s, &err) == PLUME_EIO && strstr(err.msg, "none.h5"));
    char path[256];
    snprintf(path, sizeof path, "%s/membrane_only.h5", dir);
    plume_ortho m = {1e9, 1e3, 0.0, 1e3};
    CHECK(plume_moduli_write(path, &m, "test", &err) == PLUME_OK);
    CHECK(load_scene(dir, "{\"from_moduli\": \"membrane_only.h5\"}", &s, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "D_long missing") && strstr(err.msg, "bending.from_moduli"));
    CHECK(load_scene(dir, "{\"from_moduli\": \"membrane_only.h5\", \"scale\": 2}", &s, &err) != PLUME_OK &&
          strstr(err.msg, "scale"));
    CHECK(load_scene(dir, "{\"from_moduli\": \"membrane_only.h5\", \"drop_couplings\": 1}", &s, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "drop_couplings must be true or false"));
    CHECK(s == NULL);
    CHECK(plume_moduli_read_param(path, "D_long", NULL, &err) == PLUME_EINVAL);
    CHECK(plume_moduli_read_param("/nonexistent.h5", "D_long", &m.E_xx, &err) == PLUME_EIO);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}
