/* plume: measurements of where methods fail (issue 5's stability matrix, first cell): the
 * conditioning of the penalty model as the stiffness ratio grows (paper Figure 6). */
#ifndef PLUME_STABILITY_H
#define PLUME_STABILITY_H

#include "../lib/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Condition estimate (1 / CHOLMOD rcond of the Hessian's factor at rest) of the tilted 45 deg
 * sample (1 x 1.3, aligned mesh of the given edge, grips clamped) with E_yy = G_xy = 1 and
 * E_xx = ratio. constraint 0: the penalty model, whose Hessian carries the stiff mode;
 * 1: what the constrained model leaves to the Hessian once the constraint has taken the stiff
 * mode out (the same sample with E_xx = E_yy), independent of the ratio. */
plume_status plume_stability_condition(double ratio, double edge, int constraint, double *cond, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
