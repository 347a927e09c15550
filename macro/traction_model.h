/** \file
 * plume: the macroscale traction test as a model function of the moduli — what the fitter
 * (micro/fit.h, plume_fit_model) calls: one curve per scenario angle. */
#ifndef PLUME_TRACTION_MODEL_H
#define PLUME_TRACTION_MODEL_H

#include "../lib/core/export.h"
#include "../lib/io/curves.h"
#include "../lib/solve/solver.h"
#include "patch_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double lx, ly, h;       /**< sample (m) */
    double edge;            /**< mesh edge (m) */
    plume_patch_kind mesh;
    int constraint;         /**< barbs inextensible */
    double kappa;
    double strain_max;
    int steps;
    int ncurves;
    const double *angles;   /**< [ncurves] barb angle of curve i (deg) */
    plume_solver_kind solver;
} plume_macro_model;

/** plume_fit_model for the macroscale vane: runs the traction test at angles[icurve] with moduli
 * m and returns its curve (arrays malloc'ed, owned by out). A run that does not converge gives
 * PLUME_EINFEASIBLE; barbs spanning both grips too. */
PLUME_API plume_status plume_macro_model_curve(void *ctx, const plume_ortho *m, int icurve, plume_curve *out,
                                               plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
