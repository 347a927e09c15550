/** \file
 * plume: the macroscale orthotropic vane — membrane from (E_xx, E_yy, nu_xy, G_xy) in the barb
 * frame, and the inextensibility constraint on barb-aligned edges (or the penalty alternative:
 * finite E_xx and no constraint). */
#ifndef PLUME_VANE_H
#define PLUME_VANE_H

#include "../include/plume/traction.h"

#include "../lib/core/export.h"
#include "../lib/io/curves.h"
#include "../lib/core/membrane.h"
#include "../lib/core/mesh.h"
#include "../lib/core/problem.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Edges of the mesh (topology built) parallel to the barb direction of an adjacent triangle
 * (|sin| of the angle <= align_tol); returns a malloc'ed array of 2*n vertex ids (free with
 * free()). PLUME_EINVAL (no mesh or topology, align_tol < 0) and PLUME_ENOMEM with a message in
 * err (NULL allowed). */
plume_status plume_vane_barb_edges(const plume_mesh *m, double align_tol, plume_index **edges,
                                             plume_index *n, plume_err *err);

/** Barb coverage (docs/design.md, "Meshes that respect the fibres"): counts the triangles of `m`
 * (topology built) whose material is `material` (or every triangle when material < 0) in *total,
 * and among them those owning at least one of the nbarb edges `barb_edges` (2*nbarb vertex ids,
 * either order; pairs that are not mesh edges are ignored) in *covered. With the constraint on,
 * a covered triangle has an inextensible barb (its constant strain has no barb stretch), an
 * uncovered one does not. If `uncovered` is non-NULL it receives a malloc'ed list of the
 * uncovered triangle ids (*total - *covered of them; NULL when none).
 * Errors: PLUME_EINVAL (NULL mesh or outputs, no topology, vertex id out of range, naming the
 * edge), PLUME_ENOMEM, with a message in err (NULL allowed). */
plume_status plume_vane_barb_coverage(const plume_mesh *m, const plume_index *barb_edges, plume_index nbarb,
                                                int material, plume_index *covered, plume_index *total,
                                                plume_index **uncovered, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
