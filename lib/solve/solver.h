/** \file
 * plume: nonlinear solvers with one report struct. Backends: native projected Newton / SQP with
 * CHOLMOD ("newton"), Ipopt ("ipopt"), a single linearised step ("linearized"). */
#ifndef PLUME_SOLVER_H
#define PLUME_SOLVER_H

#include "../../include/plume/problem.h"

#include "../core/export.h"
#include "../core/problem.h"
#include "options.h"
#include "report.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Replaces *s by a solver of the same kind for its problem's new Hessian pattern (after
 * plume_problem_update_terms reported a change), as plume_solver_create with options o would,
 * reusing what does not depend on the new pattern: the fill-reducing order of the problem's
 * fixed pattern (plume_problem_fixed_pattern), in which the native solver analyses every pattern
 * whose factor it keeps within 1.2 times the fixed pattern's entries, so a few contact pairs
 * more or less need no new AMD and METIS analysis. On failure *s is left as it was and err says
 * why. */
plume_status plume_solver_renew(plume_solver **s, const plume_solver_opts *o, plume_err *err);

/** The tangent (consistent) predictor of an increment: where the solve of a step should start when
 * the prescribed dofs move from where the problem's x holds them to x_target and the loads have
 * already been changed. With K the tangent (the native solver's matrix at u and the prescribed
 * values x holds now, made positive definite as a Newton iteration makes it) it solves
 *   K_ff du = -(grad_f + K_fp dx_p),  J_f du = -(g + J_p dx_p)   (linearised KKT with constraints)
 * where grad_f is the gradient at u under the current loads (so it holds the load increment) and
 * K_fp dx_p, J_p dx_p are central differences of the gradient and constraints along the prescribed
 * move. u (nfree, in: start, out: u + du) and lambda (ncons, in: guess, out: the linearised
 * multipliers; NULL without constraints) are updated; x_target (dim*nv, only its prescribed
 * entries read; NULL: no move) is copied into x's prescribed dofs and u into its free ones in any
 * case. A predicted state whose energy cannot be evaluated is pulled back halfway up to 4 times.
 * *factorizations (may be NULL) gets the numeric factorisations it took. PLUME_EINVAL (message in
 * err) for the Ipopt backend or missing arguments; PLUME_ESINGULAR when no factorisation worked
 * or the predicted states were all undefined (u, lambda then unchanged); evaluation errors at the
 * start as the problem returns them. */
plume_status plume_solver_predict(plume_solver *s, double *u, double *lambda, const double *x_target,
                                            int *factorizations, plume_err *err);

/** Changes the relative KKT tolerance of the next solves (tol_kkt > 0 and finite, else
 * PLUME_EINVAL with a message in err, NULL allowed): one solver, one symbolic analysis, for solves
 * that need different accuracies (traction's small-strain probe). */
plume_status plume_solver_set_tol_kkt(plume_solver *s, double tol_kkt, plume_err *err);

/** Time spent and count of numeric factorisations / symbolic analyses so far (benchmarks). */
void plume_solver_stats(const plume_solver *s, int *analyses, int *factorizations,
                                  double *factor_seconds);

/** What a solver carries from one solve to the next beyond its options: the native solvers' last
 * non-zero Hessian shift, where the next inertia correction starts (0 for Ipopt, which carries
 * nothing). A checkpoint saves it and a restart sets it back, so that the restarted solves repeat
 * the first run's bit for bit. */
double plume_solver_memory(const plume_solver *s);
void plume_solver_set_memory(plume_solver *s, double memory);

#ifdef __cplusplus
}
#endif
#endif
