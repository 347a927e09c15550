/* plume: the flat interface for bindings (flat.h) — JSON requests and results over the library's
 * jobs; the scene handle and the glTF export are in flat_scene.c. */
#include "flat.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "internal/flat_common.h"
#include "internal/scene_description.h"

/* ------------------------------------------------------------------------------------------ */
/* requests */

plume_status plume_flat_finish(plume_status st, const plume_err *err, char *msg, long nmsg)
{
    if (msg && nmsg > 0) {
        if (st == PLUME_OK)
            msg[0] = '\0';
        else
            snprintf(msg, (size_t)nmsg, "%s", err->msg[0] ? err->msg : plume_strerror(st));
    }
    return st;
}

/* the request text as an object; every key of it must be in `allowed` (NULL-terminated) */
static plume_status parse_request(const char *text, const char *what, const char *const *allowed, json_t **out,
                                  plume_err *err)
{
    *out = NULL;
    json_error_t je;
    json_t *doc = json_loads(text && *text ? text : "{}", JSON_REJECT_DUPLICATES, &je);
    if (!doc)
        return plume_err_set(err, PLUME_EFORMAT, "%s request:%d:%d: %s", what, je.line, je.column, je.text);
    if (!json_is_object(doc)) {
        json_decref(doc);
        return plume_err_set(err, PLUME_EFORMAT, "%s request: expected a JSON object", what);
    }
    const char *key;
    json_t *v;
    json_object_foreach(doc, key, v) {
        int known = 0;
        for (int k = 0; allowed[k] && !known; k++)
            known = strcmp(key, allowed[k]) == 0;
        if (!known) {
            plume_err_set(err, PLUME_EINVAL, "%s request: unknown key \"%s\"", what, key);
            json_decref(doc);
            return PLUME_EINVAL;
        }
    }
    *out = doc;
    return PLUME_OK;
}

/* obj[key] as a number into *out when present (kept otherwise) */
static plume_status get_number(json_t *obj, const char *what, const char *key, double *out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_number(v))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be a number", what, key);
    *out = json_number_value(v);
    if (!isfinite(*out))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be finite", what, key);
    return PLUME_OK;
}

static plume_status get_int(json_t *obj, const char *what, const char *key, int *out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_integer(v) || json_integer_value(v) < -1000000000 || json_integer_value(v) > 1000000000)
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be an integer", what, key);
    *out = (int)json_integer_value(v);
    return PLUME_OK;
}

static plume_status get_bool(json_t *obj, const char *what, const char *key, int *out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_boolean(v))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be true or false", what, key);
    *out = json_is_true(v);
    return PLUME_OK;
}

static plume_status get_string(json_t *obj, const char *what, const char *key, const char **out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_string(v))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be a string", what, key);
    *out = json_string_value(v);
    return PLUME_OK;
}

/* request.layout (an object of layout-file keys) applied to l */
static plume_status get_layout(json_t *obj, const char *what, plume_layout *l, plume_err *err)
{
    json_t *v = json_object_get(obj, "layout");
    if (!v)
        return PLUME_OK;
    char where[64];
    snprintf(where, sizeof where, "%s request.layout", what);
    char *text = json_dumps(v, JSON_REAL_PRECISION(17));
    if (!text)
        return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", where);
    plume_status st = plume_layout_apply_json(text, where, l, err);
    free(text);
    return st == PLUME_EFORMAT ? PLUME_EINVAL : st; /* a bad key of a request, not a malformed file */
}

/* {"E_xx", "E_yy", "nu_xy", "G_xy"} at obj[key] into m: all four, or obj[key] absent (m kept). A
 * partial object is refused, naming the missing keys: filling them with defaults would run a
 * material nobody asked for. */
