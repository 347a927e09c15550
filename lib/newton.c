/* Native solver. Constraints are handled by SQP on the KKT system
 *   [H + dw I   J^T ] [du     ]   [-grad f          ]
 *   [J        -dc I ] [lam_new] = [-g - dc lam      ]
 * where H is the Hessian of the Lagrangian with every element block projected to PSD. The
 * "- dc lam" term (a proximal term on the multipliers) keeps the fixed point exact: at du = 0,
 * lam_new = lam we have g = 0, whatever the small regularisation dc. Two ways to factorise:
 * - PLUME_KKT_ELIMINATE (default): the -dc I block is eliminated exactly, leaving the SPD matrix
 *   H + dw I + J^T J / dc on the Hessian's own pattern (edge constraints couple vertices that
 *   already share a triangle), factorised by CHOLMOD's supernodal LL^T; lam_new is recovered as
 *   lam + (J du + g) / dc. Same iterates as LDL^T in our tests, 2-3x faster factorisations.
 * - PLUME_KKT_LDL: the quasi-definite matrix itself, whose LDL^T without pivoting exists for any
 *   ordering, by CHOLMOD's simplicial LDL^T.
 * Either way the symbolic analysis is done once. Globalisation: l1 merit f + mu |g|_1 with Armijo
 * backtracking and one second-order correction (against the Maratos effect). Without
 * constraints this is projected Newton with LL^T. */
#include "newton.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cholesky.h"
#include "progress.h"

struct plume_newton {
    plume_problem *p;
    plume_solver_opts o;
    int single_step;
    plume_index n, m, nk;  /* free dofs, constraints, KKT size */
    plume_sparsity hp;
    plume_index jnnz;
    const plume_index *jrow, *jcol;
    plume_index *kcolptr, *krowind, *jpos, *diagpos; /* KKT pattern, J entry -> KKT slot, diag slots */
    int eliminate;           /* constraints eliminated into an SPD matrix (supernodal LL^T) */
    plume_index npairs;      /* eliminate: pairs (ka, kb) of Jacobian entries of one row ... */
    plume_index *pair_a, *pair_b, *pair_pos; /* ... and the Hessian slot of (col ka, col kb) */
    double dc;               /* the KKT regularisation of the system solved ... */
    double dcf;              /* ... and the one factorised (>= dc, kkt_solve_j) */
    double diag;             /* the diagonal shift of the last factorisation */
    double *rb, *rr, *rd;    /* [n+m+1] iterative refinement */
    int refinements;         /* refinement passes in this solve */
    double shift, shift_last; /* exact-Hessian shift of the last factorisation; the last nonzero one */
    int projected;           /* the last factorisation used the projected Hessian */
    int shifts;              /* factorisations that failed for inertia in this solve */
    double filt[2 * 64];     /* filter line search: (theta, f) pairs of this solve (a ring) */
    int nfilt;
    double theta_max, theta_min;
    int factor_valid;        /* the last factorisation may serve a chord step (kept across solves) */
    double *jval_f;          /* [jnnz] the Jacobian that factorisation was built with */
    double *u_s, *l_s, *grad_s, *g_s, *jval_s; /* the iterate before a chord step ... */
    double *u_b, *l_b;       /* the best iterate within the violation tolerance (round-off floor) */
    double saved_f, saved_g1, saved_viol;        /* ... and its f, |g|_1, violation */
    double *kwork, *lwork;   /* [n+1], [m+1] eliminate: workspaces */
    double *hval, *kval, *jval, *grad, *g, *gt, *rhs, *sol, *ut, *jtl;
    plume_chol *chol;
};

void plume_newton_destroy(plume_newton **ps)
{
    if (!ps || !*ps)
        return;
    plume_newton *s = *ps;
    plume_chol_destroy(&s->chol);
    free(s->kcolptr);
    free(s->krowind);
    free(s->jpos);
    free(s->diagpos);
    free(s->pair_a);
    free(s->pair_b);
    free(s->pair_pos);
    free(s->kwork);
    free(s->lwork);
    free(s->hval);
    free(s->kval);
    free(s->jval);
    free(s->jval_f);
    free(s->rb);
    free(s->rr);
    free(s->rd);
    free(s->u_s);
    free(s->l_s);
    free(s->grad_s);
    free(s->g_s);
    free(s->jval_s);
    free(s->u_b);
    free(s->l_b);
    free(s->grad);
    free(s->g);
    free(s->gt);
    free(s->rhs);
    free(s->sol);
    free(s->ut);
    free(s->jtl);
    free(s);
    *ps = NULL;
}

/* KKT pattern: columns < n are the Hessian's; column n + r holds the free dofs of constraint r
 * (rows sorted) and its diagonal. */
static plume_status build_kkt_pattern(plume_newton *s)
{
    plume_index n = s->n, m = s->m;
    s->kcolptr = calloc((size_t)(n + m + 1), sizeof *s->kcolptr);
    s->krowind = malloc((size_t)(s->hp.nnz + s->jnnz + m + 1) * sizeof *s->krowind);
    s->jpos = malloc((size_t)(s->jnnz + 1) * sizeof *s->jpos);
    plume_index *order = malloc((size_t)(s->jnnz + 1) * sizeof *order);
    plume_index *cnt = calloc((size_t)(m + 1), sizeof *cnt);
    if (!s->kcolptr || !s->krowind || !s->jpos || !order || !cnt) {
        free(order);
        free(cnt);
        return PLUME_ENOMEM;
    }
    memcpy(s->kcolptr, s->hp.colptr, (size_t)(n + 1) * sizeof *s->kcolptr);
    memcpy(s->krowind, s->hp.rowind, (size_t)s->hp.nnz * sizeof *s->krowind);
    for (plume_index k = 0; k < s->jnnz; k++)
        cnt[s->jrow[k]]++;
    /* bucket the triplets by constraint row (counting sort), then sort each bucket by column */
    plume_index *start = calloc((size_t)(m + 1), sizeof *start);
    if (!start) {
        free(order);
        free(cnt);
        return PLUME_ENOMEM;
    }
    for (plume_index r = 0; r < m; r++)
        start[r + 1] = start[r] + cnt[r];
    memset(cnt, 0, (size_t)(m + 1) * sizeof *cnt);
    for (plume_index k = 0; k < s->jnnz; k++)
        order[start[s->jrow[k]] + cnt[s->jrow[k]]++] = k;
    plume_index pos = s->hp.nnz;
    for (plume_index r = 0; r < m; r++) {
        plume_index *b = order + start[r];
        for (plume_index i = 1; i < cnt[r]; i++) /* insertion sort: a row has a handful of entries */
            for (plume_index j = i; j > 0 && s->jcol[b[j - 1]] > s->jcol[b[j]]; j--) {
                plume_index t = b[j];
                b[j] = b[j - 1];
                b[j - 1] = t;
            }
        for (plume_index i = 0; i < cnt[r]; i++) {
            s->krowind[pos] = s->jcol[b[i]];
            s->jpos[b[i]] = pos++;
        }
        s->krowind[pos++] = n + r;
        s->kcolptr[n + r + 1] = pos;
    }
    free(start);
    free(order);
    free(cnt);
    return PLUME_OK;
}

