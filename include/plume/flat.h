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
 *  - homogenize: {"layout": {...keys of a layout file (docs/layout-format.md): "layout", "phi", "d_B", "w_B",
 *    "E_b", "nu_b", "ratio", "nu_B", "thickness", "thickness_barb", "thickness_barbule", "kappa",
 *    "order", "e_rel", "barbule_width", "barbule_spacing", "barbule_angle"}, "strain_max": 0.05,
 *    "steps": 10, "output": "FILE.h5" (also write the moduli file plume_homog_write writes, the one
 *    apps/homogenize -o writes and a scene material's "from_moduli" reads; its directory is created
 *    with its parents, and a path that cannot be written is refused before the solve, naming it)}
 *    -> {"E_xx", "E_yy", "nu_xy", "G_xy", "C": [9], "D_long", "D_trans", "D_coupling", "D_twist",
 *        "D_16", "D_26" (N m, homogenize.h), "D": [9], "bending_change", "shear_coupling", "elements", "vertices",
 *        "newton_iterations", "seconds", "order", "element_edge", "refinement_change" (how
 *        converged: homogenize.h), "moduli_change": {"E_xx", "E_yy", "nu_xy", "G_xy"},
 *        "refinement_edge", "curves": {"uniaxial_x"|"uniaxial_y"|"shear":
 *        {"strain": [], "stress": [], "wbar": [], "iterations": []}} (curves only when
 *        strain_max > 0), "output" (the file written, as given; only with "output"), and for a
 *        layout with hooks "separation": {"strength", "energy", "opening", "capture",
 *        "stiffness", "peak_opening", "cell_length", "solves", "newton_iterations", "tensor" (the
 *        hooked cell's small-strain tensor, 9 numbers, Pa: plume_separation_tensor)}
 *        (plume_separation_law)}
 *  - traction: {"model": "macro"|"micro", "angle": 45 (deg from the pull), "lx": 1, "ly": 1.3,
 *    "thickness": 1, "moduli": {"E_xx": 1e4, "E_yy": 1, "nu_xy": 0, "G_xy": 1} (all four, or
 *    the key absent for these), "kappa": 0,
 *    "constraint": true, "mesh": "aligned"|"unaligned", "edge": min(lx, ly) / 20,
 *    "strain_max": 0.05, "steps": 10, "solver": "newton"|"ipopt"|"linearized",
 *    "layout": {...} (model micro; as apps/traction, the barbs are 0.086 ly apart and the
 *    elements quadratic, their edge chosen from the thinnest strip, unless it says otherwise),
 *    "path": [0.03, 0, 0.03] (the strains the grip goes to in turn, each leg in "steps" steps;
 *    plume_traction_opts.path; absent: one leg to strain_max), "peel": 0 and "top_grip_free": 0
 *    (how the top grip turns, how much of its edge it leaves free: plume_traction_opts), "layout"
 *    may hold the hook keys
 *    (docs/layout-format.md), "split_lines": N (model macro, mesh aligned: N barb lines that
 *    split and zip again, plume_splits_open) with "separation": {"strength": N/m, "stiffness":
 *    N/m^2, "capture": m} (their law: a homogenize result's "separation", other keys ignored),
 *    "tensor": [9 numbers] (model macro: the membrane's plane-stress tensor in the barb frame, Pa,
 *    row-major, in place of the moduli's orthotropic one: a homogenize result's "C";
 *    plume_vane_add_tensor; not with "vtk"),
 *    "convergence": true (model micro: the curve again on a mesh twice as coarse), "vtk": "DIR" (a ParaView series of the
 *    steps: DIR/steps.pvd with DIR/step_NNNNN.vtu, and DIR/step_barbs_NNNNN.vtu for the macro
 *    model's constrained barbs; docs/paraview-output.md), "checkpoint": "FILE.h5", "restart":
 *    "FILE.h5", "stop_after": N (the run's state after every step, a run continued from it bit
 *    for bit, a run ended after step N: plume_traction_opts; "restart" not with "vtk")}
 *    -> {"strain": [], "stress": [], "wbar": [], "iterations": [], "initial_slope",
 *        "converged", "failed_step", "stop_reason", "newton_iterations", "max_violation",
 *        "seconds", "elements", "vertices", "angle", and for the micro model "order",
 *        "element_edge", "refinement_change" and "slope_refinement_change" (traction.h;
 *        -1 when not estimated), and the energy balance and hooks: "peak_stress", "work",
 *        "stored_energy", "dissipated_energy", "energy_balance_error", "hooks_released",
 *        "hooks_reengaged", "largest_cascade", "release_events" (plume_traction_result), and with
 *        "split_lines" "split_pairs" (the lines' vertex pairs, which the hooks' counts count)}
 *  - fit: {"targets": [{"angle": deg, "strain": [], "stress": []}, ...] (required), "start":
 *    {"E_xx", "E_yy", "nu_xy", "G_xy"} (required), "free": ["E_yy", "G_xy"], "max_eval": 300,
 *    "xtol_rel": 1e-6, and the macro traction keys above ("lx", "ly", "thickness", "kappa",
 *    "constraint", "mesh", "edge", "steps", "solver"; strain_max is each target's largest)}
 *    -> {"E_xx", "E_yy", "nu_xy", "G_xy", "residual", "evaluations", "stop", "seconds"}
 */
#ifndef PLUME_PUBLIC_FLAT_H
#define PLUME_PUBLIC_FLAT_H

#include "base.h"


#ifdef __cplusplus
extern "C" {
#endif

/* ---- the flat interface ---- */
/** Runs the "homogenize" request above (plume_homogenize) and gives its result in *result, a
 * malloc'ed JSON text (plume_flat_free; NULL on failure). With "output": "FILE.h5" it also writes
 * the moduli file (plume_homog_write: what a scene's "from_moduli" reads) and the result names it
 * ("output"). PLUME_EFORMAT / PLUME_EINVAL for a bad request, PLUME_EIO for an output that cannot
 * be written (before the solve when its directory cannot be; the message names the key and the
 * file), and the errors of the homogenisation, with the message in msg. */
PLUME_API plume_status plume_flat_homogenize(const char *request, char **result, char *msg, long nmsg);

/** Runs the "traction" request above (the macro vane or the micro specimen through
 * plume_traction_run) and gives its result in *result (plume_flat_free; NULL on failure). A run
 * that does not converge is a result ("converged": false, "stop_reason"), not an error. */
PLUME_API plume_status plume_flat_traction(const char *request, char **result, char *msg, long nmsg);

/** Runs the "fit" request above (plume_fit_moduli over the macro traction model) and gives its
 * result in *result (plume_flat_free; NULL on failure). */
PLUME_API plume_status plume_flat_fit(const char *request, char **result, char *msg, long nmsg);

/** Frees a text this interface returned (free()); NULL-safe. */
PLUME_API void plume_flat_free(char *text);

/** A dynamic scene (docs/scene-format.md) being stepped, with its contact and friction if it has them. */
typedef struct plume_flat_scene plume_flat_scene;

/** Loads and sets up the scene at `path` (errors name the file, line and key). */
PLUME_API plume_status plume_flat_scene_open(const char *path, plume_flat_scene **out, char *msg, long nmsg);

/** The same from a scene document in memory (JSON text) standing for the file `path`: relative file
 * names in it resolve against path's directory, errors name path and the key (scene.h,
 * plume_scene_load_json). */
PLUME_API plume_status plume_flat_scene_open_json(const char *json, const char *path, plume_flat_scene **out, char *msg,
                                                  long nmsg);

/** Frees the scene, its problem, stepper and output series; sets *s = NULL; NULL-safe. */
PLUME_API void plume_flat_scene_close(plume_flat_scene **s);

/** Advances nsteps time steps of the scene's dt (each halved when it fails) through the scene runner
 * (plume_run, scene.h), so under its acceptance rule (plume_run_accepts, as apps/feather): a step is
 * accepted when it converged, or with the `linearized` solver when it advanced. *report (may be
 * NULL) gets {"steps" (accepted), "time", "converged", "halvings", "newton_iterations",
 * "max_violation", "seconds", "stop_reason"}. A step that is not accepted is not an error: the
 * state stays at the last converged substep, the call stops, "converged" is false, "stop_reason"
 * says why, and the status is PLUME_OK. */
PLUME_API plume_status plume_flat_scene_step(plume_flat_scene *s, int nsteps, char **report, char *msg, long nmsg);

/** The scene mesh's number of vertices nv (0 for s NULL). */
PLUME_API long plume_flat_scene_nv(const plume_flat_scene *s);

/** The scene mesh's number of triangles nt (0 for s NULL). */
PLUME_API long plume_flat_scene_nt(const plume_flat_scene *s);

/** The time of the current state (s; NaN for s NULL). */
PLUME_API double plume_flat_scene_time(const plume_flat_scene *s);

/** Copies the current positions (3 nv, vertex-major, m) into out (caller-allocated); nothing when
 * s or out is NULL. */
PLUME_API void plume_flat_scene_positions(const plume_flat_scene *s, double *out);

/** Copies the current velocities (3 nv, vertex-major, m/s) into out (caller-allocated). */
PLUME_API void plume_flat_scene_velocities(const plume_flat_scene *s, double *out);

/** Copies the reference positions (2 nv: the material coordinates X, m) into out (caller-allocated). */
PLUME_API void plume_flat_scene_reference(const plume_flat_scene *s, double *out);

/** Copies the triangles (3 nt vertex ids, as longs) into out (caller-allocated). */
PLUME_API void plume_flat_scene_triangles(const plume_flat_scene *s, long *out);

/** Writes the current state as the next frame of a ParaView series in directory dir (created if
 * needed): dir/frames.pvd with dir/frame_NNNNN.vtu (and dir/frame_barbs_NNNNN.vtu when the scene
 * has constrained barbs; docs/paraview-output.md); the first call with a dir starts its series (frame 0),
 * later calls with the same dir append. */
PLUME_API plume_status plume_flat_scene_write_vtk(plume_flat_scene *s, const char *dir, char *msg, long nmsg);
/** Appends the current state as a frame of the frames file `path` (HDF5, docs/hdf5-layout.md: time,
 * step, positions, velocities, multipliers), the file apps/feather writes too. The first call for
 * a path creates the file (and its directory, with its parents; a file there is replaced) with the
 * scene's absolute path in it; later calls with the same path append. Errors name the file. */
PLUME_API plume_status plume_flat_scene_write_frames(plume_flat_scene *s, const char *path, char *msg, long nmsg);

/** Writes the frames of the frames file `frames` (apps/feather's frames.h5, or
 * plume_flat_scene_write_frames') as a glTF 2.0 binary file `path` (scene.h, plume_run_write_gltf;
 * docs/graphics.md). `scene` is the scene file they were made from; NULL: the one the frames file
 * names (as recorded, else relative to the frames file's directory). `animation` "morph" (NULL:
 * the default) or "frames"; `field` a render field written per vertex, or NULL. Errors name the
 * file, the scene or the argument. */
PLUME_API plume_status plume_flat_gltf_export(const char *frames, const char *path, const char *scene,
                                              const char *animation, const char *field, char *msg, long nmsg);


#ifdef __cplusplus
}
#endif
#endif
