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

/** Used by plume_solver_*; exposed for tests and benchmarks. */
typedef struct plume_ipopt plume_ipopt;
PLUME_API plume_status plume_ipopt_create(plume_problem *p, const plume_solver_opts *o, plume_ipopt **out);
PLUME_API void plume_ipopt_destroy(plume_ipopt **s);
PLUME_API plume_status plume_ipopt_solve(plume_ipopt *s, double *u, double *lambda, plume_solve_report *rep);
PLUME_API void plume_ipopt_set_tol_kkt(plume_ipopt *s, double tol_kkt);

#ifdef __cplusplus
}
#endif
#endif
