/** \file
 * plume: the membrane element of docs/design.md — orthotropic St Venant–Kirchhoff in the barb frame
 * plus the cubic compression term (supplementary equation 6), planar (dim 2) and shell (dim 3) modes,
 * exact gradient and Hessian. */
#ifndef PLUME_MEMBRANE_H
#define PLUME_MEMBRANE_H

#include "../../include/plume/problem.h"

#include "export.h"
#include "mesh.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Checks a material: moduli finite and > 0, h > 0, kappa >= 0, and the plane-stress tensor
 * positive definite (nu_xy^2 < E_xx/E_yy). PLUME_EINVAL naming the parameter otherwise. */
plume_status plume_membrane_material_check(const plume_membrane_material *mat, plume_err *err);

/** Checks a plane-stress tensor C (3x3 row-major): finite, symmetric, positive definite.
 * PLUME_EINVAL with the reason otherwise. */
plume_status plume_membrane_tensor_check(const double C[9], plume_err *err);

/** The plane-stress stiffness C (3x3 row-major, Voigt order E11, E22, 2E12) of a material. */
void plume_membrane_stiffness(const plume_membrane_material *mat, double C[9]);

/** Energy density per reference area (J/m^2) of a uniform deformation gradient F (dim x 2,
 * row-major) for barb direction d (unit, material space): h [1/2 e.C e + psi_c(J)]. */
double plume_membrane_density(const plume_membrane_material *mat, int dim, const double *F,
                                        const double d[2]);

/** The Green strain E (dimensionless) and the second Piola–Kirchhoff stress S (Pa) of a uniform
 * deformation gradient F (dim x 2, row-major) in the barb frame of direction d, as tensor
 * components (bb, tt, bt), and the area ratio J. S = dW/dE per unit volume, the compression term
 * included: plume_membrane_density changes by h S:dE. PLUME_EINVAL for bad arguments; S is NaN
 * for a collapsed triangle (J = 0). */
plume_status plume_membrane_strain_stress(const plume_membrane_material *mat, int dim, const double *F,
                                                    const double d[2], double E[3], double S[3], double *J);

/** plume_membrane_density with the plane-stress tensor C (row-major 3x3, Pa; NULL: the moduli's) in
 * place of the material's moduli (plume_membrane_term_create_tensor). */
double plume_membrane_density_tensor(const plume_membrane_material *mat, const double *C, int dim, const double *F,
                                     const double d[2]);

/** plume_membrane_strain_stress with the plane-stress tensor C (NULL: the moduli's). */
plume_status plume_membrane_strain_stress_tensor(const plume_membrane_material *mat, const double *C, int dim,
                                                 const double *F, const double d[2], double E[3], double S[3],
                                                 double *J);

#ifdef __cplusplus
}
#endif
#endif