static plume_status get_moduli(json_t *obj, const char *what, const char *key, plume_ortho *m, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    char where[64];
    snprintf(where, sizeof where, "%s request.%s", what, key);
    if (!json_is_object(v))
        return plume_err_set(err, PLUME_EINVAL, "%s: expected an object of E_xx, E_yy, nu_xy, G_xy", where);
    const char *k;
    json_t *x;
    json_object_foreach(v, k, x) {
        double *dst = strcmp(k, "E_xx") == 0 ? &m->E_xx : strcmp(k, "E_yy") == 0 ? &m->E_yy
                    : strcmp(k, "nu_xy") == 0 ? &m->nu_xy : strcmp(k, "G_xy") == 0 ? &m->G_xy : NULL;
        if (!dst)
            return plume_err_set(err, PLUME_EINVAL, "%s: unknown key \"%s\"", where, k);
        if (!json_is_number(x) || !isfinite(json_number_value(x)))
            return plume_err_set(err, PLUME_EINVAL, "%s: \"%s\" must be a finite number", where, k);
        *dst = json_number_value(x);
    }
    static const char *const names[] = {"E_xx", "E_yy", "nu_xy", "G_xy"};
    char missing[64] = "";
    for (int i = 0; i < 4; i++)
        if (!json_object_get(v, names[i]))
            snprintf(missing + strlen(missing), sizeof missing - strlen(missing), "%s%s", missing[0] ? ", " : "",
                     names[i]);
    if (missing[0])
        return plume_err_set(err, PLUME_EINVAL, "%s: missing %s (give all of E_xx, E_yy, nu_xy, G_xy)", where, missing);
    return PLUME_OK;
}

