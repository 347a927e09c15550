/** \file
 * plume: the tangent (consistent) predictor of an increment — the linearised response of the free
 * dofs to a move of the prescribed ones and a change of the loads, solved with the native solver's
 * factorisation at the increment's start (docs/solver-nonconvexity.md). */
#ifndef PLUME_PREDICT_H
#define PLUME_PREDICT_H

#include "../core/export.h"
#include "../core/problem.h"
#include "newton.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One linear KKT solve with the native solver's matrix at (u, lambda) and a given right-hand side:
 * factorises the Hessian of the Lagrangian (and the constraints' Jacobian, at u and the problem's
 * prescribed values) exactly as an iteration of plume_newton_solve does (exact Hessian with
 * inertia correction, partial or full projection when it is not positive definite), then solves
 *   [H J^T; J 0] [du; l] = -[r; c]
 * (regularised and refined as the solver's own steps are). u (nfree), lambda (ncons, may be NULL
 * without constraints), r (nfree), c (ncons, may be NULL without constraints) are inputs; du
 * (nfree) and lambda_out (ncons, may be NULL) outputs. Leaves the solver's options and later solves
 * unchanged; counts in plume_newton_stats. PLUME_ESINGULAR when no factorisation worked;
 * PLUME_EINVAL for missing arrays; evaluation errors as returned by the problem. */
plume_status plume_newton_linear_step(plume_newton *s, const double *u, const double *lambda, const double *r,
                                                const double *c, double *du, double *lambda_out);

#ifdef __cplusplus
}
#endif
#endif
