/** \file
 * plume: parameter sweeps — a JSON sweep file expands into independent runs of one job (a
 * traction test at either scale, a homogenisation, a fit, e.g., from several starting points:
 * "vary": {"start.E_yy": [...]}, or a dynamic scene), each run a request of the flat interface
 * (include/plume/flat.h) or a scene document; their results are gathered into one HDF5 file that a killed
 * sweep resumes from.
 * apps/sweep executes the runs serially or spread over MPI ranks.
 *
 * The sweep file:
 *
 *     {"run": "traction" | "homogenize" | "fit" | "scene",
 *      "base": {...a request of that job, include/plume/flat.h...},
 *      "vary": {"key": [v1, v2, ...],                                 a list of values
 *               "key": {"from": a, "to": b, "count": n, "scale": "linear" | "log"},   a range
 *               "sample": "table1" | ["T01", "L03", ...]}}            supplementary Table 1 samples
 *                                                                      (lx, ly, thickness, angle)
 *
 * "key" names a request key; a dotted key sets a nested one ("moduli.E_yy", "layout.phi"). The
 * runs are the Cartesian product of the "vary" entries in the file's order, the last varying
 * fastest; run k's request is "base" with run k's values set. Errors name the file and the key.
 *
 * A scene job ("run": "scene") steps a dynamic scene (macro/scene/scene.h) as apps/feather does:
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

#include "../include/plume/experiments.h"

#include "../lib/core/export.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
