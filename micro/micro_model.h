/** \file
 * plume: the microscale model of a traction specimen — the resolved layout as a planar membrane
 * of barb and barbule materials, ready for the traction scenario (lib/sim/traction.h). */
#ifndef PLUME_MICRO_MODEL_H
#define PLUME_MICRO_MODEL_H

#include "../lib/core/export.h"
#include "../lib/core/problem.h"
#include "../lib/sim/traction.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Meshes the specimen [0, lx] x [0, ly] with barbs at angle_deg from the pulling axis y
 * (plume_specimen_mesh) and creates a planar problem holding the two-material membrane of the
 * layout's element order. At order 2 *mesh is the quadratic triangles split in four (its vertices
 * are the elements' nodes, lib/core/mesh_quadratic.h). The caller owns *mesh and *p (not finalised: plume_traction_run clamps and finalises it). */
PLUME_API plume_status plume_micro_specimen(const plume_layout *l, double lx, double ly, double angle_deg,
                                            plume_mesh **mesh, plume_problem **p, plume_err *err);

/** The elements of a specimen mesh made by plume_micro_specimen for layout l: its triangles, or at
 * order 2 its quadratic triangles (each split in four in the mesh). */
PLUME_API plume_index plume_micro_specimen_elements(const plume_layout *l, const plume_mesh *mesh);

/** How converged a micro traction run is: the same test on the specimen meshed with elements twice
 * as large (half as large when the layout refuses the coarser mesh). */
typedef struct {
    double edge;                  /**< target element edge of the run (m) */
    double refinement_edge;       /**< target element edge of the comparison (m) */
    double stress_change;         /**< max over the common curve points of |s - s'|, over max |s| */
    double slope_change;          /**< |initial_slope - initial_slope'| / |initial_slope| */
    plume_index refinement_elements; /**< elements of the comparison mesh */
    int converged;                /**< the comparison run converged (else the changes are -1) */
    double seconds;               /**< wall time of the comparison run */
} plume_micro_convergence;

/** Runs the traction test of `run` (options o, already done on the layout l) again on the
 * comparison mesh and fills *c. o->on_step is not called. A comparison run that does not converge
 * is not an error: c->converged is 0 and the changes are -1. */
PLUME_API plume_status plume_micro_traction_convergence(const plume_layout *l, double lx, double ly, double angle_deg,
                                                        const plume_traction_opts *o, const plume_traction_result *run,
                                                        plume_micro_convergence *c, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
