/* plume: the microscale model of a traction specimen — the resolved layout as a planar membrane
 * of barb and barbule materials, ready for the traction scenario (lib/traction.h). */
#ifndef PLUME_MICRO_MODEL_H
#define PLUME_MICRO_MODEL_H

#include "../lib/problem.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Meshes the specimen [0, lx] x [0, ly] with barbs at angle_deg from the pulling axis y
 * (plume_specimen_mesh) and creates a planar problem holding the two-material membrane. The
 * caller owns *mesh and *p (not finalised: plume_traction_run clamps and finalises it). */
plume_status plume_micro_specimen(const plume_layout *l, double lx, double ly, double angle_deg,
                                  plume_mesh **mesh, plume_problem **p, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
