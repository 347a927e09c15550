/* plume: the problem of a loaded scene (scene.h), and its implicit Euler stepper (dynamic
 * scenes) or its load-stepping driver (static scenes). */
#include "scene.h"

#include <stdlib.h>
#include <string.h>

#include "../../lib/contact/contact_friction.h"
#include "../../lib/core/edge_length.h"
#include "../../lib/core/load.h"
#include "../../lib/core/membrane.h"
#include "../../lib/core/moment.h"
#include "internal/scene_internal.h"
#include "../shell/midedge_term.h"
#include "../shell/shape_bending.h"

/* The clamped vertices of mesh m ([nv], malloc'ed; NULL without clamps or out of memory). */
static unsigned char *held_vertices(const plume_scene *s, const plume_mesh *m)
{
    unsigned char *held = s->clamped ? malloc((size_t)m->nv + 1) : NULL;
    for (plume_index v = 0; held && v < m->nv; v++)
        held[v] = (s->clamped[v] & PLUME_CLAMP_HELD) != 0;
    return held;
}

/* The scene's bending term over mesh m (materials bm): hinges, or the shape operator with mirrored
 * stencils at clamped boundary edges (shape_bending.h). Midedge bending is no term alone: its
 * unknowns belong to a problem (add_bending). */
static plume_status bending_term(const plume_scene *s, const plume_mesh *m, const plume_bending_material *bm,
                                 plume_term *term, plume_err *err)
{
    if (s->bending_model == PLUME_BENDING_HINGE)
        return plume_bending_term_create(m, bm, s->nmat, NULL, term, err);
    unsigned char *held = held_vertices(s, m);
    if (s->clamped && !held)
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    const plume_shape_bending_opts so = {held, 0, 0};
    plume_status st = plume_shape_bending_term_create_opts(m, bm, s->nmat, NULL, &so, term, err);
    free(held);
    return st;
}

/* 1 when a handle's keyframes turn it (a kinematic body's own vertices, or an attachment to one) */
static int handle_rotates(const plume_handle *h)
{
    for (int k = 0; h->rotations && k < 3 * h->nkeys; k++)
        if (h->rotations[k] != 0.0)
            return 1;
    return 0;
}

/* The scene's bending in problem p, whose x holds the start positions: a term, or for midedge the
 * edge unknowns and their term (the clamped edges' angles fixed). */
