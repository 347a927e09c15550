/* The midedge bending term of a problem (midedge_term.h): the problem's edge unknowns phi_e =
 * L_e theta_e in and out of the bending energy's (x, theta) arrays. */
#include "midedge_term.h"
#include "../../lib/core/vec3.h"
#include "internal/midedge_anchor.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct plume_midedge_term {
    plume_midedge_bending *b;
    plume_index nv, nt, ne, first; /* the edge unknowns are x[first .. first + ne - 1] */
    plume_index *stencil;          /* [3 nt] the triangles' vertices */
    plume_index *extra;            /* [3 nt] first + the edge of each slot */
    double *L;                     /* [ne] rest lengths: phi = L theta */
    double *theta, *gtheta;        /* [ne] workspaces */
    int ngroup;                    /* the held vertices' groups: 1 .. ngroup - 1 */
    plume_index *group_anchor;     /* [3 ngroup] each group's anchors, -1 for none */
};

static void term_free(void *vctx)
{
    plume_midedge_term *c = vctx;
    if (!c)
        return;
    plume_midedge_bending_destroy(&c->b);
    free(c->stencil);
    free(c->extra);
    free(c->L);
    free(c->theta);
    free(c->gtheta);
    free(c->group_anchor);
    free(c);
}

void plume_midedge_term_angles(const plume_midedge_term *t, const double *x, double *theta)
{
    for (plume_index e = 0; e < t->ne; e++)
        theta[e] = x[t->first + e] / t->L[e];
}

/* Scales rows and columns 9..11 of each 12x12 block (the angles) by 1/L: the unknowns are L theta. */
static void scale_blocks(const plume_midedge_term *c, plume_index first, plume_index count, double *hblocks)
{
    for (plume_index t = first; t < first + count; t++) {
        double *H = hblocks + 144 * (size_t)(t - first), s[12];
        for (int i = 0; i < 12; i++)
            s[i] = i < 9 ? 1.0 : 1.0 / c->L[c->extra[3 * t + i - 9] - c->first];
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++)
                H[12 * i + j] *= s[i] * s[j];
    }
}

static plume_status term_eval(void *vctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                              int project)
{
    plume_midedge_term *c = vctx;
    if (dim != 3)
        return PLUME_EINVAL;
    plume_midedge_term_angles(c, x, c->theta);
    if (grad)
        memset(c->gtheta, 0, (size_t)c->ne * sizeof *c->gtheta);
    plume_status st = plume_midedge_bending_eval(c->b, x, c->theta, energy, grad, grad ? c->gtheta : NULL, hblocks,
                                                 project, NULL);
    if (st != PLUME_OK)
        return st;
    for (plume_index e = 0; grad && e < c->ne; e++)
        grad[c->first + e] += c->gtheta[e] / c->L[e];
    if (hblocks)
        scale_blocks(c, 0, c->nt, hblocks);
    return PLUME_OK;
}

static plume_status term_hess_range(void *vctx, int dim, const double *x, plume_index first, plume_index count,
                                    double *hblocks, int project)
{
    plume_midedge_term *c = vctx;
    if (dim != 3)
        return PLUME_EINVAL;
    for (plume_index i = 3 * first; i < 3 * (first + count); i++) { /* the angles these triangles read */
        const plume_index e = c->extra[i] - c->first;
        c->theta[e] = x[c->extra[i]] / c->L[e];
    }
    plume_status st = plume_midedge_bending_blocks(c->b, x, c->theta, first, count, hblocks, project, NULL);
    if (st == PLUME_OK)
        scale_blocks(c, first, count, hblocks);
    return st;
}

static plume_status term_energies(void *vctx, int dim, const double *x, double *e)
{
    plume_midedge_term *c = vctx;
    if (dim != 3)
        return PLUME_EINVAL;
    plume_midedge_term_angles(c, x, c->theta);
    return plume_midedge_bending_energies(c->b, x, c->theta, e, NULL);
}

