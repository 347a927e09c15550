/** \file
 * plume: the microscale model of a traction specimen — the resolved layout as a planar membrane
 * of barb and barbule materials, ready for the traction scenario (lib/sim/traction.h). */
#ifndef PLUME_MICRO_MODEL_H
#define PLUME_MICRO_MODEL_H

#include "../include/plume/traction.h"

#include "../lib/core/export.h"
#include "../lib/core/problem.h"
#include "../lib/sim/traction.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
