/* plume: the `ipopt` backend (docs/design.md "Solvers"): min f(u) s.t. g(u) = 0 through Ipopt's C
 * interface with the exact sparse Hessian of the Lagrangian. The Ipopt problem (sizes, patterns,
 * options) is created once; every solve runs IpoptSolve from the caller's point and then judges
 * the result with plume's own measures, so a report means the same thing for every backend.
 *
 * Scaling (why the tolerances mean what plume means). Ipopt stops when its *scaled* error
 * max(dual infeasibility / s_d, constraint violation) <= tol. plume asks for a relative KKT
 * residual (plume_problem_kkt_residual) and a relative violation |g_c| / scale_c. Before each IpoptSolve we therefore set user scaling:
 *   x:  1 / length_scale           (Ipopt sees O(1) unknowns; its absolute guards make sense)
 *   f:  1 / (length_scale * ref)   ref = max(force scale, ||grad f||, ||J^T lambda||) at the
 *                                  start point, the reference of plume_problem_kkt_residual, so
 *                                  the scaled dual infeasibility is plume's relative residual
 *   g_c: (tol_kkt / tol_violation) * 8 / ||grad g_c||^2
 * The last one is exact for edge-length constraints (|grad g|^2 = 8 L^2 with both ends free,
 * scale L^2; 4 L^2 with one end prescribed, which only makes Ipopt stricter); for other
 * constraints it is the natural "violation over squared gradient" size. The factor
 * tol_kkt / tol_violation lets one Ipopt `tol` enforce both plume tolerances. Ipopt's unscaled
 * tests (dual_inf_tol, constr_viol_tol) are switched off: their absolute values have no meaning
 * for an SI problem whose forces may be 1e-6 N or 1e6 N.
 * ref is measured at the start; when the forces at the solution are much smaller, Ipopt may stop
 * early in plume's terms: the solve is then resumed (warm, multipliers kept) with the scale of
 * the current point (and from the second resumption on a tighter tol), at most PASSES runs in
 * all, within the max_iter budget. */
#include "ipopt_solver.h"

#include <IpStdCInterface.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "../io/progress.h"

enum {
    PASSES = 3 /* Ipopt runs per solve: the first plus at most two rescaled resumptions */
};

/* Fraction of plume's tolerance that Ipopt's scaled tol is set to (margin for the estimated
 * scales), and the tightening of each resumption. */
static const double TOL_MARGIN = 0.5;
static const double TOL_TIGHTEN = 0.1;
/* "No bound" for Ipopt: anything beyond nlp_{lower,upper}_bound_inf (default 1e19). */
static const double NO_BOUND = 2e19;

struct plume_ipopt {
    plume_problem *p; /* not owned */
    plume_solver_opts o;
    IpoptProblem ip;
    Index n, m, jnnz, hnnz;
    const plume_index *jrow, *jcol; /* Jacobian triplets, owned by p */
    plume_sparsity hp;              /* Hessian upper triangle CSC, owned by p */
    double *x;                      /* [n] Ipopt's iterate (in/out of IpoptSolve) */
    double *lam;                    /* [m+1] constraint multipliers (in/out) */
    double *zl, *zu;                /* [n] bound multipliers: no bounds, stay 0 */
    double *x0, *lam0;              /* [n], [m+1] start of the current Ipopt run */
    double *grad, *jt;              /* [n] grad f, J^T lambda */
    double *jval;                   /* [jnnz+1] Jacobian values */
    double *xscale;                 /* [n] 1 / length_scale */
    double *gscale;                 /* [m+1] constraint scaling */
    int iter;                       /* last iteration count seen by the intermediate callback */
    double dnorm;                   /* max |du| / length_scale of the last Newton direction */
    plume_status cb_status;         /* first error returned by a plume evaluation in a callback */
    int limits;                     /* a term limits steps (continuous collision detection) */
    double *xacc, *dstep;           /* [n] the accepted iterate (where Ipopt last asked for a
                                       gradient) and a trial's step from it */
    int have_acc, refused;          /* xacc is set; trial points refused for crossing */
};

/* ---- Ipopt callbacks: no allocation, plume's evaluations use the problem's workspaces ---- */

static Bool record(plume_ipopt *s, plume_status st)
{
    if (st != PLUME_OK && s->cb_status == PLUME_OK)
        s->cb_status = st;
    /* FALSE makes Ipopt treat the point as an evaluation error (the line search cuts back) */
    return st == PLUME_OK ? TRUE : FALSE;
}

