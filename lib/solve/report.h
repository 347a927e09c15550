/** \file
 * plume: what a solve reports, whichever backend ran it: why it stopped and what it took. */
#ifndef PLUME_SOLVE_REPORT_H
#define PLUME_SOLVE_REPORT_H

#include "../core/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Why a solve stopped. Only CONVERGED means the tolerances below were met. */
typedef enum {
    PLUME_REASON_CONVERGED = 0,   /**< the KKT residual and the violation met their tolerances */
    PLUME_REASON_ITERATION_CAP,   /**< max_iter reached */
    PLUME_REASON_LINE_SEARCH,     /**< no step decreased the merit function */
    PLUME_REASON_INFEASIBLE,      /**< constraints could not be satisfied */
    PLUME_REASON_NUMERICAL,       /**< non-finite values or a factorisation that kept failing */
    PLUME_REASON_SINGLE_STEP,     /**< `linearized`: one step taken, convergence not sought */
    PLUME_REASON_CONTACT_SET      /**< newton with continuous collision detection: the steps were cut
                                     to almost nothing for several iterations in a row, as when a
                                     pair outside the contact set blocks them (its barrier is not in
                                     the problem yet): the caller updates the terms' stencils and
                                     solves again from the point returned */,
    PLUME_REASON_STALLED          /**< newton with stall_iterations: that many iterations in a row
                                     cut neither the KKT residual nor the constraint violation to
                                     half of its best in this solve (a caller with a smaller step
                                     to try gives up early, instead of at the cap) */,
    PLUME_REASON_PRESCRIBED_CROSSING /**< dynamics with continuous collision detection: the step's
                                     prescribed motion alone (handles, attached and kinematic
                                     vertices moving, the rest standing still) runs into another
                                     body, so no solve can start (plume_contact_last_limit names
                                     the pair); smaller steps help only while the other body can
                                     get out of the way */
} plume_reason;

/** A short static name of r ("converged", "iteration cap", ...); "unknown" out of range. */
PLUME_API const char *plume_reason_name(plume_reason r);

/** What one solve did and where it stopped (plume_solver_solve fills every field). */
typedef struct {
    plume_reason reason;  /**< why the solve stopped */
    int converged;        /**< reason == CONVERGED */
    int iterations;       /**< Newton / SQP / Ipopt iterations */
    int factorizations;   /**< numeric factorisations (native solvers) */
    double energy;        /**< f at the returned point */
    double kkt_residual;  /**< plume_problem_kkt_residual at the returned point */
    double max_violation; /**< max relative constraint violation at the returned point */
    double seconds;       /**< wall time of the solve */
    int backtracks;       /**< newton: trial steps the line search rejected */
    int shifts;           /**< newton: factorisations rejected for inertia (each followed by a larger
                             diagonal shift, or by the projected Hessian) */
    int partial_projections; /**< newton: factorisations whose Hessian had the terms with a cheap
                              projection projected (the exact one was not positive definite) */
    int rejected_steps;   /**< newton, trust region: trial steps refused (each followed by a larger
                             regularisation and a new factorisation) */
    int curved_searches;  /**< newton: line searches along the geodesic-acceleration curve */
    int merit_fallbacks;  /**< newton, filter line search: iterations that fell back to the l1 merit
                             (no step down to 2^-29 was acceptable to the filter) */
    int chord_steps;      /**< newton: steps taken with an earlier factorisation (no new one) */
    int chord_rejected;   /**< newton: chord steps the line search refused whole (refactorised) */
    int refinements;      /**< newton, kkt_refine: iterative refinement passes over all solves */
    int step_limited;     /**< iterations whose step a term cut short (plume_term.max_step: continuous
                             collision detection), newton; ipopt: trial points refused for it */
} plume_solve_report;

#ifdef __cplusplus
}
#endif
#endif
