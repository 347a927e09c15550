/** \file
 * plume: triangle mesh with a flat 2D reference (material space) and a 2D or 3D current state. */
#ifndef PLUME_MESH_H
#define PLUME_MESH_H

#include "export.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A triangle mesh. All arrays are owned by the mesh and freed by plume_mesh_destroy.
 * Inputs (set by whoever builds the mesh): nv, nt, dim, X, x, tri, barb_dir, material.
 * Outputs of plume_mesh_build_topology: edges, edge_tri, hinges, boundary. */
typedef struct {
    plume_index nv;        /**< vertices */
    plume_index nt;        /**< triangles */
    int dim;               /**< 2: planar mode (x in R^2), 3: shell mode (x in R^3) */
    double *X;             /**< [2*nv] reference positions, material space */
    double *x;             /**< [dim*nv] current positions */
    plume_index *tri;      /**< [3*nt] vertex ids, counter-clockwise in X */
    double *barb_dir;      /**< [2*nt] unit barb direction d per triangle, material space */
    int *material;         /**< [nt] material id per triangle */

    plume_index ne;        /**< edges (topology output) */
    plume_index *edges;    /**< [2*ne] vertex ids, i < j */
    plume_index *edge_tri; /**< [2*ne] adjacent triangles; second is -1 on the boundary */
    plume_index nh;        /**< interior hinges = interior edges */
    plume_index *hinges;   /**< [4*nh] (edge v0, edge v1, opposite in tri 0, opposite in tri 1) */
    unsigned char *boundary; /**< [nv] 1 if the vertex lies on the boundary */
} plume_mesh;

/** Allocates a mesh with nv vertices and nt triangles in `dim` dimensions; arrays zeroed,
 * barb_dir set to (1, 0), material to 0. Free with plume_mesh_destroy. PLUME_EINVAL (negative
 * counts, dim not 2 or 3) and PLUME_ENOMEM with a message in err (NULL allowed). */
PLUME_API plume_status plume_mesh_create(plume_index nv, plume_index nt, int dim, plume_mesh **out, plume_err *err);
/** Frees the mesh and every array it holds, sets *m = NULL; NULL-safe. */
PLUME_API void plume_mesh_destroy(plume_mesh **m);

/** Copies X into x (z = 0 in shell mode): the rest state. */
PLUME_API void plume_mesh_reset_current(plume_mesh *m);

/** Checks indices, orientation and non-degenerate areas; builds edges, edge_tri, hinges and
 * boundary flags. Fails with PLUME_EINVAL (message in err) on a bad or non-manifold mesh. */
PLUME_API plume_status plume_mesh_build_topology(plume_mesh *m, plume_err *err);

/** The same for a mesh whose triangles from first_rigid on belong to rigid (kinematic) bodies: a
 * closed 3D surface has no flat reference, so their reference areas are not checked (they carry
 * no elastic energy; only their indices and manifoldness are). */
PLUME_API plume_status plume_mesh_build_topology_rigid(plume_mesh *m, plume_index first_rigid, plume_err *err);

/** Signed reference area of triangle t. */
PLUME_API double plume_mesh_ref_area(const plume_mesh *m, plume_index t);

/** Total reference area. */
PLUME_API double plume_mesh_total_area(const plume_mesh *m);

#ifdef __cplusplus
}
#endif
#endif
