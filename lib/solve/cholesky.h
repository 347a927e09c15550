/** \file
 * plume: sparse symmetric factorisation with CHOLMOD — symbolic analysis once per pattern,
 * numeric factorisation every iteration (LL^T for positive definite systems, simplicial LDL^T
 * for quasi-definite KKT systems). */
#ifndef PLUME_CHOLESKY_H
#define PLUME_CHOLESKY_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque CHOLMOD factorisation of one sparsity pattern: the matrix, its factor and workspaces
 * (plume_chol_create, freed by plume_chol_destroy). */
typedef struct plume_chol plume_chol;

/** Analyses the n x n symmetric pattern given by its upper triangle in CSC (copied; rows sorted).
 * ldl = 0: supernodal LL^T (matrix must be positive definite); 1: simplicial LDL^T without
 * pivoting, valid for quasi-definite matrices [H J^T; J -D] with H, D positive definite. */
plume_status plume_chol_create(plume_index n, const plume_index *colptr, const plume_index *rowind,
                                         int ldl, plume_chol **out, plume_err *err);
/** Frees the factor and the CHOLMOD workspace; sets *c = NULL; NULL-safe. */
void plume_chol_destroy(plume_chol **c);

/** Numeric factorisation of the matrix with these values (same order as rowind) plus shift*I.
 * PLUME_ESINGULAR when LL^T finds the matrix not positive definite or a pivot is zero/non-finite. */
plume_status plume_chol_factor(plume_chol *c, const double *values, double shift);

/** x = A^-1 b with the last factorisation; no allocation after the first call. */
plume_status plume_chol_solve(plume_chol *c, const double *b, double *x);

/** Reciprocal condition estimate of the last factorisation, (min diag L / max diag L)^2 for LL^T
 * (CHOLMOD's cholmod_rcond: cheap, a rough lower-bound-like estimate); 0 when singular. */
double plume_chol_rcond(plume_chol *c);

/** The factor's entries (nnz(L) without the supernodes' relaxed zeros) and flops of one
 * factorisation, from CHOLMOD's analysis of the ordering kept (benchmarks). */
void plume_chol_counts(const plume_chol *c, double *lnz, double *flops);

/** Counts and time of factorisations since creation (benchmarks and reports). */
void plume_chol_stats(const plume_chol *c, int *analyses, int *factorizations, double *factor_seconds);

#ifdef __cplusplus
}
#endif
#endif
