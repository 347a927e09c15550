#include "dense.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Jacobi converges quadratically: 4-6 sweeps for the sizes used here. The cap only guards against
 * a non-finite input, which never lets the off-diagonal part fall below the threshold. */
#define JACOBI_MAX_SWEEPS 64

void plume_dense_sym_eig(int n, double *A, double *evals, double *evecs)
{
    if (n <= 0)
        return;
    /* mirror the upper triangle so the rotations can work on full storage */
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++)
            A[i * n + j] = A[j * n + i];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            evecs[i * n + j] = i == j ? 1.0 : 0.0;

    /* Off-diagonal entries below eps ||A||_F / n are dropped: together they move no eigenvalue
     * by more than eps ||A||_F (Weyl), i.e. rounding level, and rotating them away would cost
     * a whole extra sweep. */
    double norm2 = 0.0;
    for (int i = 0; i < n * n; i++)
        norm2 += A[i] * A[i];
    const double tol = DBL_EPSILON * sqrt(norm2) / n;
    if (!isfinite(tol)) /* non-finite input: no rotation makes sense */
        goto done;

    for (int sweep = 0; sweep < JACOBI_MAX_SWEEPS; sweep++) {
        int rotated = 0;
        for (int p = 0; p < n; p++) {
            for (int q = p + 1; q < n; q++) {
                double apq = A[p * n + q];
                if (fabs(apq) <= tol)
                    continue;
                rotated = 1;
                double app = A[p * n + p], aqq = A[q * n + q];
                double theta = (aqq - app) / (2.0 * apq);
                double t;
                if (fabs(theta) > 1e150) /* theta^2 would overflow: t ~ 1/(2 theta) */
                    t = 0.5 / theta;
                else
                    t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                /* A <- P^T A P with P the rotation in the (p, q) plane, rows and columns p, q
                 * updated together to keep A exactly symmetric; V <- V P */
                for (int k = 0; k < n; k++) {
                    if (k == p || k == q)
                        continue;
                    double akp = A[k * n + p], akq = A[k * n + q];
                    A[k * n + p] = A[p * n + k] = c * akp - s * akq;
                    A[k * n + q] = A[q * n + k] = s * akp + c * akq;
                }
                /* the 2x2 pivot block in closed form (exact zero off the diagonal) */
                A[p * n + p] = app - t * apq;
                A[q * n + q] = aqq + t * apq;
                A[p * n + q] = A[q * n + p] = 0.0;
                for (int k = 0; k < n; k++) {
                    double vkp = evecs[k * n + p], vkq = evecs[k * n + q];
                    evecs[k * n + p] = c * vkp - s * vkq;
                    evecs[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
        if (!rotated)
            break;
    }
done:
    for (int i = 0; i < n; i++)
        evals[i] = A[i * n + i];
    /* selection sort, ascending, carrying the eigenvector columns along (n is small) */
    for (int i = 0; i < n - 1; i++) {
        int m = i;
        for (int j = i + 1; j < n; j++)
            if (evals[j] < evals[m])
                m = j;
        if (m != i) {
            double tmp = evals[i];
            evals[i] = evals[m];
            evals[m] = tmp;
            for (int k = 0; k < n; k++) {
                tmp = evecs[k * n + i];
                evecs[k * n + i] = evecs[k * n + m];
                evecs[k * n + m] = tmp;
            }
        }
    }
}

/* 1 if the symmetric matrix (upper triangle of A) is positive definite: an in-place Cholesky
 * factorisation of the copy L succeeds with positive pivots. Much cheaper than the
 * eigen-decomposition, and most element blocks of a stretched membrane pass it. */
static int is_positive_definite(int n, const double *A, double *L)
{
    for (int i = 0; i < n; i++)
        for (int j = i; j < n; j++)
            L[j * n + i] = A[i * n + j]; /* lower triangle of L <- upper of A */
    for (int j = 0; j < n; j++) {
        double d = L[j * n + j];
        for (int k = 0; k < j; k++)
            d -= L[j * n + k] * L[j * n + k];
        if (!(d > 0.0))
            return 0;
        d = sqrt(d);
        L[j * n + j] = d;
        for (int i = j + 1; i < n; i++) {
            double s = L[i * n + j];
            for (int k = 0; k < j; k++)
                s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s / d;
        }
    }
    return 1;
}

void plume_dense_project_psd_work(int n, double *A, double *work)
{
    if (n <= 0)
        return;
    double *M = work, *V = work + (size_t)n * n, *lam = work + 2 * (size_t)n * n;
    if (is_positive_definite(n, A, M)) {
        /* leave A as it is, but make it exactly symmetric like the projected case */
        for (int i = 0; i < n; i++)
            for (int j = 0; j < i; j++)
                A[i * n + j] = A[j * n + i];
        return;
    }
    memcpy(M, A, (size_t)n * n * sizeof *M);
    plume_dense_sym_eig(n, M, lam, V);
    if (lam[0] >= 0.0) { /* semidefinite (singular): unchanged */
        for (int i = 0; i < n; i++)
            for (int j = 0; j < i; j++)
                A[i * n + j] = A[j * n + i];
        return;
    }
    for (int k = 0; k < n; k++)
        if (lam[k] < 0.0)
            lam[k] = 0.0;
    for (int i = 0; i < n; i++) {
        for (int j = i; j < n; j++) {
            double s = 0.0;
            for (int k = 0; k < n; k++)
                s += V[i * n + k] * lam[k] * V[j * n + k];
            A[i * n + j] = A[j * n + i] = s;
        }
    }
}

void plume_dense_project_psd(int n, double *A)
{
    double work[2 * PLUME_DENSE_MAX_N * PLUME_DENSE_MAX_N + PLUME_DENSE_MAX_N];
    if (n > PLUME_DENSE_MAX_N) {
        for (long i = 0; i < (long)n * n; i++)
            A[i] = NAN;
        return;
    }
    plume_dense_project_psd_work(n, A, work);
}