/* Continuous collision detection for Ipopt, whose line search cannot be told a largest step: a
 * trial point that cannot be reached from the accepted iterate without a crossing is refused as
 * an evaluation error, and Ipopt cuts the step back. Ipopt asks for gradients only at accepted
 * iterates (and the start), so the last point of cb_grad_f is the iterate a trial comes from. */
static Bool cb_f(Index n, Number *x, Bool new_x, Number *obj, UserDataPtr ud)
{
    (void)new_x;
    plume_ipopt *s = ud;
    if (s->limits && s->have_acc) {
        for (Index i = 0; i < n; i++)
            s->dstep[i] = x[i] - s->xacc[i];
        double a = 1.0;
        plume_status st = plume_problem_max_step(s->p, s->xacc, s->dstep, &a);
        if (st != PLUME_OK)
            return record(s, st);
        if (!(a >= 1.0)) {
            s->refused++;
            return FALSE;
        }
    }
    return record(s, plume_problem_objective(s->p, x, obj, NULL));
}

static Bool cb_grad_f(Index n, Number *x, Bool new_x, Number *grad, UserDataPtr ud)
{
    (void)new_x;
    plume_ipopt *s = ud;
    double f;
    if (s->limits) {
        memcpy(s->xacc, x, (size_t)n * sizeof *x);
        s->have_acc = 1;
    }
    return record(s, plume_problem_objective(s->p, x, &f, grad));
}

static Bool cb_g(Index n, Number *x, Bool new_x, Index m, Number *g, UserDataPtr ud)
{
    (void)n;
    (void)new_x;
    plume_ipopt *s = ud;
    if (m == 0)
        return TRUE;
    return record(s, plume_problem_constraints(s->p, x, g, NULL));
}

static Bool cb_jac_g(Index n, Number *x, Bool new_x, Index m, Index nele, Index *irow, Index *jcol,
                     Number *values, UserDataPtr ud)
{
    (void)n;
    (void)new_x;
    (void)m;
    plume_ipopt *s = ud;
    if (!values) {
        for (Index k = 0; k < nele; k++) {
            irow[k] = (Index)s->jrow[k];
            jcol[k] = (Index)s->jcol[k];
        }
        return TRUE;
    }
    if (nele == 0)
        return TRUE;
    return record(s, plume_problem_jacobian(s->p, x, values));
}

static Bool cb_h(Index n, Number *x, Bool new_x, Number obj_factor, Index m, Number *lambda,
                 Bool new_lambda, Index nele, Index *irow, Index *jcol, Number *values, UserDataPtr ud)
{
    (void)n;
    (void)new_x;
    (void)new_lambda;
    (void)nele;
    plume_ipopt *s = ud;
    if (!values) {
        /* plume's upper (r, c), r <= c, is Ipopt's lower (c, r) */
        for (plume_index c = 0; c < s->hp.n; c++)
            for (plume_index k = s->hp.colptr[c]; k < s->hp.colptr[c + 1]; k++) {
                irow[k] = (Index)c;
                jcol[k] = (Index)s->hp.rowind[k];
            }
        return TRUE;
    }
    /* Ipopt's Lagrangian obj_factor f + lambda.g has plume's sign convention */
    return record(s, plume_problem_hessian(s->p, x, obj_factor, m ? lambda : NULL, 0, values));
}

static Bool cb_iter(Index alg_mod, Index iter, Number obj, Number inf_pr, Number inf_du, Number mu,
                    Number d_norm, Number reg, Number alpha_du, Number alpha_pr, Index ls_trials,
                    UserDataPtr ud)
{
    (void)mu;
    (void)alpha_du;
    plume_ipopt *s = ud;
    if (iter > s->iter)
        s->iter = iter;
    /* Ipopt's x is scaled by 1 / length_scale, so d_norm is plume's max|du| / length_scale; the
     * full direction, not alpha times it: a cut-back step is no sign of convergence */
    if (iter > 0 && alg_mod == 0)
        s->dnorm = d_norm;
    /* plume's verbose output goes to stderr (stdout may carry an app's --json summary), so
     * Ipopt's own printing stays off and the iteration line is printed here */
    if (s->o.verbose)
        fprintf(stderr, "ipopt %4d%c f % .10e  inf_pr %.2e  inf_du %.2e  |d| %.2e  reg %.1e  alpha %.2e  ls %d\n",
                (int)iter, alg_mod ? 'r' : ' ', obj, inf_pr, inf_du, d_norm, reg, alpha_pr, (int)ls_trials);
    return TRUE;
}

