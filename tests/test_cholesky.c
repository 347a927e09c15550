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
#include "../lib/solve/internal/cholesky_like.h"

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

/* a copy of a with node 0's dofs coupled to the last node's (rows 0..2 added to its 3 columns):
 * the pattern a contact pair between two far vertices adds */
static upper_csc with_far_pair(const upper_csc *a)
{
    upper_csc b;
    b.n = a->n;
    b.colptr = calloc((size_t)b.n + 1, sizeof *b.colptr);
    b.rowind = malloc(((size_t)a->colptr[a->n] + 9) * sizeof *b.rowind);
    b.val = malloc(((size_t)a->colptr[a->n] + 9) * sizeof *b.val);
    plume_index nnz = 0;
    for (plume_index col = 0; col < b.n; col++) {
        if (col >= b.n - 3)
            for (plume_index r = 0; r < 3; r++)
                b.rowind[nnz++] = r;
        for (plume_index k = a->colptr[col]; k < a->colptr[col + 1]; k++)
            b.rowind[nnz++] = a->rowind[k];
        b.colptr[col + 1] = nnz;
    }
    return b;
}

/* plume_chol_create_like: a pattern that grew by a far pair, analysed in the base pattern's order
 * (found here, then taken from the first factorisation), a denser one (every node coupled to its
 * 2-ring), whose fill sends it back to AMD and METIS, and the base pattern itself: each
 * factorises and solves its own matrix, and the base pattern's factorisation is the one
 * plume_chol_create makes (the same solution bit for bit). */
void test_cholesky_create_like(void)
{
    upper_csc a = grid_pattern(23, 17), b = with_far_pair(&a);
    plume_chol *first = NULL, *next = NULL, *self = NULL, *plain = NULL;
    CHECK(plume_chol_create_like(b.n, b.colptr, b.rowind, 0, a.colptr, a.rowind, NULL, &first, NULL) == PLUME_OK);
    CHECK(plume_chol_create_like(b.n, b.colptr, b.rowind, 0, a.colptr, a.rowind, first, &next, NULL) == PLUME_OK);
    CHECK(plume_chol_create_like(a.n, a.colptr, a.rowind, 0, a.colptr, a.rowind, first, &self, NULL) == PLUME_OK);
    CHECK(plume_chol_create(a.n, a.colptr, a.rowind, 0, &plain, NULL) == PLUME_OK);
    double *rhs = malloc((size_t)b.n * sizeof *rhs), *x = malloc((size_t)b.n * sizeof *x);
    double *y = malloc((size_t)b.n * sizeof *y);
    for (plume_index i = 0; i < b.n; i++)
        rhs[i] = cos(0.21 * (double)i) + (double)(i % 5);
    if (first && next && self && plain) {
        grid_values(&b, 0x5851F42D4C957F2DULL, 50.0);
        CHECK(plume_chol_factor(first, b.val, 0.0) == PLUME_OK);
        CHECK(plume_chol_solve(first, rhs, x) == PLUME_OK);
        CHECK(residual(&b, x, rhs, 0.0) <= 1e-13);
        CHECK(plume_chol_factor(next, b.val, 0.0) == PLUME_OK);
        CHECK(plume_chol_solve(next, rhs, y) == PLUME_OK);
        CHECK(memcmp(x, y, (size_t)b.n * sizeof *x) == 0); /* the same order, however it came */
        grid_values(&a, 0x14057B7EF767814FULL, 50.0);
        CHECK(plume_chol_factor(self, a.val, 0.25) == PLUME_OK && plume_chol_factor(plain, a.val, 0.25) == PLUME_OK);
        CHECK(plume_chol_solve(self, rhs, x) == PLUME_OK && plume_chol_solve(plain, rhs, y) == PLUME_OK);
        CHECK(residual(&a, x, rhs, 0.25) <= 1e-13);
        CHECK(memcmp(x, y, (size_t)a.n * sizeof *x) == 0);
    }
    /* the denser pattern: a 5 x 5 stencil per node */
    upper_csc d;
    d.n = a.n;
    d.colptr = calloc((size_t)d.n + 1, sizeof *d.colptr);
    d.rowind = malloc((size_t)d.n * 75 * sizeof *d.rowind);
    d.val = malloc((size_t)d.n * 75 * sizeof *d.val);
    plume_index nnz = 0;
    for (plume_index col = 0; col < d.n; col++) {
        int node = (int)(col / 3), i = node % 23, j = node / 23;
        for (int jj = j - 2; jj <= j + 2; jj++)
            for (int ii = i - 2; ii <= i + 2; ii++)
                for (int q = 0; q < 3 && ii >= 0 && jj >= 0 && ii < 23 && jj < 17; q++)
                    if (dof(23, ii, jj, q) <= col)
                        d.rowind[nnz++] = dof(23, ii, jj, q);
        d.colptr[col + 1] = nnz;
    }
    plume_chol *dense = NULL;
    CHECK(plume_chol_create_like(d.n, d.colptr, d.rowind, 0, a.colptr, a.rowind, first, &dense, NULL) == PLUME_OK);
    if (dense) {
        grid_values(&d, 0x2545F4914F6CDD1DULL, 90.0);
        CHECK(plume_chol_factor(dense, d.val, 0.0) == PLUME_OK);
        CHECK(plume_chol_solve(dense, rhs, x) == PLUME_OK);
        CHECK(residual(&d, x, rhs, 0.0) <= 1e-13);
    }
    CHECK(plume_chol_create_like(0, a.colptr, a.rowind, 0, NULL, NULL, NULL, &dense, NULL) == PLUME_EINVAL);
    plume_chol_destroy(&first);
    plume_chol_destroy(&next);
    plume_chol_destroy(&self);
    plume_chol_destroy(&plain);
    plume_chol_destroy(&dense);
    free(rhs);
    free(x);
    free(y);
    upper_csc *all[3] = {&a, &b, &d};
    for (int k = 0; k < 3; k++) {
        free(all[k]->colptr);
        free(all[k]->rowind);
        free(all[k]->val);
    }
}
