/* plume (private, not installed): the native solver's state, shared by lib/solve/newton.c (the
 * iteration: evaluation, line search, convergence) and lib/solve/newton_kkt.c (the linear algebra:
 * KKT patterns, factorisation with inertia correction, refined solves, directions). */
#ifndef PLUME_INTERNAL_NEWTON_STATE_H
#define PLUME_INTERNAL_NEWTON_STATE_H

#include <math.h>

#include "../cholesky.h"
#include "../newton.h"

/* max(m, |v|) for the residual norms' loops: a NaN entry makes it NaN, where fmax would drop it
 * (and a NaN gradient would look converged); inlined, where fmax is a libm call at -O2 (1.5-2 %
 * of a traction run at 1e4 elements, perf). */
static inline double nt_max_abs(double m, double v)
{
    const double a = fabs(v);
    return (a > m || a != a) ? a : m;
}

struct plume_newton {
    plume_problem *p;
    plume_solver_opts o;
    int single_step;
    int limits;              /* a term limits steps (continuous collision detection) */
    plume_index n, m, nk;  /* free dofs, constraints, KKT size */
    plume_sparsity hp;
    plume_index jnnz;
    const plume_index *jrow, *jcol;
    plume_index *kcolptr, *krowind, *jpos, *diagpos; /* KKT pattern, J entry -> KKT slot, diag slots */
    int eliminate;           /* constraints eliminated into an SPD matrix (supernodal LL^T) */
    plume_index npairs;      /* eliminate: pairs (ka, kb) of Jacobian entries of one row ... */
    plume_index *pair_a, *pair_b, *pair_pos; /* ... and the Hessian slot of (col ka, col kb) */
    double *dcv;             /* [m+1] the KKT regularisation of each constraint of the system solved ... */
    double *dcfv;            /* [m+1] ... and the one factorised (>= dcv, kkt_solve_j) */
    int refine;              /* dcfv > dcv: the solves refine against dcv */
    double diag;             /* the diagonal shift of the last factorisation */
    double *rb, *rr, *rd;    /* [n+m+1] iterative refinement */
    int refinements;         /* refinement passes in this solve */
    double refine_rtol;      /* refinement stops below this residual, relative to the right-hand
                                side: the forcing term of the current iteration */
    double refine_bf;        /* > 0: the force rows' residual is judged against this instead of
                                their right-hand side (plume_newton_direction: the KKT residual) */
    double shift, shift_last; /* exact-Hessian shift of the last factorisation; the last nonzero one */
    double tr_sigma;         /* trust region: the regularisation added to every factorisation of
                                this solve's iterations (0: none) */
    int projected;           /* the last factorisation used the projected Hessian */
    int shifts;              /* factorisations that failed for inertia in this solve */
    int partial_factorizations; /* factorisations of the partly projected Hessian in this solve */
    double filt[2 * 64];     /* filter line search: (theta, f) pairs of this solve (a ring) */
    int nfilt;
    double theta_max, theta_min;
    int factor_valid;        /* the last factorisation (of this solve) may serve a chord step */
    double *jval_f;          /* [jnnz] the Jacobian that factorisation was built with */
    double chord_last, chord_prev; /* the last two full Newton steps of this solve (max |du|; 0:
                                none, or damped): they predict a chord step's contraction */
    double *u_s, *l_s, *grad_s, *g_s, *jval_s; /* the iterate before a chord step ... */
    double *u_b, *l_b;       /* the best iterate within the violation tolerance (round-off floor) */
    double saved_f, saved_g1, saved_viol;        /* ... and its f, |g|_1, violation */
    double *kwork, *lwork;   /* [n+1], [m+1] eliminate: workspaces */
    double *hval;            /* the Hessian as assembled (kept: the refinement measures against it) */
    double *kval;            /* the matrix factorised: the KKT values (LDL^T) or H + J^T J / dcf */
    double *jval, *grad, *g, *gt, *rhs, *sol, *ut, *jtl;
    double *acc;             /* [n+1] the geodesic acceleration of the curved line search ... */
    double *acc_g, *acc_j;   /* [m+1], [jnnz+1] ... and its workspaces */
    double *grad_t;          /* [n+1] the gradient at the line search's first trial s->ut ... */
    int trial_grad;          /* ... valid (s->ut unchanged since), with its energy trial_f */
    double trial_f;
    plume_chol *chol;
};

/* lib/solve/newton_kkt.c */
plume_status plume_newton_build_kkt_pattern(plume_newton *s);
plume_status plume_newton_build_elimination_pairs(plume_newton *s);
/* [H + d I, J^T; J, -dc I] [x; l] = r with the last factorisation (out may alias r) */
plume_status plume_newton_kkt_solve(plume_newton *s, const double *r, double *out);
/* the Newton/SQP direction in s->sol (factorise, solve); *step_max its largest entry */
plume_status plume_newton_direction(plume_newton *s, const double *u, const double *lambda, double *step_max);
/* max |grad f + J^T lambda| over the free dofs: the force rows' nonlinear residual, the reference
 * of the forcing term (refine_bf) */
double plume_newton_force_residual(plume_newton *s, const double *lambda);
/* a chord direction in s->sol from the last factorisation; nonzero when unusable */
int plume_newton_chord_direction(plume_newton *s, const double *lambda, double L, double *step_max);

/* plume_newton_create, the factorisation analysed in the order of like's where it fits
 * (plume_chol_create_like); like may be NULL. */
plume_status plume_newton_create_like(plume_problem *p, const plume_solver_opts *o, int single_step, const plume_newton *like,
                            plume_newton **out, plume_err *err);

#endif
