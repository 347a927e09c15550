/** \file
 * plume: the small-strain (linearised) periodic cell problem, solved exactly: the effective
 * plane-stress tensor of a cell without finite differences. */
#ifndef PLUME_CELL_LINEAR_H
#define PLUME_CELL_LINEAR_H

#include "../lib/core/export.h"
#include "../lib/core/membrane.h"
#include "cell_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Effective tensor C (Pa, Voigt E11, E22, 2 E12, row-major, in the cell frame) of a periodic cell,
 * the membrane stiffness A (N/m; each material weighs with its own thickness mats[k].h) divided by
 * the reference thickness h_ref (m, finite and > 0; with one thickness h_ref = h, C is the
 * area-averaged 3D stress per unit strain):
 * for each unit macroscopic strain, the periodic fluctuation minimising the linearised membrane
 * energy 1/2 (eps + sym grad w) : C_t : (eps + sym grad w) (the small-strain limit of the
 * membrane element: its tangent at rest; the compression term has none there) is found by one
 * sparse Cholesky solve, and the area-averaged stress gives a column of C. A finite-difference
 * probe of the nonlinear cell cannot do this at a barb/barbule contrast of 1e-6: the Green strain
 * of a tiny probe loses to round-off exactly the digits the soft phase needs. */
plume_status plume_cell_linear_tensor(const plume_cell *cell, const plume_membrane_material *mats, int nmat,
                                      double h_ref, double C[9], int *iterations, plume_err *err);

/** C = T^T Cb T: a tensor given in the barb frame (Voigt with engineering shear, row-major) in the
 * cell frame, T the Voigt rotation of strains from the cell frame to the barb frame with the barb
 * direction d = (cos, sin) (unit). Curvatures (k11, k22, 2 k12) rotate like strains, so plate
 * tensors D use it too. */
void plume_cell_rotate_stiffness(const double Cb[9], const double d[2], double C[9]);

#ifdef __cplusplus
}
#endif
#endif
