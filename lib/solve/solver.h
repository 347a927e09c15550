/** \file
 * plume: nonlinear solvers with one report struct. Backends: native projected Newton / SQP with
 * CHOLMOD ("newton"), Ipopt ("ipopt"), a single linearised step ("linearized"). */
#ifndef PLUME_SOLVER_H
#define PLUME_SOLVER_H

#include "../core/export.h"
#include "../core/problem.h"
#include "options.h"
#include "report.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The solver backends (names "newton", "ipopt", "linearized"). */
typedef enum {
    PLUME_SOLVER_NEWTON = 0,    /**< the native projected Newton / SQP (lib/solve/newton.h) */
    PLUME_SOLVER_IPOPT = 1,     /**< Ipopt, interior point with exact Hessians (lib/solve/ipopt_solver.h) */
    PLUME_SOLVER_LINEARIZED = 2 /**< one full Newton step of the native solver, no convergence sought */
} plume_solver_kind;

/** Parses "newton" | "ipopt" | "linearized"; PLUME_EINVAL otherwise. */
PLUME_API plume_status plume_solver_kind_parse(const char *s, plume_solver_kind *out);
/** The name plume_solver_kind_parse accepts for k (static string); "unknown" out of range. */
PLUME_API const char *plume_solver_kind_name(plume_solver_kind k);

/** Opaque solver: one backend over one finalised problem (plume_solver_create, freed by
 * plume_solver_destroy). */
typedef struct plume_solver plume_solver;

/** Creates a solver for a finalised problem (kept by reference, not owned). Symbolic analysis
 * of the sparse systems happens here, once. PLUME_EINVAL for a problem not finalised or options
 * out of range, with a message naming them in err (NULL allowed). */
PLUME_API plume_status plume_solver_create(plume_solver_kind kind, plume_problem *p,
                                           const plume_solver_opts *o, plume_solver **out, plume_err *err);
/** Frees the solver (not the problem); sets *s = NULL; NULL-safe. */
PLUME_API void plume_solver_destroy(plume_solver **s);

/** Solves from u (nfree, in: start, out: result) and lambda (ncons, in: guess, out: multipliers
 * of the Lagrangian f + lambda.g). The problem's x holds the result on return. Returns an error
 * status only for errors (bad input, memory, dependency); convergence is in rep->reason. */
PLUME_API plume_status plume_solver_solve(plume_solver *s, double *u, double *lambda, plume_solve_report *rep);

/** Changes the relative KKT tolerance of the next solves (tol_kkt > 0 and finite, else
 * PLUME_EINVAL with a message in err, NULL allowed): one solver, one symbolic analysis, for solves
 * that need different accuracies (traction's small-strain probe). */
PLUME_API plume_status plume_solver_set_tol_kkt(plume_solver *s, double tol_kkt, plume_err *err);

/** Time spent and count of numeric factorisations / symbolic analyses so far (benchmarks). */
PLUME_API void plume_solver_stats(const plume_solver *s, int *analyses, int *factorizations,
                                  double *factor_seconds);

#ifdef __cplusplus
}
#endif
#endif
