/** \file
 * plume: the macroscale traction test as a model function of the moduli — what the fitter
 * (micro/fit.h, plume_fit_model) calls: one curve per scenario angle. */
#ifndef PLUME_TRACTION_MODEL_H
#define PLUME_TRACTION_MODEL_H

#include "../include/plume/fit.h"

#include "../lib/core/export.h"
#include "../lib/io/curves.h"
#include "../lib/solve/solver.h"
#include "patch_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