/* ---- options ---- */

/* The C interface takes non-const keyword strings: copy them (Ipopt does not keep them). */
static int opt_str(IpoptProblem ip, const char *key, const char *val)
{
    char k[64], v[64];
    snprintf(k, sizeof k, "%s", key);
    snprintf(v, sizeof v, "%s", val);
    return AddIpoptStrOption(ip, k, v) ? 1 : 0;
}

static int opt_num(IpoptProblem ip, const char *key, double val)
{
    char k[64];
    snprintf(k, sizeof k, "%s", key);
    return AddIpoptNumOption(ip, k, val) ? 1 : 0;
}

static int opt_int(IpoptProblem ip, const char *key, int val)
{
    char k[64];
    snprintf(k, sizeof k, "%s", key);
    return AddIpoptIntOption(ip, k, val) ? 1 : 0;
}

static int set_fixed_options(IpoptProblem ip)
{
    int ok = 1;
    /* no ipopt.opt from the working directory: runs must not depend on where they start */
    ok &= opt_str(ip, "option_file_name", "");
    ok &= opt_str(ip, "sb", "yes");
    ok &= opt_int(ip, "print_level", 0);
    ok &= opt_str(ip, "hessian_approximation", "exact");
    /* no bounds and no inequalities: the barrier parameter never enters the KKT system; the
     * adaptive update measured the same on small patches and worse on large ones (350 vs 197
     * iterations, and a failed step), so the plain monotone one */
    ok &= opt_str(ip, "mu_strategy", "monotone");
    ok &= opt_str(ip, "nlp_scaling_method", "user-scaling");
    /* Start from the caller's multipliers (the previous step's in a quasi-static sequence, the
     * current ones in a resumption) instead of Ipopt's least-squares estimate. Measured on a
     * planar traction patch (membrane + 45 degree inextensible barbs, n = 1.6k-6.5k): the
     * estimate saves up to 25% of iterations when steps are small or predicted, but costs an
     * extra factorisation of a differently structured system per solve, so CPU time is even
     * at n = 6.5k; from distorted starts (a grip jump taken by one row of elements) it is
     * poor and the warm start needs half the iterations (100 vs 193) and a third of the time. */
    ok &= opt_str(ip, "warm_start_init_point", "yes");
    /* plume's tolerances are relative and enforced through the scaled `tol` (file comment);
     * Ipopt's absolute ones would be meaningless in SI units */
    ok &= opt_num(ip, "dual_inf_tol", 1e300);
    ok &= opt_num(ip, "constr_viol_tol", 1e300);
    ok &= opt_num(ip, "compl_inf_tol", 1e300);
    /* never stop at "acceptable": only the requested precision counts */
    ok &= opt_int(ip, "acceptable_iter", 0);
    return ok;
}

/* ---- create / destroy ---- */

void plume_ipopt_destroy(plume_ipopt **ps)
{
    if (!ps || !*ps)
        return;
    plume_ipopt *s = *ps;
    if (s->ip)
        FreeIpoptProblem(s->ip);
    free(s->x);
    free(s->lam);
    free(s->zl);
    free(s->zu);
    free(s->x0);
    free(s->xacc);
    free(s->dstep);
    free(s->lam0);
    free(s->grad);
    free(s->jt);
    free(s->jval);
    free(s->xscale);
    free(s->gscale);
    free(s);
    *ps = NULL;
}

