/** \file
 * plume (micro): a barbule specimen's mesh opened at the barbules' distal ends, where hooks
 * (lib/core/hooks.h) hold it instead of shared vertices (docs/unzipping.md).
 *
 * An edge between a barb triangle and a barbule triangle is a distal join when the barb lies
 * ahead of the barbule along q, the direction from a barb to the next one (a barbule grows from
 * the barb behind it, which stays bonded, and hooks onto the barb ahead). The vertices of the
 * distal joins are duplicated: the barbule triangles take the copies. Each connected chain of
 * distal join edges is one hook; its pairs are (copy, original) of its vertices and, for
 * quadratic elements, of its edges' midpoints. */
#ifndef PLUME_MICRO_HOOK_MESH_H
#define PLUME_MICRO_HOOK_MESH_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A mesh opened at its distal joins, and its hooks; everything owned (plume_hook_mesh_free). */
typedef struct {
    plume_mesh *mesh;      /**< the opened mesh: the input's vertices first (same ids), then the copies;
                              the same triangles (the barbule ones renumbered to the copies); topology built */
    int nhooks;            /**< chains of distal join edges */
    plume_index *first;    /**< [nhooks + 1] hook h's pairs are first[h] .. first[h+1] - 1 */
    plume_index *pairs;    /**< [2 first[nhooks]] (copy on the barbule, original on the barb) */
    plume_index njoin;     /**< distal join edges */
    plume_index *joins;    /**< [4 njoin] each edge as (original a, b, copy a', b') */
    int *join_hook;        /**< [njoin] the hook of each */
} plume_hook_mesh;

/** Opens `m` (planar, topology built, materials PLUME_MAT_BARB and PLUME_MAT_BARBULE) at its
 * distal joins along q (2 components, any length > 0). A mesh without distal joins gives a copy
 * and no hooks. Errors: invalid arguments (PLUME_EINVAL), PLUME_ENOMEM. */
plume_status plume_hook_mesh_open(const plume_mesh *m, const double q[2], plume_hook_mesh *out, plume_err *err);

/** For a quadratic split of out->mesh (lib/core/mesh_quadratic.h: edge e's midpoint is node
 * out->mesh->nv + e), the hooks' pairs with their joins' midpoints added, into *first and *pairs
 * (allocated; freed by the caller). PLUME_ENOMEM; PLUME_EINVAL when a join edge is not an edge of
 * the mesh. */
plume_status plume_hook_mesh_quadratic_pairs(const plume_hook_mesh *h, plume_index **first, plume_index **pairs,
                                             plume_err *err);

void plume_hook_mesh_free(plume_hook_mesh *h);

#ifdef __cplusplus
}
#endif
#endif
