/** \file
 * plume: structured right-triangle grids of a rectangle (benchmark strips and plates). */
#ifndef PLUME_GRID_MESH_H
#define PLUME_GRID_MESH_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** [0, lx] x [0, ly] cut into nx x ny cells, each split into two right triangles along the
 * diagonal from its lower-left to its upper-right corner. barb_dir = d (normalised; (1, 0) if
 * d is NULL), material 0, topology built, x = X (z = 0 in shell mode). Errors (PLUME_EINVAL,
 * message): non-positive or non-finite sizes, nx or ny < 1, more than 5e6 triangles. */
plume_status plume_grid_mesh(double lx, double ly, long nx, long ny, const double d[2], int dim, plume_mesh **out,
                                       plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
