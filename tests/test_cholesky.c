/* Tests of lib/cholesky: the supernodal LL^T path lays the matrix out permuted (P M P^T, lower,
 * natural order for CHOLMOD) and scatters each factorisation's values into it; solves must come
 * back in the caller's order. Checked against the matrix itself (residuals), against the LDL^T
 * path (which factorises the upper triangle as given), and after the values change. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "test_rng.h"
#include "../lib/solve/cholesky.h"

/* the upper triangle (CSC, rows sorted) of a 2D grid of nx x ny nodes with 3 dofs each, every dof
 * of a node coupled to every dof of its 8 neighbours: the pattern of a shell mesh's Hessian */
typedef struct {
    plume_index n, *colptr, *rowind;
    double *val;
} upper_csc;

static plume_index dof(int nx, int i, int j, int c)
{
    return 3 * (plume_index)(j * nx + i) + c;
}

static upper_csc grid_pattern(int nx, int ny)
{
    upper_csc a;
    a.n = 3 * (plume_index)nx * ny;
    a.colptr = calloc((size_t)a.n + 1, sizeof *a.colptr);
    a.rowind = malloc((size_t)a.n * 27 * sizeof *a.rowind);
    a.val = malloc((size_t)a.n * 27 * sizeof *a.val);
    plume_index nnz = 0;
    for (plume_index col = 0; col < a.n; col++) {
        int node = (int)(col / 3), i = node % nx, j = node / nx;
        /* rows <= col among the neighbours' dofs, in increasing order */
        plume_index rows[27];
        int nr = 0;
        for (int jj = j - 1; jj <= j + 1; jj++)
            for (int ii = i - 1; ii <= i + 1; ii++) {
                if (ii < 0 || jj < 0 || ii >= nx || jj >= ny)
                    continue;
                for (int c = 0; c < 3; c++) {
                    plume_index r = dof(nx, ii, jj, c);
                    if (r <= col)
                        rows[nr++] = r;
                }
            }
        for (int k = 0; k < nr; k++) /* already increasing: nodes by (j, i), dofs by c */
            a.rowind[nnz++] = rows[k];
        a.colptr[col + 1] = nnz;
    }
    return a;
}

/* values: a diagonally dominant SPD matrix whose off-diagonal entries depend on seed */
static void grid_values(upper_csc *a, uint64_t seed, double diag)
{
    rng64 r = {seed};
    for (plume_index col = 0; col < a->n; col++)
        for (plume_index k = a->colptr[col]; k < a->colptr[col + 1]; k++)
            a->val[k] = a->rowind[k] == col ? diag : urange(&r, -1.0, -0.5);
}

static double residual(const upper_csc *a, const double *x, const double *b, double shift)
{
    double *r = malloc((size_t)a->n * sizeof *r);
    double rm = 0.0, bm = 0.0;
    for (plume_index i = 0; i < a->n; i++)
        r[i] = b[i] - shift * x[i];
    for (plume_index col = 0; col < a->n; col++)
        for (plume_index k = a->colptr[col]; k < a->colptr[col + 1]; k++) {
            plume_index row = a->rowind[k];
            r[row] -= a->val[k] * x[col];
            if (row != col)
                r[col] -= a->val[k] * x[row];
        }
    for (plume_index i = 0; i < a->n; i++) {
        rm = fmax(rm, fabs(r[i]));
        bm = fmax(bm, fabs(b[i]));
    }
    free(r);
    return rm / bm;
}

void test_cholesky_permuted_solves(void)
{
    upper_csc a = grid_pattern(23, 17);
    plume_chol *ll = NULL, *ldl = NULL;
    plume_err err = {{0}};
    CHECK(plume_chol_create(a.n, a.colptr, a.rowind, 0, &ll, &err) == PLUME_OK);
    CHECK(plume_chol_create(a.n, a.colptr, a.rowind, 1, &ldl, &err) == PLUME_OK);
    double *b = malloc((size_t)a.n * sizeof *b), *x = malloc((size_t)a.n * sizeof *x);
    double *y = malloc((size_t)a.n * sizeof *y);
    for (plume_index i = 0; i < a.n; i++)
        b[i] = sin(0.37 * (double)i) + (double)(i % 7);
    /* two factorisations with other values (and a shift): each solve is of its own matrix */
    for (int round = 0; round < 2 && ll && ldl; round++) {
        double shift = round ? 0.5 : 0.0;
        grid_values(&a, 0x9E3779B97F4A7C15ULL + (uint64_t)round, 40.0 + 10.0 * round);
        CHECK(plume_chol_factor(ll, a.val, shift) == PLUME_OK);
        CHECK(plume_chol_factor(ldl, a.val, shift) == PLUME_OK);
        CHECK(plume_chol_solve(ll, b, x) == PLUME_OK);
        CHECK(plume_chol_solve(ldl, b, y) == PLUME_OK);
        double rll = residual(&a, x, b, shift), rldl = residual(&a, y, b, shift), dmax = 0.0, xmax = 0.0;
        for (plume_index i = 0; i < a.n; i++) {
            dmax = fmax(dmax, fabs(x[i] - y[i]));
            xmax = fmax(xmax, fabs(y[i]));
        }
        fprintf(stderr, "    n %ld, round %d: residual LL^T %.1e, LDL^T %.1e, |x_LL - x_LDL| / |x| %.1e\n",
                (long)a.n, round, rll, rldl, dmax / xmax);
        CHECK(rll <= 1e-13 && rldl <= 1e-13);
        CHECK(dmax <= 1e-12 * xmax);
    }
    /* not positive definite: LL^T says so */
    if (ll) {
        a.val[a.colptr[a.n / 2 + 1] - 1] = -1e3; /* one negative diagonal entry */
        CHECK(plume_chol_factor(ll, a.val, 0.0) == PLUME_ESINGULAR);
        double rc = plume_chol_rcond(ll);
        CHECK(rc == 0.0 || isfinite(rc));
    }
    int analyses = 0, factorizations = 0;
    plume_chol_stats(ll, &analyses, &factorizations, NULL);
    CHECK(analyses == 1 && factorizations == 3);
    plume_chol_destroy(&ll);
    plume_chol_destroy(&ldl);
    CHECK(ll == NULL && ldl == NULL);
    free(b);
    free(x);
    free(y);
    free(a.colptr);
    free(a.rowind);
    free(a.val);
}
