/* Native solver. Constraints are handled by SQP on the KKT system
 *   [H + dw I   J^T ] [du     ]   [-grad f          ]
 *   [J        -dc I ] [lam_new] = [-g - dc lam      ]
 * where H is the exact Hessian of the Lagrangian (Ipopt's inertia correction: a diagonal shift
 * carried from one iteration to the next), or, failing that, the one with every element block
 * projected to PSD. The "- dc lam" term (a proximal term on the multipliers) keeps the fixed point
 * exact: at du = 0, lam_new = lam we have g = 0, whatever the small regularisation dc (a diagonal,
 * one value per constraint scaled to the stiffness of its own dofs: newton_kkt.c). Two ways to
 * factorise:
 * - PLUME_KKT_ELIMINATE (default): the -dc I block is eliminated, leaving the SPD matrix
 *   H + dw I + J^T J / dcf on the Hessian's own pattern (edge constraints couple vertices that
 *   already share a triangle), factorised by CHOLMOD's supernodal LL^T; lam_new is recovered as
 *   lam + (J du + g) / dcf. With kkt_refine, dcf = 1e3 dc and iterative refinement solves the dc
 *   system (kkt_solve_j). Same iterates as LDL^T in our tests, faster factorisations (docs/theory-constraints.md).
 * - PLUME_KKT_LDL: the quasi-definite matrix itself, whose LDL^T without pivoting exists for any
 *   ordering, by CHOLMOD's simplicial LDL^T.
 * Either way the symbolic analysis is done once. Globalisation: Ipopt's filter line search
 * (falling back to the l1 merit below a step of 2^-29) or the l1 merit f + mu |g|_1 with Armijo
 * backtracking, each with one second-order correction (against the Maratos effect). The line
 * search follows the curve u + alpha du + alpha^2/2 a, a the geodesic acceleration (every step
 * without constraints; with them, a full step the filter refused), or (trust_region) an adaptive
 * regularisation replaces it. Optional chord steps reuse the last factorisation. Without
 * constraints this is Newton with LL^T and the same exact-first rule. */
#include "newton.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cholesky.h"
#include "internal/cholesky_like.h"
#include "internal/newton_state.h"
#include "../io/progress.h"

/* a chord step is tried when its predicted contraction of the error is at most this */
#define CHORD_MAX_CONTRACTION 1e-2
/* chord steps stop when the rate they reach predicts more than this many to converge */
#define CHORD_MAX_MORE 4.0

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
    free(s->grad_t);
    free(s->g);
    free(s->gt);
    free(s->rhs);
    free(s->sol);
    free(s->ut);
    free(s->jtl);
    free(s->acc);
    free(s->acc_g);
    free(s->dcv);
    free(s->dcfv);
    free(s->acc_j);
    free(s);
    *ps = NULL;
}

plume_status plume_newton_create(plume_problem *p, const plume_solver_opts *o, int single_step,
                                 plume_newton **out, plume_err *err)
{
    return plume_newton_create_like(p, o, single_step, NULL, out, err);
}

