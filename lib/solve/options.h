/** \file
 * plume: the options of the nonlinear solvers (tolerances, caps, and how the native solver factorises
 * and globalises its steps). */
#ifndef PLUME_SOLVE_OPTIONS_H
#define PLUME_SOLVE_OPTIONS_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How the native solver globalises a constrained step. */
typedef enum {
    PLUME_LS_FILTER = 0, /**< Ipopt's filter line search (Waechter & Biegler 2006) with a second-order
                            correction; default */
    PLUME_LS_MERIT = 1   /**< Armijo on the l1 merit f + mu |g|_1 with a second-order correction */
} plume_line_search;

/** How the native solver globalises its Newton steps (plume_solver_opts.curved_search and
 * .trust_region in one name, for scenes and apps). */
typedef enum {
    PLUME_GLOBAL_CURVED_LINE_SEARCH = 0, /**< line search along the geodesic-acceleration curve; default */
    PLUME_GLOBAL_LINE_SEARCH = 1,        /**< line search along the straight Newton step */
    PLUME_GLOBAL_TRUST_REGION = 2        /**< adaptive-regularisation trust region */
} plume_globalization;

/** "curved_line_search" | "line_search" | "trust_region"; PLUME_EINVAL otherwise */
PLUME_API plume_status plume_globalization_parse(const char *s, plume_globalization *out);
/** The name plume_globalization_parse accepts for g (static string); "unknown" out of range. */
PLUME_API const char *plume_globalization_name(plume_globalization g);

/** How the native solver factorises a constrained Newton step. */
typedef enum {
    PLUME_KKT_LDL = 0,      /**< quasi-definite KKT matrix, CHOLMOD simplicial LDL^T */
    PLUME_KKT_ELIMINATE = 1 /**< multipliers eliminated: SPD H + J^T J / dc, CHOLMOD supernodal LL^T */
} plume_kkt_mode;

/** Options of every solver backend (the native ones read all of them, Ipopt the tolerances and the
 * cap); fill with plume_solver_opts_default, then change fields. */
typedef struct {
    int max_iter;          /**< iteration cap; default 100 */
    double tol_kkt;        /**< relative KKT residual (see plume_problem_kkt_residual); default 1e-9 */
    double tol_violation;  /**< max relative constraint violation; default 1e-10 */
    double tol_step;       /**< also converged when max|du| <= tol_step * length_scale and the
                              violation is met; default 1e-13 */
    double max_step;       /**< newton: a direction longer than max_step * length_scale is taken
                              as a sign of a singular Hessian and regularised; default 100 */
    int inertia_corrections; /**< newton, exact-Hessian path: Ipopt's inertia correction (0: off, the
                              projected Hessian whenever the exact one is not positive definite);
                              default 1. A shift that made the matrix positive definite is reused,
                              divided by 3, at the next failure, and grown 8x until it works */
    double inertia_max_shift; /**< the largest shift tried, relative to the largest Hessian diagonal,
                              before falling back to the projected Hessian; default 1 */
    plume_kkt_mode kkt;    /**< newton with constraints; default PLUME_KKT_ELIMINATE (the same
                              iterates as LDL^T, faster factorisations:
                              docs/theory-constraints.md) */
    plume_line_search line_search; /**< newton with constraints; default PLUME_LS_FILTER */
    int reuse_factorization; /**< newton: chord steps (the last factorisation of this solve) in
                                the end game, where the last two Newton steps predict a contraction
                                below 1e-2 a step; each must cut the KKT residual by reuse_rate
                                (else it is undone and the iteration refactorises), and they stop
                                once their rate predicts more than 4 to converge; default 1
                                (docs/theory-constraints.md) */
    double reuse_rate;     /**< the factor by which a chord step must cut the KKT residual, in (0, 1);
                              default 0.25 */
    int kkt_refine;        /**< newton, eliminated KKT: factorise with a 1e3 times larger multiplier
                              regularisation and refine the solution iteratively against the
                              requested one (a Cholesky factor of H + J^T J / dc, whose constraint
                              part is 1e8 times the Hessian's, loses 8 digits of H), to a linear
                              residual of min(1e-2, KKT residual) times the nonlinear one (inexact
                              Newton); default 1 */
    int verbose;           /**< print one line per iteration on stderr; default 0 */
    int partial_projection; /**< newton, exact-Hessian path: when the exact Hessian is not positive
                              definite, project the terms whose projection is a cheap closed form
                              (plume_term.partial_projection: shape bending, edge-length
                              constraints) before shifting the whole matrix; default 1 */
    int curved_search;     /**< newton without constraints: a full step the line search refuses is
                              retried along u + alpha du + alpha^2/2 a, a the geodesic acceleration
                              (lib/solve/newton.c); default 1 */
    int trust_region;      /**< newton: globalise by an adaptive-regularisation trust region (a
                              shift sigma I added to the factorised matrix, grown when the step's
                              actual decrease of the l1 merit falls short of the quadratic model's
                              and shrunk when it matches) instead of the line search; default 0 */
    int exact_hessian_first; /**< newton without constraints: factorise the exact Hessian first and
                                fall back to the PSD-projected one if it is not positive definite;
                                default 1 */
    int stall_iterations;  /**< newton: stop (PLUME_REASON_STALLED) after this many iterations in a
                              row that cut neither the KKT residual nor the constraint violation to
                              half of its best in this solve; 0 (default): only max_iter stops */
} plume_solver_opts;

/** Fills o with the defaults each field names. */
PLUME_API void plume_solver_opts_default(plume_solver_opts *o);
/** Sets curved_search and trust_region for g. */
PLUME_API void plume_solver_opts_set_globalization(plume_solver_opts *o, plume_globalization g);

#ifdef __cplusplus
}
#endif
#endif
