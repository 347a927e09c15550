/* plume: nonlinear solvers with one report struct. Backends: native projected Newton / SQP with
 * CHOLMOD ("newton"), Ipopt ("ipopt"), a single linearised step ("linearized"). */
#ifndef PLUME_SOLVER_H
#define PLUME_SOLVER_H

#include "export.h"
#include "problem.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    PLUME_SOLVER_NEWTON = 0,
    PLUME_SOLVER_IPOPT = 1,
    PLUME_SOLVER_LINEARIZED = 2
} plume_solver_kind;

/* Why a solve stopped. Only CONVERGED means the tolerances below were met. */
typedef enum {
    PLUME_REASON_CONVERGED = 0,
    PLUME_REASON_ITERATION_CAP,   /* max_iter reached */
    PLUME_REASON_LINE_SEARCH,     /* no step decreased the merit function */
    PLUME_REASON_INFEASIBLE,      /* constraints could not be satisfied */
    PLUME_REASON_NUMERICAL,       /* non-finite values or a factorisation that kept failing */
    PLUME_REASON_SINGLE_STEP,     /* `linearized`: one step taken, convergence not sought */
    PLUME_REASON_CONTACT_SET      /* newton with continuous collision detection: the steps were cut
                                     to almost nothing for several iterations in a row, as when a
                                     pair outside the contact set blocks them (its barrier is not in
                                     the problem yet): the caller updates the terms' stencils and
                                     solves again from the point returned */,
    PLUME_REASON_STALLED          /* newton with stall_iterations: that many iterations in a row
                                     cut neither the KKT residual nor the constraint violation to
                                     half of its best in this solve (a caller with a smaller step
                                     to try gives up early, instead of at the cap) */
} plume_reason;

PLUME_API const char *plume_reason_name(plume_reason r);
/* Parses "newton" | "ipopt" | "linearized"; PLUME_EINVAL otherwise. */
PLUME_API plume_status plume_solver_kind_parse(const char *s, plume_solver_kind *out);
PLUME_API const char *plume_solver_kind_name(plume_solver_kind k);

typedef struct {
    plume_reason reason;
    int converged;        /* reason == CONVERGED */
    int iterations;       /* Newton / SQP / Ipopt iterations */
    int factorizations;   /* numeric factorisations (native solvers) */
    double energy;        /* f at the returned point */
    double kkt_residual;  /* plume_problem_kkt_residual at the returned point */
    double max_violation; /* max relative constraint violation at the returned point */
    double seconds;       /* wall time of the solve */
    int backtracks;       /* newton: trial steps the line search rejected */
    int shifts;           /* newton: factorisations rejected for inertia (each followed by a larger
                             diagonal shift, or by the projected Hessian) */
    int partial_projections; /* newton: factorisations whose Hessian had the terms with a cheap
                              projection projected (the exact one was not positive definite) */
    int rejected_steps;   /* newton, trust region: trial steps refused (each followed by a larger
                             regularisation and a new factorisation) */
    int curved_searches;  /* newton: line searches along the geodesic-acceleration curve */
    int merit_fallbacks;  /* newton, filter line search: iterations that fell back to the l1 merit
                             (no step down to 2^-29 was acceptable to the filter) */
    int chord_steps;      /* newton: steps taken with an earlier factorisation (no new one) */
    int chord_rejected;   /* newton: chord steps the line search refused whole (refactorised) */
    int refinements;      /* newton, kkt_refine: iterative refinement passes over all solves */
    int step_limited;     /* iterations whose step a term cut short (plume_term.max_step: continuous
                             collision detection), newton; ipopt: trial points refused for it */
} plume_solve_report;

/* How the native solver globalises a constrained step. */
typedef enum {
    PLUME_LS_FILTER = 0, /* Ipopt's filter line search (Waechter & Biegler 2006) with a second-order
                            correction; default */
    PLUME_LS_MERIT = 1   /* Armijo on the l1 merit f + mu |g|_1 with a second-order correction */
} plume_line_search;

/* How the native solver globalises its Newton steps (plume_solver_opts.curved_search and
 * .trust_region in one name, for scenes and apps). */
typedef enum {
    PLUME_GLOBAL_CURVED_LINE_SEARCH = 0, /* line search along the geodesic-acceleration curve; default */
    PLUME_GLOBAL_LINE_SEARCH = 1,        /* line search along the straight Newton step */
    PLUME_GLOBAL_TRUST_REGION = 2        /* adaptive-regularisation trust region */
} plume_globalization;

/* "curved_line_search" | "line_search" | "trust_region"; PLUME_EINVAL otherwise */
PLUME_API plume_status plume_globalization_parse(const char *s, plume_globalization *out);
PLUME_API const char *plume_globalization_name(plume_globalization g);

/* How the native solver factorises a constrained Newton step. */
typedef enum {
    PLUME_KKT_LDL = 0,      /* quasi-definite KKT matrix, CHOLMOD simplicial LDL^T */
    PLUME_KKT_ELIMINATE = 1 /* multipliers eliminated: SPD H + J^T J / dc, CHOLMOD supernodal LL^T */
} plume_kkt_mode;

