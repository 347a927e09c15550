/* A traction run's checkpoint and restart (docs/hdf5-layout.md, "The traction checkpoint"): after
 * every nominal step the whole state of the run goes into one HDF5 file, replaced atomically; a
 * run given that file continues after its step as if it had never stopped, bit for bit (the curve,
 * the counts, the stateful terms, the predictor's history, the solver's memory; only the times
 * differ). What a run cannot continue from is refused by name: the sample, the schedule, the
 * solver and the problem's sizes are recorded and compared. */
#include "internal/traction_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/h5_atomic.h"
#include "../io/h5util.h"

#define GROUP "/traction_checkpoint"
#define FORMAT "plume traction checkpoint 1"

/* A named number of the checkpoint, a double attribute of the group. */
typedef struct {
    const char *name;
    double v;
} entry;

/* What a run must share with the one that wrote the checkpoint: the sample, the schedule, the
 * solver and the problem's sizes. Returns the count written to e. */
static int schedule_entries(const traction_run *r, entry *e)
{
    const plume_traction_opts *o = r->o;
    int n = 0;
    e[n++] = (entry){"lx", o->lx};
    e[n++] = (entry){"ly", o->ly};
    e[n++] = (entry){"thickness", o->h};
    e[n++] = (entry){"steps", o->steps};
    e[n++] = (entry){"npath", o->path ? o->npath : 0};
    e[n++] = (entry){"strain_max", o->path ? 0.0 : o->strain_max};
    e[n++] = (entry){"peel", o->peel};
    e[n++] = (entry){"top_grip_free", o->top_grip_free};
    e[n++] = (entry){"probe_strain", o->probe_strain};
    e[n++] = (entry){"max_cuts", o->max_cuts};
    e[n++] = (entry){"max_settles", o->max_settles};
    e[n++] = (entry){"solver", (double)o->solver};
    e[n++] = (entry){"tol_kkt", o->solver_opts->tol_kkt};
    e[n++] = (entry){"max_iter", o->solver_opts->max_iter};
    e[n++] = (entry){"vertices", (double)r->mesh->nv};
    e[n++] = (entry){"dim", r->dim};
    e[n++] = (entry){"dofs", (double)plume_problem_ndof(r->p)};
    e[n++] = (entry){"free_dofs", (double)r->n};
    e[n++] = (entry){"constraints", (double)r->m};
    e[n++] = (entry){"term_state", (double)plume_problem_state_size(r->p)};
    e[n++] = (entry){"link_states", (double)r->hist_cols};
    return n;
}

/* Where the run stands: its step, increments, energy sums and the result's counts so far. */
enum { STEP, INC, NOMINAL, DA, DB, F_EQ, E_EQ, E_REST, WORK, GROSS, DISSIPATED, PEAK, RELEASED, REENGAGED, CASCADE,
       EVENTS, MEMORY, SLOPE, PROBE_TOL, NEWTON, CHORD, CUTS, OVERSHOOT_CUTS, SUBSTEPS, VIOLATION, FACTORIZATIONS,
       FACTOR_SECONDS, CONVERGED, FAILED_STEP, FAILED_REASON, NSTATE };
static const char *const state_names[NSTATE] = {
    "step", "increment", "nominal_increment", "grip", "grip_before", "reaction", "energy", "energy_at_rest", "work",
    "gross_work", "dissipated_energy", "peak_reaction", "released", "reengaged", "largest_cascade", "release_events",
    "solver_memory", "initial_slope", "probe_tol_kkt", "newton_iterations", "chord_steps", "cuts", "overshoot_cuts",
    "substeps", "max_violation", "factorizations", "factor_seconds", "converged", "failed_step", "failed_reason"};

