/* Scene sweeps (drivers/sweep.h "run": "scene", drivers/sweep_scene.c): expansion of key paths into a
 * scene's document; bad keys named; runs recorded with their per-step measures and final positions,
 * bit for bit those of the same scene stepped through the flat interface; contact measures as
 * apps/feather reports them; failed scenes recorded with the loader's message; the same content
 * serially and under mpirun -n 2; a changed scene file refused on resume. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hdf5.h>
#include <jansson.h>

#include "app_runner.h"
#include "h5_units.h"
#include "harness.h"
#include "../lib/io/frames.h"
#include "../drivers/flat.h"
#include "../drivers/sweep.h"

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static void remove_dir(const char *dir)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

/* the absolute path of a file of the tree (the tests run in tests/) */
static void data_path(const char *rel, char *out, size_t n)
{
    char cwd[1024];
    if (!getcwd(cwd, sizeof cwd))
        cwd[0] = '\0';
    snprintf(out, n, "%s/../data/%s", cwd, rel);
}

/* every component of the path `obj` exists in the file f */
static int h5_has(hid_t f, const char *obj)
{
    char buf[256];
    for (const char *p = strchr(obj + 1, '/');; p = strchr(p + 1, '/')) {
        snprintf(buf, sizeof buf, "%.*s", p ? (int)(p - obj) : (int)strlen(obj), obj);
        if (H5Lexists(f, buf, H5P_DEFAULT) <= 0)
            return 0;
        if (!p)
            return 1;
    }
}

/* dataset `obj` of an HDF5 file as doubles (malloc'ed; *n its length), or NULL */
static double *read_dataset(const char *path, const char *obj, long *n)
{
    *n = 0;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return NULL;
    double *v = NULL;
    if (h5_has(f, obj)) {
        hid_t d = H5Dopen2(f, obj, H5P_DEFAULT), sp = H5Dget_space(d);
        hssize_t m = H5Sget_simple_extent_npoints(sp);
        v = malloc(((size_t)m + 1) * sizeof *v);
        if (v && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0)
            *n = (long)m;
        H5Sclose(sp);
        H5Dclose(d);
    }
    H5Fclose(f);
    return v;
}

/* attribute `name` of the object `obj`: a double (NaN when missing), or a string (malloc'ed) */
static double read_attr(const char *path, const char *obj, const char *name)
{
    double v = NAN;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return v;
    if (h5_has(f, obj) && H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0) {
        hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
        H5Aread(a, H5T_NATIVE_DOUBLE, &v);
        H5Aclose(a);
    }
    H5Fclose(f);
    return v;
}

static char *read_attr_string(const char *path, const char *obj, const char *name)
{
    char *out = NULL;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return NULL;
    if (h5_has(f, obj) && H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0) {
        hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT), t = H5Aget_type(a);
        char *s = NULL;
        if (H5Tis_variable_str(t) > 0 && H5Aread(a, t, &s) >= 0 && s) {
            out = strdup(s);
            H5free_memory(s);
        }
        H5Tclose(t);
        H5Aclose(a);
    }
    H5Fclose(f);
    return out;
}

static const char *const measures[] = {"per_step/time",          "per_step/newton_iterations",
                                       "per_step/halvings",      "per_step/contact_pairs",
                                       "per_step/min_distance",  "per_step/intersecting_pairs",
                                       "positions"};

/* a scene sweep's results as one text: per run its record and every measure to the bit */
static char *content(const char *path, int n)
{
    size_t cap = 1 << 22, len = 0;
    char *out = malloc(cap), obj[128];
    out[0] = 0;
    for (int k = 0; k < n; k++) {
        snprintf(obj, sizeof obj, "/sweep/runs/%d", k);
        char *rec = read_attr_string(path, obj, "record");
        len += (size_t)snprintf(out + len, cap - len, "%d: %s\n", k, rec ? rec : "missing");
        free(rec);
        for (size_t q = 0; q < sizeof measures / sizeof measures[0]; q++) {
            snprintf(obj, sizeof obj, "/sweep/runs/%d/%s", k, measures[q]);
            long m;
            double *v = read_dataset(path, obj, &m);
            len += (size_t)snprintf(out + len, cap - len, " %s:", measures[q]);
            for (long i = 0; i < m && len + 32 < cap; i++)
                len += (size_t)snprintf(out + len, cap - len, " %.17g", v[i]);
            len += (size_t)snprintf(out + len, cap - len, "\n");
            free(v);
        }
    }
    return out;
}