typedef struct {
    int max_iter;          /* default 100 */
    double tol_kkt;        /* relative KKT residual (see plume_problem_kkt_residual); default 1e-9 */
    double tol_violation;  /* max relative constraint violation; default 1e-10 */
    double tol_step;       /* also converged when max|du| <= tol_step * length_scale and the
                              violation is met; default 1e-13 */
    double max_step;       /* newton: a direction longer than max_step * length_scale is taken
                              as a sign of a singular Hessian and regularised; default 100 */
    int inertia_corrections; /* newton, exact-Hessian path: Ipopt's inertia correction (0: off, the
                              projected Hessian whenever the exact one is not positive definite);
                              default 1. A shift that made the matrix positive definite is reused,
                              divided by 3, at the next failure, and grown 8x until it works */
    double inertia_max_shift; /* the largest shift tried, relative to the largest Hessian diagonal,
                              before falling back to the projected Hessian; default 1 */
    plume_kkt_mode kkt;    /* newton with constraints; default PLUME_KKT_ELIMINATE (the same
                              iterates as LDL^T, faster factorisations:
                              docs/theory-constraints.md) */
    plume_line_search line_search; /* newton with constraints; default PLUME_LS_FILTER */
    int reuse_factorization; /* newton: chord steps (the last factorisation of this solve) in
                                the end game, where the last two Newton steps predict a contraction
                                below 1e-2 a step; each must cut the KKT residual by reuse_rate
                                (else it is undone and the iteration refactorises), and they stop
                                once their rate predicts more than 4 to converge; default 1
                                (docs/theory-constraints.md) */
    double reuse_rate;     /* default 0.25 */
    int kkt_refine;        /* newton, eliminated KKT: factorise with a 1e3 times larger multiplier
                              regularisation and refine the solution iteratively against the
                              requested one (a Cholesky factor of H + J^T J / dc, whose constraint
                              part is 1e8 times the Hessian's, loses 8 digits of H), to a relative
                              residual of min(1e-2, KKT residual) (inexact Newton); default 1 */
    int verbose;           /* print one line per iteration on stderr */
    int partial_projection; /* newton, exact-Hessian path: when the exact Hessian is not positive
                              definite, project the terms whose projection is a cheap closed form
                              (plume_term.partial_projection: shape bending, edge-length
                              constraints) before shifting the whole matrix; default 1 */
    int curved_search;     /* newton without constraints: a full step the line search refuses is
                              retried along u + alpha du + alpha^2/2 a, a the geodesic acceleration
                              (lib/newton.c); default 1 */
    int trust_region;      /* newton: globalise by an adaptive-regularisation trust region (a
                              shift sigma I added to the factorised matrix, grown when the step's
                              actual decrease of the l1 merit falls short of the quadratic model's
                              and shrunk when it matches) instead of the line search; default 0 */
    int exact_hessian_first; /* newton without constraints: factorise the exact Hessian first and
                                fall back to the PSD-projected one if it is not positive definite;
                                default 1 */
    int stall_iterations;  /* newton: stop (PLUME_REASON_STALLED) after this many iterations in a
                              row that cut neither the KKT residual nor the constraint violation to
                              half of its best in this solve; 0 (default): only max_iter stops */
} plume_solver_opts;

PLUME_API void plume_solver_opts_default(plume_solver_opts *o);
/* Sets curved_search and trust_region for g. */
PLUME_API void plume_solver_opts_set_globalization(plume_solver_opts *o, plume_globalization g);

typedef struct plume_solver plume_solver;

/* Creates a solver for a finalised problem (kept by reference, not owned). Symbolic analysis
 * of the sparse systems happens here, once. PLUME_EINVAL for a problem not finalised or options
 * out of range, with a message naming them in err (NULL allowed). */
PLUME_API plume_status plume_solver_create(plume_solver_kind kind, plume_problem *p,
                                           const plume_solver_opts *o, plume_solver **out, plume_err *err);
PLUME_API void plume_solver_destroy(plume_solver **s);

/* Solves from u (nfree, in: start, out: result) and lambda (ncons, in: guess, out: multipliers
 * of the Lagrangian f + lambda.g). The problem's x holds the result on return. Returns an error
 * status only for errors (bad input, memory, dependency); convergence is in rep->reason. */
PLUME_API plume_status plume_solver_solve(plume_solver *s, double *u, double *lambda, plume_solve_report *rep);

/* Changes the relative KKT tolerance of the next solves (tol_kkt > 0 and finite, else
 * PLUME_EINVAL): one solver, one symbolic analysis, for solves that need different accuracies
 * (traction's small-strain probe). */
PLUME_API plume_status plume_solver_set_tol_kkt(plume_solver *s, double tol_kkt);

/* Time spent and count of numeric factorisations / symbolic analyses so far (benchmarks). */
PLUME_API void plume_solver_stats(const plume_solver *s, int *analyses, int *factorizations,
                                  double *factor_seconds);

/* Backend entry points used by plume_solver_*; exposed for tests and benchmarks. */
typedef struct plume_ipopt plume_ipopt;
PLUME_API plume_status plume_ipopt_create(plume_problem *p, const plume_solver_opts *o, plume_ipopt **out);
PLUME_API void plume_ipopt_destroy(plume_ipopt **s);
PLUME_API plume_status plume_ipopt_solve(plume_ipopt *s, double *u, double *lambda, plume_solve_report *rep);
PLUME_API void plume_ipopt_set_tol_kkt(plume_ipopt *s, double tol_kkt);

#ifdef __cplusplus
}
#endif
#endif
