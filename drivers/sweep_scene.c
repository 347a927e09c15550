/* plume: the scene job of a parameter sweep (drivers/internal/sweep_scene.h): the scene file of the
 * base, key paths into its document, a run stepped with the measures apps/feather reports, and
 * the run's datasets in the results file. */
#include "internal/sweep_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/io/h5util.h"
#include "../lib/io/json_read.h"
#include "../include/plume/scene.h"
#include "internal/scene_description.h"

void plume_sweep_scene_free(plume_sweep_scene *sc)
{
    if (!sc)
        return;
    free(sc->path);
    free(sc->text);
    json_decref(sc->doc);
    memset(sc, 0, sizeof *sc);
}

plume_status plume_sweep_scene_setup(const char *sweep_path, json_t *base, plume_sweep_scene *sc, plume_err *err)
{
    memset(sc, 0, sizeof *sc);
    const char *key;
    json_t *v;
    json_object_foreach(base, key, v) {
        if (strcmp(key, "scene") && strcmp(key, "steps") && strcmp(key, "duration"))
            return plume_err_set(err, PLUME_EINVAL,
                                 "%s: base.%s is not a key of a scene run (scene, steps, duration); the scene's own "
                                 "keys are changed through \"vary\"",
                                 sweep_path, key);
    }
    json_t *js = json_object_get(base, "scene"), *jn = json_object_get(base, "steps"),
           *jd = json_object_get(base, "duration");
    const char *name = json_string_value(js);
    if (!name || !*name)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s: base.scene must name the scene file (relative to the sweep file's directory)",
                             sweep_path);
    if (jn && jd)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s: base.steps and base.duration: give one (steps of the scene's dt, or the time to reach)",
                             sweep_path);
    if (jn && (!json_is_integer(jn) || json_integer_value(jn) < 1 || json_integer_value(jn) > 1000000))
        return plume_err_set(err, PLUME_EINVAL, "%s: base.steps must be an integer in [1, 1000000]", sweep_path);
    if (jd && (!json_is_number(jd) || !(json_number_value(jd) > 0.0) || !isfinite(json_number_value(jd))))
        return plume_err_set(err, PLUME_EINVAL, "%s: base.duration must be a number > 0 (s)", sweep_path);
    sc->steps = jn ? (long)json_integer_value(jn) : 0;
    /* relative to the sweep file's directory, as a scene's own files are to the scene's */
    const char *slash = strrchr(sweep_path, '/');
    size_t dirlen = name[0] == '/' || !slash ? 0 : (size_t)(slash - sweep_path) + 1;
    sc->path = malloc(dirlen + strlen(name) + 1);
    if (!sc->path)
        return plume_err_set(err, PLUME_ENOMEM, "sweep: out of memory");
    memcpy(sc->path, sweep_path, dirlen);
    strcpy(sc->path + dirlen, name);
    plume_err e1 = {{0}};
    plume_status st;
    sc->text = plume_read_text(sc->path, &e1, "scene", &st);
    if (!sc->text) {
        plume_err_set(err, st, "%s: base.scene: %s", sweep_path, e1.msg);
        plume_sweep_scene_free(sc);
        return st;
    }
    json_error_t je;
    sc->doc = json_loads(sc->text, JSON_REJECT_DUPLICATES, &je);
    if (!sc->doc || !json_is_object(sc->doc)) {
        if (sc->doc)
            plume_err_set(err, PLUME_EFORMAT, "%s (base.scene of %s): expected a JSON object at the top level", sc->path,
                          sweep_path);
        else
            plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s (base.scene of %s)", sc->path, je.line, je.column, je.text,
                          sweep_path);
        plume_sweep_scene_free(sc);
        return PLUME_EFORMAT;
    }
    if (jd)
        json_object_set_new(sc->doc, "duration", json_real(json_number_value(jd)));
    return PLUME_OK;
}

json_t *plume_sweep_scene_request(const plume_sweep_scene *sc)
{
    json_t *r = json_object(), *path = json_string(sc->path), *doc = json_deep_copy(sc->doc);
    if (!r || !path || !doc || json_object_set_new(r, "scene", path) != 0 || json_object_set_new(r, "document", doc) != 0 ||
        (sc->steps > 0 && json_object_set_new(r, "steps", json_integer(sc->steps)) != 0)) {
        json_decref(r);
        return NULL;
    }
    return r;
}

/* one step of a key path: a member name or a list index, and where it ends in the key */
typedef struct {
    char name[PLUME_JSON_KEY_MAX];
    long index; /* -1: a member */
    size_t end;
} path_step;

