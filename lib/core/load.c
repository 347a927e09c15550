#include "load.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    plume_index n;
    int dim;
    plume_index *v;
    double *f, *f0; /* current and nominal forces */
} load_ctx;

static void load_destroy(void *ctx)
{
    load_ctx *c = ctx;
    if (!c)
        return;
    free(c->v);
    free(c->f);
    free(c->f0);
    free(c);
}

static plume_status load_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                              int project)
{
    (void)project;
    const load_ctx *c = ctx;
    if (dim != c->dim)
        return PLUME_EINVAL;
    for (plume_index k = 0; k < c->n; k++)
        for (int a = 0; a < dim; a++) {
            if (energy)
                *energy -= c->f[dim * k + a] * x[dim * c->v[k] + a];
            if (grad)
                grad[dim * c->v[k] + a] -= c->f[dim * k + a];
        }
    if (hblocks)
        memset(hblocks, 0, (size_t)(c->n * dim * dim) * sizeof *hblocks);
    return PLUME_OK;
}

plume_status plume_load_term_create(const plume_index *vertices, plume_index n, int dim, const double *forces,
                                    plume_term *out, plume_err *err)
{
    if (!out || n < 1 || !vertices || !forces || (dim != 2 && dim != 3))
        return plume_err_set(err, PLUME_EINVAL, "load: needs at least one vertex, its forces and dim 2 or 3");
    for (plume_index k = 0; k < n * dim; k++)
        if (!isfinite(forces[k]))
            return plume_err_set(err, PLUME_EINVAL, "load: force %ld is not finite", (long)(k / dim));
    load_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->n = n;
    c->dim = dim;
    c->v = malloc((size_t)n * sizeof *c->v);
    c->f = malloc((size_t)(n * dim) * sizeof *c->f);
    c->f0 = malloc((size_t)(n * dim) * sizeof *c->f0);
    if (!c->v || !c->f || !c->f0) {
        load_destroy(c);
        return PLUME_ENOMEM;
    }
    memcpy(c->v, vertices, (size_t)n * sizeof *c->v);
    memcpy(c->f, forces, (size_t)(n * dim) * sizeof *c->f);
    memcpy(c->f0, forces, (size_t)(n * dim) * sizeof *c->f0);
    memset(out, 0, sizeof *out);
    out->name = "load";
    out->arity = 1;
    out->nstencil = n;
    out->stencil = c->v;
    out->size = sizeof *out;
    out->eval = load_eval;
    out->destroy = load_destroy;
    out->ctx = c;
    return PLUME_OK;
}

void plume_load_scale(plume_term *load, double factor)
{
    load_ctx *c = load->ctx;
    for (plume_index k = 0; k < c->n * c->dim; k++)
        c->f[k] = factor * c->f0[k];
}
