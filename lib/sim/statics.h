/** \file
 * plume: static equilibrium under load stepping (docs/design.md "Quasi-static"): the load factor goes
 * from 0 to 1 in `steps` equal increments; at each one  min W(x) - factor f^T x  s.t. g(x) = 0 is
 * solved to convergence, starting from the secant extrapolation through the last two equilibria
 * (or from the last equilibrium). An increment that does not converge is halved (the state
 * restored) and the increment grows back (doubling, up to the nominal one) after each converged
 * sub-step, so a hard stretch of the load path costs more sub-steps, not a failure. */
#ifndef PLUME_STATICS_H
#define PLUME_STATICS_H

#include "../../include/plume/problem.h"

#include "../core/export.h"
#include "../core/problem.h"
#include "../solve/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The solver's numeric factorisations so far and the seconds spent in them (native solvers). */
void plume_statics_stats(const plume_statics *s, int *factorizations, double *factor_seconds);

/** Nominal steps completed so far (each one reached its load factor). */
int plume_statics_steps_done(const plume_statics *s);
/** The constraint multipliers of the last equilibrium, *m of them (m may be NULL); the driver's
 * array, valid until it is destroyed. */
const double *plume_statics_multipliers(const plume_statics *s, plume_index *m);

#ifdef __cplusplus
}
#endif
#endif
