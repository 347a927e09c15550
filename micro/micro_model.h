/** \file
 * plume: the microscale model of a traction specimen — the resolved layout as a planar membrane
 * of barb and barbule materials, ready for the traction scenario (lib/sim/traction.h). */
#ifndef PLUME_MICRO_MODEL_H
#define PLUME_MICRO_MODEL_H

#include "../include/plume/traction.h"

#include "../lib/core/export.h"
#include "../lib/core/problem.h"
#include "../lib/sim/traction.h"
#include "../lib/core/hooks.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

/** plume_micro_specimen (include/plume/traction.h) with the barbules' distal ends held by hooks
 * of the law `law` instead of shared vertices (micro/hook_mesh.h, lib/core/hooks.h;
 * docs/unzipping.md): the same specimen opened at its distal joins, the membrane term and the
 * hooks' term, which owns them: *hooks (may be NULL) is a view, valid while the problem lives.
 * plume_micro_specimen calls it with the layout's own law when its hook_strength is set. A
 * specimen without distal joins has no hooks (*hooks NULL). Succeeds whole or frees what it made. */
plume_status plume_micro_specimen_hooked(const plume_layout *l, double lx, double ly, double angle_deg,
                                         const plume_hook_law *law, plume_mesh **mesh, plume_problem **p,
                                         plume_hooks **hooks, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
