/** \file
 * plume: triangle mesh with a flat 2D reference (material space) and a 2D or 3D current state. */
#ifndef PLUME_MESH_H
#define PLUME_MESH_H

#include "../../include/plume/problem.h"

#include "export.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The same for a mesh whose triangles from first_rigid on belong to rigid (kinematic) bodies: a
 * closed 3D surface has no flat reference, so their reference areas are not checked (they carry
 * no elastic energy; only their indices and manifoldness are). */
plume_status plume_mesh_build_topology_rigid(plume_mesh *m, plume_index first_rigid, plume_err *err);

/** The edge joining vertices u and v (either order), or -1: a binary search of m->edges, which
 * plume_mesh_build_topology leaves sorted by (i, j). */
plume_index plume_mesh_edge(const plume_mesh *m, plume_index u, plume_index v);

#ifdef __cplusplus
}
#endif
#endif
