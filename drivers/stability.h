/** \file
 * plume: measurements of where methods fail: the
 * conditioning of the penalty model as the stiffness ratio grows (paper Figure 6), and the
 * collapse of St Venant–Kirchhoff elements under strong compression without the compression
 * term (supplementary Figure 7). */
#ifndef PLUME_STABILITY_H
#define PLUME_STABILITY_H

#include "../lib/core/export.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Condition estimate (1 / CHOLMOD rcond of the Hessian's factor at rest) of the tilted 45 deg
 * sample (1 x 1.3, aligned mesh of the given edge, grips clamped) with E_yy = G_xy = 1 and
 * E_xx = ratio. constraint 0: the penalty model, whose Hessian carries the stiff mode;
 * 1: what the constrained model leaves to the Hessian once the constraint has taken the stiff
 * mode out (the same sample with E_xx = E_yy), independent of the ratio. */
PLUME_API plume_status plume_stability_condition(double ratio, double edge, int constraint, double *cond, plume_err *err);

/** A strip one element wide (0.05 x 1 m, E = 1 Pa, nu = 0, planar) clamped at both ends and
 * compressed to a length ratio `lambda_end` in `steps` steps, with compression coefficient kappa
 * (0: plain St Venant–Kirchhoff, whose 1D energy softens below lambda = 1/sqrt 3) and the cubic
 * term, or with log_barrier the log barrier of supplementary §8 in its place. A tiny
 * deterministic imperfection lets the strip leave the unstable uniform state. Returns the
 * smallest and largest element area ratios J at the end, whether every step converged, and the
 * total Newton iterations. Without the term elements collapse and invert (J < 0) so that others
 * can stretch (J > 1); with it they stay open. */
PLUME_API plume_status plume_stability_compression(double kappa, int log_barrier, double lambda_end, int steps, double *min_J,
                                                   double *max_J, int *converged, int *iterations, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