static json_t *array_of(const double *v, plume_index n)
{
    json_t *a = json_array();
    for (plume_index i = 0; a && i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *curve_json(const plume_curve *c)
{
    return json_pack("{s:o, s:o, s:o, s:o}", "strain", array_of(c->strain, c->n), "stress", array_of(c->stress, c->n),
                     "wbar", array_of(c->wbar, c->n), "iterations", array_of(c->iterations, c->n));
}

/* the result object as text into *result (the object is released) */
plume_status plume_flat_emit(json_t *obj, char **result, plume_err *err)
{
    *result = obj ? json_dumps(obj, JSON_REAL_PRECISION(17) | JSON_COMPACT) : NULL;
    json_decref(obj);
    return *result ? PLUME_OK : plume_err_set(err, PLUME_ENOMEM, "out of memory");
}

void plume_flat_free(char *text)
{
    free(text);
}

/* ------------------------------------------------------------------------------------------ */
/* jobs */

/* homogenize request.output, checked before the solve so that a bad path costs no cell solves (as
 * apps/homogenize -o): not empty, not a directory, its directory created with its parents (as
 * write_frames does) and writable. */
static plume_status output_check(const char *path, plume_err *err)
{
    if (!*path)
        return plume_err_set(err, PLUME_EINVAL, "homogenize request: \"output\" must name a file (got \"\")");
    char dir[4096];
    if (strlen(path) >= sizeof dir)
        return plume_err_set(err, PLUME_EINVAL, "homogenize request: \"output\": the path '%.64s...' is longer than %d "
                                                "bytes", path, (int)sizeof dir - 1);
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return plume_err_set(err, PLUME_EINVAL, "homogenize request: \"output\": '%s' is a directory, not a file", path);
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == dir)
        dir[1] = '\0';
    else
        *slash = '\0';
    if (plume_make_dirs(dir) != 0)
        return plume_err_set(err, PLUME_EIO, "homogenize request: \"output\": cannot create the directory '%s' of '%s': %s",
                             dir, path, strerror(errno));
    if (access(dir, W_OK) != 0)
        return plume_err_set(err, PLUME_EIO, "homogenize request: \"output\": cannot write '%s' in the directory '%s': %s",
                             path, dir, strerror(errno));
    return PLUME_OK;
}

plume_status plume_flat_homogenize(const char *request, char **result, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!result)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "homogenize: no result pointer"), &err, msg, nmsg);
    *result = NULL;
    static const char *const keys[] = {"layout", "strain_max", "steps", "output", NULL};
    json_t *req;
    const char *output = NULL;
    plume_status st = parse_request(request, "homogenize", keys, &req, &err);
    if (st != PLUME_OK)
        return plume_flat_finish(st, &err, msg, nmsg);
    plume_layout l;
    plume_layout_default(&l);
    plume_homog_opts ho;
    plume_homog_opts_default(&ho);
    plume_homog_result r;
    memset(&r, 0, sizeof r);
    if ((st = get_layout(req, "homogenize", &l, &err)) != PLUME_OK ||
        (st = get_number(req, "homogenize", "strain_max", &ho.strain_max, &err)) != PLUME_OK ||
        (st = get_int(req, "homogenize", "steps", &ho.steps, &err)) != PLUME_OK ||
        (st = get_string(req, "homogenize", "output", &output, &err)) != PLUME_OK ||
        (st = plume_layout_check(&l, &err)) != PLUME_OK || (output && (st = output_check(output, &err)) != PLUME_OK) ||
        (st = plume_homogenize(&l, &ho, &r, &err)) != PLUME_OK)
        goto done;
    plume_separation_law sep, *with = NULL; /* a layout with hooks: its barb line's separation law */
    if (l.kind == PLUME_LAYOUT_BARBULES && l.hooks.strength > 0.0) {
        if ((st = plume_separation_law_of(&l, &sep, &err)) != PLUME_OK)
            goto done;
        with = &sep;
    }
    if (output && (st = plume_homog_write_separation(output, &l, &r, with, &err)) != PLUME_OK) {
        char why[sizeof err.msg];
        snprintf(why, sizeof why, "%s", err.msg);
        plume_err_set(&err, st, "homogenize request: \"output\": %s", why);
        goto done;
    }
    json_t *C = json_array();
    for (int k = 0; k < 9; k++)
        json_array_append_new(C, json_real(r.C[k]));
    json_t *o = json_pack("{s:f, s:f, s:f, s:f, s:o, s:f, s:I, s:I, s:i, s:f}", "E_xx", r.moduli.E_xx, "E_yy",
                          r.moduli.E_yy, "nu_xy", r.moduli.nu_xy, "G_xy", r.moduli.G_xy, "C", C, "shear_coupling",
                          r.coupling, "elements", (json_int_t)r.elements, "vertices", (json_int_t)r.vertices,
                          "newton_iterations", r.newton_iterations, "seconds", r.seconds);
    if (o) {
        json_t *D = json_array();
        for (int k = 0; k < 9; k++)
            json_array_append_new(D, json_real(r.D[k]));
        json_object_set_new(o, "D", D);
        json_object_set_new(o, "D_long", json_real(r.bending.D_long));
        json_object_set_new(o, "D_trans", json_real(r.bending.D_trans));
        json_object_set_new(o, "D_coupling", json_real(r.bending.D_coupling));
        json_object_set_new(o, "D_twist", json_real(r.bending.D_twist));
        json_object_set_new(o, "D_16", json_real(r.bending.D_16));
        json_object_set_new(o, "D_26", json_real(r.bending.D_26));
        json_object_set_new(o, "bending_change", json_real(r.bending_change));
        json_object_set_new(o, "order", json_integer(r.order));
        json_object_set_new(o, "element_edge", json_real(r.element_edge));
        json_object_set_new(o, "refinement_change", json_real(r.refinement_change));
        if (r.refinement_change >= 0.0) {
            json_object_set_new(o, "moduli_change",
                                json_pack("{s:f, s:f, s:f, s:f}", "E_xx", r.moduli_change[0], "E_yy", r.moduli_change[1],
                                          "nu_xy", r.moduli_change[2], "G_xy", r.moduli_change[3]));
            json_object_set_new(o, "refinement_edge", json_real(r.refinement_edge));
        }
    }
    if (o && with)
        json_object_set_new(o, "separation",
                            json_pack("{s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:i, s:i}", "strength", sep.strength, "energy",
                                      sep.energy, "opening", sep.opening, "capture", sep.capture, "stiffness",
                                      sep.stiffness, "peak_opening",
                                      sep.peak_opening, "cell_length", sep.cell_length, "solves", sep.solves,
                                      "newton_iterations", sep.newton_iterations));
    if (o && output)
        json_object_set_new(o, "output", json_string(output));
    if (o && ho.strain_max > 0.0)
        json_object_set_new(o, "curves", json_pack("{s:o, s:o, s:o}", "uniaxial_x", curve_json(&r.uniaxial_x),
                                                   "uniaxial_y", curve_json(&r.uniaxial_y), "shear",
                                                   curve_json(&r.shear)));
    st = plume_flat_emit(o, result, &err);