static void state_values(const traction_run *r, int k, const plume_traction_result *res, double *v)
{
    int f = 0;
    double fs = 0.0;
    plume_solver_stats(r->solver, NULL, &f, &fs);
    const double vals[NSTATE] = {
        k, r->inc, r->nominal, r->h.da, r->h.db, r->F_eq, r->E_eq, r->E_rest, r->work, r->gross_work, r->dissipated,
        r->peak, (double)r->released, (double)r->reengaged, r->cascade, r->events, plume_solver_memory(r->solver),
        res->initial_slope, res->probe_tol_kkt, res->newton_iterations, res->chord_steps, res->cuts,
        res->overshoot_cuts, res->substeps, res->max_violation, r->factorizations0 + f, r->factor_seconds0 + fs,
        res->converged, res->failed_step, (double)res->failed_reason};
    memcpy(v, vals, sizeof vals);
}

/* The arrays of the checkpoint: name, values, count. */
typedef struct {
    const char *name;
    double *v;
    plume_index n;
} array;

static int state_arrays(const traction_run *r, const plume_traction_result *res, double *terms, array *a)
{
    const plume_index nx = (plume_index)r->dim * r->mesh->nv, npts = res->curve.n;
    int n = 0;
    a[n++] = (array){"x", r->x, plume_problem_ndof(r->p)};
    a[n++] = (array){"lambda", r->lambda, r->m};
    a[n++] = (array){"x_latest", r->h.xa, nx};
    a[n++] = (array){"x_before", r->h.xb, nx};
    a[n++] = (array){"lambda_latest", r->h.la, r->m};
    a[n++] = (array){"lambda_before", r->h.lb, r->m};
    a[n++] = (array){"term_state", terms, plume_problem_state_size(r->p)};
    a[n++] = (array){"strain", res->curve.strain, npts};
    a[n++] = (array){"stress", res->curve.stress, npts};
    a[n++] = (array){"wbar", res->curve.wbar, npts};
    a[n++] = (array){"iterations", res->curve.iterations, npts};
    a[n++] = (array){"seconds", res->curve.seconds, npts};
    return n;
}

typedef struct {
    const traction_run *r;
    int k;
    const plume_traction_result *res;
    double *terms;
} write_ctx;

/* The per-stencil states of term `name` (columns c0 .. c0 + nc - 1 of the history) as an int8
 * table, rows the curve's points. 0, or -1 on failure. */