plume_status plume_newton_create_like(plume_problem *p, const plume_solver_opts *o, int single_step, const plume_newton *like,
                            plume_newton **out, plume_err *err)
{
    if (!p || !o || !out)
        return plume_err_set(err, PLUME_EINVAL, "newton: invalid arguments");
    *out = NULL;
    if (o->max_iter < 0 || o->stall_iterations < 0 || !(o->tol_kkt > 0.0) || !(o->tol_violation > 0.0) || !(o->tol_step >= 0.0) ||
        !(o->max_step > 0.0) || !isfinite(o->tol_kkt + o->tol_violation + o->tol_step + o->max_step))
        return plume_err_set(err, PLUME_EINVAL,
                             "newton: options need max_iter >= 0, stall_iterations >= 0, tol_kkt > 0, tol_violation > 0, tol_step >= 0, "
                             "max_step > 0, all finite");
    if ((unsigned)o->line_search > PLUME_LS_MERIT || !(o->reuse_rate > 0.0 && o->reuse_rate < 1.0) ||
        !(o->inertia_max_shift > 0.0) || !isfinite(o->inertia_max_shift))
        return plume_err_set(err, PLUME_EINVAL,
                             "newton: options need line_search PLUME_LS_FILTER or PLUME_LS_MERIT, reuse_rate in (0, 1), "
                             "inertia_max_shift > 0 and finite (got %d, %g, %g)",
                             (int)o->line_search, o->reuse_rate, o->inertia_max_shift);
    plume_status st = PLUME_OK;
    plume_newton *s = calloc(1, sizeof *s);
    if (!s)
        return PLUME_ENOMEM;
    s->p = p;
    s->o = *o;
    s->single_step = single_step;
    s->limits = plume_problem_limits_steps(p);
    s->refine_rtol = 1e-15;
    s->n = plume_problem_nfree(p);
    s->m = plume_problem_ncons(p);
    s->nk = s->n + s->m;
    s->hp = plume_problem_hessian_pattern(p);
    const plume_sparsity base = plume_problem_fixed_pattern(p);
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
    s->grad_t = malloc((n + 1) * sizeof *s->grad_t);
    s->g = malloc((m + 1) * sizeof *s->g);
    s->gt = malloc((m + 1) * sizeof *s->gt);
    s->rhs = malloc((nk + 1) * sizeof *s->rhs);
    s->sol = malloc((nk + 1) * sizeof *s->sol);
    s->ut = malloc((n + 1) * sizeof *s->ut);
    s->jtl = malloc((n + 1) * sizeof *s->jtl);
    s->acc = malloc((n + 1) * sizeof *s->acc);
    s->acc_g = malloc((m + 1) * sizeof *s->acc_g);
    s->dcv = malloc((m + 1) * sizeof *s->dcv);
    s->dcfv = malloc((m + 1) * sizeof *s->dcfv);
    s->acc_j = malloc(((size_t)s->jnnz + 1) * sizeof *s->acc_j);
    s->diagpos = malloc((nk + 1) * sizeof *s->diagpos);
    if (!s->hval || !s->acc || !s->acc_g || !s->dcv || !s->dcfv || !s->acc_j || !s->jval || !s->grad || !s->grad_t || !s->g || !s->gt || !s->rhs || !s->sol || !s->ut || !s->jtl ||
        !s->diagpos || !s->jval_f || !s->rb || !s->rr || !s->rd || !s->jval_s || !s->u_s || !s->grad_s || !s->l_s || !s->g_s || !s->u_b ||
        !s->l_b) {
        st = PLUME_ENOMEM;
        goto fail;
    }
    s->eliminate = s->m > 0 && o->kkt == PLUME_KKT_ELIMINATE;
    if (s->eliminate) {
        if ((st = plume_newton_build_elimination_pairs(s)) != PLUME_OK)
            goto fail;
        s->kval = malloc(((size_t)s->hp.nnz + 1) * sizeof *s->kval);
        if (!s->kval) {
            st = PLUME_ENOMEM;
            goto fail;
        }
        st = plume_chol_create_like(s->n, s->hp.colptr, s->hp.rowind, 0, base.colptr, base.rowind, like ? like->chol : NULL,
                                    &s->chol, err);
    } else if (s->m > 0) {
        if ((st = plume_newton_build_kkt_pattern(s)) != PLUME_OK)
            goto fail;
        s->kval = malloc(((size_t)s->kcolptr[nk] + 1) * sizeof *s->kval);
        if (!s->kval) {
            st = PLUME_ENOMEM;
            goto fail;
        }
        st = plume_chol_create(s->nk, s->kcolptr, s->krowind, 1, &s->chol, err);
    } else {
        st = plume_chol_create_like(s->n, s->hp.colptr, s->hp.rowind, 0, base.colptr, base.rowind, like ? like->chol : NULL,
                                    &s->chol, err);
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

/* f, grad, g, |g|_1, max relative violation and the Jacobian at u. When u is the line search's
 * first trial, accepted, its f and gradient were computed with it (merit_at, trial_grad): the
 * energy is then evaluated once an iteration instead of twice (the problem's current point is
 * already u, for the constraints). */
static plume_status evaluate(plume_newton *s, const double *u, double *f, double *g1, double *viol)
{
    plume_status st = PLUME_OK;
    if (s->trial_grad) {
        double *t = s->grad;
        s->grad = s->grad_t, s->grad_t = t;
        *f = s->trial_f;
        s->trial_grad = 0;
    } else {
        st = plume_problem_objective(s->p, u, f, s->grad);
    }
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

/* merit f + mu |g|_1 at u; with_grad: the gradient too, into s->grad_t, for evaluate() to take
 * if this trial is accepted as it is (s->trial_grad) */
static plume_status merit_at(plume_newton *s, const double *u, double mu, double *phi, double *fval, int with_grad)
{
    double f;
    s->trial_grad = 0;
    plume_status st = plume_problem_objective(s->p, u, &f, with_grad ? s->grad_t : NULL);
    if (st == PLUME_OK && with_grad && isfinite(f)) {
        s->trial_grad = 1;
        s->trial_f = f;
    }
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

/* The trust region's quadratic model of the l1 merit along alpha du, its decrease from the
 * current point: -(alpha grad.du + alpha^2/2 du.H du) + mu (|g|_1 - |g + alpha J du|_1), with H the
 * Hessian last assembled (s->hval, without any shift) and J the current Jacobian. *rayleigh gets
 * |du.H du| / |du|^2, the curvature along du (the scale of a first regularisation). */
static double tr_model_decrease(plume_newton *s, const double *du, double alpha, double mu, double g1,
                                double *rayleigh)
{
    const plume_index n = s->n, m = s->m, *cp = s->hp.colptr, *ri = s->hp.rowind;
    double gd = 0.0, dhd = 0.0, dd = 0.0;
    for (plume_index c = 0; c < n; c++) {
        gd += s->grad[c] * du[c];
        dd += du[c] * du[c];
        for (plume_index k = cp[c]; k < cp[c + 1]; k++) /* lower triangle, the diagonal included */
            dhd += (ri[k] == c ? 1.0 : 2.0) * s->hval[k] * du[ri[k]] * du[c];
    }
    *rayleigh = dd > 0.0 ? fabs(dhd) / dd : 0.0;
    double lin = 0.0;
    if (m > 0) {
        double *gl = s->rr; /* the refinement's workspace, free once the direction is solved */
        memcpy(gl, s->g, (size_t)m * sizeof *s->g);
        for (plume_index k = 0; k < s->jnnz; k++)
            gl[s->jrow[k]] += alpha * s->jval[k] * du[s->jcol[k]];
        lin = mu * (g1 - l1norm(gl, m));
    }
    return -(alpha * gd + 0.5 * alpha * alpha * dhd) + lin;
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

/* filter_step_ok, and the filter gains the current point's entry when the step is not f-type
 * (a full step at round-off level, `roundoff`, counts as f-type) */
static int filter_take(plume_newton *s, double theta0, double f0, double gd, double alpha, double theta_t, double f_t,
                       int roundoff)
{
    int f_type = 1;
    if (!roundoff && !filter_step_ok(s, theta0, f0, gd, alpha, theta_t, f_t, &f_type))
        return 0;
    if (!f_type)
        filter_add(s, (1.0 - 1e-5) * theta0, f0 - 1e-5 * theta0);
    return 1;
}

/* The second-order correction of a rejected full step: u + du + d, d solving the KKT system with
 * the constraint values at the trial (s->gt); the point goes to s->ut, its merit to *phi and f to
 * *ft. *ok = 0 when the solve failed (nothing evaluated). */
static plume_status soc_trial(plume_newton *s, const double *u, const double *du, double mu, double *phi, double *ft,
                              int *ok)
{
    plume_index n = s->n, m = s->m;
    for (plume_index i = 0; i < n; i++)
        s->rhs[i] = 0.0;
    for (plume_index r = 0; r < m; r++)
        s->rhs[n + r] = -s->gt[r];
    s->trial_grad = 0; /* s->ut is about to be another point */
    *ok = plume_newton_kkt_solve(s, s->rhs, s->rhs) == PLUME_OK;
    if (!*ok)
        return PLUME_OK;
    for (plume_index i = 0; i < n; i++)
        s->ut[i] = u[i] + du[i] + s->rhs[i];
    if (s->limits) { /* the corrected point must be reachable without crossing too */
        double a;
        for (plume_index i = 0; i < n; i++)
            s->rd[i] = s->ut[i] - u[i];
        plume_status st = plume_problem_max_step(s->p, u, s->rd, &a);
        if (st != PLUME_OK)
            return st;
        if (!(a >= 1.0)) {
            *ok = 0;
            return PLUME_OK;
        }
    }
    return merit_at(s, s->ut, mu, phi, ft, 0);
}

/* relative KKT residual from the current grad, jval and lambda */
static double kkt_residual(plume_newton *s, const double *lambda)
{
    memset(s->jtl, 0, (size_t)s->n * sizeof *s->jtl);
    for (plume_index k = 0; k < s->jnnz; k++)
        s->jtl[s->jcol[k]] += s->jval[k] * lambda[s->jrow[k]];
    double gm = 0.0, jm = 0.0, rm = 0.0;
    for (plume_index i = 0; i < s->n; i++) {
        gm = nt_max_abs(gm, s->grad[i]);
        jm = nt_max_abs(jm, s->jtl[i]);
        rm = nt_max_abs(rm, s->grad[i] + s->jtl[i]);
    }
    if (!isfinite(rm) || !isfinite(gm))
        return NAN;
    double ref = fmax(plume_problem_force_scale(s->p), fmax(gm, jm));
    return ref > 0.0 ? rm / ref : 0.0;
}

/* The largest regularisation the trust region tries, relative to the largest Hessian diagonal,
 * before it reports that no step decreases the merit */
#define TR_MAX_SIGMA 1e8

/* One trust-region trial: u + alpha du (alpha below 1 only where continuous collision detection
 * cuts the step). Taken (*taken = 1: u and lambda move) when the l1 merit falls by at least 1e-4
 * of what the quadratic model predicts, rho = actual / predicted; the regularisation shrinks 8x
 * after a step with rho > 0.75 and grows 4x after one with rho < 0.25. Refused (*taken = 0): the
 * regularisation grows (the first time to the curvature along du, which halves the step along its
 * softest part) and the caller refactorises. *taken = -1: no regularisation up to TR_MAX_SIGMA
 * times the Hessian's scale gave a decrease. */
static plume_status trust_region_step(plume_newton *s, double *u, double *lambda, const double *du,
                                      const double *lnew, double alpha, double mu, double f, double g1,
                                      int *taken)
{
    const plume_index n = s->n, m = s->m;
    double hmax = 0.0, phi, ft, rq;
    for (plume_index c = 0; c < n; c++)
        hmax = fmax(hmax, fabs(s->hval[s->hp.colptr[c + 1] - 1]));
    for (plume_index i = 0; i < n; i++)
        s->ut[i] = u[i] + alpha * du[i];
    plume_status st = merit_at(s, s->ut, mu, &phi, &ft, 1);
    if (st != PLUME_OK)
        return st;
    const double phi0 = f + mu * g1;
    const double pred = tr_model_decrease(s, du, alpha, mu, g1, &rq), ared = phi0 - phi;
    const int roundoff = isfinite(phi) && fabs(phi - phi0) <= 1e-14 * fabs(phi0);
    const double rho = pred > 0.0 ? ared / pred : (ared > 0.0 ? 1.0 : -1.0);
    *taken = isfinite(phi) && (rho > 1e-4 || roundoff);
    if (*taken) {
        memcpy(u, s->ut, (size_t)n * sizeof *u);
        if (m > 0)
            memcpy(lambda, lnew, (size_t)m * sizeof *lambda);
        if (rho > 0.75 || roundoff)
            s->tr_sigma = s->tr_sigma > 1e-12 * hmax ? s->tr_sigma / 8.0 : 0.0;
        else if (rho < 0.25)
            s->tr_sigma = s->tr_sigma > 0.0 ? 4.0 * s->tr_sigma : fmax(rq, 1e-12 * hmax);
        return PLUME_OK;
    }
    s->trial_grad = 0; /* the trial's gradient is not the next iterate's */
    s->tr_sigma = s->tr_sigma > 0.0 ? 4.0 * s->tr_sigma : fmax(rq, 1e-12 * hmax);
    if (!(s->tr_sigma <= TR_MAX_SIGMA * fmax(hmax, 1e-300)))
        *taken = -1;
    return PLUME_OK;
}

/* Geodesic acceleration (Transtrum & Sethna 2012) of the Newton direction du, for a curved line
 * search u + alpha du + alpha^2 / 2 a. On a shell the straight Newton step from a flat or nearly
 * flat state is all out of plane, and any transverse move beyond the thickness stretches the
 * membrane at second order: the line search then crawls along the valley of inextensional
 * motions about a thickness an iteration. The acceleration is the in-plane motion that keeps the
 * step in that valley to second order: a solves the same KKT system as du with the right-hand side
 * -(D^2 grad L [du, du], D^2 g [du, du]), the second directional derivatives of the Lagrangian's
 * gradient (multipliers lnew) and of the constraints along du, by central differences with
 * h max|du| = 1e-3 of the body. Into s->acc; nonzero when unusable, or when |a| > ACC_MAX_RATIO |du|
 * (the path's second-order term then dominates its first: the model behind it is not to be
 * trusted). */
#define ACC_MAX_RATIO 1.5

/* grad f + J^T lam at u + h du into out (n), g into gc (m) */
static plume_status lagrangian_gradient_at(plume_newton *s, const double *u, const double *du, double h,
                                           const double *lam, double *out, double *gc)
{
    double f;
    for (plume_index i = 0; i < s->n; i++)
        s->ut[i] = u[i] + h * du[i];
    plume_status st = plume_problem_objective(s->p, s->ut, &f, out);
    if (st != PLUME_OK || s->m == 0)
        return st;
    if ((st = plume_problem_constraints(s->p, s->ut, gc, NULL)) != PLUME_OK ||
        (st = plume_problem_jacobian(s->p, s->ut, s->acc_j)) != PLUME_OK)
        return st;
    for (plume_index k = 0; k < s->jnnz; k++)
        out[s->jcol[k]] += s->acc_j[k] * lam[s->jrow[k]];
    return PLUME_OK;
}

static int geodesic_acceleration(plume_newton *s, const double *u, const double *du, const double *lnew,
                                 double step_max, double L)
{
    const plume_index n = s->n, m = s->m;
    if (!(step_max > 0.0))
        return 1;
    const double h = fmin(1.0, 1e-3 * L / step_max);
    double *gp = s->grad_t, *gm = s->acc, *r = s->rhs;
    s->trial_grad = 0;
    if (lagrangian_gradient_at(s, u, du, h, lnew, gp, r + n) != PLUME_OK)
        return 1;
    for (plume_index i = 0; i < n; i++)
        r[i] = gp[i] - 2.0 * s->grad[i];
    for (plume_index q = 0; q < m; q++)
        r[n + q] -= 2.0 * s->g[q];
    if (lagrangian_gradient_at(s, u, du, -h, lnew, gm, s->acc_g) != PLUME_OK)
        return 1;
    for (plume_index k = 0; k < s->jnnz; k++) /* J(u)^T lnew, twice */
        r[s->jcol[k]] -= 2.0 * s->jval[k] * lnew[s->jrow[k]];
    for (plume_index i = 0; i < n; i++)
        r[i] = -(r[i] + gm[i]) / (h * h);
    for (plume_index q = 0; q < m; q++)
        r[n + q] = -(r[n + q] + s->acc_g[q]) / (h * h);
    if (plume_newton_kkt_solve(s, r, r) != PLUME_OK)
        return 1;
    double an = 0.0, vn = 0.0;
    for (plume_index i = 0; i < n; i++) {
        s->acc[i] = r[i];
        if (!isfinite(r[i]))
            return 1;
        an += r[i] * r[i], vn += du[i] * du[i];
    }
    if (s->o.verbose)
        fprintf(stderr, "           acceleration |a| / |du| = %.3e\n", sqrt(an / vn));
    return !(an <= ACC_MAX_RATIO * ACC_MAX_RATIO * vn);
}

/* save (1) or restore (0) the iterate: u, lambda and what evaluate() computed there */
static void save_iterate(plume_newton *s, int save, double *u, double *lambda, double f, double g1, double viol)
{
    size_t n = (size_t)s->n, m = (size_t)s->m, j = (size_t)s->jnnz;
    if (save) {
        memcpy(s->u_s, u, n * sizeof *u);
        if (m > 0) /* lambda may be NULL without constraints */
            memcpy(s->l_s, lambda, m * sizeof *lambda);
        memcpy(s->grad_s, s->grad, n * sizeof *u);
        memcpy(s->g_s, s->g, m * sizeof *u);
        memcpy(s->jval_s, s->jval, j * sizeof *u);
        s->saved_f = f, s->saved_g1 = g1, s->saved_viol = viol;
    } else {
        memcpy(u, s->u_s, n * sizeof *u);
        if (m > 0)
            memcpy(lambda, s->l_s, m * sizeof *lambda);
        memcpy(s->grad, s->grad_s, n * sizeof *u);
        memcpy(s->g, s->g_s, m * sizeof *u);
        memcpy(s->jval, s->jval_s, j * sizeof *u);
    }
}

/* plume_newton_solve's running state, shared by the jobs it is split into */
typedef struct {
    double *u, *lambda;      /* the iterate: the caller's arrays */
    plume_solve_report *rep;
    double L;                /* the problem's length scale (tol_step is relative to it) */
    int max_iter;
    double f, g1, viol;      /* the energy, |g|_1 and the largest relative violation at u */
    double mu;               /* the l1 merit's penalty, nondecreasing over the solve */
    double res;              /* the KKT residual at the start of the iteration */
    /* progress over the iterations: the round-off floor (stalled, f_prev, best), the best iterate
     * within the violation tolerance (best_ok; u_b, l_b), stall_iterations (flat, best_res,
     * best_viol), continuous collision detection's blocked steps */
    double f_prev, best, best_ok, best_res, best_viol;
    int stalled, flat, blocked;
    int held;                /* the last iteration's trust-region step was refused: u has not moved */
    int last_negligible;     /* the last step was at round-off level */
} nt_run;

/* one iteration's step */
typedef struct {
    int chord;               /* along a chord direction (the last factorisation reused) */
    double mu_before;        /* the merit's penalty before this direction raised it */
    double step_max;         /* max |du| */
    double dirderiv;         /* the l1 merit's slope along du */
    double alpha_max;        /* continuous collision detection: no trial beyond it (1: no bound) */
    double alpha;            /* the step taken along du */
    int negligible;          /* step_max at round-off level (tol_step) */
    int accepted;
} nt_step;

/* how an iteration's step ended */
typedef enum {
    STEP_TAKEN,  /* u moved: after_step */
    STEP_HELD,   /* the trust region refused the step: u in place, a larger regularisation */
    STEP_REDO,   /* no chord step after all (unusable direction, refused, undone): factorise */
    STEP_FAILED, /* the solve ends here, rep->reason set; this iteration does not count */
    STEP_FINAL   /* the solve ends here, rep->reason set; this iteration counts */
} nt_outcome;

/* The bookkeeping at an iteration's start: the round-off floor's count, the best residual and the
 * best iterate within the violation tolerance. Round-off floor: iterations that change neither
 * the energy (to 1e-13) nor the best residual (by half) for 4 iterations in a row have hit what
 * the arithmetic can resolve (e.g. a soft phase's stresses under a 1e6 times stiffer one). A
 * negligible last step counts as no change of f (its f may jitter at round-off); an iteration
 * whose trust-region step was refused (held) has not moved: not a stall. */
static void track_progress(plume_newton *s, nt_run *c, int it)
{
    if (!c->held)
        c->stalled = (it > 0 && (fabs(c->f - c->f_prev) <= 1e-13 * fabs(c->f) || c->last_negligible) &&
                      !(c->res < 0.5 * c->best))
                         ? c->stalled + 1
                         : 0;
    c->held = 0;
    c->last_negligible = 0;
    c->best = fmin(c->best, c->res);
    c->f_prev = c->f;
    if (c->viol <= s->o.tol_violation && c->res < c->best_ok) {
        c->best_ok = c->res;
        memcpy(s->u_b, c->u, (size_t)s->n * sizeof *c->u);
        if (s->m > 0) /* lambda may be NULL without constraints */
            memcpy(s->l_b, c->lambda, (size_t)s->m * sizeof *c->lambda);
    }
}

/* The round-off floor reached: converged if the floor is within sqrt(tol_kkt) and the
 * constraints hold, or if an earlier iterate was acceptable (its violation at the tolerance's
 * edge) and the floor wandered off it: that one is returned. A numerical failure otherwise. */
static plume_status roundoff_floor_exit(plume_newton *s, nt_run *c)
{
    int ok = c->res <= sqrt(s->o.tol_kkt) && c->viol <= s->o.tol_violation;
    if (!ok && c->best_ok <= sqrt(s->o.tol_kkt)) {
        memcpy(c->u, s->u_b, (size_t)s->n * sizeof *c->u);
        if (s->m > 0)
            memcpy(c->lambda, s->l_b, (size_t)s->m * sizeof *c->lambda);
        s->trial_grad = 0;
        plume_status st = evaluate(s, c->u, &c->f, &c->g1, &c->viol);
        if (st != PLUME_OK)
            return st;
        ok = 1;
    }
    c->rep->reason = ok ? PLUME_REASON_CONVERGED : PLUME_REASON_NUMERICAL;
    return PLUME_OK;
}

/* The tests at an iteration's start, in order: the round-off floor, a non-finite iterate, the KKT
 * test, stall_iterations, the iteration cap. *stop = 1 when the solve ends here (rep->reason set,
 * or left at the iteration cap). */
static plume_status convergence_test(plume_newton *s, nt_run *c, int it, int *stop)
{
    plume_solve_report *rep = c->rep;
    const int held_before = c->held;
    *stop = 1;
    c->res = kkt_residual(s, c->lambda);
    track_progress(s, c, it);
    if (c->stalled >= 4)
        return roundoff_floor_exit(s, c);
    if (!isfinite(c->f) || !isfinite(c->res)) {
        rep->reason = PLUME_REASON_NUMERICAL;
        return PLUME_OK;
    }
    if (s->o.verbose)
        fprintf(stderr, "  newton %3d  f % .10e  kkt %.3e  viol %.3e\n", it, c->f, c->res, c->viol);
    if (!s->single_step && c->res <= s->o.tol_kkt && c->viol <= s->o.tol_violation) {
        rep->reason = PLUME_REASON_CONVERGED;
        return PLUME_OK;
    }
    /* stall_iterations: an iteration contracts when it halves the best KKT residual or the
     * best violation of this solve; a run of iterations that do neither (a line search
     * creeping, an inertia shift holding the steps back) is reported at once, for a caller
     * that has a smaller increment to try (lib/dynamics.c) */
    if (c->res < 0.5 * c->best_res || c->viol < 0.5 * c->best_viol || it == 0)
        c->flat = 0;
    else if (!held_before)
        c->flat++;
    c->best_res = fmin(c->best_res, c->res);
    c->best_viol = fmin(c->best_viol, c->viol);
    if (s->o.stall_iterations > 0 && c->flat >= s->o.stall_iterations && !s->single_step) {
        rep->reason = PLUME_REASON_STALLED;
        return PLUME_OK;
    }
    *stop = it >= c->max_iter;
    return PLUME_OK;
}

/* Chord steps only where the last factorisation predicts a fast contraction (the end game of a
 * Newton solve), nor in the last 3 iterations of the cap (a tight cap is spent on Newton steps).
 * In Newton's quadratic regime e' = C e^2 with steps s ~ e, so the two last full Newton steps of
 * this solve give C ~ s_f / s_{f-1}^2, and a chord step at x_f + s_f with x_f's matrix contracts
 * by about C s_f = (s_f / s_{f-1})^2. Measured (docs/theory-constraints.md): tried whenever a
 * factorisation was valid they mostly failed their rate test early in a load step, where the
 * residual lags the error. */
static int chord_wanted(const plume_newton *s, const nt_run *c, int it)
{
    double chord_rho = s->chord_prev > 0.0 ? (s->chord_last / s->chord_prev) * (s->chord_last / s->chord_prev) : INFINITY;
    return s->o.reuse_factorization && s->factor_valid && !s->single_step && !s->limits && !s->o.trust_region &&
           chord_rho <= CHORD_MAX_CONTRACTION && it + 3 < c->max_iter;
}

/* The step direction in s->sol (du, then the new multipliers): a chord direction from the last
 * factorisation (d->chord; the iterate is saved, in case the step fails its rate test), or a
 * factorisation with inertia correction or partial projection (plume_newton_direction); then the merit's
 * penalty and slope along du, and continuous collision detection's bound on the step.
 * STEP_REDO: the chord direction is unusable; STEP_FAILED: the matrix is singular. */
static plume_status step_direction(plume_newton *s, nt_run *c, nt_step *d, nt_outcome *out)
{
    const plume_index n = s->n, m = s->m;
    plume_status st;
    *out = STEP_TAKEN;
    if (d->chord) {
        if (plume_newton_chord_direction(s, c->lambda, c->L, &d->step_max)) {
            if (s->o.verbose)
                fprintf(stderr, "           chord direction unusable: refactorising\n");
            s->factor_valid = 0;
            *out = STEP_REDO;
            return PLUME_OK;
        }
        save_iterate(s, 1, c->u, c->lambda, c->f, c->g1, c->viol);
    } else {
        st = plume_newton_direction(s, c->u, c->lambda, &d->step_max);
        if (st == PLUME_ESINGULAR) {
            s->factor_valid = 0;
            c->rep->reason = PLUME_REASON_NUMERICAL;
            *out = STEP_FAILED;
            return PLUME_OK;
        }
        if (st != PLUME_OK)
            return st;
        s->factor_valid = 1;
        memcpy(s->jval_f, s->jval, (size_t)s->jnnz * sizeof *s->jval_f);
    }
    const double *du = s->sol, *lnew = s->sol + n;
    double lmax = 0.0;
    d->dirderiv = 0.0;
    d->mu_before = c->mu;
    for (plume_index i = 0; i < n; i++)
        d->dirderiv += s->grad[i] * du[i];
    for (plume_index r = 0; r < m; r++)
        lmax = nt_max_abs(lmax, lnew[r]);
    c->mu = fmax(c->mu, 1.5 * lmax);
    d->dirderiv -= c->mu * c->g1;
    d->alpha_max = 1.0;
    if (s->limits) {
        if ((st = plume_problem_max_step(s->p, c->u, du, &d->alpha_max)) != PLUME_OK)
            return st;
        c->rep->step_limited += d->alpha_max < 1.0;
    }
    return PLUME_OK;
}

/* the step taken whole: one linearised step, or a step at round-off level (no line search to
 * do); the multipliers are taken whole (they may still have far to go) */
static void whole_step(plume_newton *s, nt_run *c, nt_step *d)
{
    for (plume_index i = 0; i < s->n; i++)
        c->u[i] += d->alpha_max * s->sol[i];
    if (s->m > 0)
        memcpy(c->lambda, s->sol + s->n, (size_t)s->m * sizeof *c->lambda);
    d->accepted = 1;
}

/* The trust region's iteration (trust_region_step). Refused (STEP_HELD): the same iterate, a
 * larger regularisation, a new factorisation at the next iteration; no regularisation left:
 * STEP_FAILED. */
static plume_status trust_region_iteration(plume_newton *s, nt_run *c, nt_step *d, nt_outcome *out)
{
    int taken;
    plume_status st = trust_region_step(s, c->u, c->lambda, s->sol, s->sol + s->n, d->alpha_max, c->mu, c->f, c->g1,
                                        &taken);
    if (st != PLUME_OK)
        return st;
    if (taken < 0) {
        c->rep->reason = PLUME_REASON_LINE_SEARCH;
        *out = STEP_FAILED;
        return PLUME_OK;
    }
    if (!taken) {
        c->rep->rejected_steps++;
        c->held = 1;
        *out = STEP_HELD;
        /* the problem's state back at u (the trial moved it: caches such as contact pairs) */
        return evaluate(s, c->u, &c->f, &c->g1, &c->viol);
    }
    d->accepted = 1;
    if (s->o.verbose)
        fprintf(stderr, "           step %.3e  alpha %.3e  slope %.3e  sigma %.1e  shift %.1e%s\n", d->step_max,
                d->alpha, d->dirderiv, s->tr_sigma, s->shift, s->projected ? " (projected)" : "");
    return PLUME_OK;
}

/* one line search's state */
typedef struct {
    int trial;               /* the trial's index (0: the full step) */
    double alpha;            /* the trial's step */
    double phi0;             /* the l1 merit at u */
    double gd;               /* grad f . du */
    double phi, ft;          /* the trial's merit and energy */
    int filter;              /* Ipopt's filter (with constraints), else the l1 merit with Armijo */
    int curve_first;         /* every search follows the curve (no constraints) */
    int curved;              /* the trials follow u + alpha du + alpha^2 / 2 acc */
    int accepted;
} nt_search;

/* The curved search may start: the geodesic acceleration is computed (into s->acc) only where
 * the curve may be followed, and it must be usable. Without constraints every line search follows
 * the curve. With them, only a full step the filter refused is retried along it: measured on the
 * feather at 11.4k elements, curving every step took 72 iterations against 55
 * (docs/solver-nonconvexity.md) */
static int curve_available(plume_newton *s, const nt_run *c, const nt_step *d)
{
    return !s->limits && !d->chord && s->o.curved_search &&
           !geodesic_acceleration(s, c->u, s->sol, s->sol + s->n, d->step_max, c->L);
}

/* A trial with Ipopt's filter (ls < 30): accepted, or the next trial set up (halved from
 * ls->alpha by the caller): a second-order correction of a refused full step, a restart along the
 * curve, a backtrack, and below 2^-29 the fallback to the l1 merit from the full step again, in
 * place of Ipopt's restoration phase */
static plume_status filter_trial(plume_newton *s, nt_run *c, const nt_step *d, nt_search *ls)
{
    const plume_index m = s->m;
    const double f = c->f, g1 = c->g1;
    plume_solve_report *rep = c->rep;
    double theta_t = l1norm(s->gt, m);
    /* a full step whose change of f is at round-off level and that does not raise theta is
     * taken, as with the merit function (the filter cannot see progress below the arithmetic's
     * resolution) */
    int roundoff = ls->alpha == 1.0 && isfinite(ls->ft) && fabs(ls->ft - f) <= 1e-14 * fabs(f) && theta_t <= g1;
    if (isfinite(ls->phi) && filter_take(s, g1, f, ls->gd, ls->alpha, theta_t, ls->ft, roundoff)) {
        ls->accepted = 1;
        return PLUME_OK;
    }
    if (ls->trial == 0 && ls->alpha == 1.0 && !ls->curved && isfinite(ls->phi) && theta_t >= g1) { /* second-order correction */
        int ok;
        plume_status st = soc_trial(s, c->u, s->sol, c->mu, &ls->phi, &ls->ft, &ok);
        if (st != PLUME_OK)
            return st;
        if (ok && isfinite(ls->phi) && filter_take(s, g1, f, ls->gd, 1.0, l1norm(s->gt, m), ls->ft, 0)) {
            ls->accepted = 1;
            return PLUME_OK;
        }
    }
    if (ls->trial == 0 && !ls->curve_first && !ls->curved && curve_available(s, c, d)) {
        rep->backtracks++;
        ls->curved = 1;
        rep->curved_searches++;
        ls->alpha *= 2.0; /* the same step again, along the curve */
        return PLUME_OK;
    }
    if (ls->trial < 29) {
        rep->backtracks++;
        return PLUME_OK;
    }
    /* ls == 29: fall back to the l1 merit from the full step again */
    ls->alpha = 2.0 * d->alpha_max;
    rep->merit_fallbacks++;
    return PLUME_OK;
}

/* The round-off of a merit summed over many terms, relative to its value (a sum of N terms
 * carries up to N machine epsilons of its terms: 2e-12 for 10^4 of them): a full step whose
 * predicted decrease is below it cannot be judged by Armijo. Measured on split vanes: an energy
 * of 2.3e-6 J changes by 5e-21 to 7e-20 J (2e-14 to 3e-14 of it) between points 3e-11 m apart
 * where the step predicts a decrease of 1e-20 J, one of 7.2e-10 J by steps predicting 1.3e-22 J
 * (2e-13 of it); each such solve backtracked 50 to 90 times before the round-off floor exit
 * ended it. */
#define MERIT_ROUNDOFF 1e-12

/* A trial with the l1 merit: accepted on Armijo, or when the change is at round-off level of the
 * merit (a full step whose change is within 1e-14 of it; or within MERIT_ROUNDOFF of it when the
 * step predicts a decrease below that too); else a backtrack, after the first trial a restart
 * along the curve or a second-order correction */
static plume_status merit_trial(plume_newton *s, nt_run *c, const nt_step *d, nt_search *ls)
{
    const double change = fabs(ls->phi - ls->phi0), scale = fabs(ls->phi0);
    if (ls->phi <= ls->phi0 + 1e-4 * ls->alpha * d->dirderiv ||
        (isfinite(ls->phi) && ls->alpha == 1.0 &&
         (change <= 1e-14 * scale || (change <= MERIT_ROUNDOFF * scale && fabs(d->dirderiv) <= MERIT_ROUNDOFF * scale)))) {
        ls->accepted = 1;
        return PLUME_OK;
    }
    c->rep->backtracks++;
    if (ls->trial == 0 && !ls->curve_first && !ls->curved && curve_available(s, c, d)) {
        ls->curved = 1;
        c->rep->curved_searches++;
        ls->alpha *= 2.0; /* the same step again, along the curve */
        return PLUME_OK;
    }
    if (ls->trial == 0 && ls->alpha == 1.0 && s->m > 0 && !ls->filter && !ls->curved) { /* second-order correction */
        int ok;
        plume_status st = soc_trial(s, c->u, s->sol, c->mu, &ls->phi, &ls->ft, &ok);
        if (st != PLUME_OK)
            return st;
        if (ok && ls->phi <= ls->phi0 + 1e-4 * d->dirderiv)
            ls->accepted = 1;
    }
    return PLUME_OK;
}

/* The line search along du, or along the curve u + alpha du + alpha^2 / 2 acc (curve_available):
 * the filter for its first 30 trials where there are constraints, the l1 merit otherwise. A chord
 * step is taken whole or not at all (STEP_REDO: refactorise and redo the iteration); no step
 * found: STEP_FAILED. */
static plume_status line_search(plume_newton *s, nt_run *c, nt_step *d, nt_outcome *out)
{
    const plume_index n = s->n, m = s->m;
    const double *du = s->sol, *lnew = s->sol + n;
    plume_solve_report *rep = c->rep;
    nt_search ls = {0};
    ls.phi0 = c->f + c->mu * c->g1;
    ls.gd = d->dirderiv + c->mu * c->g1;
    ls.filter = s->o.line_search == PLUME_LS_FILTER && m > 0;
    ls.curve_first = m == 0;
    *out = STEP_TAKEN;
    if (ls.curve_first && curve_available(s, c, d)) {
        ls.curved = 1;
        rep->curved_searches++;
    }
    for (ls.alpha = d->alpha_max; ls.trial < 60 && !ls.accepted; ls.trial++, ls.alpha *= 0.5) {
        if (d->chord && ls.trial > 0) {
            s->factor_valid = 0;
            rep->chord_rejected++;
            if (s->o.verbose)
                fprintf(stderr, "           chord step %.3e refused whole: refactorising\n", d->step_max);
            c->mu = d->mu_before;
            *out = STEP_REDO;
            return PLUME_OK;
        }
        for (plume_index i = 0; i < n; i++)
            s->ut[i] = c->u[i] + ls.alpha * du[i] + (ls.curved ? 0.5 * ls.alpha * ls.alpha * s->acc[i] : 0.0);
        plume_status st = merit_at(s, s->ut, c->mu, &ls.phi, &ls.ft, ls.trial == 0 || ls.curved);
        if (st == PLUME_OK)
            st = ls.filter && ls.trial < 30 ? filter_trial(s, c, d, &ls) : merit_trial(s, c, d, &ls);
        if (st != PLUME_OK)
            return st;
        if (ls.accepted)
            break;
    }
    if (!ls.accepted) {
        rep->reason = PLUME_REASON_LINE_SEARCH;
        *out = STEP_FAILED;
        return PLUME_OK;
    }
    d->alpha = ls.alpha;
    d->accepted = 1;
    if (s->o.verbose)
        fprintf(stderr, "           step %.3e  alpha %.3e  slope %.3e  %s%.1e%s\n", d->step_max, d->alpha, d->dirderiv,
                d->chord ? "chord, shift " : "shift ", s->shift, s->projected ? " (projected)" : "");
    memcpy(c->u, s->ut, (size_t)n * sizeof *c->u);
    /* the QP multipliers are taken whole even after a damped step: they are the current
     * least-squares estimate, and damping them too would freeze them whenever the line search
     * has to cut the primal step to nothing (redundant constraints) */
    if (m > 0)
        memcpy(c->lambda, lnew, (size_t)m * sizeof *c->lambda);
    return PLUME_OK;
}

/* Rate test: a chord step must cut the KKT residual by reuse_rate (or converge); otherwise it is
 * undone (back to the iterate before it) and the iteration refactorises (STEP_REDO). Keeping the
 * weaker chord steps and refactorising only at the next iteration was measured worse (tilted
 * traction at 4e4 elements: 74 iterations and 4.0 s against 41 and 2.1 s). */
static void chord_rate_test(plume_newton *s, nt_run *c, const nt_step *d, nt_outcome *out)
{
    double res_new = kkt_residual(s, c->lambda);
    /* converged, or a negligible step that the test below takes as converged (the round-off
     * floor: no rate to see there) */
    int done = c->viol <= s->o.tol_violation &&
               (res_new <= s->o.tol_kkt || (d->negligible && res_new <= sqrt(s->o.tol_kkt)));
    if (!(res_new <= s->o.reuse_rate * c->res) && !done) {
        save_iterate(s, 0, c->u, c->lambda, 0.0, 0.0, 0.0);
        c->f = s->saved_f, c->g1 = s->saved_g1, c->viol = s->saved_viol;
        kkt_residual(s, c->lambda); /* s->jtl of the restored iterate */
        s->factor_valid = 0;
        c->rep->chord_rejected++;
        if (s->o.verbose)
            fprintf(stderr, "           chord step failed its rate test (residual %.3e from %.3e): undone, "
                            "refactorising\n", res_new, c->res);
        *out = STEP_REDO;
        return;
    }
    c->rep->chord_steps++;
    /* the chord steps' own rate decides whether they go on: when reaching tol_kkt at the rate
     * just seen would take more than CHORD_MAX_MORE steps (a chord step costs about a quarter of
     * a Newton iteration), the next iteration refactorises. The prediction that let them start
     * misses where the matrix was built with multipliers still far off (the first load step of
     * a traction test: rates of 0.2 against 1e-3 predicted). */
    double rate = res_new / c->res;
    if (!done && res_new > 0.0 && rate > 0.0 && log(s->o.tol_kkt / res_new) / log(rate) > CHORD_MAX_MORE)
        s->factor_valid = 0;
}

/* After a step: the history that predicts a chord step's contraction, the new iterate's
 * evaluation, then the exits that end the solve with this iteration (STEP_FINAL): steps blocked
 * by continuous collision detection, a single step, a negligible step that has converged; a chord
 * step that fails its rate test is undone (STEP_REDO). */
static plume_status after_step(plume_newton *s, nt_run *c, const nt_step *d, nt_outcome *out)
{
    plume_solve_report *rep = c->rep;
    if (!d->chord) { /* full steps only */
        int full = d->accepted && d->alpha == d->alpha_max && d->alpha_max == 1.0 && !s->projected;
        s->chord_prev = full ? s->chord_last : 0.0;
        s->chord_last = full ? d->step_max : 0.0;
    }
    plume_status st = evaluate(s, c->u, &c->f, &c->g1, &c->viol);
    if (st != PLUME_OK)
        return st;
    /* Steps that continuous collision detection cut below 1 % of the direction four times in a
     * row: the direction runs into a pair whose barrier is not in the problem (it came within
     * reach during this solve; stencils change only between solves). Measured on the contact
     * stack: without this exit such a solve crept on at alpha ~ 1e-1, 1e-2, ... 1e-15 until the
     * round-off floor stopped it 66 iterations later, and the time step was halved. */
    c->blocked = s->limits && d->alpha_max < 1e-2 ? c->blocked + 1 : 0;
    if (c->blocked >= 4) {
        rep->reason = PLUME_REASON_CONTACT_SET;
        *out = STEP_FINAL;
        return PLUME_OK;
    }
    if (d->chord) {
        chord_rate_test(s, c, d, out);
        if (*out == STEP_REDO)
            return PLUME_OK;
    }
    if (s->single_step) {
        rep->reason = PLUME_REASON_SINGLE_STEP;
        *out = STEP_FINAL;
        return PLUME_OK;
    }
    /* the full Newton direction (not the damped step: a line search that shrank alpha to
     * nothing has not converged) is negligible, the constraints hold and the multipliers are
     * not far off (the KKT test itself may be out of reach of round-off) */
    if (d->negligible && c->viol <= s->o.tol_violation && kkt_residual(s, c->lambda) <= sqrt(s->o.tol_kkt)) {
        rep->reason = PLUME_REASON_CONVERGED;
        *out = STEP_FINAL;
    }
    return PLUME_OK;
}

/* One step, a chord step (chord) or a Newton step: the direction, then the step taken whole (a
 * single step, a negligible one), by the trust region or by the line search, then after_step */
static plume_status take_step(plume_newton *s, nt_run *c, int chord, nt_outcome *out)
{
    nt_step d = {0};
    d.chord = chord;
    plume_status st = step_direction(s, c, &d, out);
    if (st != PLUME_OK || *out != STEP_TAKEN)
        return st;
    d.alpha = d.alpha_max;
    d.negligible = d.step_max <= s->o.tol_step * c->L;
    c->last_negligible = d.negligible;
    s->trial_grad = 0; /* no trial of this iteration evaluated yet */
    if (s->single_step || d.negligible) {
        whole_step(s, c, &d);
    } else if (s->o.trust_region) {
        st = trust_region_iteration(s, c, &d, out);
        if (st != PLUME_OK || *out != STEP_TAKEN)
            return st;
    } else {
        st = line_search(s, c, &d, out);
        if (st != PLUME_OK || *out != STEP_TAKEN)
            return st;
    }
    return after_step(s, c, &d, out);
}

/* the report of a solve that has ended after `it` iterations (f0: the factorisations before it,
 * t0: its start) */
static void solve_report(plume_newton *s, const nt_run *c, int it, int f0, double t0)
{
    plume_solve_report *rep = c->rep;
    plume_problem_scatter(s->p, c->u);
    int f1;
    plume_chol_stats(s->chol, NULL, &f1, NULL);
    rep->converged = rep->reason == PLUME_REASON_CONVERGED;
    rep->iterations = it;
    rep->factorizations = f1 - f0;
    rep->shifts = s->shifts;
    rep->partial_projections = s->partial_factorizations;
    rep->refinements = s->refinements;
    if (s->o.verbose)
        fprintf(stderr, "  newton: %s after %d iterations: %d factorisations, %d chord steps, %d refinement passes, "
                        "%d backtracks, %d refused trust-region steps, %d inertia shifts, %d partly projected\n",
                plume_reason_name(rep->reason), rep->iterations, rep->factorizations, rep->chord_steps,
                rep->refinements, rep->backtracks, rep->rejected_steps, rep->shifts, rep->partial_projections);
    rep->energy = c->f;
    rep->kkt_residual = kkt_residual(s, c->lambda);
    rep->max_violation = c->viol;
    rep->seconds = plume_wall_seconds() - t0;
}

plume_status plume_newton_solve(plume_newton *s, double *u, double *lambda, plume_solve_report *rep)
{
    if (!s || !u || (s->m && !lambda) || !rep)
        return PLUME_EINVAL;
    double t0 = plume_wall_seconds();
    memset(rep, 0, sizeof *rep);
    int f0;
    plume_chol_stats(s->chol, NULL, &f0, NULL);
    nt_run c = {.u = u, .lambda = lambda, .rep = rep, .L = plume_problem_length_scale(s->p)};
    s->trial_grad = 0; /* a trial left by an earlier solve is not this start */
    plume_status st = evaluate(s, u, &c.f, &c.g1, &c.viol);
    if (st != PLUME_OK)
        return st;
    rep->reason = PLUME_REASON_ITERATION_CAP;
    s->nfilt = 0; /* a new filter per solve (Ipopt's theta_max and theta_min) */
    s->theta_max = 1e4 * fmax(1.0, c.g1);
    s->theta_min = 1e-4 * fmax(1.0, c.g1);
    s->shifts = 0;
    s->partial_factorizations = 0;
    s->refinements = 0;
    s->tr_sigma = 0.0;
    s->factor_valid = 0; /* chord steps use a factorisation of this solve (their prediction does) */
    s->chord_last = s->chord_prev = 0.0;
    c.max_iter = s->single_step ? 1 : s->o.max_iter;
    c.best = c.best_ok = c.best_res = c.best_viol = INFINITY;
    c.f_prev = c.f;
    int it;
    for (it = 0;; it++) {
        int stop;
        if ((st = convergence_test(s, &c, it, &stop)) != PLUME_OK)
            return st;
        if (stop)
            break;
        /* inexact Newton (Eisenstat & Walker's forcing term): the refined KKT solve needs a
         * linear residual of eta times the nonlinear residual (grad f + J^T lambda in the force
         * rows, g in the constraint rows; plume_newton_direction) with eta = min(1e-2, res), loose while the
         * residual is large, tight (down to round-off) near convergence, where it keeps the
         * quadratic rate */
        s->refine_rtol = fmax(1e-15, fmin(1e-2, c.res));
        /* a chord step where the last factorisation predicts one; a Newton step where none was
         * wanted, or the chord step was refused or undone (the same iteration, refactorised) */
        nt_outcome out = STEP_REDO;
        if (chord_wanted(s, &c, it) && (st = take_step(s, &c, 1, &out)) != PLUME_OK)
            return st;
        if (out == STEP_REDO && (st = take_step(s, &c, 0, &out)) != PLUME_OK) /* a Newton step */
            return st;
        if (out == STEP_FINAL)
            it++;
        if (out == STEP_FAILED || out == STEP_FINAL)
            break;
    }
    solve_report(s, &c, it, f0, t0);
    return PLUME_OK;
}

void plume_newton_set_tol_kkt(plume_newton *s, double tol_kkt)
{
    s->o.tol_kkt = tol_kkt;
}

double plume_newton_memory(const plume_newton *s)
{
    return s->shift_last;
}

void plume_newton_set_memory(plume_newton *s, double shift_last)
{
    s->shift_last = shift_last;
}

void plume_newton_stats(const plume_newton *s, int *analyses, int *factorizations, double *factor_seconds)
{
    plume_chol_stats(s ? s->chol : NULL, analyses, factorizations, factor_seconds);
}