/* A step's start: every frame becomes its director, every angle 0 (the energy unchanged). */
static plume_status term_rebase(void *vctx, int dim, double *x)
{
    plume_midedge_term *c = vctx;
    if (dim != 3)
        return PLUME_EINVAL;
    plume_midedge_term_angles(c, x, c->theta);
    plume_status st = plume_midedge_bending_rebase(c->b, x, c->theta, NULL);
    if (st != PLUME_OK)
        return st;
    for (plume_index e = 0; e < c->ne; e++)
        x[c->first + e] = 0.0;
    return PLUME_OK;
}

/* A view: the term and the problem whose x holds its angles. */
typedef struct {
    plume_midedge_term *t;
    plume_problem *p;
} view_ctx;

/* The view's eval: the energy alone, at positions x and the problem's angles */
static plume_status view_eval(void *vctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                              int project)
{
    (void)project;
    const view_ctx *v = vctx;
    if (grad || hblocks || dim != 3)
        return PLUME_EINVAL;
    plume_midedge_term_angles(v->t, plume_problem_x(v->p), v->t->theta);
    return plume_midedge_bending_eval(v->t->b, x, v->t->theta, energy, NULL, NULL, NULL, 0, NULL);
}

static plume_status view_energies(void *vctx, int dim, const double *x, double *e)
{
    const view_ctx *v = vctx;
    if (dim != 3)
        return PLUME_EINVAL;
    plume_midedge_term_angles(v->t, plume_problem_x(v->p), v->t->theta);
    return plume_midedge_bending_energies(v->t->b, x, v->t->theta, e, NULL);
}

plume_status plume_midedge_term_view_curvatures(void *vctx, int dim, const double *x, double *kappa)
{
    const view_ctx *v = vctx;
    if (dim != 3)
        return PLUME_EINVAL;
    plume_midedge_term_angles(v->t, plume_problem_x(v->p), v->t->theta);
    return plume_midedge_bending_curvatures(v->t->b, x, v->t->theta, kappa, NULL);
}

plume_status plume_midedge_term_view(plume_midedge_term *t, plume_problem *p, plume_term *out)
{
    view_ctx *v = malloc(sizeof *v);
    if (!v)
        return PLUME_ENOMEM;
    v->t = t, v->p = p;
    *out = (plume_term){.size = sizeof(plume_term),
                        .name = PLUME_MIDEDGE_TERM_NAME,
                        .arity = 3,
                        .nstencil = t->nt,
                        .stencil = t->stencil,
                        .eval = view_eval,
                        .destroy = free,
                        .ctx = v,
                        .energies = view_energies};
    return PLUME_OK;
}

const plume_midedge_bending *plume_midedge_term_bending(const plume_midedge_term *t) { return t->b; }

void plume_midedge_term_directors(const plume_midedge_term *t, const double *x, double *d)
{
    plume_midedge_term_angles(t, x, t->theta);
    for (plume_index e = 0; e < t->ne; e++)
        plume_midedge_bending_director(t->b, x, t->theta, e, d + 3 * e);
}

plume_index plume_midedge_term_nedge(const plume_midedge_term *t) { return t->ne; }
plume_index plume_midedge_term_first(const plume_midedge_term *t) { return t->first; }
const double *plume_midedge_term_frames(const plume_midedge_term *t) { return plume_midedge_bending_frames(t->b); }

plume_status plume_midedge_term_set_frames(plume_midedge_term *t, const double *r0, plume_err *err)
{
    return plume_midedge_bending_set_frames(t->b, r0, err);
}

int plume_midedge_term_group_anchored(const plume_midedge_term *t, int g)
{
    return g > 0 && g < t->ngroup && t->group_anchor[3 * g] >= 0;
}

/* 1 when edge e's two vertices share a rigid group */
static int edge_held(const plume_mesh *m, const int *group, plume_index e)
{
    return group && group[m->edges[2 * e]] > 0 && group[m->edges[2 * e]] == group[m->edges[2 * e + 1]];
}

