/** \file
 * plume: quadratic (6-node) triangles over a linear mesh — a node at the midpoint of every edge —
 * and the four-way split that shows them as an ordinary triangle mesh (output, grips, periodic
 * pairs). Linear triangles lock when a slender stiff strip bends in-plane; quadratic ones do not. */
#ifndef PLUME_MESH_QUADRATIC_H
#define PLUME_MESH_QUADRATIC_H

#include "export.h"
#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Output of plume_mesh_quadratic; every array is owned and freed by plume_quadratic_mesh_free. */
typedef struct {
    plume_mesh *split;  /**< nv + ne nodes (the corners keep their ids, edge e's midpoint is node nv + e), 4 nt
                           triangles: parent t's at 4t .. 4t+3 (corner v0, v1, v2, then the middle one), each
                           with the parent's material and barb direction; topology built */
    plume_index nt;     /**< quadratic triangles (the parent mesh's) */
    plume_index *tri6;  /**< [6 nt] corners v0 v1 v2 (counter-clockwise), then the midpoints of (v0 v1), (v1 v2),
                           (v2 v0) */
    int *material;      /**< [nt] the parents' material ids */
    double *barb_dir;   /**< [2 nt] the parents' barb directions */
} plume_quadratic_mesh;

/** Builds the quadratic triangles of a planar mesh whose topology is built (plume_mesh_build_topology):
 * midpoints in the reference (X) and current (x) configurations. PLUME_EINVAL without topology;
 * on failure nothing is left allocated. */
plume_status plume_mesh_quadratic(const plume_mesh *m, plume_quadratic_mesh *q, plume_err *err);
/** Frees the split mesh and the arrays of q and zeroes q (the struct itself is the caller's); NULL-safe. */
void plume_quadratic_mesh_free(plume_quadratic_mesh *q);

#ifdef __cplusplus
}
#endif
#endif