static plume_status add_bending(const plume_scene *s, plume_problem *p, const plume_mesh *m,
                                const plume_bending_material *bm, plume_err *err)
{
    plume_status st;
    if (s->bending_model != PLUME_BENDING_MIDEDGE) {
        plume_term term;
        if ((st = bending_term(s, m, bm, &term, err)) != PLUME_OK)
            return st;
        return plume_problem_add_term(p, &term, err);
    }
    /* the held edges: between vertices of one handle (group h + 2) and between clamped vertices of
     * one object (group nhandles + 2 + its index; 1 in a "mesh" scene), which hold their
     * triangles' slopes as the shape operator's fits do, their directors carried by the group's
     * frame (a turning handle turns them, a placed object's clamp starts turned) */
    int *group = calloc((size_t)m->nv + 1, sizeof *group);
    if (!group)
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    for (plume_index v = 0; s->clamped && v < m->nv; v++)
        group[v] = (s->clamped[v] & PLUME_CLAMP_HELD) != 0;
    for (int i = 0; s->clamped && i < s->nobjects; i++)
        for (plume_index v = s->objects[i].v0; v < s->objects[i].v0 + s->objects[i].nv && v < m->nv; v++)
            group[v] = group[v] ? s->nhandles + 2 + i : 0;
    for (int h = 0; h < s->nhandles; h++)
        for (plume_index i = 0; i < s->handles[h].nvertices; i++)
            if (s->handles[h].vertices[i] < m->nv)
                group[s->handles[h].vertices[i]] = h + 2;
    unsigned char *sym = s->supported ? malloc((size_t)m->nv + 1) : NULL; /* the symmetry planes */
    if (s->supported && !sym) {
        free(group);
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    for (plume_index v = 0; sym && v < m->nv; v++)
        sym[v] = (unsigned char)((s->supported[v] >> 3) & 7);
    const plume_midedge_term_opts o = {NULL, group, sym};
    plume_index first;
    plume_midedge_term *t = NULL;
    st = plume_midedge_term_add(p, m, bm, s->nmat, NULL, &o, &first, &t, err);
    free(sym);
    /* a turning handle needs three vertices off one line to carry its edges' directors */
    for (plume_index e = 0; st == PLUME_OK && e < m->ne; e++) {
        const int g = group[m->edges[2 * e]];
        if (g >= 2 && group[m->edges[2 * e + 1]] == g && handle_rotates(&s->handles[g - 2]) &&
            !plume_midedge_term_group_anchored(t, g))
            st = plume_err_set(err, PLUME_EINVAL,
                               "scene: handle %d rotates and its vertices lie on one line: midedge bending cannot turn "
                               "the directors of the edges it holds with it; let it hold a vertex off that line or use "
                               "\"bending_model\": \"shape_operator\"",
                               g - 2);
    }
    free(group);
    return st;
}

/* The fields' "object" array: each triangle's scene object (the series tells bodies apart). */
static plume_status fields_objects(const plume_scene *s, plume_fields *f, plume_err *err)
{
    plume_index *t0 = malloc((size_t)s->nobjects * sizeof *t0), *nt = malloc((size_t)s->nobjects * sizeof *nt);
    plume_status st = PLUME_OK;
    if (!t0 || !nt) {
        st = plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    } else {
        for (int i = 0; i < s->nobjects; i++)
            t0[i] = s->objects[i].t0, nt[i] = s->objects[i].nt;
        st = plume_fields_set_objects(f, s->nobjects, t0, nt, err);
    }
    free(t0);
    free(nt);
    return st;
}

plume_status plume_scene_fields(const plume_scene *s, plume_fields **out, plume_err *err)
{
    return plume_scene_fields_of(s, NULL, out, err);
}

/* The materials' plane-stress tensors (malloc'ed, 9 per material: a "tensor" material's own, the
 * others' from their moduli), or NULL when no material has one (or out of memory: *nomem set). */
static double *scene_tensors(const plume_scene *s, int *nomem)
{
    *nomem = 0;
    int any = 0;
    for (int k = 0; k < s->nmat; k++)
        any |= s->mats[k].tensor != 0;
    if (!any)
        return NULL;
    double *C = malloc((size_t)(9 * s->nmat) * sizeof *C);
    if (!C) {
        *nomem = 1;
        return NULL;
    }
    for (int k = 0; k < s->nmat; k++) {
        if (s->mats[k].tensor)
            memcpy(C + 9 * k, s->mats[k].C, 9 * sizeof *C);
        else
            plume_membrane_stiffness(&s->mats[k].membrane, C + 9 * k);
    }
    return C;
}

plume_status plume_scene_fields_of(const plume_scene *s, plume_problem *p, plume_fields **out, plume_err *err)
{
    if (!s || !out)
        return plume_err_set(err, PLUME_EINVAL, "scene: invalid arguments");
    *out = NULL;
    const plume_mesh *m = s->elastic ? s->elastic : s->mesh;
    plume_membrane_material *mm = malloc((size_t)s->nmat * sizeof *mm);
    plume_bending_material *bm = malloc((size_t)s->nmat * sizeof *bm);
    plume_status st = PLUME_OK;
    plume_term term = {.size = sizeof(plume_term)};
    int bending = 0;
    if (!mm || !bm) {
        st = plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        goto done;
    }
    for (int k = 0; k < s->nmat; k++) {
        mm[k] = s->mats[k].membrane;
        bm[k] = s->mats[k].bending;
        bending |= bm[k].D_long > 0.0 || bm[k].D_trans > 0.0;
    }
    if (bending && s->bending_model == PLUME_BENDING_MIDEDGE) {
        plume_midedge_term *mt = p ? plume_problem_term_ctx(p, PLUME_MIDEDGE_TERM_NAME) : NULL;
        if (!mt) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "scene: the fields of a midedge scene (its bending energies need the edge angles of a "
                               "run) come from plume_run_fields");
            goto done;
        }
        if ((st = plume_midedge_term_view(mt, p, &term)) != PLUME_OK) {
            plume_err_set(err, st, "scene: out of memory");
            goto done;
        }
    } else if (bending && (st = bending_term(s, m, bm, &term, err)) != PLUME_OK) {
        goto done;
    }
    /* the whole mesh is drawn (kinematic bodies too, with NaN fields); the elastic triangles come first */
    st = plume_fields_create(s->mesh, 3, m->nt, mm, s->nmat, bending ? &term : NULL, s->barb_edges, s->nbarb, out, err);
    int nomem = 0;
    double *tensors = st == PLUME_OK ? scene_tensors(s, &nomem) : NULL;
    if (st == PLUME_OK && (nomem || (tensors && (st = plume_fields_set_tensors(*out, tensors, err)) != PLUME_OK))) {
        st = nomem ? plume_err_set(err, PLUME_ENOMEM, "scene: out of memory") : st;
        plume_fields_destroy(out);
    }
    free(tensors);
    if (st == PLUME_OK && bending && s->bending_model == PLUME_BENDING_MIDEDGE &&
        (st = plume_fields_set_curvatures(*out, plume_midedge_term_view_curvatures, err)) != PLUME_OK)
        plume_fields_destroy(out);
    if (st == PLUME_OK && s->nobjects > 0 && (st = fields_objects(s, *out, err)) != PLUME_OK)
        plume_fields_destroy(out);
