/** \file
 * plume: discrete anisotropic bending of a shell (docs/design.md "Bending"): a hinge energy on each
 * interior edge from its dihedral angle, rest angle from the rest shape, scaled with the edge
 * length and the adjacent areas so that bending a flat patch into a cylinder of curvature k
 * stores 1/2 D k^2 per unit area; D depends on the curvature direction relative to the barbs:
 * D_long bending the barbs (curvature along d, the paper's EI_perp), D_trans across them. */
#ifndef PLUME_BENDING_H
#define PLUME_BENDING_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"
#include "../lib/core/term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Bending stiffness of one material (N m): for an isotropic plate D_long = D_trans =
 * E t^3 / (12 (1 - nu^2)), D_coupling = nu D, D_twist = (1 - nu) D / 2.
 * The orthotropic plate energy density, k11 along d, k22 across, k12 the twist in the barb frame:
 *     1/2 (D_long k11^2 + D_trans k22^2 + 2 D_coupling k11 k22 + 4 D_twist k12^2).
 * D_twist and D_coupling are read only by the shape-operator term (macro/shape_bending.h); the
 * hinge term below ignores them (a hinge sees one normal curvature, not the twist). They come
 * after D_long and D_trans so that `{D_long, D_trans}` initialisers keep meaning what they did,
 * with both new fields zero (gcc -Wextra flags such partial initialisers: spell the zeros out or
 * use designated initialisers). D_twist == 0 means "derive it by Huber's approximation for
 * orthotropic plates", D_coupling + 2 D_twist = sqrt(D_long D_trans), i.e.
 * D_twist = (sqrt(D_long D_trans) - D_coupling) / 2 (isotropic: D_coupling + 2 D_twist = D).
 * All four must be finite and >= 0, and D_coupling^2 <= D_long D_trans (a positive semidefinite
 * plate). */
typedef struct {
    double D_long;     /**< curvature along the barb direction d (bending the barbs) */
    double D_trans;    /**< curvature across the barbs */
    double D_twist;    /**< D_66, twist; 0: (sqrt(D_long D_trans) - D_coupling) / 2 (Huber) */
    double D_coupling; /**< D_12, Poisson-type coupling of k11 and k22 */
} plume_bending_material;

/** A term over every interior edge (hinge) of a shell-mode mesh (dim 3, topology built): stencil
 * (edge v0, edge v1, opposite 0, opposite 1) as in mesh->hinges. Each hinge uses the materials and
 * barb directions of its two triangles (mats[mesh->material[t]], averaged over the two). Exact
 * gradient and Hessian; with project != 0 Hessian blocks are projected to PSD. Rest dihedral
 * angles are taken from mesh->X (flat: 0) unless rest_x (3*nv, may be NULL) gives a curved rest
 * shape. Errors (PLUME_EINVAL, message): dim != 3, negative/NaN stiffness, material id out of
 * range, a degenerate triangle. D_twist and D_coupling are ignored (not validated either). */
PLUME_API plume_status plume_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                                 const double *rest_x, plume_term *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
