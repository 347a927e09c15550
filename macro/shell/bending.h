/** \file
 * plume: discrete anisotropic bending of a shell (docs/design.md "Bending"): a hinge energy on each
 * interior edge from its dihedral angle, rest angle from the rest shape, scaled with the edge
 * length and the adjacent areas so that bending a flat patch into a cylinder of curvature k
 * stores 1/2 D k^2 per unit area; D depends on the curvature direction relative to the barbs:
 * D_long bending the barbs (curvature along d, the paper's EI_perp), D_trans across them. */
#ifndef PLUME_BENDING_H
#define PLUME_BENDING_H

#include "../../include/plume/problem.h"

#include "../../lib/core/export.h"
#include "../../lib/core/mesh.h"
#include "../../lib/core/term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The plate moduli of the rotation-free bending terms (shape operator, midedge): every D finite
 * and >= 0 and D_coupling^2 <= D_long D_trans (a positive semidefinite plate), for each of the nmat
 * materials; PLUME_EINVAL naming `term`, the material and the modulus otherwise. */
plume_status plume_plate_moduli_check(const plume_bending_material *mats, int nmat, const char *term, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
