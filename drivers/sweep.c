/* plume: parameter sweeps (drivers/sweep.h) — expansion, execution through the flat interface, and
 * the results file. */
#include "sweep.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>
#include <jansson.h>

#include "../lib/io/h5_atomic.h"
#include "../lib/io/h5util.h"
#include "../lib/io/input_file.h"
#include "../lib/io/progress.h"
#include "../lib/io/sample.h"
#include "flat.h"
#include "internal/sweep_scene.h"

/* one "vary" entry: its key and its values (JSON, owned) */
typedef struct {
    char *key;
    json_t *values; /* array; for "sample": the sample objects {id, lx, ly, thickness, angle} */
    int sample;
} axis;

struct plume_sweep {
    char *path, *text, *job;
    json_t *base;
    int naxes, count;
    axis *axes;
    int is_scene;
    plume_sweep_scene scene; /* a scene job's file and document */
};

void plume_sweep_destroy(plume_sweep **ps)
{
    if (!ps || !*ps)
        return;
    plume_sweep *s = *ps;
    for (int a = 0; a < s->naxes; a++) {
        free(s->axes[a].key);
        json_decref(s->axes[a].values);
    }
    free(s->axes);
    plume_sweep_scene_free(&s->scene);
    json_decref(s->base);
    free(s->path);
    free(s->text);
    free(s->job);
    free(s);
    *ps = NULL;
}

/* the values of a range {"from", "to", "count", "scale"} */
static json_t *range_values(const char *path, const char *key, json_t *r, plume_err *err)
{
    json_t *from = json_object_get(r, "from"), *to = json_object_get(r, "to"), *count = json_object_get(r, "count"),
           *scale = json_object_get(r, "scale");
    const char *sc = scale ? json_string_value(scale) : "linear";
    if (!json_is_number(from) || !json_is_number(to) || !json_is_integer(count) || json_integer_value(count) < 1 ||
        json_integer_value(count) > 100000 || !sc || (strcmp(sc, "linear") && strcmp(sc, "log")) ||
        json_object_size(r) != 3u + (scale != NULL)) {
        plume_err_set(err, PLUME_EINVAL,
                      "%s: vary.%s: a range is {\"from\": a, \"to\": b, \"count\": n >= 1, \"scale\": \"linear\" | "
                      "\"log\"}",
                      path, key);
        return NULL;
    }
    double a = json_number_value(from), b = json_number_value(to);
    long n = (long)json_integer_value(count);
    int lg = strcmp(sc, "log") == 0;
    if (!isfinite(a) || !isfinite(b) || (lg && !(a > 0.0 && b > 0.0))) {
        plume_err_set(err, PLUME_EINVAL, "%s: vary.%s: the range's ends must be finite (and > 0 on a log scale)", path,
                      key);
        return NULL;
    }
    json_t *v = json_array();
    for (long i = 0; i < n; i++) {
        double t = n == 1 ? 0.0 : (double)i / (double)(n - 1);
        double x = lg ? a * pow(b / a, t) : a + t * (b - a);
        if (i == n - 1)
            x = b; /* the end exactly */
        json_array_append_new(v, json_real(x));
    }
    return v;
}

/* the samples of "sample": "table1" (all) or a list of ids */
static json_t *sample_values(const char *path, const char *samples_path, json_t *spec, plume_err *err)
{
    json_t *v = json_array();
    int n = 0;
    plume_status st = PLUME_OK;
    if (!samples_path) {
        plume_err_set(err, PLUME_EINVAL, "%s: vary.sample needs the samples file (data/samples.json)", path);
        json_decref(v);
        return NULL;
    }
    if (json_is_string(spec) && strcmp(json_string_value(spec), "table1") == 0) {
        if ((st = plume_sample_count(samples_path, &n, err)) != PLUME_OK) {
            json_decref(v);
            return NULL;
        }
    } else if (!json_is_array(spec) || json_array_size(spec) == 0) {
        plume_err_set(err, PLUME_EINVAL, "%s: vary.sample must be \"table1\" or a list of sample ids", path);
        json_decref(v);
        return NULL;
    } else {
        n = (int)json_array_size(spec);
    }
    for (int i = 0; i < n; i++) {
        plume_sample s;
        if (json_is_array(spec)) {
            const char *id = json_string_value(json_array_get(spec, (size_t)i));
            if (!id) {
                plume_err_set(err, PLUME_EINVAL, "%s: vary.sample[%d] must be a sample id string", path, i);
                st = PLUME_EINVAL;
            } else {
                st = plume_sample_load(samples_path, id, &s, err);
            }
        } else {
            st = plume_sample_at(samples_path, i, &s, err);
        }
        if (st != PLUME_OK) {
            json_decref(v);
            return NULL;
        }
        double angle = strcmp(s.scenario, "longitudinal") == 0 ? 0.0 : strcmp(s.scenario, "transverse") == 0 ? 90.0 : 45.0;
        json_array_append_new(v, json_pack("{s:s, s:f, s:f, s:f, s:f}", "id", s.id, "lx", s.lx, "ly", s.ly, "thickness",
                                           s.h, "angle", angle));
    }
    return v;
}

