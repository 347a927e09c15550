#include "cholesky.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>
#include "internal/cholesky_like.h"
#include "../core/blas_threads.h"
#include "../io/progress.h"

/* METIS is not reentrant: its random number generator (GKlib's) is one state for the whole
 * process, so two analyses at once in two threads draw from each other's sequence and order the
 * same matrix differently (measured: the tilted traction curves of two threads then differed from
 * the serial ones in the 11th digit; with AMD alone they did not). Analyses that may call METIS
 * hold this lock; they happen once per pattern, so threads seldom wait on it. */
static pthread_mutex_t metis_lock = PTHREAD_MUTEX_INITIALIZER;

static cholmod_factor *analyze_with_metis(cholmod_sparse *A, cholmod_common *cm)
{
    pthread_mutex_lock(&metis_lock);
    cholmod_factor *L = cholmod_l_analyze(A, cm);
    pthread_mutex_unlock(&metis_lock);
    return L;
}

struct plume_chol {
    cholmod_common cm;
    cholmod_sparse *A;
    cholmod_factor *L;
    cholmod_dense *B, *X, *Y, *E; /* solve2 workspaces, reused */
    plume_index n;
    int ldl, analyses, factorizations;
    double flops; /* CHOLMOD's flop count of one factorisation, from the analysis */
    double factor_seconds;
    /* LL^T: A holds P M P^T in lower form, analysed in its natural order (see permuted_lower) */
    SuiteSparse_long *perm; /* [n] row/column perm[k] of M is the k-th of A */
    SuiteSparse_long *slot; /* [nnz] the place in A->x of each value of M's upper triangle */
    /* plume_chol_create_like: the order found for the base pattern and its factor's entries */
    SuiteSparse_long *base_perm; /* [n] or NULL */
    double base_lnz;
};

/* A pattern analysed in its base pattern's order keeps it while its factor has at most this many
 * times the entries of the base pattern's; otherwise AMD and METIS order it afresh. */
#define CHOL_REUSE_FILL 1.2

/* CHOLMOD factorises a permuted matrix by first transposing it into P M P^T (a pass over every
 * entry, 3-4 % of a traction run at 4e4 elements: docs/benchmarks.md); in its natural order and
 * lower form it factorises the matrix as given. So the pattern is analysed once with AMD and
 * METIS for the permutation P, and A is laid out as the lower triangle of P M P^T, each value of
 * M's upper triangle with its place in A (rows sorted within each column), then analysed again in
 * its natural order: a factorisation only scatters the values (plume_chol_factor). */
static plume_status permuted_lower(plume_chol *c, const plume_index *colptr, const plume_index *rowind,
                                   const SuiteSparse_long *perm)
{
    plume_index n = c->n, nnz = colptr[n];
    SuiteSparse_long *inv = malloc((size_t)n * sizeof *inv);
    SuiteSparse_long *cnt = calloc((size_t)n + 1, sizeof *cnt);
    SuiteSparse_long *tmp_col = malloc(((size_t)nnz + 1) * sizeof *tmp_col);
    SuiteSparse_long *tmp_k = malloc(((size_t)nnz + 1) * sizeof *tmp_k);
    c->perm = malloc((size_t)n * sizeof *c->perm);
    c->slot = malloc(((size_t)nnz + 1) * sizeof *c->slot);
    c->A = cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)nnz, 1, 1, -1, CHOLMOD_REAL, &c->cm);
    plume_status st = PLUME_ENOMEM;
    if (!inv || !cnt || !tmp_col || !tmp_k || !c->perm || !c->slot || !c->A)
        goto done;
    for (plume_index k = 0; k < n; k++) {
        c->perm[k] = perm[k];
        inv[perm[k]] = k;
    }
    /* entry (i, j) of M, i <= j, lands at (max, min) of (inv i, inv j): bucket by row first, then
     * a stable bucketing by column leaves the rows of each column sorted */
    for (plume_index j = 0; j < n; j++)
        for (plume_index q = colptr[j]; q < colptr[j + 1]; q++) {
            SuiteSparse_long a = inv[rowind[q]], b = inv[j];
            cnt[(a > b ? a : b) + 1]++;
        }
    for (plume_index r = 0; r < n; r++)
        cnt[r + 1] += cnt[r];
    for (plume_index j = 0; j < n; j++)
        for (plume_index q = colptr[j]; q < colptr[j + 1]; q++) {
            SuiteSparse_long a = inv[rowind[q]], b = inv[j];
            SuiteSparse_long row = a > b ? a : b, col = a > b ? b : a;
            SuiteSparse_long at = cnt[row]++;
            tmp_col[at] = col;
            tmp_k[at] = q;
        }
    /* tmp_* now run by row; cnt[r] is the end of row r */
    SuiteSparse_long *Ap = c->A->p, *Ai = c->A->i;
    memset(Ap, 0, ((size_t)n + 1) * sizeof *Ap);
    for (plume_index e = 0; e < nnz; e++)
        Ap[tmp_col[e] + 1]++;
    for (plume_index col = 0; col < n; col++)
        Ap[col + 1] += Ap[col];
    SuiteSparse_long *next = inv; /* inv is no longer needed: the fill position of each column */
    memcpy(next, Ap, (size_t)n * sizeof *next);
    for (plume_index row = 0, e = 0; row < n; row++)
        for (; e < cnt[row]; e++) {
            SuiteSparse_long at = next[tmp_col[e]]++;
            Ai[at] = row;
            c->slot[tmp_k[e]] = at;
        }
    memset(c->A->x, 0, (size_t)nnz * sizeof(double));
    st = PLUME_OK;
