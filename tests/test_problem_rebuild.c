/* A problem whose changing term's stencils change (contact pairs) rebuilds its Hessian pattern and
 * moves the fixed stencils' scatter maps instead of searching the pattern again: after every
 * change, the assembled Hessian must equal the one of a problem built from scratch with the same
 * stencils. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../lib/core/problem.h"
#include "test_rng.h"

enum { NV = 40, NFIXED_PAIRS = 60, NCHANGING = 12, NSETS = 4 };

/* 1/2 k_s |x_i - x_j|^2 over pairs, with a stiffness per pair (a misplaced block shows) */
typedef struct {
    plume_index n;
    plume_index pairs[2 * NFIXED_PAIRS];
    double k[NFIXED_PAIRS];
    /* the changing term: NSETS sets of NCHANGING pairs, `set` the current one */
    plume_index sets[NSETS][2 * NCHANGING];
    int set;
} springs;

static plume_status springs_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *h,
                                 int project)
{
    (void)project;
    const springs *c = ctx;
    const plume_index *pairs = c->n == NCHANGING ? c->sets[c->set] : c->pairs;
    for (plume_index s = 0; s < c->n; s++) {
        plume_index i = pairs[2 * s], j = pairs[2 * s + 1];
        double k = c->k[s % NFIXED_PAIRS];
        for (int a = 0; a < dim; a++) {
            double d = x[dim * i + a] - x[dim * j + a];
            if (energy)
                *energy += 0.5 * k * d * d;
            if (grad) {
                grad[dim * i + a] += k * d;
                grad[dim * j + a] -= k * d;
            }
        }
        if (h) {
            double *b = h + (size_t)s * 36;
            memset(b, 0, 36 * sizeof *b);
            for (int a = 0; a < 3; a++) {
                b[6 * a + a] = b[6 * (a + 3) + a + 3] = k;
                b[6 * a + a + 3] = b[6 * (a + 3) + a] = -k;
            }
        }
    }
    return PLUME_OK;
}

static plume_status springs_update(void *ctx, int dim, const double *x, const plume_index **stencil,
                                   plume_index *nstencil, int *changed)
{
    (void)dim;
    (void)x;
    springs *c = ctx;
    c->set = (c->set + 1) % NSETS;
    *stencil = c->sets[c->set];
    *nstencil = NCHANGING;
    *changed = 1;
    return PLUME_OK;
}

/* |x_i - x_j|^2 - 1 over a few fixed pairs (a constraint set's scatter maps move too) */
static const plume_index CPAIRS[6] = {0, 1, 5, 9, 20, 33};
static const double CSCALE[3] = {1.0, 1.0, 1.0};

static plume_status cons_eval(void *ctx, int dim, const double *x, double *g, double *jac)
{
    (void)ctx;
    for (int s = 0; s < 3; s++) {
        plume_index i = CPAIRS[2 * s], j = CPAIRS[2 * s + 1];
        g[s] = -1.0;
        for (int a = 0; a < dim; a++) {
            double d = x[dim * i + a] - x[dim * j + a];
            g[s] += d * d;
            if (jac)
                jac[s * 2 * dim + a] = 2.0 * d, jac[s * 2 * dim + dim + a] = -2.0 * d;
        }
    }
    return PLUME_OK;
}

static plume_status cons_hess(void *ctx, int dim, const double *x, const double *lambda, double *h, int project)
{
    (void)ctx;
    (void)x;
    (void)project;
    for (int s = 0; s < 3; s++) {
        double *b = h + (size_t)s * 36, l = 2.0 * lambda[s];
        memset(b, 0, 36 * sizeof *b);
        for (int a = 0; a < dim; a++) {
            b[6 * a + a] = b[6 * (a + 3) + a + 3] = l;
            b[6 * a + a + 3] = b[6 * (a + 3) + a] = -l;
        }
    }
    return PLUME_OK;
}

/* the problem: fixed springs, the constraint set, and the changing springs (with an update, or
 * frozen at `frozen`'s current set when frozen is non-NULL); vertices 3 and 17 held */
