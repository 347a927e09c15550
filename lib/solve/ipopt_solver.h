/** \file
 * plume: the Ipopt backend of plume_solver (lib/solve/ipopt_solver.c): the problem as an NLP with
 * exact Hessians through Ipopt's C interface. */
#ifndef PLUME_SOLVE_IPOPT_SOLVER_H
#define PLUME_SOLVE_IPOPT_SOLVER_H

#include "../core/export.h"
#include "../core/problem.h"
#include "options.h"
#include "report.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque Ipopt solver over one finalised problem. Used by plume_solver_*; exposed for tests and
 * benchmarks. */
typedef struct plume_ipopt plume_ipopt;
/** Creates an Ipopt solver for a finalised problem (kept by reference, not owned), with the
 * tolerances and iteration cap of o. PLUME_EINVAL (no message) for a problem not finalised,
 * options out of range or sizes beyond Ipopt's int indices; PLUME_ENOMEM. Free with
 * plume_ipopt_destroy. */
plume_status plume_ipopt_create(plume_problem *p, const plume_solver_opts *o, plume_ipopt **out);
/** Frees the solver and its Ipopt problem; sets *s = NULL; NULL-safe. */
void plume_ipopt_destroy(plume_ipopt **s);
/** Solves from u (nfree, in: start, out: result) and lambda (ncons, in: guess, out: multipliers),
 * as plume_solver_solve does: convergence is in rep->reason, the status is an error only for bad
 * arguments, memory or Ipopt failing. */
plume_status plume_ipopt_solve(plume_ipopt *s, double *u, double *lambda, plume_solve_report *rep);
/** Sets the relative KKT tolerance of the next solves (unchecked; plume_solver_set_tol_kkt checks). */
void plume_ipopt_set_tol_kkt(plume_ipopt *s, double tol_kkt);

#ifdef __cplusplus
}
#endif
#endif