/* "a.b[2].c" into steps; -1 when it is not a key path */
static int parse_path(const char *key, path_step *steps, int max)
{
    int n = 0;
    const char *p = key;
    while (*p) {
        if (n == max)
            return -1;
        path_step *s = &steps[n];
        if (*p == '[') {
            if (n == 0)
                return -1; /* the document is an object */
            char *end;
            if (p[1] < '0' || p[1] > '9')
                return -1;
            s->index = strtol(p + 1, &end, 10);
            if (*end != ']' || s->index > 100000000)
                return -1;
            p = end + 1;
        } else {
            if (n > 0) { /* a member follows a '.' */
                if (*p != '.')
                    return -1;
                p++;
            }
            size_t len = strcspn(p, ".[]");
            if (len == 0 || len >= sizeof s->name)
                return -1;
            memcpy(s->name, p, len);
            s->name[len] = '\0';
            s->index = -1;
            p += len;
        }
        s->end = (size_t)(p - key);
        n++;
    }
    return n > 0 ? n : -1;
}

plume_status plume_sweep_scene_set(json_t *doc, const char *key, json_t *value, const char *sweep_path,
                                   const char *scene_path, plume_err *err)
{
    path_step steps[32];
    int n = parse_path(key, steps, 32);
    plume_status st = PLUME_OK;
    if (n < 0) {
        json_decref(value);
        return plume_err_set(err, PLUME_EINVAL,
                             "%s: vary.%s: a scene key is a path of names joined by '.', with [i] for the entries of a "
                             "list (\"contact.dhat\", \"materials[0].membrane.E\", \"gravity[2]\")",
                             sweep_path, key);
    }
    json_t *cur = doc;
    for (int i = 0; i < n; i++) {
        const path_step *s = &steps[i];
        int where = i ? (int)steps[i - 1].end : 0; /* the path of cur: key[0 .. where) */
        if (s->index < 0 && !json_is_object(cur)) {
            st = plume_err_set(err, PLUME_EINVAL, "%s: vary.%s: %.*s is not an object in the scene %s", sweep_path, key,
                               where, key, scene_path);
            break;
        }
        if (s->index >= 0 && !json_is_array(cur)) {
            st = plume_err_set(err, PLUME_EINVAL, "%s: vary.%s: %.*s is not a list in the scene %s", sweep_path, key,
                               where, key, scene_path);
            break;
        }
        if (s->index >= 0 && (size_t)s->index >= json_array_size(cur)) {
            st = plume_err_set(err, PLUME_EINVAL, "%s: vary.%s: %.*s has %zu entr%s in the scene %s (indices from 0)",
                               sweep_path, key, where, key, json_array_size(cur),
                               json_array_size(cur) == 1 ? "y" : "ies", scene_path);
            break;
        }
        if (i == n - 1) { /* the value's place */
            if (s->index >= 0)
                json_array_set(cur, (size_t)s->index, value);
            else
                json_object_set(cur, s->name, value);
            break;
        }
        json_t *next = s->index >= 0 ? json_array_get(cur, (size_t)s->index) : json_object_get(cur, s->name);
        if (!next && steps[i + 1].index >= 0) {
            st = plume_err_set(err, PLUME_EINVAL, "%s: vary.%s: the scene %s has no %.*s", sweep_path, key, scene_path,
                               (int)s->end, key);
            break;
        }
        if (!next) { /* a missing object is added: the scene loader judges it */
            next = json_object();
            json_object_set_new(cur, s->name, next);
        }
        cur = next;
    }
    json_decref(value);
    return st;
}

/* ------------------------------------------------------------------------------------------ */
/* a run */