/* run k's request as a JSON object (new reference) */
static json_t *request_of(const plume_sweep *s, int k, char **values)
{
    char *req = NULL;
    plume_err err = {{0}};
    *values = NULL;
    if (plume_sweep_request(s, k, &req, values, &err) != PLUME_OK)
        return NULL;
    json_t *r = json_loads(req, 0, NULL);
    free(req);
    return r;
}

void test_sweep_scene_expand(void)
{
    char dir[64] = "/tmp/plume-sweepscene-XXXXXX", path[256], strip[1200], text[2800];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    data_path("shell/strip_scene.json", strip, sizeof strip);
    snprintf(path, sizeof path, "%s/s.json", dir);
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"steps\": 2}, \"vary\": {\"materials[0].membrane.E\": "
             "[1e7, 2e6], \"gravity[2]\": {\"from\": -9.81, \"to\": -1, \"count\": 2}, \"max_iter\": [50]}}",
             strip);
    write_file(path, text);
    plume_sweep *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_sweep_load(path, NULL, &s, &err) == PLUME_OK && plume_sweep_count(s) == 4);
    CHECK(s && strcmp(plume_sweep_job(s), "scene") == 0);
    char *vals = NULL;
    json_t *r = s ? request_of(s, 1, &vals) : NULL, *doc = json_object_get(r, "document"); /* E 1e7, g_z -1 */
    json_t *mat = json_array_get(json_object_get(doc, "materials"), 0), *mem = json_object_get(mat, "membrane");
    CHECK(r && strcmp(json_string_value(json_object_get(r, "scene")), strip) == 0 &&
          json_integer_value(json_object_get(r, "steps")) == 2);
    CHECK(json_number_value(json_object_get(mem, "E")) == 1e7 && json_number_value(json_object_get(mem, "nu")) == 0.3);
    CHECK(json_number_value(json_array_get(json_object_get(doc, "gravity"), 2)) == -1.0 &&
          json_number_value(json_array_get(json_object_get(doc, "gravity"), 0)) == 0.0);
    CHECK(json_integer_value(json_object_get(doc, "max_iter")) == 50); /* a key the file does not have is added */
    CHECK(json_number_value(json_object_get(doc, "dt")) == 0.01 && json_object_get(doc, "handles"));
    CHECK(vals && strcmp(vals, "{\"materials[0].membrane.E\":10000000.0,\"gravity[2]\":-1.0,\"max_iter\":50}") == 0);
    json_decref(r);
    free(vals);
    r = s ? request_of(s, 2, &vals) : NULL; /* E 2e6, g_z -9.81 */
    mem = json_object_get(json_array_get(json_object_get(json_object_get(r, "document"), "materials"), 0), "membrane");
    CHECK(json_number_value(json_object_get(mem, "E")) == 2e6 &&
          json_number_value(json_array_get(json_object_get(json_object_get(r, "document"), "gravity"), 2)) == -9.81);
    json_decref(r);
    free(vals);
    plume_sweep_destroy(&s);

    /* base.duration is the scene's duration; the scene is found from the sweep file's directory */
    CHECK(plume_sweep_load("../data/sweeps/strip_contact.json", NULL, &s, &err) == PLUME_OK && plume_sweep_count(s) == 6);
    r = s ? request_of(s, 0, &vals) : NULL;
    doc = json_object_get(r, "document");
    CHECK(r && strcmp(json_string_value(json_object_get(r, "scene")), "../data/sweeps/../shell/strip_on_plate.json") == 0);
    CHECK(json_number_value(json_object_get(json_object_get(doc, "contact"), "dhat")) == 5e-4 &&
          json_number_value(json_object_get(json_object_get(doc, "contact"), "stiffness")) == 1.0 &&
          !json_object_get(r, "steps"));
    json_decref(r);
    free(vals);
    plume_sweep_destroy(&s);
    snprintf(text, sizeof text, "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"duration\": 0.05}}", strip);
    write_file(path, text);
    CHECK(plume_sweep_load(path, NULL, &s, &err) == PLUME_OK && plume_sweep_count(s) == 1);
    r = s ? request_of(s, 0, &vals) : NULL;
    CHECK(json_number_value(json_object_get(json_object_get(r, "document"), "duration")) == 0.05 &&
          !json_object_get(r, "steps"));
    json_decref(r);
    free(vals);
    plume_sweep_destroy(&s);

    /* list entries of list entries; a whole value of any type */
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\"}, \"vary\": {\"handles[0].keyframes[0][3]\": [-0.01], "
             "\"contact\": [{\"dhat\": 2e-3, \"stiffness\": 1}]}}",
             strip);
    write_file(path, text);
    CHECK(plume_sweep_load(path, NULL, &s, &err) == PLUME_OK);
    r = s ? request_of(s, 0, &vals) : NULL;
    doc = json_object_get(r, "document");
    json_t *key0 = json_array_get(json_object_get(json_array_get(json_object_get(doc, "handles"), 0), "keyframes"), 0);
    CHECK(json_array_size(key0) == 4 && json_number_value(json_array_get(key0, 3)) == -0.01 &&
          json_number_value(json_array_get(key0, 0)) == 0.0);
    CHECK(json_number_value(json_object_get(json_object_get(doc, "contact"), "dhat")) == 2e-3);
    json_decref(r);
    free(vals);
    plume_sweep_destroy(&s);

    /* bad keys and bases: the sweep file and the key named */
    const char *bad[][3] = {
        {"\"steps\": 2", "\"materials[3].density\": [1]", "vary.materials[3].density: materials has 1 entry"},
        {"\"steps\": 2", "\"dt.x\": [1]", "vary.dt.x: dt is not an object"},
        {"\"steps\": 2", "\"mesh[0]\": [1]", "vary.mesh[0]: mesh is not a list"},
        {"\"steps\": 2", "\"handles[0\": [1]", "vary.handles[0: a scene key is a path"},
        {"\"steps\": 2", "\"[0]\": [1]", "a scene key is a path"},
        {"\"steps\": 2", "\"gravity..x\": [1]", "a scene key is a path"},
        {"\"steps\": 2", "\"contact.x[1]\": [1]", "has no contact.x"},
        {"\"steps\": 0", "\"dt\": [1]", "base.steps must be an integer"},
        {"\"steps\": 2, \"duration\": 1", "\"dt\": [1]", "give one"},
        {"\"dt\": 0.1", "\"dt\": [1]", "base.dt is not a key of a scene run"},
        {"\"duration\": -1", "\"dt\": [1]", "base.duration must be a number > 0"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        snprintf(text, sizeof text, "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", %s}, \"vary\": {%s}}", strip,
                 bad[k][0], bad[k][1]);
        write_file(path, text);
        err.msg[0] = 0;
        CHECK(plume_sweep_load(path, NULL, &s, &err) != PLUME_OK && s == NULL);
        if (!strstr(err.msg, bad[k][2]) || !strstr(err.msg, "s.json")) {
            plume_test_failures++;
            fprintf(stderr, "    %s / %s: expected '%s' in '%s'\n", bad[k][0], bad[k][1], bad[k][2], err.msg);
        }
    }
    const char *badbase[][2] = {{"{\"run\": \"scene\", \"base\": {\"steps\": 2}}", "base.scene must name"},
                                {"{\"run\": \"scene\", \"base\": {\"scene\": \"nowhere.json\"}}", "nowhere.json"}};
    for (size_t k = 0; k < 2; k++) {
        write_file(path, badbase[k][0]);
        CHECK(plume_sweep_load(path, NULL, &s, &err) != PLUME_OK && strstr(err.msg, badbase[k][1]) &&
              strstr(err.msg, "s.json"));
    }
    remove_dir(dir);
}

