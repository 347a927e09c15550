/* plume: the flat interface's traction request (flat.h): the macro or micro traction test, and
 * the macro traction keys the fit request shares. */
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
#include "../lib/core/membrane.h"
#include "internal/flat_common.h"

/* the macro traction keys of a request into t (defaults of plume_traction_opts and the apps) */
plume_status plume_flat_get_traction_setup(json_t *req, const char *what, plume_flat_traction_setup *t, plume_err *err)
{
    plume_traction_opts d;
    plume_traction_opts_default(&d);
    t->lx = 1.0, t->ly = 1.3, t->h = 1.0, t->kappa = 0.0, t->edge = -1.0, t->strain_max = d.strain_max;
    t->constraint = 1, t->steps = d.steps, t->mesh = PLUME_PATCH_ALIGNED, t->solver = PLUME_SOLVER_NEWTON;
    const char *mesh = NULL, *solver = NULL;
    plume_status st;
    if ((st = plume_flat_get_number(req, what, "lx", &t->lx, err)) != PLUME_OK ||
                                    (st = plume_flat_get_number(req, what, "ly", &t->ly, err)) != PLUME_OK ||
                                    (st = plume_flat_get_number(req, what, "thickness", &t->h, err)) != PLUME_OK ||
                                    (st = plume_flat_get_number(req, what, "kappa", &t->kappa, err)) != PLUME_OK ||
                                    (st = plume_flat_get_number(req, what, "edge", &t->edge, err)) != PLUME_OK ||
        (st = plume_flat_get_number(req, what, "strain_max", &t->strain_max, err)) != PLUME_OK ||
        (st = plume_flat_get_bool(req, what, "constraint", &t->constraint, err)) != PLUME_OK ||
                                    (st = plume_flat_get_int(req, what, "steps", &t->steps, err)) != PLUME_OK ||
                                    (st = plume_flat_get_string(req, what, "mesh", &mesh, err)) != PLUME_OK ||
                                    (st = plume_flat_get_string(req, what, "solver", &solver, err)) != PLUME_OK)
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
/* traction request.separation: the barb lines' law, {"strength": N/m, "stiffness": N/m^2, "capture": m}
 * (the "separation" of a homogenize result: its other keys are taken and ignored). */
static plume_status get_separation(json_t *req, plume_separation_law *law, plume_err *err)
{
    json_t *js = json_object_get(req, "separation");
    memset(law, 0, sizeof *law);
    if (!json_is_object(js))
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"split_lines\" needs \"separation\": the law "
                             "{\"strength\", \"stiffness\", \"capture\"} (a homogenize result's \"separation\")");
    static const char *const keys[] = {"strength", "stiffness", "capture"};
    double *v[3] = {&law->strength, &law->stiffness, &law->capture};
    for (int k = 0; k < 3; k++) {
        json_t *x = json_object_get(js, keys[k]);
        if (!json_is_number(x))
            return plume_err_set(err, PLUME_EINVAL, "traction request: \"separation\".\"%s\" must be a number", keys[k]);
        *v[k] = json_number_value(x);
    }
    return PLUME_OK;
}

/* traction request.split_lines: that many barb lines of the macro sample open to split
 * (plume_splits_open), held by the law of request.separation; *splits NULL without the key. */
static plume_status traction_splits(json_t *req, const plume_flat_traction_setup *t, int micro, double angle,
                                    const plume_mesh *patch, plume_splits **splits, plume_separation_law *law,
                                    plume_err *err)
{
    int n = 0;
    plume_status st = plume_flat_get_int(req, "traction", "split_lines", &n, err);
    if (st != PLUME_OK || !json_object_get(req, "split_lines"))
        return st;
    if (micro)
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"split_lines\" is for the macro model (the micro "
                             "model's barbules have their own hooks)");
    if (n < 1)
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"split_lines\" must be >= 1 (got %d)", n);
    if (t->mesh != PLUME_PATCH_ALIGNED)
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"split_lines\" needs \"mesh\": \"aligned\"");
    if ((st = get_separation(req, law, err)) != PLUME_OK)
        return st;
    return plume_splits_open(patch, angle, n, splits, err);
}

/* traction request.tensor: the macro vane's plane-stress tensor, 9 numbers (Pa, row-major, Voigt
 * E11, E22, 2E12 in the barb frame: a homogenize result's "C"), in place of the moduli's; *has 0
 * without the key. */
