/** \file
 * plume: the quadratic (6-node) planar membrane element — the material law of lib/core/membrane.h on
 * straight-sided quadratic triangles, which do not lock when slender stiff strips bend in-plane. */
#ifndef PLUME_MEMBRANE_P2_H
#define PLUME_MEMBRANE_P2_H

#include "export.h"
#include "membrane.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Creates the quadratic (6-node) planar membrane term: the material law of lib/core/membrane.h on
 * straight-sided quadratic triangles, integrated by the 6-point degree-4 rule (exact for the St
 * Venant–Kirchhoff part, whose density is quartic in the positions). X: [2 nnodes] reference
 * positions; tri6: [6 nt] node ids, corners v0 v1 v2 (counter-clockwise by convention; as in
 * lib/core/membrane.h the orientation does not matter) then the mid-edge nodes of (v0 v1), (v1 v2),
 * (v2 v0), which must lie at the edge midpoints up to rounding (PLUME_EINVAL otherwise, naming the
 * triangle); material [nt] ids in [0, nmat); barb_dir [2 nt] (normalised by the term). Everything
 * is copied. The term evaluates in dim 2 only (planar; another dim is PLUME_EINVAL). Stencils are
 * the 6 nodes in tri6's order (arity 6); per-element energies are offered. PLUME_ENOMEM if an
 * allocation fails; on failure *out is zeroed. */
plume_status plume_membrane_p2_term_create(const double *X, plume_index nnodes, const plume_index *tri6,
                                                     plume_index nt, const int *material, const double *barb_dir,
                                                     const plume_membrane_material *mats, int nmat, plume_term *out,
                                                     plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