done:
    plume_homog_result_free(&r);
    json_decref(req);
    return plume_flat_finish(st, &err, msg, nmsg);
}

/* the macro traction keys shared by traction and fit */
typedef struct {
    double lx, ly, h, kappa, edge, strain_max;
    int constraint, steps;
    plume_patch_kind mesh;
    plume_solver_kind solver;
} traction_setup;

static plume_status get_traction_setup(json_t *req, const char *what, traction_setup *t, plume_err *err)
{
    plume_traction_opts d;
    plume_traction_opts_default(&d);
    t->lx = 1.0, t->ly = 1.3, t->h = 1.0, t->kappa = 0.0, t->edge = -1.0, t->strain_max = d.strain_max;
    t->constraint = 1, t->steps = d.steps, t->mesh = PLUME_PATCH_ALIGNED, t->solver = PLUME_SOLVER_NEWTON;
    const char *mesh = NULL, *solver = NULL;
    plume_status st;
    if ((st = get_number(req, what, "lx", &t->lx, err)) != PLUME_OK ||
        (st = get_number(req, what, "ly", &t->ly, err)) != PLUME_OK ||
        (st = get_number(req, what, "thickness", &t->h, err)) != PLUME_OK ||
        (st = get_number(req, what, "kappa", &t->kappa, err)) != PLUME_OK ||
        (st = get_number(req, what, "edge", &t->edge, err)) != PLUME_OK ||
        (st = get_number(req, what, "strain_max", &t->strain_max, err)) != PLUME_OK ||
        (st = get_bool(req, what, "constraint", &t->constraint, err)) != PLUME_OK ||
        (st = get_int(req, what, "steps", &t->steps, err)) != PLUME_OK ||
        (st = get_string(req, what, "mesh", &mesh, err)) != PLUME_OK ||
        (st = get_string(req, what, "solver", &solver, err)) != PLUME_OK)
        return st;
    if (!(t->lx > 0.0) || !(t->ly > 0.0) || !(t->h > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "%s request: lx, ly and thickness must be > 0 (got %g, %g, %g)", what,
                             t->lx, t->ly, t->h);
    if (!(t->strain_max > 0.0 && t->strain_max < 10.0) || t->steps < 1)
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"strain_max\" must be in (0, 10) and \"steps\" >= 1 "
                                                "(got %g, %d)", what, t->strain_max, t->steps);
    if (t->edge < 0.0)
        t->edge = plume_traction_default_edge(t->lx, t->ly);
    if (!(t->edge > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"edge\" must be > 0 (got %g)", what, t->edge);
    if (mesh && plume_patch_kind_parse(mesh, &t->mesh) != PLUME_OK)
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"mesh\" must be \"aligned\" or \"unaligned\" (got \"%s\")",
                             what, mesh);
    if (solver && plume_solver_kind_parse(solver, &t->solver) != PLUME_OK)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s request: \"solver\" must be \"newton\", \"ipopt\" or \"linearized\" (got \"%s\")", what,
                             solver);
    return PLUME_OK;
}

/* traction request.vtk: the steps as a ParaView series in DIR (like apps/traction --vtk) */
static plume_status vtk_step(void *user, int step, double strain, const double *x)
{
    plume_err err = {{0}};
    return plume_fields_series_frame(user, step, strain, x, &err);
}

/* The traction request's specimen: the layout's resolved specimen (micro; its materials in mats,
 * nmat 2) or the vane on a patch mesh (macro; its barb edges in *barbs). */
