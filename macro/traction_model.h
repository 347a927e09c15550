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

/** The macro traction test as a model (the ctx of plume_macro_model_curve); borrowed arrays. */
typedef struct {
    double lx;              /**< sample width (m) */
    double ly;              /**< sample length between the grips (m) */
    double h;               /**< thickness (m) */
    double edge;            /**< mesh edge (m) */
    plume_patch_kind mesh;  /**< aligned or unaligned patch mesh (macro/patch_mesh.h) */
    int constraint;         /**< barbs inextensible */
    double kappa;           /**< compression coefficient of the membrane (Pa); 0 disables it */
    double strain_max;      /**< final nominal strain of each curve */
    int steps;              /**< quasi-static steps of each curve */
    int ncurves;            /**< curves the model computes (entries of angles) */
    const double *angles;   /**< [ncurves] barb angle of curve i (deg) */
    plume_solver_kind solver; /**< the traction test's solver backend */
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
