/** \file
 * plume: a flat C interface for bindings (python/plume uses it through ctypes): the main jobs
 * take a JSON request and give a JSON result, scenes are stepped through an opaque handle with
 * plain arrays. Only char, int, long, double and pointers cross it, so any FFI can call it without
 * mirroring plume's structs.
 *
 * Every function returns a plume_status (0 = PLUME_OK; plume_strerror names the others) and, on
 * failure, writes plume's message to msg (size nmsg, always NUL-terminated when nmsg > 0; msg may
 * be NULL). Results are malloc'ed JSON texts owned by the caller: free them with plume_flat_free.
 *
 * Requests (JSON objects; every key optional unless said otherwise). A text that is not JSON is
 * PLUME_EFORMAT; an unknown key or a bad value is PLUME_EINVAL with a message naming the key:
 *  - homogenize: {"layout": {...keys of a --config layout file: "layout", "phi", "d_B", "w_B",
 *    "E_b", "nu_b", "ratio", "nu_B", "thickness", "thickness_barb", "thickness_barbule", "kappa",
 *    "order", "e_rel", "barbule_width", "barbule_spacing", "barbule_angle"}, "strain_max": 0.05,
 *    "steps": 10, "output": "FILE.h5" (also write the moduli file plume_homog_write writes, the one
 *    apps/homogenize -o writes and a scene material's "from_moduli" reads; its directory is created
 *    with its parents, and a path that cannot be written is refused before the solve, naming it)}
 *    -> {"E_xx", "E_yy", "nu_xy", "G_xy", "C": [9], "D_long", "D_trans", "D_coupling", "D_twist",
 *        "D_16", "D_26" (N m, micro/cell_plate.h), "D": [9], "bending_change", "shear_coupling", "elements", "vertices",
 *        "newton_iterations", "seconds", "order", "element_edge", "refinement_change" (how
 *        converged: micro/homogenize.h), "moduli_change": {"E_xx", "E_yy", "nu_xy", "G_xy"},
 *        "refinement_edge", "curves": {"uniaxial_x"|"uniaxial_y"|"shear":
 *        {"strain": [], "stress": [], "wbar": [], "iterations": []}} (curves only when
 *        strain_max > 0), "output" (the file written, as given; only with "output")}
 *  - traction: {"model": "macro"|"micro", "angle": 45 (deg from the pull), "lx": 1, "ly": 1.3,
 *    "thickness": 1, "moduli": {"E_xx": 1e4, "E_yy": 1, "nu_xy": 0, "G_xy": 1} (all four, or
 *    the key absent for these), "kappa": 0,
 *    "constraint": true, "mesh": "aligned"|"unaligned", "edge": min(lx, ly) / 20,
 *    "strain_max": 0.05, "steps": 10, "solver": "newton"|"ipopt"|"linearized",
 *    "layout": {...} (model micro; as apps/traction, the barbs are 0.086 ly apart and the
 *    elements quadratic, their edge chosen from the thinnest strip, unless it says otherwise),
 *    "convergence": true (model micro: the curve again on a mesh twice as coarse), "vtk": "DIR" (a ParaView series of the
 *    steps: DIR/steps.pvd with DIR/step_NNNNN.vtu, and DIR/step_barbs_NNNNN.vtu for the macro
 *    model's constrained barbs; docs/paraview-output.md)}
 *    -> {"strain": [], "stress": [], "wbar": [], "iterations": [], "initial_slope",
 *        "converged", "failed_step", "stop_reason", "newton_iterations", "max_violation",
 *        "seconds", "elements", "vertices", "angle", and for the micro model "order",
 *        "element_edge", "refinement_change" and "slope_refinement_change" (micro/micro_model.h;
 *        -1 when not estimated)}
 *  - fit: {"targets": [{"angle": deg, "strain": [], "stress": []}, ...] (required), "start":
 *    {"E_xx", "E_yy", "nu_xy", "G_xy"} (required), "free": ["E_yy", "G_xy"], "max_eval": 300,
 *    "xtol_rel": 1e-6, and the macro traction keys above ("lx", "ly", "thickness", "kappa",
 *    "constraint", "mesh", "edge", "steps", "solver"; strain_max is each target's largest)}
 *    -> {"E_xx", "E_yy", "nu_xy", "G_xy", "residual", "evaluations", "stop", "seconds"}
 */
#ifndef PLUME_FLAT_H
#define PLUME_FLAT_H

#include "../include/plume/flat.h"

#include "../lib/core/export.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
