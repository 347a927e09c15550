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

typedef struct plume_newton plume_newton;

/** single_step = 1 gives the `linearized` backend. Analyses the sparse pattern once. */
PLUME_API plume_status plume_newton_create(plume_problem *p, const plume_solver_opts *o, int single_step,
                                           plume_newton **out, plume_err *err);
PLUME_API void plume_newton_destroy(plume_newton **s);
PLUME_API plume_status plume_newton_solve(plume_newton *s, double *u, double *lambda, plume_solve_report *rep);
PLUME_API void plume_newton_set_tol_kkt(plume_newton *s, double tol_kkt);
PLUME_API void plume_newton_stats(const plume_newton *s, int *analyses, int *factorizations, double *factor_seconds);

#ifdef __cplusplus
}
#endif
#endif