static plume_status traction_specimen(json_t *req, const traction_setup *t, int micro, double angle, plume_vane *vane,
                                      plume_layout *layout, plume_mesh **mesh, plume_problem **p, plume_index **barbs,
                                      plume_index *nbarbs, plume_membrane_material mats[2], int *nmat, plume_err *err)
{
    plume_status st;
    if (micro) {
        /* as apps/traction: barbs plume_traction_default_barb_spacing apart, elements chosen from
         * the thinnest strip, unless the layout says */
        plume_layout_set_spacing(layout, plume_traction_default_barb_spacing(t->ly));
        if ((st = get_layout(req, "traction", layout, err)) != PLUME_OK)
            return st;
        layout->h = t->h, layout->kappa = t->kappa;
        if ((st = plume_micro_specimen(layout, t->lx, t->ly, angle, mesh, p, err)) != PLUME_OK)
            return st;
        plume_layout_materials(layout, mats);
        *nmat = 2;
        return PLUME_OK;
    }
    if (json_object_get(req, "layout"))
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"layout\" is for the micro model");
    vane->h = t->h, vane->kappa = t->kappa, vane->constraint = t->constraint;
    if ((st = plume_vane_check(vane, err)) != PLUME_OK ||
        (st = plume_patch_mesh(t->lx, t->ly, angle, t->edge, t->mesh, 2, mesh, err)) != PLUME_OK ||
        (st = plume_problem_create((*mesh)->nv, 2, fmax(t->lx, t->ly), p, err)) != PLUME_OK ||
        (st = plume_vane_add(*p, *mesh, vane, barbs, nbarbs, err)) != PLUME_OK)
        return st;
    mats[0] = plume_vane_material(vane);
    *nmat = 1;
    return PLUME_OK;
}

/* traction request.vtk: the steps as a ParaView series in DIR vtk, written by to's step callback
 * through *fields (the caller destroys it). */
static plume_status traction_vtk(const char *vtk, const plume_mesh *mesh, const plume_membrane_material *mats, int nmat,
                                 const plume_index *barbs, plume_index nbarbs, plume_fields **fields,
                                 plume_traction_opts *to, plume_err *err)
{
    char dir[4200];
    snprintf(dir, sizeof dir, "%s", vtk);
    if (plume_make_dirs(dir) != 0)
        return plume_err_set(err, PLUME_EIO, "traction request: \"vtk\": cannot create the directory '%s': %s", vtk,
                             strerror(errno));
    plume_status st;
    if ((st = plume_fields_create(mesh, 2, mesh->nt, mats, nmat, NULL, barbs, nbarbs, fields, err)) != PLUME_OK ||
        (st = plume_fields_series_start(*fields, dir, "steps.pvd", "step", -1.0, err)) != PLUME_OK)
        return st;
    to->on_step = vtk_step;
    to->on_step_user = *fields;
    return PLUME_OK;
}

/* traction request.path: a list of 1 to 1000 strains into path (*n; 0 without the key); each
 * leg is checked by plume_traction_run. */
static plume_status get_path(json_t *req, double *path, int *n, plume_err *err)
{
    json_t *jp = json_object_get(req, "path");
    *n = 0;
    if (!jp)
        return PLUME_OK;
    if (!json_is_array(jp) || json_array_size(jp) < 1 || json_array_size(jp) > 1000)
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"path\" must be a list of 1 to 1000 strains");
    size_t i;
    json_t *v;
    json_array_foreach(jp, i, v) {
        if (!json_is_number(v))
            return plume_err_set(err, PLUME_EINVAL, "traction request: \"path\"[%zu] must be a number", i);
        path[(*n)++] = json_number_value(v);
    }
    return PLUME_OK;
}