/* The whole sweep file as a string (*text, the caller frees it). */
static plume_status read_sweep_file(const char *path, char **text_out, plume_err *err)
{
    FILE *f = plume_input_fopen(path, "rb", "sweep file", err);
    if (!f)
        return PLUME_EIO;
    size_t cap = 1 << 16, n = 0;
    char *text = malloc(cap + 1);
    size_t got;
    while (text && (got = fread(text + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            char *t = realloc(text, 2 * cap + 1);
            if (!t) {
                free(text);
                text = NULL;
                break;
            }
            text = t, cap *= 2;
        }
    }
    fclose(f);
    if (!text)
        return plume_err_set(err, PLUME_ENOMEM, "sweep: out of memory");
    text[n] = '\0';
    *text_out = text;
    return PLUME_OK;
}

/* The sweep document's keys, its job ("run") and its base request (a scene job's file set up). */
static plume_status parse_job(plume_sweep *s, json_t *doc, const char *path, plume_err *err)
{
    const char *key;
    json_t *v;
    json_object_foreach(doc, key, v) {
        if (strcmp(key, "run") && strcmp(key, "base") && strcmp(key, "vary") && strcmp(key, "note"))
            return plume_err_set(err, PLUME_EINVAL, "%s: unknown key \"%s\" (run, base, vary, note)", path, key);
    }
    const char *job = json_string_value(json_object_get(doc, "run"));
    if (!job || (strcmp(job, "traction") && strcmp(job, "homogenize") && strcmp(job, "fit") && strcmp(job, "scene")))
        return plume_err_set(err, PLUME_EINVAL, "%s: \"run\" must be \"traction\", \"homogenize\", \"fit\" or \"scene\"",
                             path);
    s->job = strdup(job);
    s->is_scene = strcmp(job, "scene") == 0;
    json_t *base = json_object_get(doc, "base");
    if (base && !json_is_object(base))
        return plume_err_set(err, PLUME_EINVAL, "%s: \"base\" must be an object (a %s request)", path, job);
    s->base = base ? json_deep_copy(base) : json_object();
    if (s->is_scene)
        return plume_sweep_scene_setup(path, s->base, &s->scene, err);
    return PLUME_OK;
}

/* The sweep document's "vary": one axis per key (a list, a range, or for "sample" the samples
 * named), and the number of runs they expand to. */
static plume_status parse_vary(plume_sweep *s, json_t *doc, const char *path, const char *samples_path, plume_err *err)
{
    json_t *vary = json_object_get(doc, "vary");
    if (vary && !json_is_object(vary))
        return plume_err_set(err, PLUME_EINVAL, "%s: \"vary\" must be an object of key: values", path);
    s->count = 1;
    s->axes = calloc(json_object_size(vary) + 1, sizeof *s->axes);
    const char *key;
    json_t *v;
    json_object_foreach(vary, key, v) {
        axis *a = &s->axes[s->naxes++];
        a->key = strdup(key);
        a->sample = strcmp(key, "sample") == 0 && !s->is_scene;
        if (a->sample)
            a->values = sample_values(path, samples_path, v, err);
        else if (json_is_array(v) && json_array_size(v) > 0)
            a->values = json_deep_copy(v);
        else if (json_is_object(v))
            a->values = range_values(path, key, v, err);
        else
            plume_err_set(err, PLUME_EINVAL, "%s: vary.%s must be a non-empty list or a range", path, key);
        if (!a->values)
            return PLUME_EINVAL;
        size_t m = json_array_size(a->values);
        if ((double)s->count * (double)m > 1e6)
            return plume_err_set(err, PLUME_EINVAL, "%s: the sweep expands to more than 10^6 runs", path);
        s->count *= (int)m;
    }
    return PLUME_OK;
}

plume_status plume_sweep_load(const char *path, const char *samples_path, plume_sweep **out, plume_err *err)
{
    if (!path || !out)
        return plume_err_set(err, PLUME_EINVAL, "sweep: invalid arguments");
    *out = NULL;
    char *text = NULL;
    plume_status st = read_sweep_file(path, &text, err);
    if (st != PLUME_OK)
        return st;
    json_error_t je;
    json_t *doc = json_loads(text, JSON_REJECT_DUPLICATES, &je);
    plume_sweep *s = calloc(1, sizeof *s);
    if (!s) {
        free(text);
        json_decref(doc);
        return plume_err_set(err, PLUME_ENOMEM, "sweep: out of memory");
    }
    s->text = text, s->path = strdup(path);
    if (!doc) {
        st = plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", path, je.line, je.column, je.text);
        goto fail;
    }
    if ((st = parse_job(s, doc, path, err)) != PLUME_OK || (st = parse_vary(s, doc, path, samples_path, err)) != PLUME_OK)
        goto fail;
    json_decref(doc);
    /* every run's request must be well formed before anything runs: check run 0's keys */
    char *req = NULL, *vals = NULL;
    if ((st = plume_sweep_request(s, 0, &req, &vals, err)) != PLUME_OK) {
        plume_sweep_destroy(&s);
        return st;
    }
    free(req);
    free(vals);
    *out = s;
    return PLUME_OK;
fail:
    json_decref(doc);
    plume_sweep_destroy(&s);
    return st;
}

int plume_sweep_count(const plume_sweep *s)
{
    return s ? s->count : 0;
}

const char *plume_sweep_job(const plume_sweep *s)
{
    return s ? s->job : NULL;
}

/* obj[dotted key] = value, creating the intermediate objects */
static plume_status set_dotted(json_t *obj, const char *key, json_t *value, const char *path, plume_err *err)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", key);
    char *p = buf, *dot;
    while ((dot = strchr(p, '.'))) {
        *dot = '\0';
        json_t *sub = json_object_get(obj, p);
        if (!sub) {
            sub = json_object();
            json_object_set_new(obj, p, sub);
        } else if (!json_is_object(sub)) {
            json_decref(value);
            return plume_err_set(err, PLUME_EINVAL, "%s: vary.%s: \"%s\" of the base request is not an object", path,
                                 key, p);
        }
        obj = sub;
        p = dot + 1;
    }
    json_object_set_new(obj, p, value);
    return PLUME_OK;
}

