/** \file
 * plume: numerical homogenisation of a periodic microstructure cell into macroscale orthotropic
 * moduli, and the cell's nonlinear response curves at finite strain. */
#ifndef PLUME_HOMOGENIZE_H
#define PLUME_HOMOGENIZE_H

#include "../include/plume/homogenize.h"

#include "../lib/core/export.h"
#include "../lib/io/curves.h"
#include "../lib/solve/solver.h"
#include "cell_mesh.h"
#include "cell_plate.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Orthotropic moduli from a plane-stress tensor via its compliance: E_xx = 1/S11, E_yy = 1/S22,
 * G_xy = 1/S33, nu_xy = -S12/S11 (the shear coupling terms, if any, are ignored). PLUME_ESINGULAR
 * when the tensor is singular or not positive definite, with a message in err (NULL allowed). */
plume_status plume_ortho_from_tensor(const double C[9], plume_ortho *m, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
