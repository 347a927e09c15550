/** \file
 * plume: a flat interface for bindings (python/plume uses it through ctypes): the jobs take and give JSON texts, scenes are stepped through an opaque handle with plain arrays. */
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

/** A dynamic scene (macro/scene/scene.h) being stepped, with its contact and friction if it has them. */
typedef struct plume_flat_scene plume_flat_scene;

/** Loads and sets up the scene at `path` (errors name the file, line and key). */
PLUME_API plume_status plume_flat_scene_open(const char *path, plume_flat_scene **out, char *msg, long nmsg);

/** The same from a scene document in memory (JSON text) standing for the file `path`: relative file
 * names in it resolve against path's directory, errors name path and the key (macro/scene/scene.h,
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
 * has constrained barbs; macro/shell/fields.h); the first call with a dir starts its series (frame 0),
 * later calls with the same dir append. */
PLUME_API plume_status plume_flat_scene_write_vtk(plume_flat_scene *s, const char *dir, char *msg, long nmsg);
/** Appends the current state as a frame of the frames file `path` (HDF5, docs/hdf5-layout.md: time,
 * step, positions, velocities, multipliers), the file apps/feather writes too. The first call for
 * a path creates the file (and its directory, with its parents; a file there is replaced) with the
 * scene's absolute path in it; later calls with the same path append. Errors name the file. */
PLUME_API plume_status plume_flat_scene_write_frames(plume_flat_scene *s, const char *path, char *msg, long nmsg);


#ifdef __cplusplus
}
#endif
#endif