static plume_index hessian_slot(const plume_sparsity *hp, plume_index r, plume_index c)
{
    if (r > c) {
        plume_index t = r;
        r = c;
        c = t;
    }
    plume_index lo = hp->colptr[c], hi = hp->colptr[c + 1] - 1;
    while (lo <= hi) {
        plume_index mid = lo + (hi - lo) / 2;
        if (hp->rowind[mid] == r)
            return mid;
        if (hp->rowind[mid] < r)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* Eliminating the multipliers from the KKT system adds J_r^T J_r / dc for every constraint row
 * r: list every pair of Jacobian entries of one row with the Hessian slot it lands in (the
 * problem's Hessian pattern contains every constraint stencil, so the slot exists). */
static plume_status build_elimination_pairs(plume_newton *s)
{
    plume_index m = s->m;
    plume_index *cnt = calloc((size_t)(m + 1), sizeof *cnt), *start = calloc((size_t)(m + 2), sizeof *start);
    plume_index *order = malloc((size_t)(s->jnnz + 1) * sizeof *order);
    plume_status st = PLUME_OK;
    if (!cnt || !start || !order) {
        st = PLUME_ENOMEM;
        goto done;
    }
    for (plume_index k = 0; k < s->jnnz; k++)
        cnt[s->jrow[k]]++;
    for (plume_index r = 0; r < m; r++)
        start[r + 1] = start[r] + cnt[r];
    plume_index np = 0;
    for (plume_index r = 0; r < m; r++)
        np += cnt[r] * (cnt[r] + 1) / 2;
    memset(cnt, 0, (size_t)(m + 1) * sizeof *cnt);
    for (plume_index k = 0; k < s->jnnz; k++)
        order[start[s->jrow[k]] + cnt[s->jrow[k]]++] = k;
    s->pair_a = malloc((size_t)(np + 1) * sizeof *s->pair_a);
    s->pair_b = malloc((size_t)(np + 1) * sizeof *s->pair_b);
    s->pair_pos = malloc((size_t)(np + 1) * sizeof *s->pair_pos);
    s->kwork = malloc((size_t)(s->n + 1) * sizeof *s->kwork);
    s->lwork = malloc((size_t)(m + 1) * sizeof *s->lwork);
    if (!s->pair_a || !s->pair_b || !s->pair_pos || !s->kwork || !s->lwork) {
        st = PLUME_ENOMEM;
        goto done;
    }
    s->npairs = 0;
    for (plume_index r = 0; r < m; r++)
        for (plume_index i = 0; i < cnt[r]; i++)
            for (plume_index j = i; j < cnt[r]; j++) {
                plume_index ka = order[start[r] + i], kb = order[start[r] + j];
                plume_index pos = hessian_slot(&s->hp, s->jcol[ka], s->jcol[kb]);
                if (pos < 0) {
                    st = PLUME_EINVAL;
                    goto done;
                }
                s->pair_a[s->npairs] = ka;
                s->pair_b[s->npairs] = kb;
                s->pair_pos[s->npairs++] = pos;
            }
done:
    free(cnt);
    free(start);
    free(order);
    return st;
}

plume_status plume_newton_create(plume_problem *p, const plume_solver_opts *o, int single_step,
                                 plume_newton **out, plume_err *err)
{
    if (!p || !o || !out)
        return plume_err_set(err, PLUME_EINVAL, "newton: invalid arguments");
    *out = NULL;
    if (o->max_iter < 0 || !(o->tol_kkt > 0.0) || !(o->tol_violation > 0.0) || !(o->tol_step >= 0.0) ||
        !(o->max_step > 0.0) || !isfinite(o->tol_kkt + o->tol_violation + o->tol_step + o->max_step))
        return plume_err_set(err, PLUME_EINVAL,
                             "newton: options need max_iter >= 0, tol_kkt > 0, tol_violation > 0, tol_step >= 0, "
                             "max_step > 0, all finite");
    plume_status st = PLUME_OK;
    plume_newton *s = calloc(1, sizeof *s);
    if (!s)
        return PLUME_ENOMEM;
    s->p = p;
    s->o = *o;
    s->single_step = single_step;
    s->n = plume_problem_nfree(p);
    s->m = plume_problem_ncons(p);
    s->nk = s->n + s->m;
    s->hp = plume_problem_hessian_pattern(p);
    plume_problem_jacobian_pattern(p, &s->jnnz, &s->jrow, &s->jcol);
    size_t n = (size_t)s->n, m = (size_t)s->m, nk = (size_t)s->nk;
    s->hval = malloc(((size_t)s->hp.nnz + 1) * sizeof *s->hval);
    s->jval = malloc(((size_t)s->jnnz + 1) * sizeof *s->jval);
    s->jval_f = malloc(((size_t)s->jnnz + 1) * sizeof *s->jval_f);
    s->rb = malloc((nk + 1) * sizeof *s->rb);
    s->rr = malloc((nk + 1) * sizeof *s->rr);
    s->rd = malloc((nk + 1) * sizeof *s->rd);
    s->jval_s = malloc(((size_t)s->jnnz + 1) * sizeof *s->jval_s);
    s->u_s = malloc((size_t)(s->n + 1) * sizeof *s->u_s);
    s->grad_s = malloc((size_t)(s->n + 1) * sizeof *s->grad_s);
    s->l_s = malloc((size_t)(s->m + 1) * sizeof *s->l_s);
    s->g_s = malloc((size_t)(s->m + 1) * sizeof *s->g_s);
    s->u_b = malloc((size_t)(s->n + 1) * sizeof *s->u_b);
    s->l_b = malloc((size_t)(s->m + 1) * sizeof *s->l_b);
    s->grad = malloc((n + 1) * sizeof *s->grad);
    s->g = malloc((m + 1) * sizeof *s->g);
    s->gt = malloc((m + 1) * sizeof *s->gt);
    s->rhs = malloc((nk + 1) * sizeof *s->rhs);
    s->sol = malloc((nk + 1) * sizeof *s->sol);
    s->ut = malloc((n + 1) * sizeof *s->ut);
    s->jtl = malloc((n + 1) * sizeof *s->jtl);
    s->diagpos = malloc((nk + 1) * sizeof *s->diagpos);
    if (!s->hval || !s->jval || !s->grad || !s->g || !s->gt || !s->rhs || !s->sol || !s->ut || !s->jtl ||
        !s->diagpos || !s->jval_f || !s->rb || !s->rr || !s->rd || !s->jval_s || !s->u_s || !s->grad_s || !s->l_s || !s->g_s || !s->u_b ||
        !s->l_b) {
        st = PLUME_ENOMEM;
        goto fail;
    }
    s->eliminate = s->m > 0 && o->kkt == PLUME_KKT_ELIMINATE;
    if (s->eliminate) {
        if ((st = build_elimination_pairs(s)) != PLUME_OK)
            goto fail;
        st = plume_chol_create(s->n, s->hp.colptr, s->hp.rowind, 0, &s->chol, err);
    } else if (s->m > 0) {
        if ((st = build_kkt_pattern(s)) != PLUME_OK)
            goto fail;
        s->kval = malloc(((size_t)s->kcolptr[nk] + 1) * sizeof *s->kval);
        if (!s->kval) {
            st = PLUME_ENOMEM;
            goto fail;
        }
        st = plume_chol_create(s->nk, s->kcolptr, s->krowind, 1, &s->chol, err);
    } else {
        st = plume_chol_create(s->n, s->hp.colptr, s->hp.rowind, 0, &s->chol, err);
    }
    if (st != PLUME_OK)
        goto fail;
    const plume_index *cp = s->m > 0 && !s->eliminate ? s->kcolptr : s->hp.colptr;
    for (plume_index c = 0; c < (s->eliminate ? s->n : s->nk); c++)
        s->diagpos[c] = cp[c + 1] - 1; /* rows sorted and the diagonal is always present */
    *out = s;
    return PLUME_OK;
fail:
    plume_newton_destroy(&s);
    return st;
}

/* f, grad, g, |g|_1, max relative violation and the Jacobian at u */
static plume_status evaluate(plume_newton *s, const double *u, double *f, double *g1, double *viol)
{
    plume_status st = plume_problem_objective(s->p, u, f, s->grad);
    if (st != PLUME_OK)
        return st;
    *g1 = 0.0;
    *viol = 0.0;
    if (s->m == 0)
        return PLUME_OK;
    if ((st = plume_problem_constraints(s->p, NULL, s->g, viol)) != PLUME_OK)
        return st;
    for (plume_index r = 0; r < s->m; r++)
        *g1 += fabs(s->g[r]);
    return plume_problem_jacobian(s->p, NULL, s->jval);
}

/* merit f + mu |g|_1 at u (no gradient) */
static plume_status merit_at(plume_newton *s, const double *u, double mu, double *phi, double *fval)
{
    double f;
    plume_status st = plume_problem_objective(s->p, u, &f, NULL);
    if (st == PLUME_ESINGULAR) { /* a trial where a term is undefined (a degenerate triangle) */
        *fval = *phi = INFINITY;
        return PLUME_OK;
    }
    if (st != PLUME_OK)
        return st;
    double g1 = 0.0;
    if (s->m > 0) {
        if ((st = plume_problem_constraints(s->p, NULL, s->gt, NULL)) != PLUME_OK)
            return st;
        for (plume_index r = 0; r < s->m; r++)
            g1 += fabs(s->gt[r]);
    }
    *fval = f;
    *phi = f + mu * g1;
    if (!isfinite(*phi))
        *phi = INFINITY;
    return PLUME_OK;
}

static double l1norm(const double *v, plume_index n)
{
    double a = 0.0;
    for (plume_index i = 0; i < n; i++)
        a += fabs(v[i]);
    return a;
}

/* Ipopt's filter (Waechter & Biegler 2006, equality constraints): is (theta, f) acceptable to
 * the filter and below theta_max? */
static int filter_accepts(const plume_newton *s, double theta, double f)
{
    if (!(theta <= s->theta_max) || !isfinite(f))
        return 0;
    for (int k = 0; k < s->nfilt && k < 64; k++)
        if (!(theta < s->filt[2 * k] || f < s->filt[2 * k + 1]))
            return 0;
    return 1;
}

static void filter_add(plume_newton *s, double theta, double f)
{
    int k = s->nfilt++ % 64; /* the oldest entry goes first once 64 are kept */
    s->filt[2 * k] = theta;
    s->filt[2 * k + 1] = f;
}

/* Filter acceptance of a trial (theta_t, f_t) from (theta0, f0) with step alpha along a direction
 * with slope gd = grad f . du. f-type steps (switching condition: the model predicts a decrease
 * of f that dominates theta0, and theta0 small) need Armijo on f; the others a sufficient
 * decrease of theta or f against the current point, and enter the filter. */
static int filter_step_ok(plume_newton *s, double theta0, double f0, double gd, double alpha, double theta_t,
                          double f_t, int *f_type)
{
    const double gamma_theta = 1e-5, gamma_f = 1e-5, eta = 1e-4;
    *f_type = gd < 0.0 && theta0 <= s->theta_min && alpha * pow(-gd, 2.3) > pow(theta0, 1.1);
    if (!filter_accepts(s, theta_t, f_t))
        return 0;
    if (*f_type)
        return f_t <= f0 + eta * alpha * gd;
    return theta_t <= (1.0 - gamma_theta) * theta0 || f_t <= f0 - gamma_f * theta0;
}

/* relative KKT residual from the current grad, jval and lambda */
static double kkt_residual(plume_newton *s, const double *lambda)
{
    memset(s->jtl, 0, (size_t)s->n * sizeof *s->jtl);
    for (plume_index k = 0; k < s->jnnz; k++)
        s->jtl[s->jcol[k]] += s->jval[k] * lambda[s->jrow[k]];
    double gm = 0.0, jm = 0.0, rm = 0.0;
    for (plume_index i = 0; i < s->n; i++) {
        gm = fmax(gm, fabs(s->grad[i]));
        jm = fmax(jm, fabs(s->jtl[i]));
        rm = fmax(rm, fabs(s->grad[i] + s->jtl[i]));
    }
    if (!isfinite(rm) || !isfinite(gm))
        return NAN;
    double ref = fmax(plume_problem_force_scale(s->p), fmax(gm, jm));
    return ref > 0.0 ? rm / ref : 0.0;
}

/* Factorises the matrix of s->hval (the Hessian just assembled) with dw on its diagonal and the
 * constraints' block regularised by dc; s->hval is left as assembled. */
static plume_status factor_with(plume_newton *s, double dw, double dc)
{
    plume_status st;
    if (s->eliminate) {
        /* K = H + dw I + sum_r J_r^T J_r / dc on the Hessian's own pattern */
        for (plume_index k = 0; k < s->npairs; k++)
            s->hval[s->pair_pos[k]] += s->jval[s->pair_a[k]] * s->jval[s->pair_b[k]] / dc;
        st = plume_chol_factor(s->chol, s->hval, dw);
        for (plume_index k = 0; k < s->npairs; k++) /* undo: a retry starts from H again */
            s->hval[s->pair_pos[k]] -= s->jval[s->pair_a[k]] * s->jval[s->pair_b[k]] / dc;
    } else if (s->m > 0) {
        memcpy(s->kval, s->hval, (size_t)s->hp.nnz * sizeof *s->kval);
        for (plume_index c = 0; c < s->n; c++)
            s->kval[s->diagpos[c]] += dw;
        for (plume_index k = 0; k < s->jnnz; k++)
            s->kval[s->jpos[k]] = s->jval[k];
        for (plume_index r = 0; r < s->m; r++)
            s->kval[s->diagpos[s->n + r]] = -dc;
        st = plume_chol_factor(s->chol, s->kval, 0.0);
    } else {
        st = plume_chol_factor(s->chol, s->hval, dw);
    }
    return st;
}

/* Assembles and factorises the Newton/KKT matrix at u with multipliers lambda, with at least
 * dw_min added to the Hessian's diagonal; raises the regularisation until the factorisation
 * succeeds. *hmax_out receives the largest Hessian diagonal (the scale of any regularisation). */
static plume_status factorize(plume_newton *s, const double *u, const double *lambda, double dw_min,
                              double *dc_out, double *hmax_out)
{
    plume_status st = PLUME_ESINGULAR;
    /* Projection per element slows Newton down to a crawl where elements are indefinite but the
     * assembled matrix is not (stiff fibres in compression): try the exact Hessian first and keep
     * it whenever CHOLMOD accepts the SPD system built from it (with constraints eliminated, that
     * is H positive definite on the constraints' tangent space — the second-order condition),
     * otherwise the projected one. The LDL^T mode cannot tell inertia, so it always projects. */
    int exact_first = s->o.exact_hessian_first && dw_min == 0.0 && (s->m == 0 || s->eliminate);
    for (int project = !exact_first; project <= 1; project++) {
        if ((st = plume_problem_hessian(s->p, u, 1.0, s->m ? lambda : NULL, project, s->hval)) != PLUME_OK)
            return st;
        double hmax = 0.0;
        for (plume_index c = 0; c < s->n; c++)
            hmax = fmax(hmax, fabs(s->hval[s->hp.colptr[c + 1] - 1]));
        if (!(hmax > 0.0) || !isfinite(hmax))
            hmax = 1.0;
        *hmax_out = hmax;
        double jmax = 0.0;
        for (plume_index k = 0; k < s->jnnz; k++)
            jmax = fmax(jmax, fabs(s->jval[k]));
        double dc = s->m ? 1e-8 * (jmax > 0.0 ? jmax * jmax : 1.0) / hmax : 0.0;
        *dc_out = s->dc = dc;
        s->dcf = s->eliminate && s->o.kkt_refine ? 1e4 * dc : dc;
        double dw = fmax(dw_min, s->m && !s->eliminate ? 1e-12 * hmax : 0.0);
        /* Exact Hessian: Ipopt's inertia correction. Try no shift; if the matrix is not positive
         * definite, start from a third of the last shift that worked (or 1e-6 hmax the first
         * time) and grow it 8x (100x the first time) until it is, up to hmax; then fall back to
         * the projected Hessian. The shift carried from one iteration to the next damps the
         * directions along soft (buckling) modes the way a trust region would, so full steps are
         * taken instead of cut ones. */
        if (!project) {
            double sh = 0.0;
            for (int attempt = 0; attempt < 40; attempt++) {
                st = factor_with(s, dw + sh, s->dcf);
                if (st != PLUME_ESINGULAR) {
                    if (st == PLUME_OK) {
                        s->diag = dw + sh;
                        s->shift = sh;
                        s->projected = 0;
                        if (sh > 0.0)
                            s->shift_last = sh;
                        else
                            s->shift_last *= 1.0 / 3.0; /* forget it slowly once not needed */
                    }
                    return st;
                }
                s->shifts++;
                if (sh == 0.0)
                    sh = s->shift_last > 1e-12 * hmax ? s->shift_last / 3.0 : 1e-6 * hmax;
                else
                    sh *= s->shift_last > 1e-12 * hmax ? 8.0 : 100.0;
                if (!(sh <= s->o.inertia_max_shift * hmax) || s->o.inertia_corrections == 0)
                    break;
            }
            continue;
        }
        for (int attempt = 0; attempt < 12; attempt++) {
            st = factor_with(s, dw, s->dcf);
            if (st != PLUME_ESINGULAR) {
                if (st == PLUME_OK) {
                    s->diag = dw;
                    s->shift = dw;
                    s->projected = 1;
                }
                return st;
            }
            dw = dw > 0.0 ? dw * 100.0 : 1e-10 * hmax;
        }
    }
    return st;
}

/* One solve of [H + d I, J^T; J, -dcf I] [x; l] = [r1; r2] with the eliminated factorisation
 * (J values jv): K x = r1 + J^T r2 / dcf, then l = (J x - r2) / dcf. r and out may alias. */
static plume_status elim_solve(plume_newton *s, const double *jv, const double *r, double *out)
{
    plume_index n = s->n, m = s->m;
    const double dcf = s->dcf;
    for (plume_index i = 0; i < n; i++)
        s->kwork[i] = r[i];
    for (plume_index k = 0; k < s->jnnz; k++)
        s->kwork[s->jcol[k]] += jv[k] * r[n + s->jrow[k]] / dcf;
    for (plume_index q = 0; q < m; q++) /* r2 is read before out (which may alias r) is written */
        s->lwork[q] = -r[n + q];
    plume_status st = plume_chol_solve(s->chol, s->kwork, out);
    if (st != PLUME_OK)
        return st;
    for (plume_index k = 0; k < s->jnnz; k++)
        s->lwork[s->jrow[k]] += jv[k] * out[s->jcol[k]];
    for (plume_index q = 0; q < m; q++)
        out[n + q] = s->lwork[q] / dcf;
    return PLUME_OK;
}

/* Solves the regularised KKT system [H + d I, J^T; J, -dc I] [x; l] = [r1; r2] (H and d of the
 * last factorisation, J values jv); out holds x (n) then l (m); r and out may alias.
 * With the multipliers eliminated, the factorised matrix is H + d I + J^T J / dcf with a dcf
 * larger than dc (kkt_refine): J^T J / dc is 1e8 times the Hessian's scale, and a Cholesky
 * factor of that loses 8 digits of the Hessian's own part (the soft, buckling directions of a
 * feather: Newton then converged linearly), while 1e4 loses 4. Iterative refinement against the
 * dc system recovers the rest: its error contracts by dcf / (dcf + sigma(J H^-1 J^T)) a pass. */
static plume_status kkt_solve_j(plume_newton *s, const double *jv, const double *r, double *out)
{
    if (!s->eliminate)
        return plume_chol_solve(s->chol, r, out);
    plume_index n = s->n, m = s->m, nk = n + m;
    if (s->dcf == s->dc)
        return elim_solve(s, jv, r, out);
    double *b = s->rb, *res = s->rr, *dx = s->rd;
    memcpy(b, r, (size_t)nk * sizeof *b);
    plume_status st = elim_solve(s, jv, b, out);
    double bmax = 0.0;
    for (plume_index i = 0; i < nk; i++)
        bmax = fmax(bmax, fabs(b[i]));
    double last = INFINITY;
    for (int pass = 0; st == PLUME_OK && pass < 8; pass++) {
        /* res = b - [H + d I, J^T; J, -dc I] out */
        for (plume_index i = 0; i < n; i++)
            res[i] = b[i] - s->diag * out[i];
        for (plume_index q = 0; q < m; q++)
            res[n + q] = b[n + q] + s->dc * out[n + q];
        const plume_index *cp = s->hp.colptr, *ri = s->hp.rowind;
        for (plume_index c = 0; c < n; c++)
            for (plume_index k = cp[c]; k < cp[c + 1]; k++) {
                plume_index rw = ri[k];
                res[rw] -= s->hval[k] * out[c];
                if (rw != c)
                    res[c] -= s->hval[k] * out[rw];
            }
        for (plume_index k = 0; k < s->jnnz; k++) {
            res[s->jcol[k]] -= jv[k] * out[n + s->jrow[k]];
            res[n + s->jrow[k]] -= jv[k] * out[s->jcol[k]];
        }
        double rmax = 0.0;
        for (plume_index i = 0; i < nk; i++)
            rmax = fmax(rmax, fabs(res[i]));
        if (!(rmax > 1e-15 * bmax) || !(rmax < 0.5 * last))
            break;
        last = rmax;
        if ((st = elim_solve(s, jv, res, dx)) == PLUME_OK)
            for (plume_index i = 0; i < nk; i++)
                out[i] += dx[i];
        s->refinements++;
    }
    return st;
}

static plume_status kkt_solve(plume_newton *s, const double *r, double *out)
{
    return kkt_solve_j(s, s->jval, r, out);
}

/* Newton/SQP direction: factorise and solve. A direction longer than max_step times the body
 * means the Hessian is (nearly) singular on the constraints' null space (e.g. a straight chain
 * with zero multipliers has no sideways stiffness), so the regularisation is raised,
 * Levenberg–Marquardt style, until the step is of a sensible size (after 8 tries the last step is
 * returned as it is: the line search judges it). PLUME_ESINGULAR when no factorisation worked. */
static plume_status direction(plume_newton *s, const double *u, const double *lambda, double *step_max)
{
    plume_index n = s->n, m = s->m;
    double L = plume_problem_length_scale(s->p), dw = 0.0, dc, hmax;
    plume_status st = PLUME_OK;
    for (int attempt = 0; attempt < 8; attempt++) {
        if ((st = factorize(s, u, lambda, dw, &dc, &hmax)) != PLUME_OK)
            return st;
        for (plume_index i = 0; i < n; i++)
            s->rhs[i] = -s->grad[i];
        for (plume_index r = 0; r < m; r++)
            s->rhs[n + r] = -s->g[r] - dc * lambda[r];
        if ((st = kkt_solve(s, s->rhs, s->sol)) != PLUME_OK && st != PLUME_ESINGULAR)
            return st;
        *step_max = 0.0;
        double slope = 0.0;
        for (plume_index i = 0; i < n; i++) {
            *step_max = fmax(*step_max, fabs(s->sol[i]));
            slope += s->grad[i] * s->sol[i];
        }
        /* Without constraints a factorisation CHOLMOD accepted must give a descent direction;
         * near a bifurcation (a nearly singular exact Hessian) round-off can make it point
         * uphill: then regularise, which also switches to the projected Hessian. */
        int uphill = m == 0 && !(slope < 0.0) && *step_max > 0.0;
        if (st == PLUME_OK && *step_max <= s->o.max_step * L && !uphill)
            return PLUME_OK;
        dw = dw > 0.0 ? dw * 100.0 : 1e-8 * hmax;
    }
    return st == PLUME_OK ? PLUME_OK : PLUME_ESINGULAR; /* a long step is still a step */
}

/* Chord direction: the last factorisation (of an earlier iterate's matrix, perhaps of an earlier
 * solve) with the current residual. The fixed point is exact whatever matrix is used; only the
 * rate of convergence suffers, which the caller measures. Not usable (nonzero) when the solve
 * fails, the step is absurdly long, or (without constraints) it does not descend. */
/* save (1) or restore (0) the iterate: u, lambda and what evaluate() computed there */
static void save_iterate(plume_newton *s, int save, double *u, double *lambda, double f, double g1, double viol)
{
    size_t n = (size_t)s->n, m = (size_t)s->m, j = (size_t)s->jnnz;
    if (save) {
        memcpy(s->u_s, u, n * sizeof *u);
        memcpy(s->l_s, lambda, m * sizeof *lambda);
        memcpy(s->grad_s, s->grad, n * sizeof *u);
        memcpy(s->g_s, s->g, m * sizeof *u);
        memcpy(s->jval_s, s->jval, j * sizeof *u);
        s->saved_f = f, s->saved_g1 = g1, s->saved_viol = viol;
    } else {
        memcpy(u, s->u_s, n * sizeof *u);
        memcpy(lambda, s->l_s, m * sizeof *lambda);
        memcpy(s->grad, s->grad_s, n * sizeof *u);
        memcpy(s->g, s->g_s, m * sizeof *u);
        memcpy(s->jval, s->jval_s, j * sizeof *u);
    }
}

static int chord_direction(plume_newton *s, const double *lambda, double L, double *step_max)
{
    /* increment form with the factorisation's own Jacobian J_f, so that only the matrix is stale:
     *   (H_f + J_f^T J_f / dc) dx = r1 + J_f^T r2 / dc,  dlam = (J_f dx - r2) / dc,
     * r1 = -(grad + J^T lam) (s->jtl holds J^T lam from kkt_residual), r2 = -g */
    plume_index n = s->n, m = s->m;
    if (!s->eliminate && m > 0)
        return 1; /* the LDL^T mode keeps J inside its factorisation: no chord steps */
    for (plume_index i = 0; i < n; i++)
        s->rhs[i] = -(s->grad[i] + (m ? s->jtl[i] : 0.0));
    for (plume_index r = 0; r < m; r++)
        s->rhs[n + r] = -s->g[r];
    if (kkt_solve_j(s, s->jval_f, s->rhs, s->sol) != PLUME_OK)
        return 1;
    for (plume_index r = 0; r < m; r++)
        s->sol[n + r] += lambda[r];
    double slope = 0.0;
    *step_max = 0.0;
    for (plume_index i = 0; i < n; i++) {
        if (!isfinite(s->sol[i]))
            return 1;
        *step_max = fmax(*step_max, fabs(s->sol[i]));
        slope += s->grad[i] * s->sol[i];
    }
    return !(*step_max <= s->o.max_step * L) || (m == 0 && !(slope < 0.0) && *step_max > 0.0);
}

plume_status plume_newton_solve(plume_newton *s, double *u, double *lambda, plume_solve_report *rep)
{
    if (!s || !u || (s->m && !lambda) || !rep)
        return PLUME_EINVAL;
    double t0 = plume_wall_seconds();
    memset(rep, 0, sizeof *rep);
    int f0;
    plume_chol_stats(s->chol, NULL, &f0, NULL);
    plume_index n = s->n, m = s->m;
    double L = plume_problem_length_scale(s->p);
    double f, g1, viol, mu = 0.0;
    plume_status st = evaluate(s, u, &f, &g1, &viol);
    if (st != PLUME_OK)
        return st;
    rep->reason = PLUME_REASON_ITERATION_CAP;
    s->nfilt = 0; /* a new filter per solve (Ipopt's theta_max and theta_min) */
    s->theta_max = 1e4 * fmax(1.0, g1);
    s->theta_min = 1e-4 * fmax(1.0, g1);
    s->shifts = 0;
    s->refinements = 0;
    int max_iter = s->single_step ? 1 : s->o.max_iter;
    int it = 0, stalled = 0, last_negligible = 0;
    double best = INFINITY, f_prev = f, best_ok = INFINITY;
    if (!s->o.reuse_factorization)
        s->factor_valid = 0;
    for (;; it++) {
        double res = kkt_residual(s, lambda);
        /* Round-off floor: iterations that change neither the energy (to 1e-13) nor the best
         * residual (by half) for 4 iterations in a row have hit what the arithmetic can resolve
         * (e.g. a soft phase's stresses under a 1e6 times stiffer one). Converged if that floor is
         * within sqrt(tol_kkt) and the constraints hold; a numerical failure otherwise. */
        /* (a negligible last step counts as no change of f: its f may jitter at round-off) */
        stalled = (it > 0 && (fabs(f - f_prev) <= 1e-13 * fabs(f) || last_negligible) && !(res < 0.5 * best))
                      ? stalled + 1
                      : 0;
        last_negligible = 0;
        best = fmin(best, res);
        f_prev = f;
        /* the best iterate that meets the violation tolerance, for the floor's exit */
        if (viol <= s->o.tol_violation && res < best_ok) {
            best_ok = res;
            memcpy(s->u_b, u, (size_t)n * sizeof *u);
            memcpy(s->l_b, lambda, (size_t)m * sizeof *lambda);
        }
        if (stalled >= 4) {
            int ok = res <= sqrt(s->o.tol_kkt) && viol <= s->o.tol_violation;
            if (!ok && best_ok <= sqrt(s->o.tol_kkt)) {
                /* the floor wandered off an iterate that was acceptable (its violation at the
                 * tolerance's edge): return that one */
                memcpy(u, s->u_b, (size_t)n * sizeof *u);
                memcpy(lambda, s->l_b, (size_t)m * sizeof *lambda);
                if ((st = evaluate(s, u, &f, &g1, &viol)) != PLUME_OK)
                    return st;
                ok = 1;
            }
            rep->reason = ok ? PLUME_REASON_CONVERGED : PLUME_REASON_NUMERICAL;
            break;
        }
        if (!isfinite(f) || !isfinite(res)) {
            rep->reason = PLUME_REASON_NUMERICAL;
            break;
        }
        if (s->o.verbose)
            fprintf(stderr, "  newton %3d  f % .10e  kkt %.3e  viol %.3e\n", it, f, res, viol);
        if (!s->single_step && res <= s->o.tol_kkt && viol <= s->o.tol_violation) {
            rep->reason = PLUME_REASON_CONVERGED;
            break;
        }
        if (it >= max_iter)
            break;
        double step_max;
    retry:;
        /* no chord steps within 100 tol_kkt of convergence (the last iterations are full Newton
         * steps, so the end game and the round-off floor it may meet are Newton's own), nor in
         * the last 3 iterations of the cap (a tight cap is spent on Newton steps) */
        int chord = s->o.reuse_factorization && s->factor_valid && !s->single_step &&
                    res > 100.0 * s->o.tol_kkt && it + 3 < max_iter;
        if (chord && chord_direction(s, lambda, L, &step_max)) {
            if (s->o.verbose)
                fprintf(stderr, "           chord direction unusable: refactorising\n");
            chord = 0, s->factor_valid = 0;
        }
        if (chord) /* keep the iterate, in case the chord step fails its rate test */
            save_iterate(s, 1, u, lambda, f, g1, viol);
        if (!chord) {
            st = direction(s, u, lambda, &step_max);
            if (st == PLUME_ESINGULAR) {
                s->factor_valid = 0;
                rep->reason = PLUME_REASON_NUMERICAL;
                break;
            }
            if (st != PLUME_OK)
                return st;
            s->factor_valid = 1;
            memcpy(s->jval_f, s->jval, (size_t)s->jnnz * sizeof *s->jval_f);
        }
        const double *du = s->sol, *lnew = s->sol + n;
        double dirderiv = 0.0, lmax = 0.0, mu_before = mu;
        for (plume_index i = 0; i < n; i++)
            dirderiv += s->grad[i] * du[i];
        for (plume_index r = 0; r < m; r++)
            lmax = fmax(lmax, fabs(lnew[r]));
        mu = fmax(mu, 1.5 * lmax);
        dirderiv -= mu * g1;
        double phi0 = f + mu * g1, alpha = 1.0, phi, ft;
        int accepted = 0;
        int negligible = step_max <= s->o.tol_step * L;
        last_negligible = negligible;
        if (s->single_step || negligible) {
            /* one linearised step, or a step at round-off level: no line search to do, and the
             * multipliers are taken whole (they may still have far to go) */
            for (plume_index i = 0; i < n; i++)
                u[i] += du[i];
            if (m > 0)
                memcpy(lambda, lnew, (size_t)m * sizeof *lambda);
            accepted = 1;
        } else {
            int filter = s->o.line_search == PLUME_LS_FILTER && m > 0;
            double gd = dirderiv + mu * g1; /* grad f . du */
            for (int ls = 0; ls < 60 && !accepted; ls++, alpha *= 0.5) {
                if (chord && ls > 0) {
                    /* a chord step is taken whole or not at all: refactorise and redo the iteration */
                    s->factor_valid = 0;
                    rep->chord_rejected++;
                    if (s->o.verbose)
                        fprintf(stderr, "           chord step %.3e refused whole: refactorising\n", step_max);
                    mu = mu_before;
                    goto retry;
                }
                for (plume_index i = 0; i < n; i++)
                    s->ut[i] = u[i] + alpha * du[i];
                if ((st = merit_at(s, s->ut, mu, &phi, &ft)) != PLUME_OK)
                    return st;
                if (filter) {
                    /* filter line search; a step below 2^-30 falls back to the merit function,
                     * in place of Ipopt's restoration phase */
                    int f_type;
                    double theta_t = l1norm(s->gt, m);
                    /* a full step whose change of f is at round-off level and that does not raise
                     * theta is taken, as with the merit function (the filter cannot see progress
                     * below the arithmetic's resolution) */
                    int roundoff = alpha == 1.0 && isfinite(ft) && fabs(ft - f) <= 1e-14 * fabs(f) && theta_t <= g1;
                    if (isfinite(phi) && ls < 30 &&
                        (roundoff || filter_step_ok(s, g1, f, gd, alpha, theta_t, ft, &f_type))) {
                        if (roundoff)
                            f_type = 1;
                        if (!f_type)
                            filter_add(s, (1.0 - 1e-5) * g1, f - 1e-5 * g1);
                        accepted = 1;
                        break;
                    }
                    if (ls == 0 && isfinite(phi) && theta_t >= g1) {
                        /* second-order correction at the full step */
                        for (plume_index i = 0; i < n; i++)
                            s->rhs[i] = 0.0;
                        for (plume_index r = 0; r < m; r++)
                            s->rhs[n + r] = -s->gt[r];
                        if (kkt_solve(s, s->rhs, s->rhs) == PLUME_OK) {
                            for (plume_index i = 0; i < n; i++)
                                s->ut[i] = u[i] + du[i] + s->rhs[i];
                            if ((st = merit_at(s, s->ut, mu, &phi, &ft)) != PLUME_OK)
                                return st;
                            theta_t = l1norm(s->gt, m);
                            if (isfinite(phi) && filter_step_ok(s, g1, f, gd, 1.0, theta_t, ft, &f_type)) {
                                if (!f_type)
                                    filter_add(s, (1.0 - 1e-5) * g1, f - 1e-5 * g1);
                                accepted = 1;
                                break;
                            }
                        }
                    }
                    if (ls < 29) {
                        rep->backtracks++;
                        continue;
                    }
                    if (ls == 29) { /* fall back: the l1 merit from the full step again */
                        alpha = 2.0;
                        rep->merit_fallbacks++;
                        continue;
                    }
                }
                /* accept on Armijo, or when the change is at round-off level of the merit */
                if (phi <= phi0 + 1e-4 * alpha * dirderiv ||
                    (isfinite(phi) && fabs(phi - phi0) <= 1e-14 * fabs(phi0) && alpha == 1.0)) {
                    accepted = 1;
                    break;
                }
                rep->backtracks++;
                if (ls == 0 && m > 0 && !filter) {
                    /* second-order correction: re-solve with the constraint values at the trial */
                    for (plume_index i = 0; i < n; i++)
                        s->rhs[i] = 0.0;
                    for (plume_index r = 0; r < m; r++)
                        s->rhs[n + r] = -s->gt[r];
                    if (kkt_solve(s, s->rhs, s->rhs) == PLUME_OK) {
                        for (plume_index i = 0; i < n; i++)
                            s->ut[i] = u[i] + du[i] + s->rhs[i];
                        if ((st = merit_at(s, s->ut, mu, &phi, &ft)) != PLUME_OK)
                            return st;
                        if (phi <= phi0 + 1e-4 * dirderiv) {
                            accepted = 1;
                            break;
                        }
                    }
                }
            }
            if (!accepted) {
                rep->reason = PLUME_REASON_LINE_SEARCH;
                break;
            }
            if (s->o.verbose)
                fprintf(stderr, "           step %.3e  alpha %.3e  slope %.3e  %s%.1e%s\n", step_max, alpha, dirderiv,
                        chord ? "chord, shift " : "shift ", s->shift, s->projected ? " (projected)" : "");
            memcpy(u, s->ut, (size_t)n * sizeof *u);
            /* the QP multipliers are taken whole even after a damped step: they are the current
             * least-squares estimate, and damping them too would freeze them whenever the line
             * search has to cut the primal step to nothing (redundant constraints) */
            if (m > 0)
                memcpy(lambda, lnew, (size_t)m * sizeof *lambda);
        }
        if ((st = evaluate(s, u, &f, &g1, &viol)) != PLUME_OK)
            return st;
        if (chord) {
            /* rate test: a chord step must cut the KKT residual by reuse_rate (or converge);
             * otherwise it is undone (back to the iterate before it) and the iteration
             * refactorises. Keeping the weaker chord steps and refactorising only at the next
             * iteration was measured worse (tilted traction at 4e4 elements: 74 iterations and
             * 4.0 s against 41 and 2.1 s). */
            double res_new = kkt_residual(s, lambda);
            int done = res_new <= s->o.tol_kkt && viol <= s->o.tol_violation;
            if (!(res_new <= s->o.reuse_rate * res) && !done) {
                save_iterate(s, 0, u, lambda, 0.0, 0.0, 0.0);
                f = s->saved_f, g1 = s->saved_g1, viol = s->saved_viol;
                kkt_residual(s, lambda); /* s->jtl of the restored iterate */
                s->factor_valid = 0;
                rep->chord_rejected++;
                if (s->o.verbose)
                    fprintf(stderr, "           chord step failed its rate test (residual %.3e from %.3e): undone, "
                                    "refactorising\n", res_new, res);
                goto retry;
            }
            rep->chord_steps++;
        }
        if (s->single_step) {
            it++;
            rep->reason = PLUME_REASON_SINGLE_STEP;
            break;
        }
        /* the full Newton direction (not the damped step: a line search that shrank alpha to
         * nothing has not converged) is negligible, the constraints hold and the multipliers
         * are not far off (the KKT test itself may be out of reach of round-off) */
        if (negligible && viol <= s->o.tol_violation && kkt_residual(s, lambda) <= sqrt(s->o.tol_kkt)) {
            it++;
            rep->reason = PLUME_REASON_CONVERGED;
            break;
        }
    }
    plume_problem_scatter(s->p, u);
    int f1;
    plume_chol_stats(s->chol, NULL, &f1, NULL);
    rep->converged = rep->reason == PLUME_REASON_CONVERGED;
    rep->iterations = it;
    rep->factorizations = f1 - f0;
    rep->shifts = s->shifts;
    rep->refinements = s->refinements;
    rep->energy = f;
    rep->kkt_residual = kkt_residual(s, lambda);
    rep->max_violation = viol;
    rep->seconds = plume_wall_seconds() - t0;
    return PLUME_OK;
}

void plume_newton_stats(const plume_newton *s, int *analyses, int *factorizations, double *factor_seconds)
{
    plume_chol_stats(s ? s->chol : NULL, analyses, factorizations, factor_seconds);
}
