/* A scene material's membrane moduli from a homogenise file ("membrane": {"from_moduli": ...}),
 * the thickness the file's moduli are over, the errors naming the scene, the key path and the file,
 * and the record of what each material was made of in frames.h5 (/materials/<k>) and in
 * apps/feather --json. */
#include <hdf5.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app_runner.h"
#include "harness.h"
#include "h5_units.h"
#include "plume_tree.h"
#include "../lib/io/frames.h"
#include "../macro/scene/scene.h"

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
    buf[0] = '\0';
    return h5_string_attr(path, obj, name, buf, n);
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
        CHECK(mat->membrane.moduli.E_xx == m.E_xx && mat->membrane.moduli.E_yy == m.E_yy && mat->membrane.moduli.nu_xy == m.nu_xy &&
              mat->membrane.moduli.G_xy == m.G_xy);
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
        CHECK(s->mats[0].membrane.moduli.E_yy == 2e5 && s->mats[0].membrane.h == 3e-4 && s->mats[0].membrane.moduli.nu_xy == 0.1);
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

/* apps/feather on a scene taking both membrane and bending from a homogenise file: --json's
 * "materials" and frames.h5's /materials/0 say the moduli used and the file; a hand-set material
 * has no file attribute; /materials survives an append that rebuilds the file. */