/* a sweep's runs executed and recorded through the library into h5 (NULL sweep: load failed) */
static plume_sweep *run_sweep(const char *path, const char *h5)
{
    plume_sweep *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_sweep_load(path, NULL, &s, &err) == PLUME_OK);
    if (!s) {
        fprintf(stderr, "    %s\n", err.msg);
        return NULL;
    }
    CHECK(plume_sweep_results_open(h5, s, &err) == PLUME_OK);
    for (int k = 0; k < plume_sweep_count(s); k++) {
        char *rec = plume_sweep_execute(s, k);
        CHECK(rec && plume_sweep_results_add(h5, s, k, rec, &err) == PLUME_OK);
        free(rec);
    }
    return s;
}

/* a sweep over the bending models: the midedge run is the flat interface's (the package's) run of
 * the same document to the bit, and the models' strips differ */
void test_sweep_scene_bending_models(void)
{
    char dir[64] = "/tmp/plume-sweepscene-XXXXXX", path[256], h5[256], strip[1200], text[2800], msg[512];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    data_path("shell/strip_scene.json", strip, sizeof strip);
    snprintf(path, sizeof path, "%s/b.json", dir);
    snprintf(h5, sizeof h5, "%s/b.h5", dir);
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"steps\": 3}, \"vary\": {\"bending_model\": "
             "[\"shape_operator\", \"midedge\"]}}",
             strip);
    write_file(path, text);
    plume_sweep *s = run_sweep(path, h5);
    long n0 = 0, n1 = 0;
    double *p0 = read_dataset(h5, "/sweep/runs/0/positions", &n0), *p1 = read_dataset(h5, "/sweep/runs/1/positions", &n1);
    CHECK(p0 && p1 && n0 == n1 && n0 > 0 && memcmp(p0, p1, (size_t)n0 * sizeof *p0) != 0);
    json_t *d = json_load_file(strip, 0, NULL);
    json_object_set_new(d, "bending_model", json_string("midedge"));
    char *doc = json_dumps(d, JSON_REAL_PRECISION(17));
    json_decref(d);
    plume_flat_scene *fs = NULL;
    CHECK(doc && plume_flat_scene_open_json(doc, strip, &fs, msg, sizeof msg) == PLUME_OK);
    if (fs && p1) {
        for (int i = 0; i < 3; i++) {
            char *rep = NULL;
            CHECK(plume_flat_scene_step(fs, 1, &rep, msg, sizeof msg) == PLUME_OK);
            plume_flat_free(rep);
        }
        double *x = malloc((size_t)n1 * sizeof *x);
        CHECK(x && plume_flat_scene_nv(fs) * 3 == n1);
        if (x && plume_flat_scene_nv(fs) * 3 == n1) {
            plume_flat_scene_positions(fs, x);
            CHECK(memcmp(x, p1, (size_t)n1 * sizeof *x) == 0);
        }
        free(x);
    }
    plume_flat_scene_close(&fs);
    free(doc), free(p0), free(p1);
    plume_sweep_destroy(&s);
    remove_dir(dir);
}