plume_status plume_ipopt_create(plume_problem *p, const plume_solver_opts *o, plume_ipopt **out)
{
    if (!out)
        return PLUME_EINVAL;
    *out = NULL;
    if (!p || !o || o->max_iter < 0 || !(o->tol_kkt > 0.0) || !(o->tol_violation > 0.0))
        return PLUME_EINVAL;
    plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p), jnnz;
    const plume_index *jrow, *jcol;
    plume_sparsity hp = plume_problem_hessian_pattern(p);
    if (n <= 0 || !hp.colptr) /* not finalised */
        return PLUME_EINVAL;
    plume_problem_jacobian_pattern(p, &jnnz, &jrow, &jcol);
    if (n > INT_MAX || m > INT_MAX || jnnz > INT_MAX || hp.nnz > INT_MAX)
        return PLUME_EINVAL; /* beyond Ipopt's int indices */

    plume_status st = PLUME_OK;
    double *xl = NULL, *xu = NULL, *gb = NULL;
    plume_ipopt *s = calloc(1, sizeof *s);
    if (!s)
        return PLUME_ENOMEM;
    s->p = p;
    s->o = *o;
    s->n = (Index)n;
    s->m = (Index)m;
    s->jnnz = (Index)jnnz;
    s->hnnz = (Index)hp.nnz;
    s->jrow = jrow;
    s->jcol = jcol;
    s->hp = hp;
    size_t nn = (size_t)n, mm = (size_t)m + 1;
    s->x = calloc(nn, sizeof *s->x);
    s->lam = calloc(mm, sizeof *s->lam);
    s->zl = calloc(nn, sizeof *s->zl);
    s->zu = calloc(nn, sizeof *s->zu);
    s->x0 = calloc(nn, sizeof *s->x0);
    s->limits = plume_problem_limits_steps(p);
    s->xacc = calloc(nn, sizeof *s->xacc);
    s->dstep = calloc(nn, sizeof *s->dstep);
    s->lam0 = calloc(mm, sizeof *s->lam0);
    s->grad = calloc(nn, sizeof *s->grad);
    s->jt = calloc(nn, sizeof *s->jt);
    s->jval = calloc((size_t)jnnz + 1, sizeof *s->jval);
    s->xscale = calloc(nn, sizeof *s->xscale);
    s->gscale = calloc(mm, sizeof *s->gscale);
    xl = malloc(nn * sizeof *xl);
    xu = malloc(nn * sizeof *xu);
    gb = calloc(mm, sizeof *gb); /* g_L = g_U = 0 */
    if (!s->x || !s->lam || !s->zl || !s->zu || !s->x0 || !s->xacc || !s->dstep || !s->lam0 || !s->grad || !s->jt ||
        !s->jval || !s->xscale || !s->gscale || !xl || !xu || !gb) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    for (size_t i = 0; i < nn; i++) {
        xl[i] = -NO_BOUND;
        xu[i] = NO_BOUND;
        s->xscale[i] = 1.0 / plume_problem_length_scale(p);
    }
    /* Ipopt copies the bounds; the callbacks give the patterns once, on its first request */
    s->ip = CreateIpoptProblem(s->n, xl, xu, s->m, gb, gb, s->jnnz, s->hnnz, 0, cb_f, cb_g, cb_grad_f,
                               cb_jac_g, cb_h);
    if (!s->ip || !set_fixed_options(s->ip) || !SetIntermediateCallback(s->ip, cb_iter)) {
        st = PLUME_EDEP;
        goto cleanup;
    }
cleanup:
    free(xl);
    free(xu);
    free(gb);
    if (st != PLUME_OK)
        plume_ipopt_destroy(&s);
    *out = s;
    return st;
}

/* ---- solve ---- */

