/* Finite-difference checks of a shell-mode (dim 3) energy term over a whole mesh, shared by the
 * bending tests (tests/test_bending.c, tests/test_shape_bending.c). Header-only, static inline. */
#ifndef PLUME_TEST_TERM_FD_H
#define PLUME_TEST_TERM_FD_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../lib/core/term.h"

static inline double term_max_abs(const double *a, long n)
{
    double m = 0.0;
    for (long i = 0; i < n; i++)
        if (fabs(a[i]) > m)
            m = fabs(a[i]);
    return m;
}

/* Scatters the term's stencil blocks (any arity) into a dense Hessian (3 nv square). */
static inline void term_dense_hessian(const plume_term *t, plume_index nv, const double *blocks, double *H)
{
    const long n = 3 * (long)nv;
    memset(H, 0, sizeof(double) * (size_t)(n * n));
    for (plume_index s = 0; s < t->nstencil; s++) {
        const int ar = t->arity, ka = 3 * ar;
        const plume_index *v = t->stencil + (size_t)ar * s;
        const double *B = blocks + (size_t)s * (size_t)(ka * ka);
        for (int a = 0; a < ar; a++)
            for (int b = 0; b < ar; b++)
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++)
                        H[(3 * v[a] + i) * n + 3 * v[b] + j] += B[(3 * a + i) * ka + 3 * b + j];
    }
}

/* Central differences of the whole term: gradient against energy, Hessian against gradient,
 * errors relative to the largest entry of each; a failure is counted (and printed with `what`). */
static inline void term_fd_check(const plume_term *t, plume_index nv, double *x, double step, double tol,
                                 const char *what)
{
    const long n = 3 * (long)nv;
    double *g = calloc((size_t)n, sizeof *g), *gp = calloc((size_t)n, sizeof *gp);
    double *gm = calloc((size_t)n, sizeof *gm);
    double *blocks = malloc(sizeof(double) * (size_t)(9 * t->arity * t->arity) * (size_t)(t->nstencil + 1));
    double *H = malloc(sizeof(double) * (size_t)(n * n));
    CHECK(g && gp && gm && blocks && H);
    if (!g || !gp || !gm || !blocks || !H)
        goto done;
    double E = 0.0;
    CHECK(t->eval(t->ctx, 3, x, &E, g, blocks, 0) == PLUME_OK);
    term_dense_hessian(t, nv, blocks, H);
    const double gs = term_max_abs(g, n), hs = term_max_abs(H, n * n);
    double gerr = 0.0, herr = 0.0;
    for (long i = 0; i < n; i++) {
        const double xi = x[i];
        double Ep = 0.0, Em = 0.0;
        memset(gp, 0, sizeof(double) * (size_t)n);
        memset(gm, 0, sizeof(double) * (size_t)n);
        x[i] = xi + step;
        CHECK(t->eval(t->ctx, 3, x, &Ep, gp, NULL, 0) == PLUME_OK);
        x[i] = xi - step;
        CHECK(t->eval(t->ctx, 3, x, &Em, gm, NULL, 0) == PLUME_OK);
        x[i] = xi;
        gerr = fmax(gerr, fabs((Ep - Em) / (2.0 * step) - g[i]));
        for (long j = 0; j < n; j++)
            herr = fmax(herr, fabs((gp[j] - gm[j]) / (2.0 * step) - H[j * n + i]));
    }
    fprintf(stderr, "    FD %-40s gradient error %.2e of %.2e, Hessian %.2e of %.2e\n", what, gerr, gs, herr, hs);
    if (!(gerr <= tol * gs) || !(herr <= tol * hs) || !(gs > 0.0) || !(hs > 0.0)) {
        plume_test_failures++;
        fprintf(stderr, "    FD failed (%s)\n", what);
    }
done:
    free(g);
    free(gp);
    free(gm);
    free(blocks);
    free(H);
}

#endif