/* The traction result's document; conv only when has_conv. */
static json_t *traction_json(const plume_traction_result *res, int micro, const plume_layout *layout,
                             const plume_mesh *mesh, double angle, int has_conv, const plume_micro_convergence *conv)
{
    json_t *o = curve_json(&res->curve);
    json_object_set_new(o, "initial_slope", json_real(res->initial_slope));
    json_object_set_new(o, "converged", json_boolean(res->converged));
    json_object_set_new(o, "failed_step", json_integer(res->failed_step));
    json_object_set_new(o, "stop_reason", json_string(res->converged ? "converged" : plume_reason_name(res->failed_reason)));
    json_object_set_new(o, "newton_iterations", json_integer(res->newton_iterations));
    json_object_set_new(o, "max_violation", json_real(res->max_violation));
    json_object_set_new(o, "seconds", json_real(res->seconds));
    json_object_set_new(o, "elements", json_integer(micro ? plume_micro_specimen_elements(layout, mesh) : mesh->nt));
    json_object_set_new(o, "vertices", json_integer(mesh->nv));
    json_object_set_new(o, "angle", json_real(angle));
    if (micro) {
        json_object_set_new(o, "order", json_integer(layout->order));
        json_object_set_new(o, "element_edge", json_real(plume_layout_element_edge(layout, PLUME_MESH_SPECIMEN)));
        json_object_set_new(o, "refinement_change", json_real(has_conv ? conv->stress_change : -1.0));
        json_object_set_new(o, "slope_refinement_change", json_real(has_conv ? conv->slope_change : -1.0));
    }
    json_object_set_new(o, "peak_stress", json_real(res->peak_stress));
    json_object_set_new(o, "work", json_real(res->work));
    json_object_set_new(o, "stored_energy", json_real(res->stored_energy));
    json_object_set_new(o, "dissipated_energy", json_real(res->dissipated_energy));
    json_object_set_new(o, "energy_balance_error", json_real(res->energy_balance_error));
    json_object_set_new(o, "hooks_released", json_integer(res->released));
    json_object_set_new(o, "hooks_reengaged", json_integer(res->reengaged));
    json_object_set_new(o, "largest_cascade", json_integer(res->largest_cascade));
    json_object_set_new(o, "release_events", json_integer(res->release_events));
    return o;
}

plume_status plume_flat_traction(const char *request, char **result, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!result)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "traction: no result pointer"), &err, msg, nmsg);
    *result = NULL;
    static const char *const keys[] = {"model", "angle", "lx", "ly", "thickness", "moduli", "kappa", "constraint",
                                       "mesh", "edge", "strain_max", "steps", "solver", "layout", "vtk",
                                       "convergence", "path", "peel", "top_grip_free", NULL};
    json_t *req;
    plume_status st = parse_request(request, "traction", keys, &req, &err);
    if (st != PLUME_OK)
        return plume_flat_finish(st, &err, msg, nmsg);
    traction_setup t;
    const char *model = "macro", *vtk = NULL;
    double angle = 45.0;
    int convergence = 1;
    plume_vane vane;
    plume_vane_default(&vane);
    plume_layout layout;
    plume_layout_default(&layout);
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nbarbs = 0;
    plume_fields *fields = NULL;
    plume_traction_result res;
    memset(&res, 0, sizeof res);
    double path[1000];
    int npath = 0;
    if ((st = get_path(req, path, &npath, &err)) != PLUME_OK ||
        (st = get_traction_setup(req, "traction", &t, &err)) != PLUME_OK ||
        (st = get_string(req, "traction", "model", &model, &err)) != PLUME_OK ||
        (st = get_string(req, "traction", "vtk", &vtk, &err)) != PLUME_OK ||
        (st = get_bool(req, "traction", "convergence", &convergence, &err)) != PLUME_OK ||
        (st = get_number(req, "traction", "angle", &angle, &err)) != PLUME_OK ||
        (st = get_moduli(req, "traction", "moduli", &vane.moduli, &err)) != PLUME_OK)
        goto done;
    int micro = strcmp(model, "micro") == 0;
    if (!micro && strcmp(model, "macro") != 0) {
        st = plume_err_set(&err, PLUME_EINVAL, "traction request: \"model\" must be \"macro\" or \"micro\" (got \"%s\")",
                           model);
        goto done;
    }
    if (!(angle >= 0.0 && angle <= 180.0)) {
        st = plume_err_set(&err, PLUME_EINVAL, "traction request: \"angle\" must be in [0, 180] degrees (got %g)", angle);
        goto done;
    }
    plume_membrane_material mats[2];
    int nmat = 1;
    if ((st = traction_specimen(req, &t, micro, angle, &vane, &layout, &mesh, &p, &barbs, &nbarbs, mats, &nmat, &err)) !=
        PLUME_OK)
        goto done;
    plume_traction_opts to;
    plume_traction_opts_default(&to);
    to.lx = t.lx, to.ly = t.ly, to.h = t.h, to.strain_max = t.strain_max, to.steps = t.steps, to.solver = t.solver;
    to.progress = 0;
    if (npath > 0)
        to.path = path, to.npath = npath;
    if ((st = get_number(req, "traction", "peel", &to.peel, &err)) != PLUME_OK ||
        (st = get_number(req, "traction", "top_grip_free", &to.top_grip_free, &err)) != PLUME_OK)
        goto done;
    if ((vtk && (st = traction_vtk(vtk, mesh, mats, nmat, barbs, nbarbs, &fields, &to, &err)) != PLUME_OK) ||
        (fields && micro && layout.kind == PLUME_LAYOUT_BARBULES && layout.hooks.strength > 0.0 &&
         (st = plume_fields_add_links(fields, p, "hooks", &err)) != PLUME_OK) ||
        (st = plume_traction_run(mesh, p, barbs, nbarbs, &to, &res, &err)) != PLUME_OK)
        goto done;
    plume_micro_convergence conv;
    int has_conv = micro && convergence && res.converged && to.solver != PLUME_SOLVER_LINEARIZED;
    if (has_conv && (st = plume_micro_traction_convergence(&layout, t.lx, t.ly, angle, &to, &res, &conv, &err)) != PLUME_OK)
        goto done;
    st = plume_flat_emit(traction_json(&res, micro, &layout, mesh, angle, has_conv, &conv), result, &err);