done:
    free(mm);
    free(bm);
    return st;
}

/* A problem over the scene's mesh with its elastic terms (membrane and bending per material)
 * and its barb constraints, x at the rest state; not finalised. */
static plume_status elastic_problem(const plume_scene *s, plume_problem **out, plume_err *err)
{
    const plume_mesh *m = s->elastic ? s->elastic : s->mesh; /* kinematic bodies have no elastic energy */
    plume_problem *p = NULL;
    plume_membrane_material *mm = malloc((size_t)s->nmat * sizeof *mm);
    plume_bending_material *bm = malloc((size_t)s->nmat * sizeof *bm);
    plume_status st = PLUME_ENOMEM;
    if (!mm || !bm || (st = plume_problem_create(m->nv, 3, s->length, &p, err)) != PLUME_OK) {
        plume_err_set(err, st, "scene: out of memory");
        goto done;
    }
    int bending = 0;
    for (int k = 0; k < s->nmat; k++) {
        mm[k] = s->mats[k].membrane;
        bm[k] = s->mats[k].bending;
        bending |= bm[k].D_long > 0.0 || bm[k].D_trans > 0.0;
    }
    plume_term term;
    memcpy(plume_problem_x(p), s->mesh->x, (size_t)(3 * m->nv) * sizeof(double));
    int nomem = 0;
    double *tensors = scene_tensors(s, &nomem);
    if (nomem) {
        st = plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        goto done;
    }
    st = plume_membrane_term_create_tensor(m, 3, mm, tensors, s->nmat, &term, err);
    free(tensors);
    if (st != PLUME_OK || (st = plume_problem_add_term(p, &term, err)) != PLUME_OK)
        goto done;
    if (bending && (st = add_bending(s, p, m, bm, err)) != PLUME_OK)
        goto done;
    if ((st = plume_scene_add_splits(s, p, err)) != PLUME_OK)
        goto done;
    if (s->nbarb > 0) {
        plume_constraint con;
        if ((st = plume_edge_length_create(s->barb_edges, s->nbarb, m->X, m->nv, &con, err)) != PLUME_OK ||
            (st = plume_problem_add_constraint(p, &con, err)) != PLUME_OK)
            goto done;
    }
done:
    free(mm);
    free(bm);
    if (st != PLUME_OK)
        plume_problem_destroy(&p);
    *out = p;
    return st;
}

/* the contact term between the mesh's bodies (its connected components); *handle (may be NULL)
 * serves plume_contact_term_stats */
static plume_status add_contact(const plume_scene *s, plume_problem *p, plume_contact **handle, plume_err *err)
{
    const plume_mesh *m = s->mesh;
    int *body = plume_scene_body_labels(s, err);
    if (!body)
        return PLUME_ENOMEM;
    plume_contact_term_opts co = s->contact;
    co.weld = s->split_weld; /* a split line's lips touch where they coincide, as neighbours do */
    plume_term t;
    plume_contact *c = NULL;
    plume_status st = plume_contact_term_create(m->nv, m->nt, m->tri, body, m->x, &co, &t, &c, err);
    free(body);
    if (st == PLUME_OK)
        st = plume_problem_add_term(p, &t, err);
    if (handle)
        *handle = st == PLUME_OK ? c : NULL;
    if (st != PLUME_OK || !(s->friction_mu > 0.0))
        return st;
    /* friction lags from the contact term's pairs at the start of every step */
    plume_friction_opts fo;
    plume_friction_opts_default(&fo);
    fo.mu = s->friction_mu;
    fo.eps_v = s->friction_eps_v;
    fo.dt = s->dt;
    plume_friction *f = NULL;
    if ((st = plume_friction_term_create(m->nv, &fo, &t, &f, err)) != PLUME_OK)
        return st;
    plume_friction_follow_contact(f, c);
    return plume_problem_add_term(p, &t, err);
}