plume_status plume_sweep_request(const plume_sweep *s, int k, char **request, char **values, plume_err *err)
{
    if (!s || k < 0 || k >= s->count || !request || !values)
        return plume_err_set(err, PLUME_EINVAL, "sweep: run %d is not one of the %d runs", k, s ? s->count : 0);
    *request = *values = NULL;
    json_t *req = s->is_scene ? plume_sweep_scene_request(&s->scene) : json_deep_copy(s->base), *vals = json_object();
    plume_status st = PLUME_OK;
    int rest = k, *index = malloc(((size_t)s->naxes + 1) * sizeof *index);
    if (!index || !req || !vals) {
        free(index);
        json_decref(req), json_decref(vals);
        return plume_err_set(err, PLUME_ENOMEM, "sweep: out of memory");
    }
    for (int a = s->naxes - 1; a >= 0; a--) { /* the last axis varies fastest */
        int m = (int)json_array_size(s->axes[a].values);
        index[a] = rest % m;
        rest /= m;
    }
    for (int a = 0; a < s->naxes && st == PLUME_OK; a++) { /* values in the file's order */
        const axis *ax = &s->axes[a];
        json_t *v = json_array_get(ax->values, (size_t)index[a]);
        if (ax->sample) {
            static const char *const keys[] = {"lx", "ly", "thickness", "angle"};
            for (int q = 0; q < 4 && st == PLUME_OK; q++)
                st = set_dotted(req, keys[q], json_deep_copy(json_object_get(v, keys[q])), s->path, err);
            json_object_set(vals, "sample", json_object_get(v, "id"));
        } else {
            if (s->is_scene) /* a key path into the scene's document */
                st = plume_sweep_scene_set(json_object_get(req, "document"), ax->key, json_deep_copy(v), s->path,
                                           s->scene.path, err);
            else
                st = set_dotted(req, ax->key, json_deep_copy(v), s->path, err);
            json_object_set(vals, ax->key, v);
        }
    }
    free(index);
    if (st == PLUME_OK) {
        *request = json_dumps(req, JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_SORT_KEYS);
        *values = json_dumps(vals, JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_PRESERVE_ORDER);
        if (!*request || !*values) {
            free(*request), free(*values);
            *request = *values = NULL;
            st = plume_err_set(err, PLUME_ENOMEM, "sweep: out of memory");
        }
    }
    json_decref(req);
    json_decref(vals);
    return st;
}