/* the strip under two moduli, recorded by the sweep, against the same scene stepped through the
 * flat interface (the file itself, and the document with the modulus changed): the same
 * positions, times and iterations to the bit */
void test_sweep_scene_matches_library(void)
{
    char dir[64] = "/tmp/plume-sweepscene-XXXXXX", path[256], h5[256], strip[1200], text[2800], msg[512], obj[128];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    data_path("shell/strip_scene.json", strip, sizeof strip);
    snprintf(path, sizeof path, "%s/s.json", dir);
    snprintf(h5, sizeof h5, "%s/s.h5", dir);
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"steps\": 3}, \"vary\": {\"materials[0].membrane.E\": "
             "[1e7, 2e6]}}",
             strip);
    write_file(path, text);
    plume_sweep *s = run_sweep(path, h5);
    double *pos[2] = {NULL, NULL};
    long nvs = 0;
    for (int k = 0; s && k < 2; k++) {
        plume_flat_scene *fs = NULL;
        char *doc = NULL;
        if (k == 0) { /* the file as it is (E 1e7) */
            CHECK(plume_flat_scene_open(strip, &fs, msg, sizeof msg) == PLUME_OK);
        } else { /* its document with E 2e6 */
            json_t *d = json_load_file(strip, 0, NULL);
            json_object_set_new(json_object_get(json_array_get(json_object_get(d, "materials"), 0), "membrane"), "E",
                                json_real(2e6));
            doc = json_dumps(d, JSON_REAL_PRECISION(17));
            json_decref(d);
            CHECK(plume_flat_scene_open_json(doc, strip, &fs, msg, sizeof msg) == PLUME_OK);
        }
        if (!fs)
            break;
        long nv = plume_flat_scene_nv(fs);
        nvs = nv;
        double *x0 = malloc(3 * (size_t)nv * sizeof *x0), *x = malloc(3 * (size_t)nv * sizeof *x);
        double t[3], it[3], hv[3];
        plume_flat_scene_positions(fs, x0);
        for (int i = 0; i < 3; i++) {
            char *rep = NULL;
            CHECK(plume_flat_scene_step(fs, 1, &rep, msg, sizeof msg) == PLUME_OK);
            json_t *j = rep ? json_loads(rep, 0, NULL) : NULL;
            t[i] = json_real_value(json_object_get(j, "time"));
            it[i] = (double)json_integer_value(json_object_get(j, "newton_iterations"));
            hv[i] = (double)json_integer_value(json_object_get(j, "halvings"));
            json_decref(j);
            plume_flat_free(rep);
        }
        plume_flat_scene_positions(fs, x);
        double umax = 0.0;
        for (long v = 0; v < nv; v++)
            umax = fmax(umax, hypot(hypot(x[3 * v] - x0[3 * v], x[3 * v + 1] - x0[3 * v + 1]), x[3 * v + 2] - x0[3 * v + 2]));
        /* what the sweep recorded */
        long n;
        snprintf(obj, sizeof obj, "/sweep/runs/%d/positions", k);
        pos[k] = read_dataset(h5, obj, &n);
        CHECK(pos[k] && n == 3 * nv && memcmp(pos[k], x, (size_t)n * sizeof *x) == 0);
        const char *names[3] = {"time", "newton_iterations", "halvings"};
        const double *want[3] = {t, it, hv};
        for (int q = 0; q < 3; q++) {
            snprintf(obj, sizeof obj, "/sweep/runs/%d/per_step/%s", k, names[q]);
            double *v = read_dataset(h5, obj, &n);
            CHECK(v && n == 3 && memcmp(v, want[q], 3 * sizeof *v) == 0);
            free(v);
        }
        snprintf(obj, sizeof obj, "/sweep/runs/%d", k);
        CHECK(read_attr(h5, obj, "max_displacement") == umax && umax > 1e-5);
        CHECK(read_attr(h5, obj, "time") == plume_flat_scene_time(fs) && read_attr(h5, obj, "steps") == 3.0);
        CHECK(read_attr(h5, obj, "newton_iterations") == it[0] + it[1] + it[2]);
        char *outcome = read_attr_string(h5, obj, "outcome"), *rec = read_attr_string(h5, obj, "record");
        CHECK(outcome && strcmp(outcome, "converged") == 0);
        /* the record leaves out timings and the arrays stored as datasets */
        CHECK(rec && !strstr(rec, "seconds") && !strstr(rec, "positions") && !strstr(rec, "per_step") &&
              strstr(rec, "\"max_displacement\""));
        free(outcome), free(rec);
        free(x0), free(x), free(doc);
        plume_flat_scene_close(&fs);
    }
    /* the modulus reached the scene: the softer strip sags otherwise */
    CHECK(pos[0] && pos[1] && memcmp(pos[0], pos[1], 3 * (size_t)nvs * sizeof **pos) != 0);
    free(pos[0]), free(pos[1]);
    char units[256] = "";
    CHECK(h5_units(h5, "/sweep/runs/0/positions", units, sizeof units) == 0 && strcmp(units, "m") == 0);
    CHECK(h5_units(h5, "/sweep/runs/0/per_step/time", units, sizeof units) == 0 && strcmp(units, "s") == 0);
    CHECK(h5_units(h5, "/sweep/runs/0/per_step/newton_iterations", units, sizeof units) == 0 && strcmp(units, "1") == 0);
    CHECK(h5_units(h5, "/sweep/runs/0", units, sizeof units) == 0 && strstr(units, "max_displacement: m") &&
          strstr(units, "time: s"));
    char *scene_attr = read_attr_string(h5, "/sweep", "scene"), *scene_text = NULL;
    FILE *f = fopen(strip, "r");
    if (f) {
        scene_text = calloc(1, 1 << 16);
        if (fread(scene_text, 1, (1 << 16) - 1, f)) {
        }
        fclose(f);
    }
    CHECK(scene_attr && scene_text && strcmp(scene_attr, scene_text) == 0); /* the scene file is kept */
    free(scene_attr), free(scene_text);
    /* the summary: a scene row */
    char md[256], *json = NULL;
    plume_err err = {{0}};
    snprintf(md, sizeof md, "%s/s.md", dir);
    CHECK(s && plume_sweep_summary(h5, s, md, &json, &err) == PLUME_OK);
    json_t *rows = json ? json_loads(json, 0, NULL) : NULL;
    CHECK(json_array_size(rows) == 2 && json_integer_value(json_object_get(json_array_get(rows, 1), "steps")) == 3 &&
          json_real_value(json_object_get(json_array_get(rows, 1), "time")) > 0.0299);
    json_decref(rows);
    free(json);
    char mdtext[4096];
    app_slurp(md, mdtext, sizeof mdtext);
    CHECK(strstr(mdtext, "| steps | time (s) | max displacement (m) |") && strstr(mdtext, "| converged | 3 | 0.03 |"));
    /* the flat entry point's own errors name the file it stands for and the key, without a line */
    plume_flat_scene *fs = NULL;
    CHECK(plume_flat_scene_open_json("{", strip, &fs, msg, sizeof msg) == PLUME_EFORMAT && !fs && strstr(msg, strip));
    CHECK(plume_flat_scene_open_json(NULL, strip, &fs, msg, sizeof msg) == PLUME_EINVAL && !fs);
    plume_sweep_destroy(&s);
    remove_dir(dir);
}

