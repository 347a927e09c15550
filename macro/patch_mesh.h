/** \file
 * plume: meshes of a rectangular vane sample [0,lx] x [0,ly] with barbs at any angle. */
#ifndef PLUME_PATCH_MESH_H
#define PLUME_PATCH_MESH_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How a rectangular sample is meshed (names "aligned", "unaligned"). */
typedef enum {
    PLUME_PATCH_ALIGNED = 0,  /**< corner-exact: a barb line through every corner of the sample, the
                                 others uniformly between (<= edge sqrt(3)/2 apart), vertices on them
                                 every ~`edge` (and boundary points only where they meet the sides),
                                 barb segments kept as edges: every triangle owns a barb edge
                                 (check with plume_vane_barb_coverage, macro/vane.h) */
    PLUME_PATCH_UNALIGNED = 1 /**< quality Delaunay mesh (CGAL refinement) that ignores the barbs */
} plume_patch_kind;

/** Parses "aligned" | "unaligned" into *out; PLUME_EINVAL (no message) otherwise. */
PLUME_API plume_status plume_patch_kind_parse(const char *s, plume_patch_kind *out);

/** Barb direction for an angle (degrees) measured from the pulling axis y toward +x:
 * d = (sin a, cos a). */
PLUME_API void plume_patch_barb_direction(double angle_deg, double d[2]);

/** Meshes the rectangle at target edge length `edge` (m) with barbs at `angle_deg` in [0, 180].
 * Every triangle gets barb_dir = d, material 0; topology is built; x = X (z = 0 in shell mode).
 * Errors (PLUME_EINVAL, message names the parameter): non-finite or non-positive sizes, edge
 * larger than the sample, angle out of range, more than ~5e6 triangles requested. */
PLUME_API plume_status plume_patch_mesh(double lx, double ly, double angle_deg, double edge, plume_patch_kind kind,
                                        int dim, plume_mesh **out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
