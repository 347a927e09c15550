/* A scene material's membrane moduli from a homogenise file ("membrane": {"from_moduli": ...}),
 * the thickness the file's moduli are over, and the errors naming the scene, the key path and the
 * file. */
#include <hdf5.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app_runner.h"
#include "harness.h"
#include "../include/plume.h"
#include "../lib/io/frames.h"
#include "../macro/scene.h"

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* dir/scene.json: one material whose membrane and bending are the JSON texts given, held at a
 * corner and left to sag for 3 steps */
static void write_scene(const char *dir, const char *membrane, const char *bending)
{
    char path[256], text[2048];
    snprintf(path, sizeof path, "%s/scene.json", dir);
    snprintf(text, sizeof text,
             "{\"mesh\": {\"rectangle\": [0.01, 0.01], \"edge\": 0.0025},\n"
             " \"materials\": [{\"membrane\": %s,\n"
             "                 \"bending\": %s, \"density\": 0.026}],\n"
             " \"handles\": [{\"near\": [0, 0], \"radius\": 0.003, \"keyframes\": [[0, 0, 0, 0]]}],\n"
             " \"dt\": 0.01, \"duration\": 0.03}\n",
             membrane, bending);
    write_text(path, text);
}

static plume_status load(const char *dir, const char *membrane, plume_scene **s, plume_err *err)
{
    char path[256];
    write_scene(dir, membrane, "{\"D\": 1e-6}");
    snprintf(path, sizeof path, "%s/scene.json", dir);
    return plume_scene_load(path, s, err);
}

/* a numeric or a string attribute of obj in an HDF5 file; NAN / -1 when missing */
static double h5_num(const char *path, const char *obj, const char *name)
{
    double v = NAN;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return v;
    if (H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0) {
        hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
        if (a < 0 || H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0)
            v = NAN;
        if (a >= 0)
            H5Aclose(a);
    }
    H5Fclose(f);
    return v;
}

static int h5_str(const char *path, const char *obj, const char *name, char *buf, size_t n)
{
    int rc = -1;
    buf[0] = '\0';
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return -1;
    if (H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0) {
        hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT), t = H5Aget_type(a);
        char *s = NULL;
        if (a >= 0 && t >= 0 && H5Tis_variable_str(t) > 0 && H5Aread(a, t, &s) >= 0 && s) {
            snprintf(buf, n, "%s", s);
            H5free_memory(s);
            rc = 0;
        }
        if (t >= 0)
            H5Tclose(t);
        if (a >= 0)
            H5Aclose(a);
    }
    H5Fclose(f);
    return rc;
}

static int ends_with(const char *s, const char *tail)
{
    size_t a = strlen(s), b = strlen(tail);
    return a >= b && strcmp(s + a - b, tail) == 0;
}

/* homogenize -o cell/m.h5 beside the scene, whose membrane and bending say from_moduli
 * "cell/m.h5": the four moduli and the thickness are the file's, bit for bit, the path resolved
 * against the scene's directory; the same thickness given again is accepted. */
void test_membrane_moduli_from_file(void)
{
    char dir[64] = "/tmp/plume-memmod-XXXXXX", args[1024], path[256], out[8192], errs[8192];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "mkdir -p %s/cell", dir);
    CHECK(system(args) == 0);
    snprintf(path, sizeof path, "%s/cell/m.h5", dir);
    snprintf(args, sizeof args, "--strain-max 0 --no-convergence --thickness 2e-4 -o %s", path);
    CHECK(app_run(dir, "homogenize", args, out, sizeof out, errs, sizeof errs) == 0);
    plume_ortho m = {0, 0, 0, 0};
    plume_err err = {{0}};
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_OK);

    plume_scene *s = NULL;
    CHECK(load(dir, "{\"from_moduli\": \"cell/m.h5\", \"kappa\": 5}", &s, &err) == PLUME_OK);
    if (s) {
        const plume_scene_material *mat = &s->mats[0];
        CHECK(mat->membrane.E_xx == m.E_xx && mat->membrane.E_yy == m.E_yy && mat->membrane.nu_xy == m.nu_xy &&
              mat->membrane.G_xy == m.G_xy);
        CHECK(mat->membrane.h == 2e-4 && mat->membrane.kappa == 5.0);
        CHECK(strcmp(mat->membrane_from, path) == 0);
        CHECK(mat->bending_from[0] == '\0');
        plume_scene_destroy(&s);
    } else {
        fprintf(stderr, "    %s\n", err.msg);
    }
    CHECK(load(dir, "{\"from_moduli\": \"cell/m.h5\", \"thickness\": 2e-4}", &s, &err) == PLUME_OK);
    plume_scene_destroy(&s);

    /* a file that says no thickness (plume_moduli_write alone, as apps/fit): the scene's is needed */
    snprintf(path, sizeof path, "%s/fitted.h5", dir);
    plume_ortho fit = {1e9, 2e5, 0.1, 1e5};
    CHECK(plume_moduli_write(path, &fit, "test", &err) == PLUME_OK);
    CHECK(load(dir, "{\"from_moduli\": \"fitted.h5\"}", &s, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "materials[0].membrane.thickness is missing"));
    CHECK(load(dir, "{\"from_moduli\": \"fitted.h5\", \"thickness\": 3e-4}", &s, &err) == PLUME_OK);
    if (s) {
        CHECK(s->mats[0].membrane.E_yy == 2e5 && s->mats[0].membrane.h == 3e-4 && s->mats[0].membrane.nu_xy == 0.1);
        plume_scene_destroy(&s);
    }
    snprintf(args, sizeof args, "rm -rf %s", dir);
    CHECK(system(args) == 0);
}