/* the strip lowered towards the plate, two barrier thicknesses: the contact measures recorded per
 * step agree with those apps/feather writes in its frames file for the same four steps */
void test_sweep_scene_contact_measures(void)
{
    char dir[64] = "/tmp/plume-sweepscene-XXXXXX", path[256], h5[256], plate[1200], text[2800], obj[128];
    char args[2000], out[8192], errs[8192];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    data_path("shell/strip_on_plate.json", plate, sizeof plate);
    snprintf(path, sizeof path, "%s/s.json", dir);
    snprintf(h5, sizeof h5, "%s/s.h5", dir);
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"steps\": 4}, \"vary\": {\"contact.dhat\": [1e-3, 2e-3]}}",
             plate);
    write_file(path, text);
    plume_sweep *s = run_sweep(path, h5);
    /* apps/feather on the file (dhat 1e-3): one frame of output_every = 4 steps */
    snprintf(args, sizeof args, "%s -o %s/feather --frames 1 --quiet", plate, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(path, sizeof path, "%s/feather/frames.h5", dir);
    plume_frame_measures fm;
    plume_frame fr;
    plume_err err = {{0}};
    memset(&fr, 0, sizeof fr);
    CHECK(plume_frames_read_measures(path, 1, &fm, &err) == PLUME_OK);
    CHECK(plume_frames_read(path, 1, &fr, &err) == PLUME_OK && fr.step == 4);
    const char *names[6] = {"time", "newton_iterations", "halvings", "contact_pairs", "min_distance",
                            "intersecting_pairs"};
    double *v[6];
    long n[6];
    for (int q = 0; q < 6; q++) {
        snprintf(obj, sizeof obj, "/sweep/runs/0/per_step/%s", names[q]);
        v[q] = read_dataset(h5, obj, &n[q]);
        CHECK(v[q] && n[q] == 4);
    }
    if (v[0] && v[1] && v[2] && v[3] && v[4] && v[5] && n[5] == 4) {
        double iters = 0, halv = 0, pairs = 0, dmin = INFINITY, inter = 0;
        for (int i = 0; i < 4; i++)
            iters += v[1][i], halv += v[2][i], pairs = fmax(pairs, v[3][i]), dmin = fmin(dmin, v[4][i]),
                inter = fmax(inter, v[5][i]);
        CHECK(iters == fm.newton_iterations && halv == fm.steps_halved && pairs == fm.contact_pairs &&
              inter == fm.intersecting_pairs);
        CHECK_REL(dmin, fm.min_distance, 1e-9, 1e-12);
        CHECK(dmin < 0.01 && dmin > 0.005); /* the strip still 1 cm beside the plate, below the cap 10 dhat */
        CHECK(fabs(v[0][3] - fr.t) < 1e-15);
        CHECK(read_attr(h5, "/sweep/runs/0", "min_distance") == dmin);
    }
    for (int q = 0; q < 6; q++)
        free(v[q]);
    long np;
    double *x = read_dataset(h5, "/sweep/runs/0/positions", &np);
    CHECK(x && np == 3 * fr.nv);
    double dx = 0.0;
    for (long i = 0; x && np == 3 * fr.nv && i < np; i++)
        dx = fmax(dx, fabs(x[i] - fr.x[i]));
    CHECK(dx < 1e-12);
    fprintf(stderr, "    positions after 4 steps: at most %.3g m from apps/feather's\n", dx);
    free(x);
    plume_frame_free(&fr);
    /* the other run has its own dhat and cap */
    char *rec = read_attr_string(h5, "/sweep/runs/1", "record");
    json_t *r = rec ? json_loads(rec, 0, NULL) : NULL, *c = json_object_get(json_object_get(r, "result"), "contact");
    CHECK(json_real_value(json_object_get(c, "dhat")) == 2e-3 &&
          json_real_value(json_object_get(c, "min_distance_cap")) == 2e-2 &&
          json_integer_value(json_object_get(c, "max_intersecting_pairs")) == 0);
    json_decref(r);
    free(rec);
    char units[64];
    CHECK(h5_units(h5, "/sweep/runs/1/per_step/min_distance", units, sizeof units) == 0 && strcmp(units, "m") == 0);
    CHECK(h5_units(h5, "/sweep/runs/1/per_step/contact_pairs", units, sizeof units) == 0 && strcmp(units, "1") == 0);
    plume_sweep_destroy(&s);
    remove_dir(dir);
}