char *plume_sweep_execute(const plume_sweep *s, int k)
{
    plume_err err = {{0}};
    char *req = NULL, *vals = NULL, *result = NULL, msg[1024] = "";
    plume_status st = plume_sweep_request(s, k, &req, &vals, &err);
    double t0 = plume_wall_seconds();
    if (st != PLUME_OK)
        snprintf(msg, sizeof msg, "%s", err.msg);
    else if (strcmp(s->job, "traction") == 0)
        st = plume_flat_traction(req, &result, msg, sizeof msg);
    else if (strcmp(s->job, "fit") == 0)
        st = plume_flat_fit(req, &result, msg, sizeof msg);
    else if (s->is_scene)
        st = plume_sweep_scene_run(req, &result, msg, sizeof msg);
    else
        st = plume_flat_homogenize(req, &result, msg, sizeof msg);
    double seconds = plume_wall_seconds() - t0;
    json_t *rec = json_object(), *res = result ? json_loads(result, 0, NULL) : NULL;
    json_object_set_new(rec, "run", json_integer(k));
    json_object_set_new(rec, "values", vals ? json_loads(vals, JSON_DECODE_ANY, NULL) : json_object());
    const char *outcome = "error";
    if (st == PLUME_OK && res) {
        json_t *conv = json_object_get(res, "converged"), *why = json_object_get(res, "stop_reason");
        outcome = !conv || json_is_true(conv) ? "converged" : why ? json_string_value(why) : "not converged";
    }
    json_object_set_new(rec, "outcome", json_string(outcome));
    if (st != PLUME_OK)
        json_object_set_new(rec, "message", json_string(msg));
    json_object_set_new(rec, "seconds", json_real(seconds));
    if (res) {
        json_object_del(res, "seconds"); /* timings are kept apart, in "seconds" */
        json_object_set_new(rec, "result", res);
    }
    char *text = json_dumps(rec, JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_PRESERVE_ORDER);
    json_decref(rec);
    plume_flat_free(result);
    free(req);
    free(vals);
    return text;
}

/* ------------------------------------------------------------------------------------------ */
/* the results file */

static plume_status open_rw(const char *h5path, hid_t *fid, plume_err *err)
{
    struct stat st;
    if (stat(h5path, &st) != 0 || !S_ISREG(st.st_mode) || !h5_is_hdf5(h5path))
        return plume_err_set(err, PLUME_EIO, "sweep results '%s': not an HDF5 file", h5path);
    *fid = H5Fopen(h5path, H5F_ACC_RDWR, H5P_DEFAULT);
    return *fid < 0 ? plume_err_set(err, PLUME_EIO, "sweep results '%s': cannot open for writing", h5path) : PLUME_OK;
}