static json_t *array_real(const double *v, long n)
{
    json_t *a = json_array();
    for (long i = 0; a && i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *array_int(const double *v, long n)
{
    json_t *a = json_array();
    for (long i = 0; a && i < n; i++)
        json_array_append_new(a, json_integer((json_int_t)v[i]));
    return a;
}

/* per-step measures: time, newton_iterations, halvings, contact_pairs, min_distance, intersecting_pairs */
enum { M_TIME, M_ITER, M_HALV, M_PAIRS, M_DIST, M_INTER, M_COUNT };

/* What a run measured step by step: the per-step measures m[k][0 .. entries) (the runner's report
 * has the totals). */
typedef struct {
    double *m[M_COUNT];
    long entries;
} run_record;

/* The scene of the request's document (its file name `path` for messages and relative files); a
 * static scene is refused. *text holds the document's text (the caller frees it). */
static plume_status load_dynamic_scene(const char *path, json_t *doc, char **text, plume_scene **scene, json_t **desc,
                                       plume_err *err)
{
    *text = json_dumps(doc, JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_PRESERVE_ORDER);
    if (!*text)
        return plume_err_set(err, PLUME_ENOMEM, "scene run: out of memory");
    plume_status st = plume_scene_load_json(*text, path, NULL, scene, err);
    if (st != PLUME_OK)
        return st;
    if (!(*desc = plume_scene_description(*scene, err)))
        return PLUME_ENOMEM;
    if (strcmp(json_string_value(json_object_get(*desc, "solve")), "static") == 0)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s is a static scene (\"solve\": \"static\"): a sweep steps dynamic scenes (apps/shell "
                             "solves static ones)",
                             path);
    return PLUME_OK;
}

/* The steps of the run: the request's `steps` if > 0, else the scene's duration over dt. */
static plume_status planned_steps(json_t *desc, const char *path, long steps, long *n_out, plume_err *err)
{
    const double dt = plume_scene_description_number(desc, "dt");
    const long n =
        steps > 0 ? steps : (long)fmax(0.0, floor(plume_scene_description_number(desc, "duration") / dt + 0.5));
    if (n > 1000000)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s: the run would take %ld steps of dt = %g s (more than 10^6): set the sweep's base.steps "
                             "or a shorter duration",
                             path, n, dt);
    *n_out = n;
    return PLUME_OK;
}

/* Steps the scene n times through the runner (or until a step is refused: macro/scene/run.h's
 * acceptance rule), recording each step's measures into rec. */
static plume_status step_scene(plume_run *run, const char *path, long n, run_record *rec, plume_err *err)
{
    plume_status st = PLUME_OK;
    for (long i = 0; i < n; i++) {
        plume_run_step_info info;
        plume_err why = {{0}};
        if ((st = plume_run_step(run, &info, &why)) != PLUME_OK)
            return plume_err_set(err, st, "%s: %s", path, why.msg);
        const long e = rec->entries++;
        rec->m[M_TIME][e] = info.t1, rec->m[M_ITER][e] = info.step.iterations;
        rec->m[M_HALV][e] = info.step.halvings;
        rec->m[M_PAIRS][e] = info.contact_pairs, rec->m[M_DIST][e] = info.min_distance;
        rec->m[M_INTER][e] = info.intersecting;
        if (!info.accepted)
            break;
    }
    return PLUME_OK;
}

/* The largest displacement of x from x0 and its vertex. */
static void largest_displacement(const plume_mesh *mesh, const double *x, const double *x0, double *umax_out,
                                 long *vmax_out)
{
    double umax = 0.0;
    long vmax = 0;
    for (plume_index v = 0; v < mesh->nv; v++) {
        double u = hypot(hypot(x[3 * v] - x0[3 * v], x[3 * v + 1] - x0[3 * v + 1]), x[3 * v + 2] - x0[3 * v + 2]);
        if (u > umax)
            umax = u, vmax = (long)v;
    }
    *umax_out = umax, *vmax_out = vmax;
}

/* The run's result object (plume_sweep_scene_run's document; the caller owns it). */
static json_t *run_result(const plume_run *run, json_t *desc, const char *path, long n, const run_record *rec,
                          const double *x0)
{
    const plume_mesh *mesh = plume_scene_mesh(plume_run_scene(run));
    const double *x = plume_run_positions(run);
    plume_run_report r;
    plume_run_get_report(run, &r);
    double umax;
    long vmax;
    largest_displacement(mesh, x, x0, &umax, &vmax);
    json_t *o = json_object();
    json_object_set_new(o, "scene", json_string(path));
    json_object_set_new(o, "vertices", json_integer(mesh->nv));
    json_object_set_new(o, "elements", json_integer(mesh->nt));
    json_object_set(o, "dt", json_object_get(desc, "dt"));
    json_object_set_new(o, "steps", json_integer(r.steps));
    json_object_set_new(o, "steps_planned", json_integer(n));
    json_object_set_new(o, "time", json_real(r.time));
    json_object_set_new(o, "converged", json_boolean(!r.stopped));
    json_object_set_new(o, "stop_reason", json_string(plume_reason_name(r.stop_reason)));
    json_object_set_new(o, "newton_iterations", json_integer(r.iterations));
    json_object_set_new(o, "halvings", json_integer(r.halvings));
    json_object_set_new(o, "max_violation", json_real(r.max_violation));
    json_object_set_new(o, "max_displacement", json_real(umax));
    json_object_set_new(o, "max_displacement_vertex", json_integer(vmax));
    json_t *ps = json_object();
    json_object_set_new(ps, "time", array_real(rec->m[M_TIME], rec->entries));
    json_object_set_new(ps, "newton_iterations", array_int(rec->m[M_ITER], rec->entries));
    json_object_set_new(ps, "halvings", array_int(rec->m[M_HALV], rec->entries));
    json_t *contact = json_object_get(desc, "contact");
    if (contact) {
        json_object_set_new(o, "contact",
                            json_pack("{s:O, s:O, s:I, s:f, s:f, s:I, s:I, s:I}", "model",
                                      json_object_get(contact, "model"), "dhat",
                                      json_object_get(contact, "dhat"), "max_contact_pairs", (json_int_t)r.max_pairs,
                                      "min_distance", r.min_distance, "min_distance_cap", r.distance_cap,
                                      "max_intersecting_pairs", (json_int_t)r.max_intersecting, "steps_intersecting",
                                      (json_int_t)r.steps_intersecting, "step_limited",
                                      (json_int_t)r.step_limited));
        json_object_set_new(ps, "contact_pairs", array_int(rec->m[M_PAIRS], rec->entries));
        json_object_set_new(ps, "min_distance", array_real(rec->m[M_DIST], rec->entries));
        json_object_set_new(ps, "intersecting_pairs", array_int(rec->m[M_INTER], rec->entries));
    }
    json_object_set_new(o, "per_step", ps);
    if (mesh->nv <= PLUME_SWEEP_SCENE_MAX_POSITIONS)
        json_object_set_new(o, "positions", array_real(x, (long)(3 * (size_t)mesh->nv)));
    return o;
}

plume_status plume_sweep_scene_run(const char *request, char **result, char *msg, long nmsg)
{
    plume_err err = {{0}};
    plume_status st = PLUME_OK;
    json_t *req = request ? json_loads(request, 0, NULL) : NULL, *o = NULL, *desc = NULL;
    const char *path = json_string_value(json_object_get(req, "scene"));
    json_t *doc = json_object_get(req, "document");
    long steps = (long)json_integer_value(json_object_get(req, "steps")), n = 0;
    char *text = NULL;
    plume_scene *scene = NULL;
    plume_run *run = NULL;
    run_record rec = {{NULL}, 0};
    double *x0 = NULL;
    if (result)
        *result = NULL;
    if (!result || !path || !json_is_object(doc)) {
        st = plume_err_set(&err, PLUME_EINVAL, "scene run: the request needs \"scene\" and \"document\"");
        goto done;
    }
    plume_run_opts ro; /* stepped one dt at a time, the contact audit on, no frames */
    plume_run_opts_default(&ro);
    ro.open = 1;
    if ((st = load_dynamic_scene(path, doc, &text, &scene, &desc, &err)) != PLUME_OK ||
        (st = plume_run_create(scene, &ro, &run, &err)) != PLUME_OK ||
        (st = planned_steps(desc, path, steps, &n, &err)) != PLUME_OK)
        goto done;
    size_t nx = 3 * (size_t)plume_scene_mesh(scene)->nv;
    int nomem = !(x0 = malloc(nx * sizeof *x0));
    for (int k = 0; k < M_COUNT; k++)
        nomem |= !(rec.m[k] = malloc(((size_t)n + 1) * sizeof **rec.m));
    if (nomem) {
        st = plume_err_set(&err, PLUME_ENOMEM, "scene run: out of memory");
        goto done;
    }
    memcpy(x0, plume_run_positions(run), nx * sizeof *x0);
    if ((st = plume_run_start(run, &err)) != PLUME_OK || (st = step_scene(run, path, n, &rec, &err)) != PLUME_OK)
        goto done;
    o = run_result(run, desc, path, n, &rec, x0);
    *result = json_dumps(o, JSON_REAL_PRECISION(17) | JSON_COMPACT | JSON_PRESERVE_ORDER);
    if (!*result)
        st = plume_err_set(&err, PLUME_ENOMEM, "scene run: out of memory");
done:
    json_decref(o);
    for (int k = 0; k < M_COUNT; k++)
        free(rec.m[k]);
    free(x0);
    plume_run_destroy(&run);
    plume_scene_destroy(&scene);
    free(text);
    json_decref(req);
    json_decref(desc);
    if (msg && nmsg > 0)
        snprintf(msg, (size_t)nmsg, "%s", st == PLUME_OK ? "" : err.msg[0] ? err.msg : plume_strerror(st));
    return st;
}

/* ------------------------------------------------------------------------------------------ */
/* the results file and the summary */

const char *const plume_sweep_scene_arrays[] = {"per_step", "positions", NULL};

static const struct {
    const char *name, *units;
} step_measures[] = {{"time", "s"},          {"newton_iterations", "1"}, {"halvings", "1"},
                     {"contact_pairs", "1"}, {"min_distance", "m"},      {"intersecting_pairs", "1"}};

/* json array a as a dataset of doubles */
static int write_array(hid_t g, const char *name, json_t *a, const char *units)
{
    size_t n = json_array_size(a);
    double *v = malloc((n + 1) * sizeof *v);
    if (!v)
        return -1;
    for (size_t i = 0; i < n; i++)
        v[i] = json_number_value(json_array_get(a, i));
    int rc = h5_write_dataset(g, name, v, (plume_index)n, units);
    free(v);
    return rc;
}

int plume_sweep_scene_write(hid_t g, json_t *res)
{
    json_t *ps = json_object_get(res, "per_step"), *pos = json_object_get(res, "positions"),
           *c = json_object_get(res, "contact");
    if (!json_is_object(ps))
        return 0; /* no result (a run that failed): nothing but the record */
    hid_t sg = H5Gcreate2(g, "per_step", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int bad = sg < 0;
    for (size_t k = 0; !bad && k < sizeof step_measures / sizeof step_measures[0]; k++) {
        json_t *a = json_object_get(ps, step_measures[k].name);
        if (json_is_array(a))
            bad = write_array(sg, step_measures[k].name, a, step_measures[k].units) < 0;
    }
    if (sg >= 0)
        H5Gclose(sg);
    if (!bad && json_is_array(pos))
        bad = write_array(g, "positions", pos, "m") < 0;
    /* the run's scalars as numbers, their units in one string beside them (docs/hdf5-layout.md) */
    static const struct {
        const char *name, *units;
        int contact;
    } scalars[] = {{"time", "s", 0},          {"steps", "1", 0},        {"newton_iterations", "1", 0},
                   {"halvings", "1", 0},      {"max_displacement", "m", 0}, {"min_distance", "m", 1},
                   {"max_intersecting_pairs", "1", 1}, {"max_contact_pairs", "1", 1}};
    char units[400] = "";
    for (size_t k = 0; !bad && k < sizeof scalars / sizeof scalars[0]; k++) {
        json_t *v = json_object_get(scalars[k].contact ? c : res, scalars[k].name);
        if (!json_is_number(v))
            continue;
        bad = h5_write_attr_double(g, scalars[k].name, json_number_value(v)) < 0;
        snprintf(units + strlen(units), sizeof units - strlen(units), "%s%s: %s", units[0] ? "; " : "",
                 scalars[k].name, scalars[k].units);
    }
    if (!bad)
        bad = h5_write_attr_string(g, "units", units) < 0;
    return bad ? -1 : 0;
}

const char plume_sweep_scene_summary_header[] = "steps | time (s) | max displacement (m) | min distance (m)";

void plume_sweep_scene_summary_row(json_t *res, char *cells, size_t n, json_t *row)
{
    if (!json_is_object(res)) {
        snprintf(cells, n, " | | | ");
        return;
    }
    json_t *c = json_object_get(res, "contact");
    double t = json_number_value(json_object_get(res, "time")),
           u = json_number_value(json_object_get(res, "max_displacement"));
    json_int_t steps = json_integer_value(json_object_get(res, "steps"));
    char dist[64] = "";
    if (c)
        snprintf(dist, sizeof dist, "%.6g", json_number_value(json_object_get(c, "min_distance")));
    snprintf(cells, n, "%" JSON_INTEGER_FORMAT " | %.6g | %.6g | %s", steps, t, u, dist);
    json_object_set_new(row, "steps", json_integer(steps));
    json_object_set_new(row, "time", json_real(t));
    json_object_set_new(row, "max_displacement", json_real(u));
    if (c) {
        json_object_set_new(row, "min_distance", json_real(json_number_value(json_object_get(c, "min_distance"))));
        json_object_set_new(row, "max_intersecting_pairs",
                            json_integer(json_integer_value(json_object_get(c, "max_intersecting_pairs"))));
    }
}
