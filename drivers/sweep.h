/** \file
 * plume: parameter sweeps — a JSON sweep file expands into independent runs of one job (a
 * traction test at either scale, a homogenisation, a fit, e.g., from several starting points:
 * "vary": {"start.E_yy": [...]}, or a dynamic scene), each run a request of the flat interface
 * (drivers/flat.h) or a scene document; their results are gathered into one HDF5 file that a killed
 * sweep resumes from.
 * apps/sweep executes the runs serially or spread over MPI ranks.
 *
 * The sweep file:
 *
 *     {"run": "traction" | "homogenize" | "fit" | "scene",
 *      "base": {...a request of that job, drivers/flat.h...},
 *      "vary": {"key": [v1, v2, ...],                                 a list of values
 *               "key": {"from": a, "to": b, "count": n, "scale": "linear" | "log"},   a range
 *               "sample": "table1" | ["T01", "L03", ...]}}            supplementary Table 1 samples
 *                                                                      (lx, ly, thickness, angle)
 *
 * "key" names a request key; a dotted key sets a nested one ("moduli.E_yy", "layout.phi"). The
 * runs are the Cartesian product of the "vary" entries in the file's order, the last varying
 * fastest; run k's request is "base" with run k's values set. Errors name the file and the key.
 *
 * A scene job ("run": "scene") steps a dynamic scene (macro/scene.h) as apps/feather does:
 *
 *     "base": {"scene": "FILE.json" (relative to the sweep file's directory),
 *              "steps": n (time steps of the scene's dt) | "duration": s (sets the scene's
 *              "duration"; the default is the scene's own)},
 *     "vary": {"contact.dhat": [...], "materials[0].membrane.E": [...], "gravity[2]": [...], ...}
 *
 * Its "vary" keys are key paths into the scene's document: names joined by '.', [i] an entry of a
 * list (the paths the scene loader's messages use). A list entry the scene does not have, or a
 * path through a value that is not an object or a list, is an error of the sweep file naming
 * `vary.<key>`; a missing object member is added, and the scene loader checks it as any key of the
 * file (a misspelt key fails the run with the loader's message naming it). Each run loads the changed document (plume_scene_load_json), its relative
 * file names resolving against the scene file's directory. */
#ifndef PLUME_SWEEP_H
#define PLUME_SWEEP_H

#include "../lib/core/export.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque expanded sweep: the sweep file's base request, its varied axes and run count
 * (plume_sweep_load, freed by plume_sweep_destroy). */
typedef struct plume_sweep plume_sweep;

/** Loads and expands a sweep file; samples come from samples_path (data/samples.json) when the
 * file varies "sample". */
PLUME_API plume_status plume_sweep_load(const char *path, const char *samples_path, plume_sweep **out, plume_err *err);
/** Frees the sweep; sets *s = NULL; NULL-safe. */
PLUME_API void plume_sweep_destroy(plume_sweep **s);

/** The number of runs (the product of the "vary" entries' lengths; 0 for s NULL). */
PLUME_API int plume_sweep_count(const plume_sweep *s);
/** The job: "traction" | "homogenize" | "fit" | "scene" (the sweep's string; NULL for s NULL). */
PLUME_API const char *plume_sweep_job(const plume_sweep *s);

/** Run k's request and its varied values ({"angle": 45, "sample": "T01", ...}) as JSON texts,
 * malloc'ed (free with free()). A scene run's request is {"scene": the file, "steps": n (when
 * given), "document": the scene's document with run k's values set}. */
PLUME_API plume_status plume_sweep_request(const plume_sweep *s, int k, char **request, char **values, plume_err *err);

/** Executes run k and returns its record as a JSON text (malloc'ed): {"run": k, "values": {...},
 * "outcome": "converged" | the solver's stop reason | "error", "message": plume's message (errors),
 * "result": the job's result (drivers/flat.h; a scene's: drivers/internal/sweep_scene.h, and
 * docs/apps/sweep.md)}. A run that fails is a record, not an error: NULL only when memory runs out. A
 * scene run whose step does not converge at the smallest step has that solver's reason as its
 * outcome and keeps the steps done. */
PLUME_API char *plume_sweep_execute(const plume_sweep *s, int k);

/** The results file: /sweep with attributes "job", "runs" and "file" (the sweep file's text); one
 * group `/sweep/runs/<k>` per recorded run with datasets strain, stress, wbar (when the job gives a
 * curve; units 1, Pa, 1) and string attributes "values", "outcome", "record" (the JSON record
 * without the curve arrays and without timings, so that the file's content does not depend on
 * how the runs were spread) and "seconds". A scene run has instead `per_step/<measure>` datasets
 * (time s, newton_iterations, halvings, and for contact scenes contact_pairs, min_distance m,
 * intersecting_pairs), positions (3 nv, m; scenes of at most 20000 vertices) and its numbers as
 * attributes with a "units" string (docs/hdf5-layout.md); /sweep then keeps the scene file's text
 * in "scene". Creates the file when it does not exist (refusing one of another sweep, or, for a
 * scene sweep, one whose scene file has changed since: PLUME_EINVAL). */
PLUME_API plume_status plume_sweep_results_open(const char *h5path, const plume_sweep *s, plume_err *err);

/** Which runs the file holds (done[k] = 1), e.g., after a sweep was killed: those are not redone. */
PLUME_API plume_status plume_sweep_results_done(const char *h5path, const plume_sweep *s, unsigned char *done, plume_err *err);

/** Adds run k's record (from plume_sweep_execute) to the file; a run is written whole or not at
 * all (its group is created last, from a complete temporary name). */
PLUME_API plume_status plume_sweep_results_add(const char *h5path, const plume_sweep *s, int k, const char *record, plume_err *err);

/** A markdown table of every recorded run (run, values, outcome, last strain and stress, seconds;
 * for a scene: steps, final time, max displacement and min contact distance) into md_path, and
 * the same as a JSON array into *json (malloc'ed; may be NULL). */
PLUME_API plume_status plume_sweep_summary(const char *h5path, const plume_sweep *s, const char *md_path, char **json,
                                           plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