static int write_states(hid_t g, const traction_run *r, const char *name, plume_index c0, plume_index nc)
{
    hsize_t dims[2] = {(hsize_t)r->hist_rows, (hsize_t)nc};
    signed char *v = malloc((size_t)(dims[0] * dims[1]) + 1);
    if (!v)
        return -1;
    for (long i = 0; i < r->hist_rows; i++)
        for (plume_index c = 0; c < nc; c++)
            v[(size_t)i * (size_t)nc + (size_t)c] = (signed char)r->hist[(size_t)i * (size_t)r->hist_cols + (size_t)(c0 + c)];
    hid_t sp = H5Screate_simple(2, dims, NULL);
    hid_t ds = sp < 0 ? H5I_INVALID_HID : H5Dcreate2(g, name, H5T_STD_I8LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int ok = ds >= 0 && (dims[0] * dims[1] == 0 || H5Dwrite(ds, H5T_NATIVE_SCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0);
    if (ds >= 0)
        H5Dclose(ds);
    if (sp >= 0)
        H5Sclose(sp);
    free(v);
    return ok ? 0 : -1;
}

static plume_status fill_checkpoint(hid_t fid, const char *path, const void *vctx, plume_err *err)
{
    const write_ctx *c = vctx;
    const traction_run *r = c->r;
    entry e[32];
    double v[NSTATE];
    array a[16];
    const int ne = schedule_entries(r, e), na = state_arrays(r, c->res, c->terms, a);
    state_values(r, c->k, c->res, v);
    h5_detail d;
    hid_t g = H5Gcreate2(fid, GROUP, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t gs = g < 0 ? H5I_INVALID_HID : H5Gcreate2(g, "states", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int ok = gs >= 0 && h5_write_attr_string(g, "format", FORMAT) == 0;
    for (int i = 0; ok && i < ne; i++)
        ok = h5_write_attr_double(g, e[i].name, e[i].v) == 0;
    for (int i = 0; ok && i < NSTATE; i++)
        ok = h5_write_attr_double(g, state_names[i], v[i]) == 0;
    for (int i = 0; ok && i < na; i++)
        ok = h5_write_dataset(g, a[i].name, a[i].v, a[i].n, NULL) == 0;
    if (ok && r->o->path)
        ok = h5_write_dataset(g, "path", (double *)r->o->path, r->o->npath, "1") == 0;
    plume_index c0 = 0;
    for (int t = 0; ok; t++) {
        const char *name = plume_problem_states_term(r->p, t);
        plume_index nc = 0;
        if (!name)
            break;
        ok = plume_problem_term_states(r->p, name, NULL, &nc, NULL) == PLUME_OK &&
             write_states(gs, r, name, c0, nc) == 0;
        c0 += nc;
    }
    if (gs >= 0)
        H5Gclose(gs);
    if (g >= 0)
        H5Gclose(g);
    return ok ? PLUME_OK : plume_err_set(err, PLUME_EIO, "traction checkpoint '%s': cannot write (HDF5: %s)", path,
                                         h5_cause(&d));
}

plume_status plume_traction_checkpoint_write(const traction_run *r, int k, const plume_traction_result *res,
                                             plume_err *err)
{
    const plume_index ns = plume_problem_state_size(r->p);
    if (ns < 0)
        return plume_err_set(err, PLUME_EINVAL,
                             "traction checkpoint: a stateful term of the problem cannot save its state "
                             "(plume_term.state_size)");
    write_ctx c = {r, k, res, malloc((size_t)(ns + 1) * sizeof(double))};
    if (!c.terms)
        return plume_err_set(err, PLUME_ENOMEM, "traction checkpoint: out of memory");
    plume_problem_state_get(r->p, c.terms);
    h5_quiet q;
    quiet_begin(&q);
    plume_status st = plume_h5_atomic_replace(r->o->checkpoint, "traction checkpoint", fill_checkpoint, &c, err);
    quiet_end(&q);
    free(c.terms);
    return st;
}

plume_status plume_traction_states_record(traction_run *r, plume_err *err)
{
    if (!r->o->checkpoint || r->hist_cols == 0)
        return PLUME_OK;
    if (r->hist_rows == r->hist_cap) {
        const long cap = r->hist_cap ? 2 * r->hist_cap : 64;
        int *h = realloc(r->hist, (size_t)cap * (size_t)r->hist_cols * sizeof *h);
        if (!h)
            return plume_err_set(err, PLUME_ENOMEM, "traction: out of memory recording the links' states");
        r->hist = h, r->hist_cap = cap;
    }
    int *row = r->hist + (size_t)r->hist_rows * (size_t)r->hist_cols;
    for (int t = 0;; t++) {
        const char *name = plume_problem_states_term(r->p, t);
        plume_index nc = 0;
        if (!name)
            break;
        plume_status st = plume_problem_term_states(r->p, name, row, &nc, err);
        if (st != PLUME_OK)
            return st;
        row += nc;
    }
    r->hist_rows++;
    return PLUME_OK;
}

/* ---- reading ---- */

static int read_attr(hid_t g, const char *name, double *v)
{
    if (H5Aexists(g, name) <= 0)
        return -1;
    hid_t a = H5Aopen(g, name, H5P_DEFAULT);
    int ok = a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, v) >= 0;
    if (a >= 0)
        H5Aclose(a);
    return ok ? 0 : -1;
}

/* A 1D dataset of exactly n values into v. 0; -1 missing or unreadable; -2 another length (*got). */
static int read_array(hid_t g, const char *name, double *v, plume_index n, hsize_t *got)
{
    if (H5Lexists(g, name, H5P_DEFAULT) <= 0)
        return -1;
    hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
    hid_t sp = ds < 0 ? H5I_INVALID_HID : H5Dget_space(ds);
    int rc = -1;
    *got = 0;
    if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == 1) {
        H5Sget_simple_extent_dims(sp, got, NULL);
        rc = *got != (hsize_t)n ? -2 : (n == 0 || H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0) ? 0 : -1;
    }
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    return rc;
}

/* The int8 table at dpath under loc (malloc'ed into *out, its rows and columns in dims): 0; -1
 * missing or not a table; -2 unreadable or out of memory. */
static int read_table(hid_t loc, const char *dpath, hsize_t dims[2], signed char **out)
{
    *out = NULL;
    dims[0] = dims[1] = 0;
    char parent[256];
    snprintf(parent, sizeof parent, "%s", dpath);
    char *slash = strrchr(parent, '/');
    if (slash)
        *slash = '\0';
    if ((slash && parent[0] && H5Lexists(loc, parent, H5P_DEFAULT) <= 0) || H5Lexists(loc, dpath, H5P_DEFAULT) <= 0)
        return -1;
    hid_t ds = H5Dopen2(loc, dpath, H5P_DEFAULT), sp = ds < 0 ? H5I_INVALID_HID : H5Dget_space(ds);
    int rc = -1;
    if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == 2 && H5Sget_simple_extent_dims(sp, dims, NULL) == 2) {
        *out = malloc((size_t)(dims[0] * dims[1]) + 1);
        rc = *out && (dims[0] * dims[1] == 0 || H5Dread(ds, H5T_NATIVE_SCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, *out) >= 0)
                 ? 0
                 : -2;
    }
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    if (rc != 0) {
        free(*out);
        *out = NULL;
    }
    return rc;
}

/* The run's history of per-stencil states from the checkpoint's tables (rows rows). */
static plume_status read_history(hid_t g, traction_run *r, long rows, const char *path, plume_err *err)
{
    if (r->hist_cols == 0 || rows == 0)
        return PLUME_OK;
    r->hist = malloc((size_t)rows * (size_t)r->hist_cols * sizeof *r->hist);
    if (!r->hist)
        return plume_err_set(err, PLUME_ENOMEM, "restart: out of memory");
    r->hist_rows = r->hist_cap = rows;
    plume_index c0 = 0;
    for (int t = 0;; t++) {
        const char *name = plume_problem_states_term(r->p, t);
        plume_index nc = 0;
        if (!name)
            break;
        plume_problem_term_states(r->p, name, NULL, &nc, NULL);
        char dpath[256];
        snprintf(dpath, sizeof dpath, "states/%s", name);
        hsize_t dims[2];
        signed char *v = NULL;
        const int ok = read_table(g, dpath, dims, &v) == 0 && dims[0] == (hsize_t)rows && dims[1] == (hsize_t)nc;
        if (!ok) {
            free(v);
            return plume_err_set(err, PLUME_EFORMAT, "restart: '%s' has no table %s of %ld x %ld states", path,
                                 GROUP "/states/", rows, (long)nc);
        }
        for (long i = 0; i < rows; i++)
            for (plume_index c = 0; c < nc; c++)
                r->hist[(size_t)i * (size_t)r->hist_cols + (size_t)(c0 + c)] = v[(size_t)i * (size_t)nc + (size_t)c];
        free(v);
        c0 += nc;
    }
    return PLUME_OK;
}

/* The checkpoint's entries against this run's: the first that differs named. */
static plume_status check_schedule(hid_t g, const traction_run *r, const char *path, plume_err *err)
{
    entry e[32];
    const int ne = schedule_entries(r, e);
    for (int i = 0; i < ne; i++) {
        double v;
        if (read_attr(g, e[i].name, &v) != 0)
            return plume_err_set(err, PLUME_EFORMAT, "restart: '%s' has no attribute '%s' in %s", path, e[i].name,
                                 GROUP);
        if (!(v == e[i].v))
            return plume_err_set(err, PLUME_EINVAL,
                                 "restart: '%s' was written by a run with %s = %.17g, this one has %.17g: a restart "
                                 "continues the same sample, schedule and solver",
                                 path, e[i].name, v, e[i].v);
    }
    if (r->o->path) {
        double *p = malloc((size_t)r->o->npath * sizeof *p);
        hsize_t got;
        int rc = p ? read_array(g, "path", p, r->o->npath, &got) : -1;
        int same = rc == 0 && memcmp(p, r->o->path, (size_t)r->o->npath * sizeof *p) == 0;
        free(p);
        if (!same)
            return plume_err_set(err, PLUME_EINVAL, "restart: '%s' was written by a run with another path", path);
    }
    return PLUME_OK;
}

/* The arrays into the run and the result's curve (npts points, allocated as alloc_run did). */
static plume_status read_arrays(hid_t g, traction_run *r, plume_traction_result *res, long npts, double *terms,
                                const char *path, plume_err *err)
{
    res->curve.n = (plume_index)npts;
    array a[16];
    const int na = state_arrays(r, res, terms, a);
    for (int i = 0; i < na; i++) {
        hsize_t got;
        const int rc = read_array(g, a[i].name, a[i].v, a[i].n, &got);
        if (rc == -2)
            return plume_err_set(err, PLUME_EFORMAT, "restart: '%s': %s/%s has %llu values, this run needs %ld", path,
                                 GROUP, a[i].name, (unsigned long long)got, (long)a[i].n);
        if (rc != 0)
            return plume_err_set(err, PLUME_EFORMAT, "restart: '%s' has no readable dataset %s/%s", path, GROUP,
                                 a[i].name);
    }
    return PLUME_OK;
}

/* Where the run stood, into r and res; *k its step, checked against the schedule. */
static plume_status read_state(hid_t g, traction_run *r, int *k, plume_traction_result *res, long nsteps,
                               const char *path, plume_err *err)
{
    double v[NSTATE];
    for (int i = 0; i < NSTATE; i++)
        if (read_attr(g, state_names[i], &v[i]) != 0)
            return plume_err_set(err, PLUME_EFORMAT, "restart: '%s' has no attribute '%s' in %s", path,
                                 state_names[i], GROUP);
    if (!(v[STEP] >= 1 && v[STEP] <= (double)nsteps && v[STEP] == floor(v[STEP])))
        return plume_err_set(err, PLUME_EFORMAT, "restart: '%s': step %g is not one of this run's 1 .. %ld", path,
                             v[STEP], nsteps);
    *k = (int)v[STEP];
    r->inc = v[INC], r->nominal = v[NOMINAL], r->h.da = v[DA], r->h.db = v[DB];
    r->F_eq = v[F_EQ], r->E_eq = v[E_EQ], r->E_rest = v[E_REST];
    r->work = v[WORK], r->gross_work = v[GROSS], r->dissipated = v[DISSIPATED], r->peak = v[PEAK];
    r->released = (long)v[RELEASED], r->reengaged = (long)v[REENGAGED];
    r->cascade = (int)v[CASCADE], r->events = (int)v[EVENTS];
    r->memory = v[MEMORY];
    res->initial_slope = v[SLOPE], res->probe_tol_kkt = v[PROBE_TOL];
    res->newton_iterations = (int)v[NEWTON], res->chord_steps = (int)v[CHORD], res->cuts = (int)v[CUTS];
    res->overshoot_cuts = (int)v[OVERSHOOT_CUTS], res->substeps = (int)v[SUBSTEPS];
    res->max_violation = v[VIOLATION];
    r->factorizations0 = (int)v[FACTORIZATIONS], r->factor_seconds0 = v[FACTOR_SECONDS];
    res->converged = (int)v[CONVERGED], res->failed_step = (int)v[FAILED_STEP];
    res->failed_reason = (plume_reason)v[FAILED_REASON];
    return PLUME_OK;
}

plume_status plume_traction_checkpoint_read(traction_run *r, int *k, plume_traction_result *res, plume_err *err)
{
    const char *path = r->o->restart;
    const plume_index ns = plume_problem_state_size(r->p);
    if (ns < 0)
        return plume_err_set(err, PLUME_EINVAL,
                             "restart: a stateful term of the problem cannot set its state (plume_term.state_size)");
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid = h5_is_hdf5(path) ? H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT) : H5I_INVALID_HID;
    hid_t g = fid >= 0 && H5Lexists(fid, GROUP, H5P_DEFAULT) > 0 ? H5Gopen2(fid, GROUP, H5P_DEFAULT) : H5I_INVALID_HID;
    double *terms = malloc((size_t)(ns + 1) * sizeof *terms);
    plume_status st = PLUME_OK;
    double npts = 0.0;
    const long nsteps = (long)r->o->steps * (r->o->path ? r->o->npath : 1);
    if (fid < 0)
        st = plume_err_set(err, PLUME_EIO, "restart: '%s' cannot be read as an HDF5 file", path);
    else if (g < 0)
        st = plume_err_set(err, PLUME_EFORMAT, "restart: '%s' is not a traction checkpoint (no %s)", path, GROUP);
    else if (!terms)
        st = plume_err_set(err, PLUME_ENOMEM, "restart: out of memory");
    else if ((st = check_schedule(g, r, path, err)) == PLUME_OK && (st = read_state(g, r, k, res, nsteps, path, err)) == PLUME_OK) {
        hsize_t got = 0;
        if (H5Lexists(g, "strain", H5P_DEFAULT) > 0) { /* the curve's length: its points so far */
            hid_t ds = H5Dopen2(g, "strain", H5P_DEFAULT), sp = ds < 0 ? H5I_INVALID_HID : H5Dget_space(ds);
            if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == 1)
                H5Sget_simple_extent_dims(sp, &got, NULL);
            if (sp >= 0)
                H5Sclose(sp);
            if (ds >= 0)
                H5Dclose(ds);
        }
        npts = (double)got;
        if (!(npts >= 2 && npts <= (double)(nsteps + 1)))
            st = plume_err_set(err, PLUME_EFORMAT, "restart: '%s': its curve has %g points, not 2 .. %ld", path, npts,
                               nsteps + 1);
    }
    if (st == PLUME_OK && (st = read_arrays(g, r, res, (long)npts, terms, path, err)) == PLUME_OK &&
        (st = read_history(g, r, (long)npts, path, err)) == PLUME_OK) {
        plume_err why;
        if ((st = plume_problem_state_set(r->p, terms, &why)) != PLUME_OK)
            plume_err_set(err, st, "restart: '%s': %s", path, why.msg);
    }
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    free(terms);
    if (st == PLUME_OK)
        r->restarted = 1;
    return st;
}