done:
    plume_traction_result_free(&res);
    plume_fields_destroy(&fields);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    json_decref(req);
    return plume_flat_finish(st, &err, msg, nmsg);
}

#define FLAT_MAX_TARGETS 16

/* fit request.start: the starting moduli (required), E_xx, E_yy and G_xy > 0. */
static plume_status get_fit_start(json_t *req, plume_ortho *start, plume_err *err)
{
    if (!json_object_get(req, "start"))
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"start\" (the starting moduli) is required");
    plume_status st = get_moduli(req, "fit", "start", start, err);
    if (st != PLUME_OK)
        return st;
    if (!(start->E_xx > 0.0 && start->E_yy > 0.0 && start->G_xy > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"start\" needs E_xx, E_yy and G_xy > 0");
    return PLUME_OK;
}

/* fit request.free: the names of the fitted moduli into *mask (left as it is without "free"). */
static plume_status get_fit_free(json_t *req, unsigned *mask, plume_err *err)
{
    json_t *jf = json_object_get(req, "free");
    if (!jf)
        return PLUME_OK;
    *mask = 0;
    size_t i;
    json_t *v;
    if (!json_is_array(jf))
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"free\" must be a list of modulus names");
    json_array_foreach(jf, i, v) {
        const char *s = json_is_string(v) ? json_string_value(v) : "";
        unsigned bit = strcmp(s, "E_xx") == 0 ? PLUME_FIT_EXX : strcmp(s, "E_yy") == 0 ? PLUME_FIT_EYY
                     : strcmp(s, "nu_xy") == 0 ? PLUME_FIT_NU : strcmp(s, "G_xy") == 0 ? PLUME_FIT_GXY : 0;
        if (!bit)
            return plume_err_set(err, PLUME_EINVAL, "fit request: \"free\"[%zu] must be E_xx, E_yy, nu_xy or G_xy", i);
        *mask |= bit;
    }
    if (!*mask)
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"free\" names no modulus");
    return PLUME_OK;
}

/* fit request.targets: the curves (curves[0 .. *nt), their arrays the caller's to free even on
 * failure), their barb angles and the largest last strain. */