static int all_finite(const double *v, plume_index n)
{
    for (plume_index i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Objective and constraint scaling for the point (s->x, s->lam), see the file comment. */
static plume_status set_scaling(plume_ipopt *s)
{
    double f, gmax = 0.0, jmax = 0.0;
    plume_status st = plume_problem_objective(s->p, s->x, &f, s->grad);
    if (st != PLUME_OK)
        return st;
    for (Index i = 0; i < s->n; i++) {
        gmax = fmax(gmax, fabs(s->grad[i]));
        s->jt[i] = 0.0;
    }
    if (s->m > 0) {
        st = plume_problem_jacobian(s->p, s->x, s->jval);
        if (st != PLUME_OK)
            return st;
        for (Index c = 0; c < s->m; c++)
            s->gscale[c] = 0.0;
        for (Index k = 0; k < s->jnnz; k++) {
            s->jt[s->jcol[k]] += s->jval[k] * s->lam[s->jrow[k]];
            s->gscale[s->jrow[k]] += s->jval[k] * s->jval[k];
        }
        for (Index i = 0; i < s->n; i++)
            jmax = fmax(jmax, fabs(s->jt[i]));
        double ls = plume_problem_length_scale(s->p), ratio = s->o.tol_kkt / s->o.tol_violation;
        for (Index c = 0; c < s->m; c++) {
            double r2 = s->gscale[c];
            /* a vanishing gradient (degenerate start) falls back to the body's size */
            s->gscale[c] = ratio * (r2 > 0.0 && isfinite(r2) ? 8.0 / r2 : 1.0 / (ls * ls));
        }
    }
    /* the same reference as plume_problem_kkt_residual (reactions on prescribed dofs included) */
    double ref = fmax(plume_problem_force_scale(s->p), fmax(gmax, jmax));
    /* zero forces (or garbage, which Ipopt will report) leave the objective in its own units */
    double fs = ref > 0.0 && isfinite(ref) ? 1.0 / (plume_problem_length_scale(s->p) * ref) : 1.0;
    if (!SetIpoptProblemScaling(s->ip, fs, s->xscale, s->m > 0 ? s->gscale : NULL))
        return PLUME_EDEP;
    return PLUME_OK;
}

/* plume's measures at (s->x, s->lam); the problem's x is left at s->x. */
static plume_status measure(plume_ipopt *s, plume_solve_report *rep)
{
    plume_status st = plume_problem_kkt_residual(s->p, s->x, s->m ? s->lam : NULL, &rep->kkt_residual);
    if (st == PLUME_OK)
        st = plume_problem_constraints(s->p, s->x, NULL, &rep->max_violation);
    if (st == PLUME_OK)
        st = plume_problem_objective(s->p, s->x, &rep->energy, NULL);
    return st;
}

/* plume's convergence test (solver.h): relative KKT residual and violation, or, when Ipopt
 * itself claims success (ipopt_ok), a Newton direction below tol_step and the violation met:
 * the residual is then at its round-off floor. */
static int tolerances_met(const plume_ipopt *s, const plume_solve_report *rep, int ipopt_ok)
{
    if (!(rep->max_violation <= s->o.tol_violation))
        return 0;
    return rep->kkt_residual <= s->o.tol_kkt || (ipopt_ok && s->dnorm <= s->o.tol_step);
}

/* Outcome of one IpoptSolve. ok: Ipopt claims a solution; fail: reason otherwise;
 * err: not a convergence outcome but an error status. */
typedef struct {
    int ok;
    plume_reason fail;
    plume_status err;
} outcome;

static outcome classify(enum ApplicationReturnStatus r)
{
    outcome o = {0, PLUME_REASON_NUMERICAL, PLUME_OK};
    switch (r) {
    case Solve_Succeeded:
    case Solved_To_Acceptable_Level:
    case Feasible_Point_Found:
        o.ok = 1;
        break;
    case Search_Direction_Becomes_Too_Small:
        /* steps below round-off: a solution if plume's measures agree, else a precision floor */
        o.ok = 1;
        break;
    case Maximum_Iterations_Exceeded:
    case Maximum_CpuTime_Exceeded:
        o.fail = PLUME_REASON_ITERATION_CAP;
        break;
    case Infeasible_Problem_Detected:
        o.fail = PLUME_REASON_INFEASIBLE;
        break;
    case Not_Enough_Degrees_Of_Freedom:
        /* more equality constraints than unknowns: Ipopt refuses to start (the point is
         * returned as given). Such a system is generically infeasible (an over-constrained
         * vane); when the start already satisfies it, plume's measures say CONVERGED first */
        o.fail = PLUME_REASON_INFEASIBLE;
        break;
    case Restoration_Failed:
        /* the filter line search failed and feasibility restoration could not recover */
        o.fail = PLUME_REASON_LINE_SEARCH;
        break;
    case Error_In_Step_Computation:
    case Diverging_Iterates:
    case Invalid_Number_Detected:
    case User_Requested_Stop:
        o.fail = PLUME_REASON_NUMERICAL;
        break;
    case Insufficient_Memory:
        o.err = PLUME_ENOMEM;
        break;
    case Invalid_Problem_Definition:
    case Invalid_Option:
    case Unrecoverable_Exception:
    case NonIpopt_Exception_Thrown:
    case Internal_Error:
    default:
        o.err = PLUME_EDEP;
        break;
    }
    return o;
}

void plume_ipopt_set_tol_kkt(plume_ipopt *s, double tol_kkt)
{
    s->o.tol_kkt = tol_kkt; /* Ipopt's own tol and scaling are set from it at every solve */
}

plume_status plume_ipopt_solve(plume_ipopt *s, double *u, double *lambda, plume_solve_report *rep)
{
    if (!s || !u || !rep || (s->m > 0 && !lambda))
        return PLUME_EINVAL;
    double t0 = plume_wall_seconds();
    plume_status st = PLUME_OK;
    memset(rep, 0, sizeof *rep);
    rep->reason = PLUME_REASON_NUMERICAL;
    s->refused = 0;
    memcpy(s->x, u, (size_t)s->n * sizeof *s->x);
    if (s->m > 0)
        memcpy(s->lam, lambda, (size_t)s->m * sizeof *s->lam);
    double tol = TOL_MARGIN * fmin(s->o.tol_kkt, 1.0);
    int used = 0, measured = 0;
    for (int pass = 0; pass < PASSES; pass++) {
        st = set_scaling(s);
        if (st != PLUME_OK)
            goto cleanup;
        if (!opt_num(s->ip, "tol", tol) || !opt_int(s->ip, "max_iter", s->o.max_iter - used)) {
            st = PLUME_EDEP;
            goto cleanup;
        }
        memcpy(s->x0, s->x, (size_t)s->n * sizeof *s->x);
        memcpy(s->lam0, s->lam, (size_t)s->m * sizeof *s->lam);
        s->iter = 0;
        s->dnorm = INFINITY;
        s->cb_status = PLUME_OK;
        s->have_acc = 0;
        enum ApplicationReturnStatus r = IpoptSolve(s->ip, s->x, NULL, NULL, s->lam, s->zl, s->zu, s);
        used += s->iter;
        outcome oc = classify(r);
        if (s->cb_status == PLUME_ENOMEM || s->cb_status == PLUME_EDEP)
            oc.err = s->cb_status; /* a hard failure inside an evaluation, not a bad trial point */
        else if (oc.err == PLUME_EDEP && s->cb_status != PLUME_OK)
            oc.err = s->cb_status; /* Ipopt gave up on an evaluation error: name plume's */
        if (oc.err != PLUME_OK) {
            st = oc.err;
            goto cleanup;
        }
        if (!all_finite(s->x, s->n) || !all_finite(s->lam, s->m)) {
            /* nothing usable: return this run's start point */
            memcpy(s->x, s->x0, (size_t)s->n * sizeof *s->x);
            memcpy(s->lam, s->lam0, (size_t)s->m * sizeof *s->lam);
            rep->reason = PLUME_REASON_NUMERICAL;
            measured = 0;
            break;
        }
        st = measure(s, rep);
        if (st != PLUME_OK)
            goto cleanup;
        measured = 1;
        if (s->o.verbose)
            fprintf(stderr, "ipopt run %d: status %d, %d iterations, kkt %.3e, violation %.3e\n", pass + 1,
                    (int)r, s->iter, rep->kkt_residual, rep->max_violation);
        if (tolerances_met(s, rep, oc.ok)) {
            /* whatever Ipopt said, this point meets plume's definition of a solution */
            rep->reason = PLUME_REASON_CONVERGED;
            break;
        }
        if (!oc.ok) {
            rep->reason = oc.fail;
            break;
        }
        /* Ipopt's success, plume's failure: the scales estimated at the start were off (or a
         * round-off floor is reached). Resume with the current scales if budget remains; the
         * last word is ITERATION_CAP when iterations ran out, NUMERICAL when precision did. */
        if (used >= s->o.max_iter) {
            rep->reason = PLUME_REASON_ITERATION_CAP;
            break;
        }
        rep->reason = PLUME_REASON_NUMERICAL;
        /* the first resumption corrects the scale; if that was not enough, ask for more */
        if (pass > 0)
            tol *= TOL_TIGHTEN;
    }
    memcpy(u, s->x, (size_t)s->n * sizeof *u);
    if (s->m > 0)
        memcpy(lambda, s->lam, (size_t)s->m * sizeof *lambda);
    if (!measured)
        st = measure(s, rep);
    /* measure() left the problem's x at s->x, that is at u */
cleanup:
    if (st != PLUME_OK) {
        plume_problem_scatter(s->p, u); /* the problem's x follows u, as on success */
        rep->reason = PLUME_REASON_NUMERICAL;
    }
    rep->converged = st == PLUME_OK && rep->reason == PLUME_REASON_CONVERGED;
    rep->iterations = used;
    /* Ipopt's C interface does not expose its factorisation count (at least one per iteration,
     * more with inertia correction): 0 means "not counted", not "none" */
    rep->factorizations = 0;
    rep->step_limited = s->refused;
    rep->seconds = plume_wall_seconds() - t0;
    return st;
}