/* the string attribute `name` of obj (malloc'ed) or NULL */
static char *attr_string(hid_t obj, const char *name)
{
    if (H5Aexists(obj, name) <= 0)
        return NULL;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), t = a >= 0 ? H5Aget_type(a) : H5I_INVALID_HID;
    char *s = NULL, *out = NULL;
    if (t >= 0 && H5Tis_variable_str(t) > 0 && H5Aread(a, t, &s) >= 0 && s) {
        out = strdup(s);
        H5free_memory(s);
    }
    if (t >= 0)
        H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
    return out;
}

/* A new results file's /sweep group: the job, the sweep file's text (and the scene's), the count of
 * runs, and an empty /sweep/runs. */
static plume_status fill_new_results(hid_t fid, const char *path, const void *ctx, plume_err *err)
{
    const plume_sweep *s = ctx;
    hid_t g = H5Gcreate2(fid, "/sweep", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t r = g >= 0 ? H5Gcreate2(g, "runs", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
    long runs = s->count;
    plume_status st = PLUME_OK;
    if (r < 0 || h5_write_attr_string(g, "job", s->job) < 0 || h5_write_attr_string(g, "file", s->text) < 0 ||
        h5_write_attr(g, "runs", H5T_STD_I64LE, H5T_NATIVE_LONG, &runs) < 0 ||
        (s->is_scene && h5_write_attr_string(g, "scene", s->scene.text) < 0))
        st = plume_err_set(err, PLUME_EIO, "sweep results '%s': cannot create its /sweep group", path);
    if (r >= 0)
        H5Gclose(r);
    if (g >= 0)
        H5Gclose(g);
    return st;
}

plume_status plume_sweep_results_open(const char *h5path, const plume_sweep *s, plume_err *err)
{
    if (!h5path || !s)
        return plume_err_set(err, PLUME_EINVAL, "sweep results: invalid arguments");
    h5_quiet q;
    quiet_begin(&q);
    struct stat sb;
    plume_status st = PLUME_OK;
    if (stat(h5path, &sb) == 0) { /* resuming: it must be this sweep's file */
        hid_t fid = H5I_INVALID_HID;
        if ((st = open_rw(h5path, &fid, err)) == PLUME_OK) {
            hid_t g = H5Lexists(fid, "/sweep", H5P_DEFAULT) > 0 ? H5Gopen2(fid, "/sweep", H5P_DEFAULT) : -1;
            char *file = g >= 0 ? attr_string(g, "file") : NULL;
            char *scene = g >= 0 && s->is_scene ? attr_string(g, "scene") : NULL;
            if (!file || strcmp(file, s->text) != 0)
                st = plume_err_set(err, PLUME_EINVAL,
                                   "sweep results '%s': holds %s (remove it, or name another output file)", h5path,
                                   file ? "another sweep's runs" : "no /sweep group of plume");
            else if (s->is_scene && (!scene || strcmp(scene, s->scene.text) != 0)) /* its runs would mix two scenes */
                st = plume_err_set(err, PLUME_EINVAL,
                                   "sweep results '%s': the scene file %s changed since its runs were recorded (remove "
                                   "it, or name another output file)",
                                   h5path, s->scene.path);
            free(file);
            free(scene);
            if (g >= 0)
                H5Gclose(g);
            H5Fclose(fid);
        }
    } else {
        st = plume_h5_atomic_write(h5path, "sweep results", fill_new_results, s, err);
    }
    quiet_end(&q);
    return st;
}

/* the results file read-only and its /sweep/runs group (-1 when there is none yet) */
static plume_status open_runs(const char *h5path, hid_t *fid, hid_t *runs, plume_err *err)
{
    *runs = -1;
    *fid = H5Fopen(h5path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (*fid < 0)
        return plume_err_set(err, PLUME_EIO, "sweep results '%s': cannot open", h5path);
    if (H5Lexists(*fid, "/sweep/runs", H5P_DEFAULT) > 0)
        *runs = H5Gopen2(*fid, "/sweep/runs", H5P_DEFAULT);
    return PLUME_OK;
}

plume_status plume_sweep_results_done(const char *h5path, const plume_sweep *s, unsigned char *done, plume_err *err)
{
    memset(done, 0, (size_t)s->count);
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid, g;
    if (open_runs(h5path, &fid, &g, err) != PLUME_OK) {
        quiet_end(&q);
        return PLUME_EIO;
    }
    for (int k = 0; g >= 0 && k < s->count; k++) {
        char name[32];
        snprintf(name, sizeof name, "%d", k);
        done[k] = H5Lexists(g, name, H5P_DEFAULT) > 0;
    }
    if (g >= 0)
        H5Gclose(g);
    H5Fclose(fid);
    quiet_end(&q);
    return PLUME_OK;
}

/* json array `a` of numbers into a malloc'ed vector of *n doubles */
static double *vector(json_t *a, plume_index *n)
{
    *n = (plume_index)json_array_size(a);
    double *v = malloc(((size_t)*n + 1) * sizeof *v);
    for (plume_index i = 0; v && i < *n; i++)
        v[i] = json_number_value(json_array_get(a, (size_t)i));
    return v;
}

/* One run's record: its curves, its scene measures, the record without arrays and timing, the
 * values, the outcome and the seconds, in the group /sweep/runs/<k> (replacing one there). */
typedef struct {
    const plume_sweep *s;
    int k;
    json_t *rec;
} run_record_ctx;

static plume_status fill_run_record(hid_t fid, const char *path, const void *vctx, plume_err *err)
{
    const run_record_ctx *c = vctx;
    const plume_sweep *s = c->s;
    json_t *rec = c->rec;
    char name[32];
    snprintf(name, sizeof name, "%d", c->k);
    hid_t runs = H5Gopen2(fid, "/sweep/runs", H5P_DEFAULT);
    if (runs >= 0 && H5Lexists(runs, name, H5P_DEFAULT) > 0)
        H5Ldelete(runs, name, H5P_DEFAULT);
    hid_t g = runs >= 0 ? H5Gcreate2(runs, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
    json_t *res = json_object_get(rec, "result");
    int bad = g < 0;
    static const char *const curves[3] = {"strain", "stress", "wbar"};
    static const char *const units[3] = {"1", "Pa", "1"};
    for (int q = 0; q < 3 && !bad; q++) {
        json_t *a = json_object_get(res, curves[q]);
        if (!json_is_array(a))
            continue;
        plume_index n;
        double *v = vector(a, &n);
        bad = !v || h5_write_dataset(g, curves[q], v, n, units[q]) < 0;
        free(v);
    }
    if (!bad && s->is_scene) /* per-step measures, final positions, the run's numbers with units */
        bad = plume_sweep_scene_write(g, res) < 0;
    /* the record without the arrays and without the timing: the content a sweep's spread leaves alone */
    json_t *slim = json_deep_copy(rec);
    json_object_del(slim, "seconds");
    json_t *sres = json_object_get(slim, "result");
    for (int q = 0; q < 3; q++)
        json_object_del(sres, curves[q]);
    json_object_del(sres, "iterations");
    for (int q = 0; s->is_scene && plume_sweep_scene_arrays[q]; q++)
        json_object_del(sres, plume_sweep_scene_arrays[q]);
    char *slim_text = json_dumps(slim, JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_SORT_KEYS);
    char *values = json_dumps(json_object_get(rec, "values"), JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_SORT_KEYS);
    const char *outcome = json_string_value(json_object_get(rec, "outcome"));
    if (!bad)
        bad = !slim_text || !values || h5_write_attr_string(g, "record", slim_text) < 0 ||
              h5_write_attr_string(g, "values", values) < 0 ||
              h5_write_attr_string(g, "outcome", outcome ? outcome : "error") < 0 ||
              h5_write_attr_double(g, "seconds", json_number_value(json_object_get(rec, "seconds"))) < 0;
    if (g >= 0)
        H5Gclose(g);
    if (runs >= 0)
        H5Gclose(runs);
    free(slim_text);
    free(values);
    json_decref(slim);
    return bad ? plume_err_set(err, PLUME_EIO, "sweep results '%s': cannot write run %d", path, c->k) : PLUME_OK;
}

/* The results file is rewritten whole for each run (a copy edited and renamed over it,
 * lib/io/h5_atomic.h): an HDF5 file edited in place and killed in the middle of its
 * metadata flush can lose links or point them at other runs' groups (measured: 45 of 130 kill
 * points of a 9-run sweep). A full disk fails the copy and leaves the file as it was. */
plume_status plume_sweep_results_add(const char *h5path, const plume_sweep *s, int k, const char *record,
                                     plume_err *err)
{
    json_t *rec = record ? json_loads(record, 0, NULL) : NULL;
    if (!s || !rec || k < 0 || k >= s->count) {
        json_decref(rec);
        return plume_err_set(err, PLUME_EINVAL, "sweep results: run %d: invalid record", k);
    }
    h5_quiet q;
    quiet_begin(&q);
    struct stat sb;
    plume_status st;
    if (stat(h5path, &sb) != 0 || !S_ISREG(sb.st_mode) || !h5_is_hdf5(h5path))
        st = plume_err_set(err, PLUME_EIO, "sweep results '%s': not an HDF5 file", h5path);
    else {
        run_record_ctx c = {s, k, rec};
        st = plume_h5_atomic_write(h5path, "sweep results", fill_run_record, &c, err);
    }
    quiet_end(&q);
    json_decref(rec);
    return st;
}

/* the last value of dataset `name` of group g, or NaN */
static double last_value(hid_t g, const char *name)
{
    double v = NAN;
    if (H5Lexists(g, name, H5P_DEFAULT) <= 0)
        return v;
    hid_t d = H5Dopen2(g, name, H5P_DEFAULT), sp = d >= 0 ? H5Dget_space(d) : -1;
    hssize_t n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : 0;
    if (n > 0 && n < 100000000) {
        double *all = malloc((size_t)n * sizeof *all);
        if (all && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, all) >= 0)
            v = all[n - 1];
        free(all);
    }
    if (sp >= 0)
        H5Sclose(sp);
    if (d >= 0)
        H5Dclose(d);
    return v;
}

/* What the summary adds up over the recorded runs. */
typedef struct {
    int recorded, converged;
    double total; /* seconds */
} summary_totals;

/* The summary table's title and header: a scene run's columns are its steps, time, displacement
 * and contact distance, another run's its last strain and stress. */
static void summary_header(FILE *md, const plume_sweep *s)
{
    if (s->is_scene)
        fprintf(md, "# plume sweep: %s, %d runs (%s)\n\n| run | values | outcome | %s | seconds |\n"
                    "|---|---|---|---|---|---|---|---|\n",
                s->job, s->count, s->path, plume_sweep_scene_summary_header);
    else
        fprintf(md, "# plume sweep: %s, %d runs (%s)\n\n| run | values | outcome | strain | stress (Pa) | seconds |\n"
                    "|---|---|---|---|---|---|\n",
                s->job, s->count, s->path);
}

/* The run group's "seconds" attribute, NaN without one. */
static double run_seconds(hid_t g)
{
    double seconds = NAN;
    if (H5Aexists(g, "seconds") > 0) {
        hid_t a = H5Aopen(g, "seconds", H5P_DEFAULT);
        H5Aread(a, H5T_NATIVE_DOUBLE, &seconds);
        H5Aclose(a);
    }
    return seconds;
}

/* Recorded run k (its group g): its row of the table (md, may be NULL) and of the JSON array, and
 * its share of the totals. */
static void summarize_run(hid_t g, int k, const plume_sweep *s, FILE *md, json_t *arr, summary_totals *tot)
{
    char *values = attr_string(g, "values"), *outcome = attr_string(g, "outcome"), *rec = attr_string(g, "record");
    json_t *rj = rec ? json_loads(rec, 0, NULL) : NULL;
    const char *message = json_string_value(json_object_get(rj, "message"));
    double seconds = run_seconds(g), strain = last_value(g, "strain"), stress = last_value(g, "stress");
    tot->recorded++;
    tot->converged += outcome && strcmp(outcome, "converged") == 0;
    tot->total += isfinite(seconds) ? seconds : 0.0;
    /* a fit's outcome is its moduli and misfit */
    json_t *res = json_object_get(rj, "result");
    char fitted[256] = "";
    if (json_object_get(res, "residual"))
        snprintf(fitted, sizeof fitted, " (E_xx %.6g, E_yy %.6g, nu_xy %.4g, G_xy %.6g Pa; residual %.3g)",
                 json_number_value(json_object_get(res, "E_xx")), json_number_value(json_object_get(res, "E_yy")),
                 json_number_value(json_object_get(res, "nu_xy")), json_number_value(json_object_get(res, "G_xy")),
                 json_number_value(json_object_get(res, "residual")));
    if (s->is_scene) {
        json_t *row = json_pack("{s:i, s:o, s:s, s:f}", "run", k, "values",
                                values ? json_loads(values, 0, NULL) : json_object(), "outcome",
                                outcome ? outcome : "?", "seconds", isfinite(seconds) ? seconds : 0.0);
        char cells[256];
        plume_sweep_scene_summary_row(res, cells, sizeof cells, row);
        if (md)
            fprintf(md, "| %d | `%s` | %s%s%.100s | %s | %.3f |\n", k, values ? values : "", outcome ? outcome : "?",
                    message ? ": " : "", message ? message : "", cells, seconds);
        json_array_append_new(arr, row);
    } else {
        if (md)
            fprintf(md, "| %d | `%s` | %s%s%.100s%s | %.6g | %.6g | %.3f |\n", k, values ? values : "",
                    outcome ? outcome : "?", message ? ": " : "", message ? message : "", fitted, strain, stress,
                    seconds);
        json_array_append_new(arr, json_pack("{s:i, s:o, s:s, s:f, s:f, s:f}", "run", k, "values",
                                             values ? json_loads(values, 0, NULL) : json_object(), "outcome",
                                             outcome ? outcome : "?", "strain", isfinite(strain) ? strain : 0.0,
                                             "stress", isfinite(stress) ? stress : 0.0, "seconds",
                                             isfinite(seconds) ? seconds : 0.0));
    }
    free(values);
    free(outcome);
    free(rec);
    json_decref(rj);
}

/* The table's last line, then the table (written under the name tmp) renamed to md_path. */
static plume_status summary_close(FILE *md, const char *tmp, const char *md_path, const plume_sweep *s,
                                  const summary_totals *tot, plume_err *err)
{
    fprintf(md, "\n%d of %d runs recorded, %d converged; %.1f s of runs in all.\n", tot->recorded, s->count,
            tot->converged, tot->total);
    int bad = ferror(md);
    if (fclose(md) != 0 || bad || rename(tmp, md_path) != 0) {
        unlink(tmp);
        return plume_err_set(err, PLUME_EIO, "sweep summary '%s': cannot write", md_path);
    }
    return PLUME_OK;
}

plume_status plume_sweep_summary(const char *h5path, const plume_sweep *s, const char *md_path, char **json,
                                 plume_err *err)
{
    if (json)
        *json = NULL;
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid, runs;
    if (open_runs(h5path, &fid, &runs, err) != PLUME_OK) {
        quiet_end(&q);
        return PLUME_EIO;
    }
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", md_path ? md_path : "", (long)getpid());
    FILE *md = md_path ? fopen(tmp, "w") : NULL;
    if (md_path && !md) {
        if (runs >= 0)
            H5Gclose(runs);
        H5Fclose(fid);
        quiet_end(&q);
        return plume_err_set(err, PLUME_EIO, "sweep summary '%s': cannot create: %s", md_path, strerror(errno));
    }
    json_t *arr = json_array();
    summary_totals tot = {0, 0, 0.0};
    if (md)
        summary_header(md, s);
    for (int k = 0; runs >= 0 && k < s->count; k++) {
        char name[32];
        snprintf(name, sizeof name, "%d", k);
        if (H5Lexists(runs, name, H5P_DEFAULT) <= 0) {
            if (md)
                fprintf(md, "| %d | | not run | | | |%s\n", k, s->is_scene ? " | |" : "");
            continue;
        }
        hid_t g = H5Gopen2(runs, name, H5P_DEFAULT);
        summarize_run(g, k, s, md, arr, &tot);
        H5Gclose(g);
    }
    if (runs >= 0)
        H5Gclose(runs);
    H5Fclose(fid);
    quiet_end(&q);
    plume_status st = md ? summary_close(md, tmp, md_path, s, &tot, err) : PLUME_OK;
    if (json && st == PLUME_OK)
        *json = json_dumps(arr, JSON_REAL_PRECISION(17) | JSON_INDENT(2));
    json_decref(arr);
    return st;
}