/* runs that fail are recorded: a value the scene loader refuses (its message, naming the key), a
 * misspelt key (the loader's unknown key), a step that does not converge (its reason, the steps
 * done); the others run */
void test_sweep_scene_failures(void)
{
    char dir[64] = "/tmp/plume-sweepscene-XXXXXX", path[256], h5[256], strip[1200], text[2800], obj[128];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    data_path("shell/strip_scene.json", strip, sizeof strip);
    snprintf(path, sizeof path, "%s/s.json", dir);
    snprintf(h5, sizeof h5, "%s/s.h5", dir);
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"steps\": 2}, \"vary\": {\"max_iter\": [1, 100], "
             "\"dt\": [0.01, -1]}}",
             strip);
    write_file(path, text);
    plume_sweep *s = run_sweep(path, h5);
    char *c[4];
    json_t *r[4];
    for (int k = 0; k < 4; k++) {
        snprintf(obj, sizeof obj, "/sweep/runs/%d", k);
        c[k] = read_attr_string(h5, obj, "record");
        r[k] = c[k] ? json_loads(c[k], 0, NULL) : NULL;
        CHECK(r[k] != NULL);
    }
    /* dt -1: the loader's message names the scene and the key, not a line of the file */
    char want[1300];
    snprintf(want, sizeof want, "%s: dt must be > 0 (got -1)", strip);
    for (int k = 1; k < 4; k += 2) {
        const char *m = json_string_value(json_object_get(r[k], "message"));
        CHECK(strcmp(json_string_value(json_object_get(r[k], "outcome")), "error") == 0 && m && strstr(m, want));
        snprintf(obj, sizeof obj, "/sweep/runs/%d/per_step/time", k);
        long n;
        double *v = read_dataset(h5, obj, &n);
        CHECK(v == NULL);
        free(v);
    }
    /* one Newton iteration a step: the first step fails even halved, and says why */
    json_t *res = json_object_get(r[0], "result");
    CHECK(strcmp(json_string_value(json_object_get(r[0], "outcome")), "iteration cap") == 0 &&
          json_is_false(json_object_get(res, "converged")) && json_integer_value(json_object_get(res, "steps")) == 0 &&
          json_integer_value(json_object_get(res, "halvings")) == 6);
    long n;
    double *h = read_dataset(h5, "/sweep/runs/0/per_step/halvings", &n);
    CHECK(h && n == 1 && h[0] == 6.0);
    free(h);
    CHECK(strcmp(json_string_value(json_object_get(r[2], "outcome")), "converged") == 0 &&
          json_integer_value(json_object_get(json_object_get(r[2], "result"), "steps")) == 2);
    for (int k = 0; k < 4; k++)
        json_decref(r[k]), free(c[k]);
    /* the summary shows the message */
    char md[256], mdtext[8192], *json = NULL;
    plume_err err = {{0}};
    snprintf(md, sizeof md, "%s/s.md", dir);
    CHECK(s && plume_sweep_summary(h5, s, md, &json, &err) == PLUME_OK);
    app_slurp(md, mdtext, sizeof mdtext);
    CHECK(strstr(mdtext, "| error: ") && strstr(mdtext, "dt must be > 0") && strstr(mdtext, "| iteration cap | 0 |"));
    free(json);
    plume_sweep_destroy(&s);
    /* a misspelt key reaches the loader, which names it */
    snprintf(text, sizeof text,
             "{\"run\": \"scene\", \"base\": {\"scene\": \"%s\", \"steps\": 1}, \"vary\": {\"materials[0].membrane.Eyy\": "
             "[1e6]}}",
             strip);
    write_file(path, text);
    CHECK(plume_sweep_load(path, NULL, &s, &err) == PLUME_OK);
    char *rec = s ? plume_sweep_execute(s, 0) : NULL;
    CHECK(rec && strstr(rec, "\"outcome\":\"error\"") && strstr(rec, "materials[0].membrane.Eyy is an unknown key"));
    free(rec);
    plume_sweep_destroy(&s);
    remove_dir(dir);
}

