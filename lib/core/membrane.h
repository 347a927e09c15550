/** \file
 * plume: the membrane element of docs/design.md — orthotropic St Venant–Kirchhoff in the barb frame
 * plus the cubic compression term (supplementary equation 6), planar (dim 2) and shell (dim 3) modes,
 * exact gradient and Hessian. */
#ifndef PLUME_MEMBRANE_H
#define PLUME_MEMBRANE_H

#include "export.h"
#include "mesh.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One membrane material: 3D moduli (Pa) in the barb frame (x along the barbs), thickness h (m)
 * and the compression coefficient kappa (Pa; 0 disables the term). */
typedef struct {
    double E_xx;  /**< Young's modulus along the barbs (Pa) */
    double E_yy;  /**< Young's modulus across the barbs (Pa) */
    double nu_xy; /**< Poisson's ratio: contraction across the barbs under a pull along them */
    double G_xy;  /**< in-plane shear modulus (Pa) */
    double h;     /**< thickness (m) */
    double kappa; /**< compression coefficient (Pa); 0 disables the compression term */
    int log_barrier; /**< 0: the cubic compression term (default); 1: a log barrier
                        kappa/12 (J - 1 - ln J) for J < 1 in its place (supplementary §8: it blows
                        up as J -> 0, and the paper found the solver could not converge with it) */
} plume_membrane_material;

/** Checks a material: moduli finite and > 0, h > 0, kappa >= 0, and the plane-stress tensor
 * positive definite (nu_xy^2 < E_xx/E_yy). PLUME_EINVAL naming the parameter otherwise. */
PLUME_API plume_status plume_membrane_material_check(const plume_membrane_material *mat, plume_err *err);

/** The plane-stress stiffness C (3x3 row-major, Voigt order E11, E22, 2E12) of a material. */
PLUME_API void plume_membrane_stiffness(const plume_membrane_material *mat, double C[9]);

/** Energy density per reference area (J/m^2) of a uniform deformation gradient F (dim x 2,
 * row-major) for barb direction d (unit, material space): h [1/2 e.C e + psi_c(J)]. */
PLUME_API double plume_membrane_density(const plume_membrane_material *mat, int dim, const double *F,
                                        const double d[2]);

/** The Green strain E (dimensionless) and the second Piola–Kirchhoff stress S (Pa) of a uniform
 * deformation gradient F (dim x 2, row-major) in the barb frame of direction d, as tensor
 * components (bb, tt, bt), and the area ratio J. S = dW/dE per unit volume, the compression term
 * included: plume_membrane_density changes by h S:dE. PLUME_EINVAL for bad arguments; S is NaN
 * for a collapsed triangle (J = 0). */
PLUME_API plume_status plume_membrane_strain_stress(const plume_membrane_material *mat, int dim, const double *F,
                                                    const double d[2], double E[3], double S[3], double *J);

/** Creates a term over every triangle of `mesh`: triangle t uses mats[mesh->material[t]] (ids
 * must be in [0, nmat), else PLUME_EINVAL) and mesh->barb_dir[t]. Reference geometry is precomputed (copied), so the
 * mesh may be freed afterwards. The term's stencils are the triangles (arity 3). */
PLUME_API plume_status plume_membrane_term_create(const plume_mesh *mesh, int dim,
                                                  const plume_membrane_material *mats, int nmat,
                                                  plume_term *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