done:
    free(inv);
    free(cnt);
    free(tmp_col);
    free(tmp_k);
    return st;
}

/* The LL^T layout in the order perm, analysed in its natural order; PLUME_EDEP when CHOLMOD
 * fails or does not keep that order. c->A holds the pattern's upper triangle on entry (freed). */
static plume_status analyse_in_order(plume_chol *c, const plume_index *colptr, const plume_index *rowind,
                                     const SuiteSparse_long *perm)
{
    cholmod_l_free_sparse(&c->A, &c->cm);
    cholmod_l_free_factor(&c->L, &c->cm);
    plume_status st = permuted_lower(c, colptr, rowind, perm);
    if (st != PLUME_OK)
        return st;
    c->cm.nmethods = 1;
    c->cm.method[0].ordering = CHOLMOD_NATURAL;
    c->cm.postorder = 0;
    c->L = cholmod_l_analyze(c->A, &c->cm);
    if (!c->L || c->cm.status < CHOLMOD_OK || c->L->ordering != CHOLMOD_NATURAL)
        return PLUME_EDEP;
    return PLUME_OK;
}

/* A factorisation object with CHOLMOD started and set up, nothing analysed. */
static plume_chol *chol_start(plume_index n, int ldl)
{
    plume_chol *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    cholmod_l_start(&c->cm);
    c->cm.print = 0;
    c->cm.error_handler = NULL;
    c->cm.quick_return_if_not_posdef = 1;
    /* 2D meshes: nested dissection (METIS) gives ~40% fewer flops than AMD here; analysing with
     * both and keeping the better one costs once per pattern */
    c->cm.nmethods = 2;
    c->cm.method[0].ordering = CHOLMOD_AMD;
    c->cm.method[1].ordering = CHOLMOD_METIS;
    c->cm.postorder = 1;
    /* fewer, larger supernodes than CHOLMOD's defaults (nrelax 4/16/48, zrelax 0.8/0.1/0.05): each
     * supernode's BLAS calls and OpenMP regions cost the same overhead, and shell patterns make many
     * small ones. Measured on the idle 2-core machine: tilted traction at 4e4 elements 1.27-1.29 s
     * against 1.39-1.41 s (factorisations 0.56 against 0.72 s) for 13 % more memory (149 against
     * 132 MB), the wing's first 30 steps 0.78-0.81 s a frame against 0.83-0.86 s, the feather at
     * 44.7k elements unchanged (0.92-1.00 s an iteration either way) */
    c->cm.nrelax[0] = 16, c->cm.nrelax[1] = 64, c->cm.nrelax[2] = 128;
    c->cm.zrelax[0] = 0.8, c->cm.zrelax[1] = 0.2, c->cm.zrelax[2] = 0.1;
    c->n = n;
    c->ldl = ldl;
    if (ldl) {
        c->cm.supernodal = CHOLMOD_SIMPLICIAL;
        c->cm.final_ll = 0;
    } else {
        /* LL^T also when CHOLMOD picks a simplicial factor (small matrices): its simplicial LDL^T
         * accepts negative pivots, and the callers rely on a failed factorisation to see that a
         * matrix is not positive definite (the exact Hessian tried first, inertia corrections) */
        c->cm.final_ll = 1;
    }
    c->B = cholmod_l_zeros((size_t)n, 1, CHOLMOD_REAL, &c->cm);
    if (!c->B)
        plume_chol_destroy(&c);
    return c;
}

