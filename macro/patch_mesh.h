/** \file
 * plume: meshes of a rectangular vane sample [0,lx] x [0,ly] with barbs at any angle. */
#ifndef PLUME_PATCH_MESH_H
#define PLUME_PATCH_MESH_H

#include "../include/plume/traction.h"

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Barb direction for an angle (degrees) measured from the pulling axis y toward +x:
 * d = (sin a, cos a). */
void plume_patch_barb_direction(double angle_deg, double d[2]);

#ifdef __cplusplus
}
#endif
#endif