void test_membrane_moduli_recorded(void)
{
    char dir[64] = "/tmp/plume-memrec-XXXXXX", args[1024], path[256], frames[256], out[32768], errs[8192], buf[4096];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/m.h5", dir);
    snprintf(args, sizeof args, "--strain-max 0 --no-convergence -o %s", path);
    CHECK(app_run(dir, "homogenize", args, out, sizeof out, errs, sizeof errs) == 0);
    plume_ortho m = {0, 0, 0, 0};
    plume_err err = {{0}};
    double D_long = NAN;
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_OK && plume_moduli_read_param(path, "D_long", &D_long, &err) == PLUME_OK);
    write_scene(dir, "{\"from_moduli\": \"m.h5\"}", "{\"from_moduli\": \"m.h5\"}");
    snprintf(args, sizeof args, "%s/scene.json -o %s/run --json --quiet", dir, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    json_t *j = json_loads(out, 0, NULL);
    json_t *jm = json_array_get(json_object_get(j, "materials"), 0);
    json_t *mem = json_object_get(jm, "membrane"), *ben = json_object_get(jm, "bending");
    CHECK(json_array_size(json_object_get(j, "materials")) == 1);
    /* --json prints 12 significant digits */
    CHECK_REL(json_number_value(json_object_get(mem, "E_xx")), m.E_xx, 1e-11, 0.0);
    CHECK_REL(json_number_value(json_object_get(mem, "G_xy")), m.G_xy, 1e-11, 0.0);
    CHECK(json_number_value(json_object_get(mem, "thickness")) == 1e-4);
    CHECK_REL(json_number_value(json_object_get(ben, "D_long")), D_long, 1e-11, 0.0);
    CHECK(json_is_string(json_object_get(mem, "from_moduli")) &&
          ends_with(json_string_value(json_object_get(mem, "from_moduli")), "/m.h5"));
    CHECK(json_is_string(json_object_get(ben, "from_moduli")) &&
          ends_with(json_string_value(json_object_get(ben, "from_moduli")), "/m.h5"));
    CHECK(json_is_true(json_object_get(j, "converged")));
    json_decref(j);

    snprintf(frames, sizeof frames, "%s/run/frames.h5", dir);
    CHECK(h5_num(frames, "/materials/0", "E_xx") == m.E_xx && h5_num(frames, "/materials/0", "E_yy") == m.E_yy &&
          h5_num(frames, "/materials/0", "nu_xy") == m.nu_xy && h5_num(frames, "/materials/0", "D_long") == D_long &&
          h5_num(frames, "/materials/0", "thickness") == 1e-4 && h5_num(frames, "/materials/0", "density") == 0.026);
    CHECK(h5_str(frames, "/materials/0", "membrane_from_moduli", buf, sizeof buf) == 0 && ends_with(buf, "/m.h5"));
    CHECK(h5_str(frames, "/materials/0", "bending_from_moduli", buf, sizeof buf) == 0 && ends_with(buf, "/m.h5"));
    CHECK(h5_str(frames, "/materials/0", "units", buf, sizeof buf) == 0 && strstr(buf, "E_xx, E_yy, G_xy, kappa: Pa") &&
          strstr(buf, "D_twist: N m") && strstr(buf, "density: kg/m^2"));
    plume_frames_info info;
    CHECK(plume_frames_info_read(frames, &info, &err) == PLUME_OK && info.count == 4);

    /* a hand-set material: the moduli, no file */
    write_scene(dir, "{\"E\": 1e6, \"nu\": 0.25, \"thickness\": 1e-4}", "{\"D\": 1e-6}");
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    j = json_loads(out, 0, NULL);
    mem = json_object_get(json_array_get(json_object_get(j, "materials"), 0), "membrane");
    CHECK(json_number_value(json_object_get(mem, "E_yy")) == 1e6 && json_number_value(json_object_get(mem, "G_xy")) == 4e5 &&
          !json_object_get(mem, "from_moduli"));
    json_decref(j);
    CHECK(h5_num(frames, "/materials/0", "E_xx") == 1e6 && h5_num(frames, "/materials/0", "D_trans") == 1e-6);
    CHECK(h5_str(frames, "/materials/0", "membrane_from_moduli", buf, sizeof buf) == -1 &&
          h5_str(frames, "/materials/0", "bending_from_moduli", buf, sizeof buf) == -1);

    /* an interrupted append's group (count 4, a group /frames/4): the next append rebuilds the file
     * from its committed frames, and keeps /materials */
    hid_t f = H5Fopen(frames, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t g = f < 0 ? H5I_INVALID_HID : H5Gcreate2(f, "/frames/4", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    CHECK(g >= 0);
    if (g >= 0)
        H5Gclose(g);
    if (f >= 0)
        H5Fclose(f);
    plume_frame fr = {0};
    CHECK(plume_frames_read(frames, -1, &fr, &err) == PLUME_OK);
    CHECK(plume_frames_append(frames, fr.nv, fr.ncons, fr.t + 0.01, fr.step + 1, fr.x, fr.v, fr.lambda, &err) == PLUME_OK);
    plume_frame_free(&fr);
    CHECK(plume_frames_info_read(frames, &info, &err) == PLUME_OK && info.count == 5);
    CHECK(h5_num(frames, "/materials/0", "E_xx") == 1e6 && h5_num(frames, "/materials/0", "nu_xy") == 0.25);

    /* the writer's own errors */
    plume_param p2[2] = {{"E_xx", 1}, {"E_xx", 2}};
    CHECK(plume_frames_material_write(frames, 0, p2, 2, NULL, 0, "", &err) == PLUME_EINVAL && strstr(err.msg, "E_xx given twice"));
    plume_param pu = {"units", 1};
    CHECK(plume_frames_material_write(frames, 0, &pu, 1, NULL, 0, "", &err) == PLUME_EINVAL);
    CHECK(plume_frames_material_write(frames, -1, NULL, 0, NULL, 0, "", &err) == PLUME_EINVAL);
    CHECK(plume_frames_material_write(path, 0, NULL, 0, NULL, 0, "", &err) == PLUME_EFORMAT && strstr(err.msg, "/frames"));
    snprintf(args, sizeof args, "rm -rf %s", dir);
    CHECK(system(args) == 0);
}

/* data/feather/scene_from_cell.json: apps/homogenize on the real-scale layout writes the file the
 * scene names (here in a scratch copy of the scene and its mesh inputs), and the vane's membrane
 * (with its thickness) and bending are that file's, bit for bit; the rachis keeps its own. The
 * feather steps: a few frames, every step converged without halving. */
void test_membrane_moduli_scene_from_cell(void)
{
    char dir[] = "/tmp/plume-fromcell-XXXXXX", cmd[1024], path[256], out[32768], errs[4096];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(cmd, sizeof cmd, "cp ../data/feather/scene_from_cell.json ../data/feather/feather_shape.json "
             "../data/feather/outline.obj %s/", dir);
    CHECK(system(cmd) == 0);
    snprintf(path, sizeof path, "%s/moduli_feather_si.h5", dir);
    snprintf(cmd, sizeof cmd, "--config ../data/layout_feather_si.json -o %s", path);
    CHECK(app_run(dir, "homogenize", cmd, out, sizeof out, errs, sizeof errs) == 0);
    plume_ortho m = {0, 0, 0, 0};
    plume_err err = {{0}};
    double D[4] = {NAN, NAN, NAN, NAN}, h = NAN;
    const char *names[4] = {"D_long", "D_trans", "D_coupling", "D_twist"};
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_OK && plume_moduli_read_param(path, "thickness", &h, &err) == PLUME_OK);
    for (int k = 0; k < 4; k++)
        CHECK(plume_moduli_read_param(path, names[k], &D[k], &err) == PLUME_OK);
    snprintf(cmd, sizeof cmd, "%s/scene_from_cell.json", dir);
    plume_scene *s = NULL;
    CHECK(plume_scene_load(cmd, &s, &err) == PLUME_OK);
    if (s) {
        const plume_scene_material *v = &s->mats[0];
        CHECK(v->membrane.moduli.E_xx == m.E_xx && v->membrane.moduli.E_yy == m.E_yy && v->membrane.moduli.nu_xy == m.nu_xy &&
              v->membrane.moduli.G_xy == m.G_xy && v->membrane.h == h && h == 1.2e-4);
        CHECK(v->bending.D_long == D[0] && v->bending.D_trans == D[1] && v->bending.D_coupling == D[2] &&
              v->bending.D_twist == D[3]);
        CHECK(strcmp(v->membrane_from, path) == 0 && strcmp(v->bending_from, path) == 0);
        CHECK(s->nmat == 2 && !s->mats[1].membrane_from[0] && s->mats[1].membrane.h == 3e-3);
    } else {
        fprintf(stderr, "    %s\n", err.msg);
    }
    plume_scene_destroy(&s);
    snprintf(cmd, sizeof cmd, "%s/scene_from_cell.json -o %s/run --frames 4 --json --quiet", dir, dir);
    CHECK(app_run(dir, "feather", cmd, out, sizeof out, errs, sizeof errs) == 0);
    json_t *j = json_loads(out, 0, NULL);
    CHECK(json_is_true(json_object_get(j, "converged")) && json_integer_value(json_object_get(j, "steps")) == 4 &&
          json_integer_value(json_object_get(j, "steps_halved")) == 0);
    json_decref(j);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

/* The last frame's positions of dir/scene.json run by apps/feather into dir/out (malloc'ed, NULL
 * when the run fails). */
static double *run_last_x(const char *dir, plume_index *nv)
{
    char out[8192], errs[8192], path[256], args[512];
    snprintf(args, sizeof args, "%s/scene.json -o %s/out --quiet", dir, dir);
    if (app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) != 0) {
        fprintf(stderr, "    feather: %s\n", errs);
        return NULL;
    }
    snprintf(path, sizeof path, "%s/out/frames.h5", dir);
    plume_frame fr;
    memset(&fr, 0, sizeof fr);
    plume_err err = {{0}};
    if (plume_frames_read(path, -1, &fr, &err) != PLUME_OK) {
        fprintf(stderr, "    %s\n", err.msg);
        return NULL;
    }
    double *x = fr.x;
    *nv = fr.nv;
    fr.x = NULL;
    plume_frame_free(&fr);
    return x;
}

/* "membrane": {"from_moduli": ..., "tensor": "full"}: the file's plane-stress tensor (/moduli
 * C11 .. C33) in place of its four moduli (docs/monoclinic-vane.md). A file whose tensor is the
 * moduli's own orthotropic one runs the scene bit for bit as "moduli" does, so the tensor is what
 * the solver uses; a coupled tensor moves it; "hooked" needs the hooked cell's tensor; a bad name
 * is refused by its key path. */
void test_membrane_moduli_tensor(void)
{
    char dir[64] = "/tmp/plume-memten-XXXXXX", path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/m.h5", dir);
    plume_layout l;
    plume_layout_default(&l);
    l.h = 1e-4;
    plume_homog_result r;
    memset(&r, 0, sizeof r);
    r.moduli = (plume_ortho){1e9, 2e5, 0.1, 1e5};
    r.order = 2;
    plume_membrane_material mat = {r.moduli, 1e-4, 0.0, 0};
    plume_membrane_stiffness(&mat, r.C);
    plume_err err = {{0}};
    CHECK(plume_homog_write(path, &l, &r, &err) == PLUME_OK);
    write_scene(dir, "{\"from_moduli\": \"m.h5\"}", "{\"D\": 1e-7}");
    plume_index nv = 0, nv2 = 0;
    double *x0 = run_last_x(dir, &nv);
    write_scene(dir, "{\"from_moduli\": \"m.h5\", \"tensor\": \"full\"}", "{\"D\": 1e-7}");
    double *x1 = run_last_x(dir, &nv2);
    CHECK(x0 && x1 && nv == nv2 && memcmp(x0, x1, (size_t)(3 * nv) * sizeof *x0) == 0);
    /* the run records the tensor it used (/materials/0) */
    char frames[256], kind[32];
    snprintf(frames, sizeof frames, "%s/out/frames.h5", dir);
    CHECK(h5_num(frames, "/materials/0", "C22") == r.C[4] && h5_num(frames, "/materials/0", "C23") == 0.0);
    CHECK(h5_str(frames, "/materials/0", "membrane_tensor", kind, sizeof kind) == 0 && strcmp(kind, "full") == 0);
    plume_scene *s = NULL;
    CHECK(plume_scene_load(strcat(strcpy(path, dir), "/scene.json"), &s, &err) == PLUME_OK);
    if (s) {
        CHECK(s->mats[0].tensor == 1 && s->mats[0].C[4] == r.C[4] && s->mats[0].C[5] == 0.0);
        plume_scene_destroy(&s);
    }
    /* coupled: C23 at 0.9 of sqrt(C22 C33) */
    r.C[5] = r.C[7] = 0.9 * sqrt(r.C[4] * r.C[8]);
    snprintf(path, sizeof path, "%s/m.h5", dir);
    CHECK(plume_homog_write(path, &l, &r, &err) == PLUME_OK);
    double *x2 = run_last_x(dir, &nv2);
    double moved = 0.0;
    for (plume_index k = 0; x0 && x2 && k < 3 * nv; k++)
        moved = fmax(moved, fabs(x2[k] - x0[k]));
    printf("    coupled tensor: the last frame moves by %.3g m\n", moved);
    CHECK(x2 && moved > 1e-9);
    /* without "tensor" the coupled cell takes its tensor (the default for a coupling above 1e-3):
     * the same run as "full"; "moduli" asked for keeps the four moduli, as the uncoupled cell did */
    write_scene(dir, "{\"from_moduli\": \"m.h5\"}", "{\"D\": 1e-7}");
    double *x3 = run_last_x(dir, &nv2);
    CHECK(x2 && x3 && nv == nv2 && memcmp(x2, x3, (size_t)(3 * nv) * sizeof *x2) == 0);
    CHECK(h5_str(frames, "/materials/0", "membrane_tensor", kind, sizeof kind) == 0 && strcmp(kind, "full") == 0);
    write_scene(dir, "{\"from_moduli\": \"m.h5\", \"tensor\": \"moduli\"}", "{\"D\": 1e-7}");
    double *x4 = run_last_x(dir, &nv2);
    CHECK(x0 && x4 && nv == nv2 && memcmp(x0, x4, (size_t)(3 * nv) * sizeof *x0) == 0);
    free(x3);
    free(x4);
    /* "hooked" without a law in the file; a bad name */
    snprintf(path, sizeof path, "%s/scene.json", dir);
    write_scene(dir, "{\"from_moduli\": \"m.h5\", \"tensor\": \"hooked\"}", "{\"D\": 1e-7}");
    CHECK(plume_scene_load(path, &s, &err) != PLUME_OK);
    CHECK(strstr(err.msg, "materials[0].membrane.tensor") && strstr(err.msg, "separation_C11"));
    write_scene(dir, "{\"from_moduli\": \"m.h5\", \"tensor\": \"monoclinic\"}", "{\"D\": 1e-7}");
    CHECK(plume_scene_load(path, &s, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "materials[0].membrane.tensor") && strstr(err.msg, "\"full\""));
    free(x0);
    free(x1);
    free(x2);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}
