/** \file
 * plume: the periodic Kirchhoff plate cell problem, solved exactly — the effective bending tensor
 * of a cell whose phases are plates of their own thickness (docs/bending-homogenisation.md). */
#ifndef PLUME_CELL_PLATE_H
#define PLUME_CELL_PLATE_H

#include "../include/plume/homogenize.h"

#include "../lib/core/export.h"
#include "../lib/core/membrane.h"
#include "cell_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The moduli of a tensor D (3x3 row-major, the Voigt order above). */
void plume_plate_moduli_from_tensor(const double D[9], plume_plate_moduli *m);

/** Sizes of a plate cell solve (optional output). */
typedef struct {
    plume_index elements; /**< Morley triangles: the cell mesh's triangles */
    plume_index dofs;     /**< unknowns: periodic vertex deflections (one anchored) and edge slopes */
    plume_index nnz;      /**< stored entries of the upper triangle of the matrix */
} plume_cell_plate_info;

/** Effective bending tensor D (N m, Voigt (k11, k22, 2 k12) as above, row-major, in the cell frame)
 * of a periodic cell: for each unit macroscopic curvature kbar the deflection
 * w = 1/2 X^T kbar X + w~, w~ periodic, minimising the Kirchhoff plate energy
 * 1/2 sum_i int (kbar + grad grad w~)^T D_i (kbar + grad grad w~), D_i = h_i^3 / 12 Q_i (Q_i the
 * plane-stress tensor of mats[material] rotated from its triangle's barb direction, h_i its
 * thickness; all phases share one mid-surface), is found by one sparse Cholesky factorisation and
 * three solves, and the area-averaged moment gives a column of D. Morley triangles over the cell
 * mesh's triangles (at order 2 the split ones): curvature constant per triangle, periodicity by
 * pairing vertices and edges. Errors: PLUME_EINVAL (invalid arguments or material, a material id
 * out of range, a degenerate triangle, an edge without its periodic image), PLUME_ENOMEM,
 * PLUME_ESINGULAR (the matrix is not positive definite: a cell falling apart). */
plume_status plume_cell_plate_tensor(const plume_cell *cell, const plume_membrane_material *mats, int nmat,
                                     double D[9], plume_cell_plate_info *info, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