static plume_problem *build(springs *fixed, springs *changing, int with_update)
{
    plume_problem *p = NULL;
    CHECK(plume_problem_create(NV, 3, 1.0, &p, NULL) == PLUME_OK);
    if (!p)
        return NULL;
    plume_term tf = {.size = sizeof(plume_term), .name = "fixed", .arity = 2, .nstencil = fixed->n, .stencil = fixed->pairs, .eval = springs_eval,
                     .ctx = fixed};
    plume_term tc = {.size = sizeof(plume_term), .name = "changing", .arity = 2, .nstencil = NCHANGING, .stencil = changing->sets[changing->set],
                     .eval = springs_eval, .ctx = changing, .update = with_update ? springs_update : NULL};
    plume_constraint c = {.size = sizeof(plume_constraint), .name = "lengths", .arity = 2, .m = 3, .stencil = CPAIRS, .scale = CSCALE,
                          .eval = cons_eval, .hess = cons_hess};
    CHECK(plume_problem_add_term(p, &tc, NULL) == PLUME_OK && plume_problem_add_term(p, &tf, NULL) == PLUME_OK &&
          plume_problem_add_constraint(p, &c, NULL) == PLUME_OK);
    for (int a = 0; a < 3; a++)
        CHECK(plume_problem_fix_dof(p, 3 * 3 + a, NULL) == PLUME_OK && plume_problem_fix_dof(p, 3 * 17 + a, NULL) == PLUME_OK);
    double *x = plume_problem_x(p);
    rng64 s = {7};
    for (plume_index i = 0; i < 3 * NV; i++)
        x[i] = urand(&s);
    plume_err err;
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
    return p;
}

/* the Hessian of p at its x with multipliers lam, dense (nfree x nfree, both triangles) */
static double *dense_hessian(plume_problem *p, const double *lam)
{
    plume_sparsity sp = plume_problem_hessian_pattern(p);
    plume_index n = plume_problem_nfree(p);
    double *v = calloc((size_t)sp.nnz + 1, sizeof *v), *H = calloc((size_t)(n * n), sizeof *H);
    double *u = malloc((size_t)n * sizeof *u);
    plume_problem_gather(p, u);
    CHECK(plume_problem_hessian(p, u, 1.0, lam, PLUME_HESSIAN_EXACT, v) == PLUME_OK);
    for (plume_index c = 0; c < n; c++)
        for (plume_index k = sp.colptr[c]; k < sp.colptr[c + 1]; k++)
            H[sp.rowind[k] * n + c] = H[c * n + sp.rowind[k]] = v[k];
    free(v);
    free(u);
    return H;
}

void test_problem_rebuild_moves_fixed_maps(void)
{
    springs fixed = {.n = NFIXED_PAIRS}, changing = {.n = NCHANGING};
    rng64 s = {11};
    for (int q = 0; q < NFIXED_PAIRS; q++) {
        fixed.pairs[2 * q] = q % NV;
        fixed.pairs[2 * q + 1] = (q + 1 + q / NV * 7) % NV;
        fixed.k[q] = changing.k[q] = 1.0 + q + urand(&s);
    }
    for (int t = 0; t < NSETS; t++)
        for (int q = 0; q < NCHANGING; q++) { /* far pairs: entries the fixed part does not have */
            changing.sets[t][2 * q] = (plume_index)(urand(&s) * NV) % NV;
            changing.sets[t][2 * q + 1] = (changing.sets[t][2 * q] + 11 + t * 3 + q) % NV;
        }
    plume_problem *p = build(&fixed, &changing, 1);
    if (!p)
        return;
    const double lam[3] = {0.3, -1.1, 2.0};
    plume_index n = plume_problem_nfree(p);
    double worst = 0.0;
    for (int round = 0; round < 2 * NSETS; round++) {
        int changed = 0;
        plume_err err;
        CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed);
        springs frozen = changing; /* the same current set, in a problem built from scratch */
        plume_problem *q = build(&fixed, &frozen, 0);
        if (!q)
            break;
        memcpy(plume_problem_x(q), plume_problem_x(p), 3 * NV * sizeof(double));
        CHECK(plume_problem_hessian_pattern(q).nnz == plume_problem_hessian_pattern(p).nnz);
        double *A = dense_hessian(p, lam), *B = dense_hessian(q, lam);
        for (plume_index i = 0; i < n * n; i++)
            worst = fmax(worst, fabs(A[i] - B[i]));
        free(A);
        free(B);
        plume_problem_destroy(&q);
    }
    fprintf(stderr, "    %d rebuilds: largest difference from a fresh build %.3g\n", 2 * NSETS, worst);
    CHECK(worst == 0.0);
    plume_problem_destroy(&p);
}
