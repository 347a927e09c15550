/** \file
 * plume: the quasi-static traction test (docs/design.md, Scenarios): a rectangle [0,lx] x [0,ly]
 * clamped at y = 0 and at y = ly, the top grip moved by delta along y in steps. Works for any
 * planar or shell problem whose vertices are those of the mesh. */
#ifndef PLUME_TRACTION_H
#define PLUME_TRACTION_H

#include "../../include/plume/traction.h"

#include "../core/export.h"
#include "../io/curves.h"
#include "../core/mesh.h"
#include "../core/problem.h"
#include "../solve/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