plume_status plume_scene_dynamics(const plume_scene *s, plume_problem **pp, plume_dynamics **pd, plume_err *err)
{
    return plume_scene_dynamics_contact(s, pp, pd, NULL, err);
}

plume_status plume_scene_dynamics_contact(const plume_scene *s, plume_problem **pp, plume_dynamics **pd,
                                          plume_contact **contact, plume_err *err)
{
    if (contact)
        *contact = NULL;
    if (!s || !s->mesh || !pp || !pd)
        return plume_err_set(err, PLUME_EINVAL, "scene: invalid arguments");
    *pp = NULL;
    *pd = NULL;
    if (s->is_static)
        return plume_err_set(err, PLUME_EINVAL, "%s: a static scene (\"solve\": \"static\") has no dynamics", s->path);
    plume_status cs = plume_scene_check_start(s, err);
    if (cs != PLUME_OK)
        return cs;
    plume_problem *p = NULL;
    double *rho = malloc((size_t)s->nmat * sizeof *rho);
    plume_status st = PLUME_ENOMEM;
    if (!rho) {
        plume_err_set(err, st, "scene: out of memory");
        goto fail;
    }
    for (int k = 0; k < s->nmat; k++)
        rho[k] = s->mats[k].density;
    if ((st = elastic_problem(s, &p, err)) != PLUME_OK || (s->has_contact && (st = add_contact(s, p, contact, err)) != PLUME_OK))
        goto fail;
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = s->dt;
    memcpy(o.gravity, s->gravity, sizeof o.gravity);
    o.max_halvings = s->max_halvings;
    o.solver = s->solver;
    o.solver_opts.max_iter = s->max_iter;
    o.solver_opts.verbose = s->verbose;
    o.adaptive = s->adaptive_dt;
    o.dt_max = s->dt_max;
    o.tangent_predictor = s->predictor == PLUME_PREDICT_TANGENT || s->predictor == PLUME_PREDICT_SECANT_TANGENT;
    plume_solver_opts_set_globalization(&o.solver_opts, s->globalization);
    if ((st = plume_dynamics_create(s->mesh, p, rho, s->nmat, s->handles, s->nhandles, &o, pd, err)) != PLUME_OK)
        goto fail;
    *pp = p;
    free(rho);
    return PLUME_OK;
fail:
    plume_problem_destroy(&p);
    free(rho);
    return st;
}


/* What the load scaler of a static scene needs: the load terms (their ctx live in the problem)
 * and the handles, whose prescribed positions are X + factor * (last keyframe offset). */
typedef struct {
    const plume_scene *s;
    plume_problem *p;
    int has_force;
    plume_term force;
    int nmoments;
    plume_term *moments;
} static_loads;

static void static_loads_free(void *user)
{
    static_loads *l = user;
    if (l)
        free(l->moments);
    free(l);
}

static void static_loads_scale(void *user, double factor)
{
    static_loads *l = user;
    if (l->has_force)
        plume_load_scale(&l->force, factor);
    for (int k = 0; k < l->nmoments; k++)
        plume_moment_scale(l->moments + k, factor);
    double *x = plume_problem_x(l->p);
    const plume_mesh *m = l->s->mesh;
    for (int h = 0; h < l->s->nhandles; h++) {
        const plume_handle *hd = l->s->handles + h;
        const double *off = hd->offsets + 3 * (hd->nkeys - 1);
        for (plume_index i = 0; i < hd->nvertices; i++) {
            plume_index v = hd->vertices[i];
            x[3 * v] = m->X[2 * v] + factor * off[0];
            x[3 * v + 1] = m->X[2 * v + 1] + factor * off[1];
            x[3 * v + 2] = factor * off[2];
        }
    }
}

