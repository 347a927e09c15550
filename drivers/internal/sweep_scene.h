/* plume (private, not installed): the scene job of a parameter sweep (drivers/sweep_scene.c), for
 * drivers/sweep.c. A scene sweep's base names a scene file and how long to run it; its "vary" keys
 * are key paths into the scene's document ("contact.dhat", "materials[0].membrane.E",
 * "gravity[2]"); each run loads the changed document (plume_scene_load_json) and steps it. */
#ifndef PLUME_INTERNAL_SWEEP_SCENE_H
#define PLUME_INTERNAL_SWEEP_SCENE_H

#include <hdf5.h>
#include <jansson.h>

#include "../../lib/core/status.h"

/* A run records its final positions when the scene has at most this many vertices. */
enum { PLUME_SWEEP_SCENE_MAX_POSITIONS = 20000 };

/* What a scene sweep keeps of its base. Owned; freed by plume_sweep_scene_free. */
typedef struct {
    char *path;  /* the scene file, relative to the sweep file's directory when the base's was */
    char *text;  /* its text as read: the results file keeps it, and a resume checks it */
    json_t *doc; /* its document, with base.duration set */
    long steps;  /* base.steps; 0: the document's duration / dt */
} plume_sweep_scene;

/* Reads base {"scene": file, "steps": n | "duration": s} of the sweep file sweep_path and the
 * scene file it names; errors name the sweep file and the key, or the scene file. */
plume_status plume_sweep_scene_setup(const char *sweep_path, json_t *base, plume_sweep_scene *sc, plume_err *err);
void plume_sweep_scene_free(plume_sweep_scene *sc);

/* A run's request {"scene": path, "steps": n (when given), "document": a copy of the document}
 * (new reference), or NULL when memory runs out. */
json_t *plume_sweep_scene_request(const plume_sweep_scene *sc);

/* Sets doc[key path] = value (a reference taken in every case). A missing object member is
 * added (the scene loader then checks it like any key of a file); a list index must exist.
 * Errors name the sweep file, vary.<key> and the scene file. */
plume_status plume_sweep_scene_set(json_t *doc, const char *key, json_t *value, const char *sweep_path,
                                   const char *scene_path, plume_err *err);

/* Runs a request: loads the document, steps it, and gives the result as a JSON text (malloc'ed)
 * as the flat interface's jobs do (include/plume/flat.h): {"scene", "vertices", "elements", "dt",
 * "steps" (done), "steps_planned", "time", "converged", "stop_reason", "newton_iterations",
 * "halvings", "max_violation", "max_displacement", "max_displacement_vertex", "contact": {...}
 * (contact scenes), "per_step": {"time", "newton_iterations", "halvings", and "contact_pairs",
 * "min_distance", "intersecting_pairs" for contact scenes}, "positions": [3 nv] (small scenes)}.
 * No timings: the result is the same wherever it runs. */
plume_status plume_sweep_scene_run(const char *request, char **result, char *msg, long nmsg);

/* Writes a scene result's arrays into run group g: g/steps/<measure> and g/positions with their
 * units, and its scalars as attributes with a "units" string; 0, or -1 on failure. */
int plume_sweep_scene_write(hid_t g, json_t *result);

/* The keys of a scene result that plume_sweep_scene_write stores as datasets (NULL-terminated):
 * the record attribute leaves them out. */
extern const char *const plume_sweep_scene_arrays[];

/* A summary row of a scene run: the markdown cells after "outcome" (steps, time, max |x - x0|,
 * min distance) into cells, and the same values set in the JSON row. */
void plume_sweep_scene_summary_row(json_t *result, char *cells, size_t n, json_t *row);

/* The summary table's header after "outcome" (markdown). */
extern const char plume_sweep_scene_summary_header[];

#endif