plume_status plume_chol_create(plume_index n, const plume_index *colptr, const plume_index *rowind,
                               int ldl, plume_chol **out, plume_err *err)
{
    plume_openmp_thread_serial(); /* the analysis too runs in this thread's OpenMP settings */
    if (!out || n <= 0 || !colptr || !rowind)
        return plume_err_set(err, PLUME_EINVAL, "cholesky: invalid arguments");
    *out = NULL;
    plume_chol *c = chol_start(n, ldl);
    if (!c)
        return PLUME_ENOMEM;
    plume_index nnz = colptr[n];
    c->A = cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)nnz, 1, 1, 1, CHOLMOD_REAL, &c->cm);
    if (!c->A) {
        plume_chol_destroy(&c);
        return PLUME_ENOMEM;
    }
    memcpy(c->A->p, colptr, (size_t)(n + 1) * sizeof(SuiteSparse_long));
    memcpy(c->A->i, rowind, (size_t)nnz * sizeof(SuiteSparse_long));
    for (plume_index k = 0; k < nnz; k++)
        ((double *)c->A->x)[k] = 0.0;
    c->L = analyze_with_metis(c->A, &c->cm);
    if (c->L && c->cm.status >= CHOLMOD_OK && !ldl && c->L->ordering != CHOLMOD_NATURAL) {
        /* LL^T: lay the matrix out in the order found, and analyse that in its natural order */
        cholmod_sparse *upper = c->A;
        cholmod_factor *first = c->L;
        c->A = NULL;
        c->L = NULL;
        plume_status st = permuted_lower(c, colptr, rowind, first->Perm);
        cholmod_l_free_sparse(&upper, &c->cm);
        cholmod_l_free_factor(&first, &c->cm);
        if (st != PLUME_OK) {
            plume_chol_destroy(&c);
            return st;
        }
        c->cm.nmethods = 1;
        c->cm.method[0].ordering = CHOLMOD_NATURAL;
        c->cm.postorder = 0;
        c->L = cholmod_l_analyze(c->A, &c->cm);
        if (c->L && c->L->ordering != CHOLMOD_NATURAL) { /* CHOLMOD chose otherwise: not expected */
            plume_chol_destroy(&c);
            return plume_err_set(err, PLUME_EDEP, "cholesky: CHOLMOD did not keep the natural order");
        }
    }
    if (!c->L || c->cm.status < CHOLMOD_OK) {
        int s = c->cm.status;
        plume_chol_destroy(&c);
        return plume_err_set(err, s == CHOLMOD_OUT_OF_MEMORY ? PLUME_ENOMEM : PLUME_EDEP,
                             "cholesky: CHOLMOD analysis failed (status %d)", s);
    }
    c->analyses = 1;
    c->flops = c->cm.fl;
    *out = c;
    return PLUME_OK;
}

plume_status plume_chol_create_like(plume_index n, const plume_index *colptr, const plume_index *rowind, int ldl,
                                    const plume_index *base_colptr, const plume_index *base_rowind,
                                    const plume_chol *like, plume_chol **out, plume_err *err)
{
    plume_openmp_thread_serial(); /* the analysis too runs in this thread's OpenMP settings */
    if (!out || n <= 0 || !colptr || !rowind)
        return plume_err_set(err, PLUME_EINVAL, "cholesky: invalid arguments");
    *out = NULL;
    if (ldl || !base_colptr || !base_rowind)
        return plume_chol_create(n, colptr, rowind, ldl, out, err);
    const int same = base_colptr[n] == colptr[n] && !memcmp(base_colptr, colptr, (size_t)(n + 1) * sizeof *colptr) &&
                     !memcmp(base_rowind, rowind, (size_t)colptr[n] * sizeof *rowind);
    /* the base pattern's order: like's (the same base pattern), or found now */
    SuiteSparse_long *bperm = NULL;
    double blnz = 0.0;
    plume_status st = PLUME_OK;
    if (like && like->n == n && like->base_perm) {
        bperm = malloc((size_t)n * sizeof *bperm);
        if (!bperm)
            return PLUME_ENOMEM;
        memcpy(bperm, like->base_perm, (size_t)n * sizeof *bperm);
        blnz = like->base_lnz;
    } else {
        plume_chol *b = NULL;
        if ((st = plume_chol_create(n, base_colptr, base_rowind, 0, &b, err)) != PLUME_OK)
            return st;
        blnz = b->cm.lnz;
        bperm = b->perm; /* NULL when CHOLMOD kept the natural order */
        b->perm = NULL;
        if (same) { /* the base pattern itself: that analysis is the one wanted */
            b->perm = bperm;
            b->base_perm = bperm ? malloc((size_t)n * sizeof *bperm) : NULL;
            if (bperm && !b->base_perm) {
                plume_chol_destroy(&b);
                return PLUME_ENOMEM;
            }
            if (bperm)
                memcpy(b->base_perm, bperm, (size_t)n * sizeof *bperm);
            b->base_lnz = blnz;
            *out = b;
            return PLUME_OK;
        }
        plume_chol_destroy(&b);
    }
    if (!bperm)
        return plume_chol_create(n, colptr, rowind, 0, out, err);
    /* the base order, while the fill stays close to the base pattern's: a pattern that changed by
     * a few contact pairs is analysed without AMD and METIS (most of an analysis) */
    plume_chol *c = chol_start(n, 0);
    if (!c) {
        free(bperm);
        return PLUME_ENOMEM;
    }
    if (analyse_in_order(c, colptr, rowind, bperm) != PLUME_OK || !(c->cm.lnz <= CHOL_REUSE_FILL * blnz)) {
        plume_chol_destroy(&c);
        if ((st = plume_chol_create(n, colptr, rowind, 0, &c, err)) != PLUME_OK) {
            free(bperm);
            return st;
        }
    }
    c->base_perm = bperm;
    c->base_lnz = blnz;
    c->analyses = 1;
    c->flops = c->cm.fl;
    *out = c;
    return PLUME_OK;
}

