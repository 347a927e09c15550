/** \file
 * plume: mesh-independent anisotropic bending of a shell (docs/design.md "Bending"; "Bending is a
 * property of the surface, not of the mesh's edges"): a per-triangle second fundamental form
 * fitted exactly to every quadratic height field on any triangulation (the 6-vertex
 * shape-operator stencil, macro/shape_bending.c), and the orthotropic plate energy of its
 * change from the rest shape in each triangle's barb frame:
 *     A/2 (D_long k11^2 + D_trans k22^2 + 2 D_coupling k11 k22 + 4 D_twist k12^2).
 * A flat patch bent into a cylinder of curvature k at angle phi to the barbs stores, per unit
 * area, 1/2 k^2 (D_long c^4 + D_trans s^4 + (2 D_coupling + 4 D_twist) c^2 s^2), c = cos phi,
 * s = sin phi, whatever the mesh (up to O(h^2), measured in tests/test_shape_bending.c). */
#ifndef PLUME_SHAPE_BENDING_H
#define PLUME_SHAPE_BENDING_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"
#include "../lib/core/term.h"
#include "bending.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A term with one stencil per triangle of a shell-mode mesh (dim 3, topology built): arity 6,
 * (x0, x1, x2, p1, p2, p3) with (x0, x1, x2) = mesh->tri[t] and p_k the vertex across the edge
 * opposite x_{k-1} in the neighbouring triangle, or, on a boundary edge, the vertex of the 2-ring
 * (3-ring if need be) that keeps the quadratic fit best conditioned. Material mats[material[t]]
 * (all four fields, D_twist == 0 derived as documented in bending.h), barb direction
 * barb_dir[t] (normalised here). Rest shape mesh->X (flat) unless rest_x (3*nv, may be NULL)
 * gives a curved one. Exact gradient and Hessian; with project != 0 the Hessian blocks are the
 * Gauss-Newton part only (PSD by construction, no eigen-decomposition). eval fails with
 * PLUME_ESINGULAR when a current triangle has collapsed (its normal is undefined); the energy and
 * gradient are then not accumulated in full. Errors at create (PLUME_EINVAL, message): dim != 3,
 * topology not built, a negative/NaN/infinite stiffness or D_coupling^2 > D_long D_trans (naming
 * the material and field), material or vertex id out of range, a barb direction that cannot be
 * normalised, a degenerate reference triangle, a triangle with no well-conditioned stencil (a
 * mesh with too few vertices, e.g., one or two triangles), a rest_x that is not finite or
 * collapses a triangle. */
plume_status plume_shape_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                                       const double *rest_x, plume_term *out, plume_err *err);

/** Options of plume_shape_bending_term_create_opts (all zero: the default term above).
 *
 * clamped (nv flags, may be NULL) marks the vertices a clamp holds. A boundary edge whose two
 * vertices are both clamped is a clamped edge: the surface leaves it with zero slope, in the
 * rest tangent plane of the clamp. Its triangle's missing stencil vertex is then the mirror image
 * of the triangle's own vertex opposite the edge, through the plane that contains the edge and the
 * rest normal (of rest_x if given, else of the flat mesh->X at z = 0; the clamped vertices must
 * be held at their rest positions, which the caller does). The fit is exact for every quadratic
 * surface that meets the clamp with zero slope, so a clamped strip bends from the clamp line
 * itself, not from its second row (which would shorten it by about half an element).
 *
 * own_fit_only != 0 uses each triangle's own 6-point fit alone (the first formulation, arity 6):
 * exact for quadratics but it fails the patch test on irregular meshes (kept for comparison,
 * see shape_bending.c).
 *
 * phase_aware != 0 treats a change of material id as a boundary for the fit: a triangle's own fit
 * takes its points from triangles of its own material only (the vertex across an edge into
 * another material is replaced from the triangle's rings within its material, as on a boundary).
 * The slope across such an edge is still the mean of the two sides' fits, so the patch test and
 * the exactness for quadratics are kept; what changes is that a curvature jump between phases (a
 * stiff barb beside a soft matrix) is no longer smeared by a fit through both: a piecewise
 * quadratic C1 surface whose pieces meet on mesh edges is reproduced exactly. Where a phase is too
 * thin to hold a well-conditioned stencil, the triangle's stencil is searched in the whole mesh,
 * as without the option. For resolved microstructures (plume_shell_specimen). */
typedef struct {
    const unsigned char *clamped; /**< [nv] non-zero for a clamped vertex, or NULL (borrowed) */
    int own_fit_only;             /**< != 0: each triangle's own 6-point fit alone */
    int phase_aware;              /**< != 0: no fit spans two materials (see above) */
} plume_shape_bending_opts;

/** The term with options (o may be NULL). Errors as above, and PLUME_EINVAL for a clamped edge
 * with no mirror plane (a collapsed rest_x triangle). */
plume_status plume_shape_bending_term_create_opts(const plume_mesh *mesh, const plume_bending_material *mats,
                                                            int nmat, const double *rest_x, const plume_shape_bending_opts *o,
                                                            plume_term *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
