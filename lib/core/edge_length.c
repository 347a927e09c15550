#include "edge_length.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    plume_index m;
    plume_index *edges;
    double *rest2; /* L^2, also the scale */
} edge_ctx;

static void edge_destroy(void *ctx)
{
    edge_ctx *c = ctx;
    if (!c)
        return;
    free(c->edges);
    free(c->rest2);
    free(c);
}

static plume_status edge_eval(void *ctx, int dim, const double *x, double *g, double *jac)
{
    const edge_ctx *c = ctx;
    for (plume_index e = 0; e < c->m; e++) {
        const double *a = x + dim * c->edges[2 * e], *b = x + dim * c->edges[2 * e + 1];
        double s = 0.0;
        for (int k = 0; k < dim; k++) {
            double dk = a[k] - b[k];
            s += dk * dk;
            if (jac) {
                jac[2 * dim * e + k] = 2.0 * dk;
                jac[2 * dim * e + dim + k] = -2.0 * dk;
            }
        }
        if (g)
            g[e] = s - c->rest2[e];
    }
    return PLUME_OK;
}

/* Hess(lambda g) = 2 lambda [I -I; -I I]; its eigenvalues are 4 lambda and 0, so the PSD
 * projection is the same block with lambda clamped at 0. */
static plume_status edge_hess(void *ctx, int dim, const double *x, const double *lambda,
                              double *hblocks, int project)
{
    (void)x;
    const edge_ctx *c = ctx;
    int k = 2 * dim;
    for (plume_index e = 0; e < c->m; e++) {
        double l = lambda[e];
        if (project && l < 0.0)
            l = 0.0;
        double *h = hblocks + (size_t)e * k * k;
        memset(h, 0, (size_t)k * k * sizeof *h);
        for (int i = 0; i < dim; i++) {
            h[i * k + i] = h[(dim + i) * k + dim + i] = 2.0 * l;
            h[i * k + dim + i] = h[(dim + i) * k + i] = -2.0 * l;
        }
    }
    return PLUME_OK;
}

plume_status plume_edge_length_create(const plume_index *edges, plume_index n, const double *X,
                                      plume_index nv, plume_constraint *out, plume_err *err)
{
    if (!out || n < 0 || (n && (!edges || !X)))
        return plume_err_set(err, PLUME_EINVAL, "edge-length constraint: invalid arguments");
    edge_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->m = n;
    c->edges = malloc((size_t)(2 * n + 1) * sizeof *c->edges);
    c->rest2 = malloc((size_t)(n + 1) * sizeof *c->rest2);
    if (!c->edges || !c->rest2) {
        edge_destroy(c);
        return PLUME_ENOMEM;
    }
    for (plume_index e = 0; e < n; e++) {
        plume_index i = edges[2 * e], j = edges[2 * e + 1];
        if (i < 0 || j < 0 || i >= nv || j >= nv || i == j) {
            edge_destroy(c);
            return plume_err_set(err, PLUME_EINVAL, "edge-length constraint %ld: bad vertex pair (%ld, %ld)",
                                 (long)e, (long)i, (long)j);
        }
        double dx = X[2 * i] - X[2 * j], dy = X[2 * i + 1] - X[2 * j + 1];
        c->edges[2 * e] = i;
        c->edges[2 * e + 1] = j;
        c->rest2[e] = dx * dx + dy * dy;
        if (!(c->rest2[e] > 0.0)) {
            edge_destroy(c);
            return plume_err_set(err, PLUME_EINVAL, "edge-length constraint %ld: zero rest length", (long)e);
        }
    }
    memset(out, 0, sizeof *out);
    out->name = "edge length";
    out->arity = 2;
    out->m = n;
    out->stencil = c->edges;
    out->scale = c->rest2;
    out->size = sizeof *out;
    out->eval = edge_eval;
    out->hess = edge_hess;
    out->partial_projection = 1; /* lambda clamped at 0: a compressed edge's sideways curvature dropped */
    out->destroy = edge_destroy;
    out->ctx = c;
    return PLUME_OK;
}