/* apps/sweep on a scene next to the sweep file (relative names): serially, again (nothing to do),
 * under mpirun -n 2 (the same content to the bit); a changed scene file is refused on resume */
void test_sweep_scene_app_ranks(void)
{
    char dir[64] = "/tmp/plume-sweepscene-XXXXXX", path[256], args[512], out[16384], errs[8192], cmd[1024];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(cmd, sizeof cmd, "mkdir -p %s/scene && cp ../data/shell/strip_scene.json ../data/shell/strip.obj %s/scene/",
             dir, dir);
    CHECK(system(cmd) == 0);
    snprintf(path, sizeof path, "%s/s.json", dir);
    write_file(path, "{\"run\": \"scene\", \"base\": {\"scene\": \"scene/strip_scene.json\", \"steps\": 2},\n"
                     " \"vary\": {\"materials[0].density\": [0.1, 0.3], \"gravity[2]\": [-9.81, -3]}}\n");
    snprintf(args, sizeof args, "%s -o %s/r1.h5 --json --quiet", path, dir);
    CHECK(app_run(dir, "sweep", args, out, sizeof out, errs, sizeof errs) == 0);
    json_t *j = json_loads(out, 0, NULL);
    CHECK(json_array_size(j) == 4 &&
          strcmp(json_string_value(json_object_get(json_array_get(j, 3), "outcome")), "converged") == 0 &&
          json_integer_value(json_object_get(json_array_get(j, 3), "steps")) == 2);
    json_decref(j);
    snprintf(path, sizeof path, "%s/r1.h5", dir);
    char *c1 = content(path, 4);
    CHECK(c1 && !strstr(c1, "missing") && !strstr(c1, "positions:\n") && !strstr(c1, "per_step/time:\n"));
    snprintf(args, sizeof args, "%s/s.json -o %s/r1.h5", dir, dir);
    CHECK(app_run(dir, "sweep", args, out, sizeof out, errs, sizeof errs) == 0 && strstr(errs, "4 already in"));
    int mpi = system("command -v mpirun >/dev/null 2>&1") == 0 &&
              system("ldd ../apps/sweep 2>/dev/null | grep -q libmpi") == 0;
    if (mpi) {
        snprintf(cmd, sizeof cmd,
                 "mpirun --allow-run-as-root --oversubscribe -n 2 ../apps/sweep %s/s.json -o %s/r2.h5 --quiet "
                 ">%s/mpi.txt 2>&1",
                 dir, dir, dir);
        int rc = system(cmd);
        CHECK(rc == 0);
        if (rc != 0) {
            static char said[4096];
            snprintf(path, sizeof path, "%s/mpi.txt", dir);
            app_slurp(path, said, sizeof said);
            fprintf(stderr, "    mpirun -n 2 failed: %s\n", said);
        }
        snprintf(path, sizeof path, "%s/r2.h5", dir);
        char *c2 = content(path, 4);
        CHECK(c1 && c2 && strcmp(c1, c2) == 0);
        fprintf(stderr, "    mpirun -n 2: scene results %s those of the serial sweep\n",
                c1 && c2 && strcmp(c1, c2) == 0 ? "identical to" : "DIFFERENT from");
        free(c2);
    } else {
        fprintf(stderr, "    MPI not installed (or sweep built without it): serial sweep only\n");
    }
    free(c1);
    /* the scene file changed: its old runs would mix with new ones */
    snprintf(cmd, sizeof cmd, "sed -i 's/\"dt\": 0.01/\"dt\": 0.005/' %s/scene/strip_scene.json", dir);
    CHECK(system(cmd) == 0);
    snprintf(args, sizeof args, "%s/s.json -o %s/r1.h5", dir, dir);
    CHECK(app_run(dir, "sweep", args, out, sizeof out, errs, sizeof errs) == 1 && strstr(errs, "changed since") &&
          strstr(errs, "strip_scene.json"));
    remove_dir(dir);
}