plume_status plume_traction_checkpoint_states(const char *path, const char *term, int *states, long *rows,
                                              plume_index *cols, plume_err *err)
{
    if (!path || !term || !rows || !cols || !term[0] || strchr(term, '/'))
        return plume_err_set(err, PLUME_EINVAL, "traction checkpoint states: a file, a term name (no '/') and the "
                                                "row and column counts are required");
    h5_quiet q;
    quiet_begin(&q);
    char dpath[256];
    snprintf(dpath, sizeof dpath, GROUP "/states/%s", term);
    hid_t fid = h5_is_hdf5(path) ? H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT) : H5I_INVALID_HID;
    hsize_t dims[2];
    signed char *v = NULL;
    const int rc = fid >= 0 ? read_table(fid, dpath, dims, &v) : -1;
    plume_status st = PLUME_OK;
    if (fid < 0)
        st = plume_err_set(err, PLUME_EIO, "traction checkpoint '%s' cannot be read as an HDF5 file", path);
    else if (rc == -1)
        st = plume_err_set(err, PLUME_EFORMAT, "traction checkpoint '%s' has no states table of a term \"%s\" (%s)",
                           path, term, dpath);
    else if (rc != 0)
        st = plume_err_set(err, PLUME_EIO, "traction checkpoint '%s': %s cannot be read", path, dpath);
    else {
        *rows = (long)dims[0], *cols = (plume_index)dims[1];
        for (size_t i = 0; states && i < (size_t)(dims[0] * dims[1]); i++)
            states[i] = v[i];
    }
    free(v);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return st;
}
