#include "periodic.h"

#include <stdlib.h>
#include <string.h>

struct plume_periodic {
    plume_term inner;
    plume_index nv;
    plume_index *stencil;  /* inner stencils mapped to masters */
    const plume_index *master;
    const double *shift;   /* [2 nv], X_v - X_master(v): borrowed copies below */
    plume_index *master_own;
    double *shift_own;
    double Fbar[4];
    double area;
    double *xfull, *gfull; /* [2 nv] scratch: positions of every vertex, their forces */
    int have_forces;
};

static void periodic_destroy(void *ctx)
{
    plume_periodic *h = ctx;
    if (!h)
        return;
    if (h->inner.destroy)
        h->inner.destroy(h->inner.ctx);
    free(h->stencil);
    free(h->master_own);
    free(h->shift_own);
    free(h->xfull);
    free(h->gfull);
    free(h);
}

/* x holds the masters' positions (other entries ignored); the inner term sees every vertex at
 * x_master + Fbar shift. Hessian blocks pass through unchanged (dx_v/dx_master = I); forces fold
 * onto the masters. */
static plume_status periodic_eval(void *ctx, int dim, const double *x, double *energy, double *grad,
                                  double *hblocks, int project)
{
    plume_periodic *h = ctx;
    if (dim != 2)
        return PLUME_EINVAL;
    const double *F = h->Fbar;
    for (plume_index v = 0; v < h->nv; v++) {
        const double *xm = x + 2 * h->master[v], *s = h->shift + 2 * v;
        h->xfull[2 * v] = xm[0] + F[0] * s[0] + F[1] * s[1];
        h->xfull[2 * v + 1] = xm[1] + F[2] * s[0] + F[3] * s[1];
    }
    if (grad)
        memset(h->gfull, 0, (size_t)(2 * h->nv) * sizeof *h->gfull);
    plume_status st = h->inner.eval(h->inner.ctx, 2, h->xfull, energy, grad ? h->gfull : NULL, hblocks, project);
    if (st != PLUME_OK || !grad)
        return st;
    for (plume_index v = 0; v < h->nv; v++) {
        grad[2 * h->master[v]] += h->gfull[2 * v];
        grad[2 * h->master[v] + 1] += h->gfull[2 * v + 1];
    }
    h->have_forces = 1;
    return PLUME_OK;
}

plume_status plume_periodic_term_create(const plume_cell *cell, const plume_term *inner, plume_periodic **handle,
                                        plume_term *out, plume_err *err)
{
    plume_periodic *h = NULL;
    if (!cell || !inner || !handle || !out || !inner->eval) {
        if (inner && inner->destroy)
            inner->destroy(inner->ctx);
        return plume_err_set(err, PLUME_EINVAL, "periodic: invalid arguments");
    }
    *handle = NULL;
    h = calloc(1, sizeof *h);
    if (!h) {
        if (inner->destroy)
            inner->destroy(inner->ctx);
        return PLUME_ENOMEM;
    }
    h->inner = *inner;
    h->nv = cell->mesh->nv;
    size_t ns = (size_t)(inner->nstencil * inner->arity);
    h->stencil = malloc((ns + 1) * sizeof *h->stencil);
    h->master_own = malloc((size_t)h->nv * sizeof *h->master_own);
    h->shift_own = malloc((size_t)(2 * h->nv) * sizeof *h->shift_own);
    h->xfull = malloc((size_t)(2 * h->nv) * sizeof *h->xfull);
    h->gfull = calloc((size_t)(2 * h->nv), sizeof *h->gfull);
    if (!h->stencil || !h->master_own || !h->shift_own || !h->xfull || !h->gfull) {
        periodic_destroy(h);
        return PLUME_ENOMEM;
    }
    memcpy(h->master_own, cell->master, (size_t)h->nv * sizeof *h->master_own);
    memcpy(h->shift_own, cell->shift, (size_t)(2 * h->nv) * sizeof *h->shift_own);
    h->master = h->master_own;
    h->shift = h->shift_own;
    for (size_t i = 0; i < ns; i++) {
        plume_index v = inner->stencil[i];
        if (v < 0 || v >= h->nv) {
            periodic_destroy(h);
            return plume_err_set(err, PLUME_EINVAL, "periodic: term '%s' has vertex %ld outside the cell",
                                 inner->name, (long)v);
        }
        h->stencil[i] = h->master[v];
    }
    h->Fbar[0] = h->Fbar[3] = 1.0;
    h->area = cell->a * cell->b;
    memset(out, 0, sizeof *out);
    out->name = "periodic";
    out->arity = inner->arity;
    out->nstencil = inner->nstencil;
    out->stencil = h->stencil;
    out->size = sizeof *out;
    out->eval = periodic_eval;
    out->destroy = periodic_destroy;
    out->ctx = h;
    *handle = h;
    return PLUME_OK;
}

void plume_periodic_set_macro(plume_periodic *h, const double Fbar[4])
{
    memcpy(h->Fbar, Fbar, sizeof h->Fbar);
}

/* dW/dFbar_ij = sum_v f_v,i s_v,j at fixed masters, which is the total derivative at equilibrium
 * (the masters' forces vanish there), divided by the cell area. */
void plume_periodic_average_stress(const plume_periodic *h, double P[4])
{
    memset(P, 0, 4 * sizeof *P);
    for (plume_index v = 0; v < h->nv; v++) {
        const double *f = h->gfull + 2 * v, *s = h->shift + 2 * v;
        P[0] += f[0] * s[0];
        P[1] += f[0] * s[1];
        P[2] += f[1] * s[0];
        P[3] += f[1] * s[1];
    }
    for (int k = 0; k < 4; k++)
        P[k] /= h->area;
}

void plume_periodic_hold(const plume_cell *cell, plume_problem *p, plume_err *err)
{
    const plume_mesh *m = cell->mesh;
    plume_index anchor = cell->master[0];
    for (plume_index v = 0; v < m->nv; v++)
        if (cell->master[v] == v && m->X[2 * v] == 0.0 && m->X[2 * v + 1] == 0.0)
            anchor = v;
    double *x = plume_problem_x(p);
    memcpy(x, m->X, (size_t)(2 * m->nv) * sizeof *x);
    for (plume_index v = 0; v < m->nv; v++)
        if (cell->master[v] != v || v == anchor) {
            plume_problem_fix_dof(p, 2 * v, err);
            plume_problem_fix_dof(p, 2 * v + 1, err);
        }
}
