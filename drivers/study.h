/** \file
 * plume: one measured traction run for studies of cost, error and sensitivity (apps/study): the
 * macroscale vane or the resolved microscale specimen, a configuration in, stress and w-bar at the
 * last load step, wall time, iterations and the convergence outcome out. */
#ifndef PLUME_STUDY_H
#define PLUME_STUDY_H

#include "../lib/core/export.h"
#include "../lib/io/curves.h"
#include "../lib/solve/solver.h"
#include "../micro/layout.h"
#include "../macro/patch_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Input of one run. */
typedef struct {
    double lx;                 /**< sample width (m); default 1 (supplementary Table 4) */
    double ly;                 /**< sample length between the grips (m); default 1.3 */
    double h;                  /**< thickness (m); default 1 (a micro run's layout.h follows it) */
    double angle;              /**< barb angle from the pulling axis y (deg); default 45 (tilted) */
    plume_ortho moduli;        /**< Pa; default E_xx 1e4, E_yy 1, G_xy 1, nu 0 */
    double kappa;              /**< compression-term coefficient; default 0 */
    int constraint;            /**< 1: inextensible barbs; 0: penalty (finite E_xx); default 1 */
    plume_patch_kind mesh;     /**< default PLUME_PATCH_ALIGNED */
    double edge;               /**< target edge length (m); default 0.065 (min(lx, ly)/20 is 0.05) */
    double strain_max;         /**< default 0.05 */
    int steps;                 /**< default 2 */
    plume_solver_kind solver;  /**< default newton */
    int max_iter;              /**< solver iteration cap per step; default 100 */
    int micro;                 /**< 1: the resolved microscale specimen of `layout` (plume_micro_specimen)
                                  in place of the vane: lx, ly, angle, strain_max, steps, solver and
                                  max_iter apply, moduli, kappa, constraint, mesh and edge do not, and h
                                  must equal layout.h. Default 0: the macroscale vane */
    plume_layout layout;       /**< micro only; default plume_layout_default */
} plume_study_config;

/** Fills c with the defaults each field names (layout.h set to h). */
PLUME_API void plume_study_config_default(plume_study_config *c);

/** Output of one run. `curve` is owned by the result (plume_study_result_free). */
typedef struct {
    plume_curve curve;       /**< the points computed (all steps unless a step failed) */
    double strain;           /**< nominal strain at the last computed point */
    double stress;           /**< nominal stress at the last computed point (Pa) */
    double wbar;             /**< w-bar at the last computed point */
    double seconds;          /**< wall time of the traction run (mesh and set-up excluded) */
    int iterations;          /**< solver iterations, all steps and the small-strain probe (solved
                                with the steps' tolerance: the study reads no initial slope) */
    int converged;           /**< every step converged (never for `linearized`) */
    int complete;            /**< the last point is at strain_max (linearized runs count) */
    plume_reason reason;     /**< CONVERGED, or why the first failed step stopped */
    long elements;           /**< elements (micro at order 2: quadratic triangles, not the four
                                triangles each is split into) */
    long vertices;           /**< mesh vertices (nodes) */
} plume_study_result;

/** Meshes, builds and runs the traction test of `c` (the vane, or the micro specimen). A step that does not converge is not an
 * error: the result says so (converged 0, reason) and holds the points before it. Errors
 * (invalid input or layout, barbs spanning both grips with the constraint on: PLUME_EINFEASIBLE,
 * a dependency) leave `r` zeroed with a message in err. */
PLUME_API plume_status plume_study_traction(const plume_study_config *c, plume_study_result *r, plume_err *err);

/** Frees the curve's arrays and zeroes r; NULL-safe. */
PLUME_API void plume_study_result_free(plume_study_result *r);

/** |a - ref| / |ref| (|a - ref| if ref is 0); NaN if either is not finite. */
PLUME_API double plume_study_rel_error(double a, double ref);

#ifdef __cplusplus
}
#endif
#endif