plume_status plume_scene_statics(const plume_scene *s, plume_problem **pp, plume_statics **pst, plume_err *err)
{
    if (!s || !s->mesh || !pp || !pst)
        return plume_err_set(err, PLUME_EINVAL, "scene: invalid arguments");
    *pp = NULL;
    *pst = NULL;
    if (!s->is_static)
        return plume_err_set(err, PLUME_EINVAL, "%s: not a static scene (add \"solve\": \"static\")", s->path);
    const plume_mesh *m = s->mesh;
    plume_problem *p = NULL;
    plume_index *ids = malloc((size_t)(m->nv + 1) * sizeof *ids), nf = 0;
    double *f = malloc((size_t)(3 * m->nv + 1) * sizeof *f), *X3 = malloc((size_t)(3 * m->nv + 1) * sizeof *X3);
    static_loads *l = calloc(1, sizeof *l);
    plume_status st = PLUME_ENOMEM;
    if (!ids || !f || !X3 || !l || !(l->moments = calloc((size_t)s->nmoments + 1, sizeof *l->moments))) {
        plume_err_set(err, st, "scene: out of memory");
        goto fail;
    }
    if ((st = elastic_problem(s, &p, err)) != PLUME_OK)
        goto fail;
    l->s = s;
    l->p = p;
    for (plume_index v = 0; v < m->nv; v++) {
        const double *fv = s->force + 3 * v;
        if (fv[0] != 0.0 || fv[1] != 0.0 || fv[2] != 0.0) {
            memcpy(f + 3 * nf, fv, 3 * sizeof *f);
            ids[nf++] = v;
        }
    }
    if (nf > 0) {
        plume_term t;
        if ((st = plume_load_term_create(ids, nf, 3, f, &t, err)) != PLUME_OK ||
            (st = plume_problem_add_term(p, &t, err)) != PLUME_OK)
            goto fail;
        l->force = t; /* a copy: its ctx is the problem's, which scales it */
        l->has_force = 1;
    }
    for (plume_index v = 0; v < m->nv; v++)
        X3[3 * v] = m->X[2 * v], X3[3 * v + 1] = m->X[2 * v + 1], X3[3 * v + 2] = 0.0;
    for (int k = 0; k < s->nmoments; k++) {
        const plume_scene_moment *mo = s->moments + k;
        plume_term t;
        if ((st = plume_moment_term_create(mo->end, mo->nend, mo->row, mo->nrow, mo->axis, mo->moment, X3, &t, err)) !=
                PLUME_OK ||
            (st = plume_problem_add_term(p, &t, err)) != PLUME_OK)
            goto fail;
        l->moments[l->nmoments++] = t;
    }
    /* clamps: positions of the clamped vertices; the rest height of their second row where the
     * bending does not hold the clamp's slope itself (scene.h, "clamps") */
    for (plume_index v = 0; v < m->nv; v++) {
        if (s->clamped[v] & PLUME_CLAMP_HELD)
            for (int a = 0; a < 3; a++)
                plume_problem_fix_dof(p, 3 * v + a, err);
        else if ((s->clamped[v] & PLUME_CLAMP_ROW) || ((s->clamped[v] & PLUME_CLAMP_ROW_EDGE) && s->bending_model == PLUME_BENDING_HINGE))
            plume_problem_fix_dof(p, 3 * v + 2, err);
    }
    for (plume_index v = 0; v < m->nv; v++)
        for (int a = 0; a < 3; a++)
            if (s->supported[v] & (1u << a))
                plume_problem_fix_dof(p, 3 * v + a, err);
    for (int h = 0; h < s->nhandles; h++)
        for (plume_index i = 0; i < s->handles[h].nvertices; i++)
            for (int a = 0; a < 3; a++)
                plume_problem_fix_dof(p, 3 * s->handles[h].vertices[i] + a, err);
    static_loads_scale(l, 0.0);
    if ((st = plume_problem_finalize(p, err)) != PLUME_OK)
        goto fail;
    plume_statics_opts o;
    plume_statics_opts_default(&o);
    o.steps = s->steps;
    o.predictor = s->predictor;
    o.solver = s->solver;
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    so.max_iter = s->max_iter;
    so.verbose = s->verbose;
    plume_solver_opts_set_globalization(&so, s->globalization);
    o.solver_opts = &so;
    st = plume_statics_create(p, &o, static_loads_scale, l, static_loads_free, pst, err);
    l = NULL; /* the driver owns it now, or has freed it */
    if (st != PLUME_OK)
        goto fail;
    *pp = p;
    free(ids);
    free(f);
    free(X3);
    return PLUME_OK;
fail:
    static_loads_free(l);
    plume_problem_destroy(&p);
    free(ids);
    free(f);
    free(X3);
    return st;
}