/* The symmetry plane edge e lies on: its axis 0, 1, 2, or -1 (plume_midedge_term_opts.sym). */
static int edge_sym_axis(const plume_mesh *m, const double *rest_x, const unsigned char *sym, plume_index e)
{
    const plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
    if (!sym)
        return -1;
    double pa[3], pb[3];
    plume_midedge_rest_point(m, rest_x, a, pa);
    plume_midedge_rest_point(m, rest_x, b, pb);
    const double len = sqrt((pb[0] - pa[0]) * (pb[0] - pa[0]) + (pb[1] - pa[1]) * (pb[1] - pa[1]) + (pb[2] - pa[2]) * (pb[2] - pa[2]));
    for (int k = 0; k < 3; k++)
        if ((sym[a] & sym[b] & (1 << k)) && fabs(pb[k] - pa[k]) <= 1e-9 * len)
            return k;
    return -1;
}

/* The groups' anchors, and each held edge's ([3 ne] in *anchor, or NULL with no group). */
static plume_status held_anchors(plume_midedge_term *c, const plume_mesh *m, const double *rest_x, const int *group,
                                 plume_index **anchor, plume_err *err)
{
    *anchor = NULL;
    if (!group)
        return PLUME_OK;
    c->ngroup = 1;
    for (plume_index v = 0; v < m->nv; v++) {
        if (group[v] < 0)
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: vertex %ld: negative group %d", (long)v, group[v]);
        c->ngroup = group[v] >= c->ngroup ? group[v] + 1 : c->ngroup;
    }
    c->group_anchor = malloc(3 * (size_t)c->ngroup * sizeof *c->group_anchor);
    *anchor = malloc(3 * (size_t)(m->ne > 0 ? m->ne : 1) * sizeof **anchor);
    if (!c->group_anchor || !*anchor || plume_midedge_group_anchors(m, rest_x, group, c->ngroup, c->group_anchor) != 0)
        return plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory for the held edges' anchors");
    for (plume_index e = 0; e < m->ne; e++) {
        const plume_index *a = c->group_anchor + 3 * group[m->edges[2 * e]];
        for (int k = 0; k < 3; k++)
            (*anchor)[3 * e + k] = edge_held(m, group, e) ? a[k] : -1;
    }
    return PLUME_OK;
}

/* The start angle of edge e: the mean of its faces' current unit normals (x, vertex part). */
static int start_angle(const plume_midedge_term *c, const plume_mesh *m, const double *x, plume_index e, double *theta)
{
    double n[3] = {0.0, 0.0, 0.0};
    for (int s = 0; s < 2; s++) {
        const plume_index t = m->edge_tri[2 * e + s];
        if (t < 0)
            continue;
        const plume_index *v = m->tri + 3 * t;
        double a[3], b[3], nt[3];
        sub3(x + 3 * v[1], x + 3 * v[0], a);
        sub3(x + 3 * v[2], x + 3 * v[0], b);
        cross3(a, b, nt);
        const double l = sqrt(dot3(nt, nt));
        if (!(l > 0.0))
            return -1;
        for (int i = 0; i < 3; i++)
            n[i] += nt[i] / l;
    }
    if (!(dot3(n, n) > 0.0))
        return -1;
    *theta = plume_midedge_bending_angle_of(c->b, x, e, n);
    return isfinite(*theta) ? 0 : -1;
}