static plume_status get_tensor(json_t *req, double C[9], int *has, plume_err *err)
{
    *has = 0;
    json_t *jc = json_object_get(req, "tensor");
    if (!jc || json_is_null(jc))
        return PLUME_OK;
    if (!json_is_array(jc) || json_array_size(jc) != 9)
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"tensor\" must be 9 numbers (Pa, the plane-stress "
                             "tensor row by row; a homogenize result's \"C\")");
    for (int k = 0; k < 9; k++) {
        json_t *v = json_array_get(jc, (size_t)k);
        if (!json_is_number(v))
            return plume_err_set(err, PLUME_EINVAL, "traction request: \"tensor\"[%d] must be a number", k);
        C[k] = json_number_value(v);
    }
    plume_err why;
    if (plume_membrane_tensor_check(C, &why) != PLUME_OK)
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"tensor\": %s", why.msg);
    *has = 1;
    return PLUME_OK;
}

static plume_status traction_specimen(json_t *req, const plume_flat_traction_setup *t, int micro, double angle,
                                      plume_vane *vane, plume_layout *layout, plume_mesh **mesh, plume_splits **splits,
                                      plume_problem **p, plume_index **barbs, plume_index *nbarbs,
                                      plume_membrane_material mats[2], int *nmat, plume_err *err)
{
    plume_status st;
    if (micro) {
        /* as apps/traction: barbs plume_traction_default_barb_spacing apart, elements chosen from
         * the thinnest strip, unless the layout says */
        plume_layout_set_spacing(layout, plume_traction_default_barb_spacing(t->ly));
        if ((st = plume_flat_get_layout(req, "traction", layout, err)) != PLUME_OK)
            return st;
        layout->h = t->h, layout->kappa = t->kappa;
        if (json_object_get(req, "split_lines"))
            return plume_err_set(err, PLUME_EINVAL, "traction request: \"split_lines\" is for the macro model (the "
                                 "micro model's barbules have their own hooks)");
        if (json_object_get(req, "tensor"))
            return plume_err_set(err, PLUME_EINVAL, "traction request: \"tensor\" is for the macro model (the micro "
                                 "model resolves the barbules)");
        if ((st = plume_micro_specimen(layout, t->lx, t->ly, angle, mesh, p, err)) != PLUME_OK)
            return st;
        plume_layout_materials(layout, mats);
        *nmat = 2;
        return PLUME_OK;
    }
    if (json_object_get(req, "layout"))
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"layout\" is for the micro model");
    double C[9];
    int has_tensor;
    if ((st = get_tensor(req, C, &has_tensor, err)) != PLUME_OK)
        return st;
    if (has_tensor && json_object_get(req, "vtk"))
        return plume_err_set(err, PLUME_EINVAL, "traction request: \"vtk\" writes the orthotropic moduli's stresses: "
                             "not with \"tensor\"");
    vane->h = t->h, vane->kappa = t->kappa, vane->constraint = t->constraint;
    plume_separation_law law;
    if ((st = plume_vane_check(vane, err)) != PLUME_OK ||
        (st = plume_patch_mesh(t->lx, t->ly, angle, t->edge, t->mesh, 2, mesh, err)) != PLUME_OK ||
        (st = traction_splits(req, t, micro, angle, *mesh, splits, &law, err)) != PLUME_OK)
        return st;
    const plume_mesh *m = *splits ? plume_splits_mesh(*splits) : *mesh; /* the problem's: the opened mesh */
    if ((st = plume_problem_create(m->nv, 2, fmax(t->lx, t->ly), p, err)) != PLUME_OK ||
        (st = plume_vane_add_tensor(*p, m, vane, has_tensor ? C : NULL, barbs, nbarbs, err)) != PLUME_OK ||
        (*splits && (st = plume_splits_add(*p, *splits, &law, err)) != PLUME_OK))
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
    json_t *o = plume_flat_curve_json(&res->curve);
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
                                       "convergence", "path", "peel", "top_grip_free", "split_lines", "separation",
                                       "tensor", "checkpoint", "restart", "stop_after", NULL};
    json_t *req;
    plume_status st = plume_flat_parse_request(request, "traction", keys, &req, &err);
    if (st != PLUME_OK)
        return plume_flat_finish(st, &err, msg, nmsg);
    plume_flat_traction_setup t;
    const char *model = "macro", *vtk = NULL;
    double angle = 45.0;
    int convergence = 1;
    plume_vane vane;
    plume_vane_default(&vane);
    plume_layout layout;
    plume_layout_default(&layout);
    plume_mesh *mesh = NULL;
    plume_splits *splits = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nbarbs = 0;
    plume_fields *fields = NULL;
    plume_traction_result res;
    memset(&res, 0, sizeof res);
    double path[1000];
    int npath = 0;
    if ((st = get_path(req, path, &npath, &err)) != PLUME_OK ||
        (st = plume_flat_get_traction_setup(req, "traction", &t, &err)) != PLUME_OK ||
        (st = plume_flat_get_string(req, "traction", "model", &model, &err)) != PLUME_OK ||
        (st = plume_flat_get_string(req, "traction", "vtk", &vtk, &err)) != PLUME_OK ||
        (st = plume_flat_get_bool(req, "traction", "convergence", &convergence, &err)) != PLUME_OK ||
        (st = plume_flat_get_number(req, "traction", "angle", &angle, &err)) != PLUME_OK ||
        (st = plume_flat_get_moduli(req, "traction", "moduli", &vane.moduli, &err)) != PLUME_OK)
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
    if ((st = traction_specimen(req, &t, micro, angle, &vane, &layout, &mesh, &splits, &p, &barbs, &nbarbs, mats, &nmat,
                                &err)) != PLUME_OK)
        goto done;
    const plume_mesh *run_mesh = splits ? plume_splits_mesh(splits) : mesh;
    plume_traction_opts to;
    plume_traction_opts_default(&to);
    to.lx = t.lx, to.ly = t.ly, to.h = t.h, to.strain_max = t.strain_max, to.steps = t.steps, to.solver = t.solver;
    to.progress = 0;
    if (npath > 0)
        to.path = path, to.npath = npath;
    if ((st = plume_flat_get_number(req, "traction", "peel", &to.peel, &err)) != PLUME_OK ||
        (st = plume_flat_get_number(req, "traction", "top_grip_free", &to.top_grip_free, &err)) != PLUME_OK ||
        (st = plume_flat_get_string(req, "traction", "checkpoint", &to.checkpoint, &err)) != PLUME_OK ||
        (st = plume_flat_get_string(req, "traction", "restart", &to.restart, &err)) != PLUME_OK ||
        (st = plume_flat_get_int(req, "traction", "stop_after", &to.stop_after, &err)) != PLUME_OK)
        goto done;
    if (vtk && to.restart) {
        st = plume_err_set(&err, PLUME_EINVAL, "traction request: \"restart\" does not continue a \"vtk\" series: "
                           "write it from a run without a restart");
        goto done;
    }
    if ((vtk && (st = traction_vtk(vtk, run_mesh, mats, nmat, barbs, nbarbs, &fields, &to, &err)) != PLUME_OK) ||
        (fields && micro && layout.kind == PLUME_LAYOUT_BARBULES && layout.hooks.strength > 0.0 &&
         (st = plume_fields_add_links(fields, p, "hooks", &err)) != PLUME_OK) ||
        (fields && splits && (st = plume_fields_add_links(fields, p, "splits", &err)) != PLUME_OK) ||
        (st = plume_traction_run(run_mesh, p, barbs, nbarbs, &to, &res, &err)) != PLUME_OK)
        goto done;
    plume_micro_convergence conv;
    const int stopped = to.stop_after > 0 && res.curve.n == to.stop_after + 1 &&
                        to.stop_after < to.steps * (npath > 0 ? npath : 1);
    int has_conv = micro && convergence && res.converged && to.solver != PLUME_SOLVER_LINEARIZED && !stopped;
    to.checkpoint = to.restart = NULL, to.stop_after = 0; /* the estimate runs from rest, unrecorded */
    if (has_conv && (st = plume_micro_traction_convergence(&layout, t.lx, t.ly, angle, &to, &res, &conv, &err)) != PLUME_OK)
        goto done;
    json_t *o = traction_json(&res, micro, &layout, run_mesh, angle, has_conv, &conv);
    if (o && splits)
        json_object_set_new(o, "split_pairs", json_integer(plume_splits_pairs(splits)));
    st = plume_flat_emit(o, result, &err);
done:
    plume_traction_result_free(&res);
    plume_fields_destroy(&fields);
    free(barbs);
    plume_problem_destroy(&p);
    plume_splits_destroy(&splits);
    plume_mesh_destroy(&mesh);
    json_decref(req);
    return plume_flat_finish(st, &err, msg, nmsg);
}