/* Each error names the scene file, the key path and, for the file's, the moduli file and what in
 * it is missing. */
void test_membrane_moduli_bad_input(void)
{
    char dir[64] = "/tmp/plume-membad-XXXXXX", path[256], cmd[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_err err = {{0}};
    plume_scene *s = NULL;
    snprintf(path, sizeof path, "%s/m.h5", dir);
    plume_ortho m = {1e9, 2e5, 0.0, 1e5};
    plume_param h = {"thickness", 1e-4};
    CHECK(plume_moduli_write_params(path, &m, "test", &h, 1, &err) == PLUME_OK);
    CHECK(load(dir, "{\"from_moduli\": \"m.h5\"}", &s, &err) == PLUME_OK);
    plume_scene_destroy(&s);
    static const struct {
        const char *membrane;
        plume_status st;
        const char *says[3];
    } bad[] = {
        {"{\"from_moduli\": \"none.h5\"}", PLUME_EIO, {"scene.json:2: materials[0].membrane.from_moduli", "none.h5", NULL}},
        {"{\"from_moduli\": 7}", PLUME_EFORMAT, {"materials[0].membrane.from_moduli must be the name of an HDF5", NULL}},
        {"{\"from_moduli\": \"scene.json\"}", PLUME_EFORMAT, {"materials[0].membrane.from_moduli", "not an HDF5 file", NULL}},
        {"{\"from_moduli\": \"curves.h5\"}", PLUME_EFORMAT, {"materials[0].membrane.from_moduli (curves.h5)", "no /moduli", NULL}},
        {"{\"from_moduli\": \"m.h5\", \"E_xx\": 1e9}", PLUME_EINVAL,
         {"materials[0].membrane.E_xx is given twice", "\"from_moduli\": \"m.h5\"", NULL}},
        {"{\"from_moduli\": \"m.h5\", \"E\": 1e9, \"nu\": 0}", PLUME_EINVAL, {"materials[0].membrane.E is given twice", NULL}},
        {"{\"from_moduli\": \"m.h5\", \"nu_xy\": 0.3}", PLUME_EINVAL, {"materials[0].membrane.nu_xy is given twice", NULL}},
        {"{\"from_moduli\": \"m.h5\", \"thickness\": 1.5e-4}", PLUME_EINVAL,
         {"materials[0].membrane.thickness = 0.00015 m is not the thickness 0.0001 m", "m.h5", "1.5 times"}},
        {"{\"from_moduli\": \"m.h5\", \"thickness\": -1}", PLUME_EINVAL, {"materials[0].membrane.thickness must be > 0", NULL}},
        {"{\"from_moduli\": \"m.h5\", \"drop_couplings\": true}", PLUME_EFORMAT,
         {"materials[0].membrane.drop_couplings is an unknown key", NULL}},
        {"{\"from_moduli\": \"bad_thickness.h5\"}", PLUME_EINVAL, {"thickness must be finite and > 0", "bad_thickness.h5", NULL}},
    };
    /* an HDF5 file with curves but no /moduli, and one whose thickness is 0 */
    char other[256];
    snprintf(other, sizeof other, "%s/curves.h5", dir);
    double strain[2] = {0, 0.1}, stress[2] = {0, 1}, wbar[2] = {0, 0}, it[2] = {0, 1}, sec[2] = {0, 0};
    plume_curve c = {2, strain, stress, wbar, it, sec};
    CHECK(plume_curve_write(other, "macro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_OK);
    snprintf(other, sizeof other, "%s/bad_thickness.h5", dir);
    plume_param h0 = {"thickness", 0.0};
    CHECK(plume_moduli_write_params(other, &m, "test", &h0, 1, &err) == PLUME_OK);
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        err.msg[0] = '\0';
        plume_status st = load(dir, bad[k].membrane, &s, &err);
        int ok = st == bad[k].st && s == NULL;
        for (int i = 0; i < 3 && bad[k].says[i]; i++)
            ok = ok && strstr(err.msg, bad[k].says[i]) != NULL;
        ok = ok && strstr(err.msg, "scene.json") != NULL;
        CHECK(ok);
        if (!ok)
            fprintf(stderr, "    %s -> %d %s\n", bad[k].membrane, (int)st, err.msg);
        plume_scene_destroy(&s);
    }
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}