void plume_chol_destroy(plume_chol **pc)
{
    if (!pc || !*pc)
        return;
    plume_chol *c = *pc;
    cholmod_l_free_sparse(&c->A, &c->cm);
    cholmod_l_free_factor(&c->L, &c->cm);
    cholmod_l_free_dense(&c->B, &c->cm);
    cholmod_l_free_dense(&c->X, &c->cm);
    cholmod_l_free_dense(&c->Y, &c->cm);
    cholmod_l_free_dense(&c->E, &c->cm);
    cholmod_l_finish(&c->cm);
    free(c->perm);
    free(c->slot);
    free(c->base_perm);
    free(c);
    *pc = NULL;
}

plume_status plume_chol_factor(plume_chol *c, const double *values, double shift)
{
    double t0 = plume_wall_seconds();
    plume_index nnz = ((SuiteSparse_long *)c->A->p)[c->n];
    if (c->slot) {
        double *ax = c->A->x;
        for (plume_index k = 0; k < nnz; k++)
            ax[c->slot[k]] = values[k];
    } else {
        memcpy(c->A->x, values, (size_t)nnz * sizeof(double));
    }
    double beta[2] = {shift, 0.0};
    /* large factorisations share their BLAS calls among the cores (lib/core/blas_threads.h) */
    plume_openmp_thread_serial();
    const int threads = plume_blas_threads_for(c->flops);
    if (threads > 1)
        plume_blas_threads_set(threads);
    int ok = cholmod_l_factorize_p(c->A, beta, NULL, 0, c->L, &c->cm);
    if (threads > 1)
        plume_blas_threads_set(1);
    c->factorizations++;
    c->factor_seconds += plume_wall_seconds() - t0;
    if (!ok || c->cm.status == CHOLMOD_OUT_OF_MEMORY)
        return c->cm.status == CHOLMOD_OUT_OF_MEMORY ? PLUME_ENOMEM : PLUME_EDEP;
    if (c->cm.status == CHOLMOD_NOT_POSDEF || c->L->minor < (size_t)c->n)
        return PLUME_ESINGULAR;
    return PLUME_OK;
}

plume_status plume_chol_solve(plume_chol *c, const double *b, double *x)
{
    double *bs = c->B->x;
    if (c->perm) /* P b, then x = P^T y */
        for (plume_index k = 0; k < c->n; k++)
            bs[k] = b[c->perm[k]];
    else
        memcpy(bs, b, (size_t)c->n * sizeof(double));
    if (!cholmod_l_solve2(CHOLMOD_A, c->L, c->B, NULL, &c->X, NULL, &c->Y, &c->E, &c->cm))
        return c->cm.status == CHOLMOD_OUT_OF_MEMORY ? PLUME_ENOMEM : PLUME_EDEP;
    const double *xs = c->X->x;
    for (plume_index k = 0; k < c->n; k++) {
        if (!isfinite(xs[k]))
            return PLUME_ESINGULAR;
        x[c->perm ? c->perm[k] : k] = xs[k];
    }
    return PLUME_OK;
}

double plume_chol_rcond(plume_chol *c)
{
    if (!c || !c->L || !c->factorizations)
        return 0.0;
    return cholmod_l_rcond(c->L, &c->cm);
}

void plume_chol_counts(const plume_chol *c, double *lnz, double *flops)
{
    *lnz = c ? c->cm.lnz : 0.0;
    *flops = c ? c->flops : 0.0;
}

void plume_chol_stats(const plume_chol *c, int *analyses, int *factorizations, double *factor_seconds)
{
    if (analyses)
        *analyses = c ? c->analyses : 0;
    if (factorizations)
        *factorizations = c ? c->factorizations : 0;
    if (factor_seconds)
        *factor_seconds = c ? c->factor_seconds : 0.0;
}
