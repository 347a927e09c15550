/** \file
 * plume: the native solver — Newton (no constraints) or SQP on the regularised KKT system
 * (constraints), CHOLMOD factorisations, filter or merit line search (lib/solve/newton.c,
 * docs/theory-constraints.md). `linearized` is the same machinery limited to one full step. */
#ifndef PLUME_NEWTON_H
#define PLUME_NEWTON_H

#include "../core/export.h"
#include "../core/problem.h"
#include "options.h"
#include "report.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque native Newton/SQP solver over one finalised problem: its CHOLMOD factor and every
 * workspace of an iteration. */
typedef struct plume_newton plume_newton;

/** Creates the native solver for a finalised problem (kept by reference, not owned);
 * single_step = 1 gives the `linearized` backend. Analyses the sparse pattern once. PLUME_EINVAL
 * with a message naming the options out of range; PLUME_ENOMEM; errors of the symbolic analysis.
 * Free with plume_newton_destroy. */
plume_status plume_newton_create(plume_problem *p, const plume_solver_opts *o, int single_step,
                                           plume_newton **out, plume_err *err);
/** Frees the solver and its factorisation; sets *s = NULL; NULL-safe. */
void plume_newton_destroy(plume_newton **s);
/** Solves from u (nfree, in: start, out: result) and lambda (ncons, in: guess, out: multipliers),
 * as plume_solver_solve does: convergence is in rep->reason, the status is an error only for bad
 * arguments, memory or an evaluation that failed. */
plume_status plume_newton_solve(plume_newton *s, double *u, double *lambda, plume_solve_report *rep);
/** Sets the relative KKT tolerance of the next solves (unchecked; plume_solver_set_tol_kkt checks). */
void plume_newton_set_tol_kkt(plume_newton *s, double tol_kkt);
/** Symbolic analyses, numeric factorisations and factorisation seconds since creation (each output
 * may be NULL; zeros for s NULL). */
/* the last non-zero Hessian shift, the start of the next inertia correction (plume_solver_memory) */
double plume_newton_memory(const plume_newton *s);
void plume_newton_set_memory(plume_newton *s, double shift_last);
void plume_newton_stats(const plume_newton *s, int *analyses, int *factorizations, double *factor_seconds);

#ifdef __cplusplus
}
#endif
#endif
