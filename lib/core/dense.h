/** \file
 * plume: small dense symmetric kernels for per-element blocks (eigen-decomposition, projection of
 * a Hessian block to the nearest positive semidefinite matrix). Sizes are those of one stencil
 * (a few to a few dozen rows); nothing here allocates. */
#ifndef PLUME_DENSE_H
#define PLUME_DENSE_H

#include "export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest n plume_dense_project_psd handles with its internal stack workspace (8 shell vertices);
 * larger blocks go through plume_dense_project_psd_work with a caller workspace. */
#define PLUME_DENSE_MAX_N 24

/** Eigen-decomposition of a symmetric n x n matrix by cyclic Jacobi rotations (accurate to a few
 * ulps of the largest eigenvalue). A: row-major, only the upper triangle is read; destroyed.
 * evals[n]: eigenvalues in ascending order. evecs[n*n]: row-major, column k is the unit
 * eigenvector of evals[k] (evecs[i*n + k] = component i). */
void plume_dense_sym_eig(int n, double *A, double *evals, double *evecs);

/** Replaces the symmetric n x n row-major matrix A (upper triangle read, full matrix written) by its
 * projection onto the positive semidefinite cone: negative eigenvalues clamped to 0. A matrix that
 * is already positive semidefinite is left unchanged (bit for bit when it was stored symmetric;
 * otherwise its lower triangle is mirrored from the upper one). Requires n <= PLUME_DENSE_MAX_N;
 * a larger n is a programming error and fills A with NaN so that it cannot pass unnoticed. */
void plume_dense_project_psd(int n, double *A);

/** The same for any n, with a caller workspace `work` of 2*n*n + n doubles. */
void plume_dense_project_psd_work(int n, double *A, double *work);

#ifdef __cplusplus
}
#endif
#endif
