/* plume: discrete anisotropic bending of a shell (DESIGN.md "Bending"): a hinge energy on each
 * interior edge from its dihedral angle, rest angle from the rest shape, scaled with the edge
 * length and the adjacent areas so that bending a flat patch into a cylinder of curvature k
 * stores 1/2 D k^2 per unit area; D depends on the curvature direction relative to the barbs:
 * D_long bending the barbs (curvature along d, the paper's EI_perp), D_trans across them. */
#ifndef PLUME_BENDING_H
#define PLUME_BENDING_H

#include "../lib/mesh.h"
#include "../lib/term.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bending stiffness of one material (N m): for an isotropic plate D_long = D_trans =
 * E t^3 / (12 (1 - nu^2)). */
typedef struct {
    double D_long;   /* curvature along the barb direction d (bending the barbs) */
    double D_trans;  /* curvature across the barbs */
} plume_bending_material;

/* A term over every interior edge (hinge) of a shell-mode mesh (dim 3, topology built): stencil
 * (edge v0, edge v1, opposite 0, opposite 1) as in mesh->hinges. Each hinge uses the materials and
 * barb directions of its two triangles (mats[mesh->material[t]], averaged over the two). Exact
 * gradient and Hessian; with project != 0 Hessian blocks are projected to PSD. Rest dihedral
 * angles are taken from mesh->X (flat: 0) unless rest_x (3*nv, may be NULL) gives a curved rest
 * shape. Errors (PLUME_EINVAL, message): dim != 3, negative/NaN stiffness, material id out of
 * range, a degenerate triangle. */
plume_status plume_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                       const double *rest_x, plume_term *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