plume_status plume_midedge_term_add(plume_problem *p, const plume_mesh *mesh, const plume_bending_material *mats,
                                    int nmat, const double *rest_x, const plume_midedge_term_opts *o,
                                    plume_index *first, plume_midedge_term **term, plume_err *err)
{
    if (!p || !mesh || !first)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: a problem, a mesh and first are required");
    if (plume_problem_nvert(p) != mesh->nv || plume_problem_dim(p) != 3)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: the problem must be over the mesh's %ld vertices in 3D",
                             (long)mesh->nv);
    plume_midedge_term *c = calloc(1, sizeof *c);
    if (!c)
        return plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory");
    const int *group = o ? o->group : NULL;
    plume_index *anchor = NULL;
    plume_status st = held_anchors(c, mesh, rest_x, group, &anchor, err);
    if (st == PLUME_OK) {
        const plume_midedge_bending_opts bo = {o ? o->rest_dir : NULL, anchor};
        st = plume_midedge_bending_create_opts(mesh, mats, nmat, rest_x, &bo, &c->b, err);
    }
    free(anchor);
    if (st != PLUME_OK) {
        term_free(c);
        return st;
    }
    c->nv = mesh->nv, c->nt = mesh->nt, c->ne = mesh->ne;
    c->stencil = malloc(3 * (size_t)c->nt * sizeof *c->stencil);
    c->extra = malloc(3 * (size_t)c->nt * sizeof *c->extra);
    c->L = malloc((size_t)(c->ne + 1) * sizeof *c->L);
    c->theta = calloc((size_t)(c->ne + 1), sizeof *c->theta);
    c->gtheta = calloc((size_t)(c->ne + 1), sizeof *c->gtheta);
    if (!c->stencil || !c->extra || !c->L || !c->theta || !c->gtheta ||
        (st = plume_problem_add_unknowns(p, c->ne, &c->first, err)) != PLUME_OK) {
        term_free(c);
        return st != PLUME_OK ? st : plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory");
    }
    const plume_index *fe = plume_midedge_bending_face_edges(c->b);
    memcpy(c->stencil, mesh->tri, 3 * (size_t)c->nt * sizeof *c->stencil);
    for (plume_index i = 0; i < 3 * c->nt; i++)
        c->extra[i] = c->first + fe[i];
    for (plume_index e = 0; e < c->ne; e++) {
        const plume_index a = mesh->edges[2 * e], b = mesh->edges[2 * e + 1];
        c->L[e] = hypot(mesh->X[2 * b] - mesh->X[2 * a], mesh->X[2 * b + 1] - mesh->X[2 * a + 1]);
    }
    double *x = plume_problem_x(p);
    const unsigned char *sym = o ? o->sym : NULL;
    const double *r0 = plume_midedge_bending_frames(c->b); /* the rest directors, before any re-basing */
    for (plume_index e = 0; e < c->ne; e++) {
        const int k = edge_held(mesh, group, e) ? -1 : edge_sym_axis(mesh, rest_x, sym, e);
        if (k >= 0 && !(fabs(r0[3 * e + k]) <= 1e-6)) {
            const double off = r0[3 * e + k]; /* read before the term (and its frames) is freed */
            term_free(c);
            return plume_err_set(err, PLUME_EINVAL,
                                 "midedge bending: edge %ld lies on a symmetry plane normal to %c, and its rest director "
                                 "leaves the plane (%c component %.3g): the rest shape is not symmetric there",
                                 (long)e, "xyz"[k], "xyz"[k], off);
        }
    }
    for (plume_index e = 0; e < c->ne; e++) {
        /* a held edge keeps its rest director in its group's frame (theta = 0), or where it starts
         * when its group has no frame (its vertices on one line: a clamped edge); a symmetry edge
         * keeps its rest director, in the plane */
        double th = 0.0;
        const int anchored = edge_held(mesh, group, e) && plume_midedge_term_group_anchored(c, group[mesh->edges[2 * e]]);
        const int on_plane = !edge_held(mesh, group, e) && edge_sym_axis(mesh, rest_x, sym, e) >= 0;
        if (!anchored && !on_plane && start_angle(c, mesh, x, e, &th) != 0) {
            term_free(c);
            return plume_err_set(err, PLUME_EINVAL,
                                 "midedge bending: edge %ld: no start angle (a face collapsed at the start)", (long)e);
        }
        x[c->first + e] = c->L[e] * th;
    }
    for (plume_index e = 0; e < c->ne; e++)
        if ((edge_held(mesh, group, e) || edge_sym_axis(mesh, rest_x, sym, e) >= 0) &&
            (st = plume_problem_fix_dof(p, c->first + e, err)) != PLUME_OK) {
            term_free(c);
            return st;
        }
    plume_term t = {.size = sizeof(plume_term),
                    .name = PLUME_MIDEDGE_TERM_NAME,
                    .arity = 3,
                    .nstencil = c->nt,
                    .stencil = c->stencil,
                    .eval = term_eval,
                    .destroy = term_free,
                    .ctx = c,
                    .energies = term_energies,
                    .partial_projection = 1,
                    .hess_range = term_hess_range,
                    .nextra = 3,
                    .extra = c->extra,
                    .rebase = term_rebase};
    *first = c->first;
    if ((st = plume_problem_add_term(p, &t, err)) == PLUME_OK && term)
        *term = c;
    return st;
}