static plume_status get_fit_targets(json_t *req, plume_curve *curves, double *angles, int *nt, double *strain_max,
                                    plume_err *err)
{
    json_t *jt = json_object_get(req, "targets");
    if (!json_is_array(jt) || json_array_size(jt) < 1 || json_array_size(jt) > FLAT_MAX_TARGETS)
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"targets\" must be a list of 1 to %d curves",
                             FLAT_MAX_TARGETS);
    *strain_max = 0.0;
    for (size_t i = 0; i < json_array_size(jt); i++) {
        json_t *c = json_array_get(jt, i), *a = json_object_get(c, "angle"), *se = json_object_get(c, "strain"),
               *ss = json_object_get(c, "stress");
        size_t n = json_array_size(se);
        if (!json_is_object(c) || !json_is_number(a) || !json_is_array(se) || !json_is_array(ss) || n < 2 ||
            json_array_size(ss) != n)
            return plume_err_set(err, PLUME_EINVAL,
                                 "fit request: targets[%zu] needs \"angle\" and \"strain\", \"stress\" lists of equal "
                                 "length >= 2",
                                 i);
        angles[*nt] = json_number_value(a);
        if (!(angles[*nt] >= 0.0 && angles[*nt] <= 180.0))
            return plume_err_set(err, PLUME_EINVAL, "fit request: targets[%zu].angle must be in [0, 180] (got %g)", i,
                                 angles[*nt]);
        plume_curve *cv = &curves[(*nt)++];
        cv->n = (plume_index)n;
        cv->strain = calloc(n, sizeof(double)), cv->stress = calloc(n, sizeof(double));
        cv->wbar = calloc(n, sizeof(double)), cv->iterations = calloc(n, sizeof(double));
        cv->seconds = calloc(n, sizeof(double));
        if (!cv->strain || !cv->stress || !cv->wbar || !cv->iterations || !cv->seconds)
            return plume_err_set(err, PLUME_ENOMEM, "fit: out of memory");
        for (size_t k = 0; k < n; k++) {
            json_t *x = json_array_get(se, k), *y = json_array_get(ss, k);
            if (!json_is_number(x) || !json_is_number(y))
                return plume_err_set(err, PLUME_EINVAL, "fit request: targets[%zu] point %zu is not a number", i, k);
            cv->strain[k] = json_number_value(x), cv->stress[k] = json_number_value(y);
        }
        *strain_max = fmax(*strain_max, cv->strain[n - 1]);
    }
    return PLUME_OK;
}

plume_status plume_flat_fit(const char *request, char **result, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!result)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "fit: no result pointer"), &err, msg, nmsg);
    *result = NULL;
    static const char *const keys[] = {"targets", "start", "free", "max_eval", "xtol_rel", "lx", "ly", "thickness",
                                       "kappa", "constraint", "mesh", "edge", "steps", "solver", NULL};
    json_t *req;
    plume_status st = parse_request(request, "fit", keys, &req, &err);
    if (st != PLUME_OK)
        return plume_flat_finish(st, &err, msg, nmsg);
    plume_curve curves[FLAT_MAX_TARGETS];
    double angles[FLAT_MAX_TARGETS];
    memset(curves, 0, sizeof curves);
    int nt = 0;
    traction_setup t;
    plume_fit_opts fo;
    plume_fit_opts_default(&fo);
    plume_ortho start = {0.0, 0.0, 0.0, 0.0}, fit;
    double strain_max = 0.0;
    if ((st = get_traction_setup(req, "fit", &t, &err)) != PLUME_OK ||
        (st = get_int(req, "fit", "max_eval", &fo.max_eval, &err)) != PLUME_OK ||
        (st = get_number(req, "fit", "xtol_rel", &fo.xtol_rel, &err)) != PLUME_OK ||
        (st = get_fit_start(req, &start, &err)) != PLUME_OK || (st = get_fit_free(req, &fo.free_mask, &err)) != PLUME_OK ||
        (st = get_fit_targets(req, curves, angles, &nt, &strain_max, &err)) != PLUME_OK)
        goto done;
    plume_macro_model mm = {t.lx, t.ly, t.h, t.edge, t.mesh, t.constraint, t.kappa, strain_max, t.steps, nt, angles,
                            t.solver};
    plume_fit_report rep;
    if ((st = plume_fit_moduli(plume_macro_model_curve, &mm, curves, nt, &start, &fo, &fit, &rep, &err)) != PLUME_OK)
        goto done;
    st = plume_flat_emit(json_pack("{s:f, s:f, s:f, s:f, s:f, s:i, s:s, s:f}", "E_xx", fit.E_xx, "E_yy", fit.E_yy, "nu_xy",
                        fit.nu_xy, "G_xy", fit.G_xy, "residual", rep.residual, "evaluations", rep.evaluations, "stop",
                        rep.stop, "seconds", rep.seconds),
              result, &err);
done:
    for (int k = 0; k < nt; k++)
        plume_curve_free(&curves[k]);
    json_decref(req);
    return plume_flat_finish(st, &err, msg, nmsg);
}
