/** \file
 * plume: load a scene (a feather, a wing, a bird: docs/scene-format.md), solve or step it, and read
 * its frames back. */
#ifndef PLUME_PUBLIC_SCENE_H
#define PLUME_PUBLIC_SCENE_H

#include "problem.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A loaded, validated scene (opaque): its mesh, materials, handles, loads and run settings. */
typedef struct plume_scene plume_scene;

/* ---- from macro/scene.h ---- */
/** Reads, validates and meshes the scene in `path`. Errors (PLUME_EIO unreadable file,
 * PLUME_EFORMAT malformed JSON or a wrong type, PLUME_EINVAL a bad value) name the file, the line
 * and the key ("scene.json:12: materials[0].density must be finite and > 0 (got -1)"). */
PLUME_API plume_status plume_scene_load(const char *path, plume_scene **out, plume_err *err);

/** What a caller may change in a scene before it is meshed (convergence studies). */
typedef struct {
    double edge;          /**< > 0: replaces mesh.edge (feather and rectangle meshes) */
    const char *pattern;  /**< non-NULL: replaces a rectangle's "pattern" */
} plume_scene_load_opts;

/** plume_scene_load with overrides (o may be NULL); an override that does not apply to the
 * scene's mesh (an edge for an OBJ) is an error naming the key. */
PLUME_API plume_status plume_scene_load_with(const char *path, const plume_scene_load_opts *o, plume_scene **out,
                                             plume_err *err);

/** plume_scene_load_with on a scene document held in memory (JSON text, e.g., a file's document
 * with some keys changed: apps/sweep) instead of the file: `path` is the file it stands for, whose
 * directory relative file names (OBJ meshes, feather shapes) resolve against; errors name `path`
 * and the key, without a line (the text is not the file). The caller keeps json. */
PLUME_API plume_status plume_scene_load_json(const char *json, const char *path, const plume_scene_load_opts *o,
                                             plume_scene **out, plume_err *err);

/** Frees the scene and everything it owns (mesh, materials, handles, probes, ...); sets *s = NULL;
 * NULL-safe. */
PLUME_API void plume_scene_destroy(plume_scene **s);

/** Builds the problem of a static scene (membrane, bending, constraints, the nominal loads and
 * moments; clamps and handles fixed) and its load-stepping driver (lib/sim/statics.h) with the
 * scene's steps, solver and max_iter. *p and *st belong to the caller (destroy st first); the
 * scene must outlive them. Errors: the scene is not static (PLUME_EINVAL). */
PLUME_API plume_status plume_scene_statics(const plume_scene *s, plume_problem **p, plume_statics **st, plume_err *err);


/* ---- from lib/io/frames.h ---- */
/** What /frames holds. scene is a NUL-terminated copy (truncated to fit). */
typedef struct {
    long count;       /**< committed frames */
    plume_index nv;   /**< vertices (x and v have 3 nv values) */
    plume_index ncons;/**< multipliers per frame */
    double dt;        /**< the run's time step (s) */
    char scene[1024]; /**< the scene file the run was made from */
} plume_frames_info;

/** One frame. Read by plume_frames_read, which allocates x, v (3 nv) and lambda (ncons, or NULL
 * when ncons = 0); free with plume_frame_free. */
typedef struct {
    long index;       /**< k */
    long step;        /**< time steps taken since t = 0 */
    double t;         /**< time (s) */
    plume_index nv;   /**< vertices */
    plume_index ncons;/**< constraint multipliers */
    double *x;        /**< [3 nv] positions (m), vertex-major */
    double *v;        /**< [3 nv] velocities (m/s) */
    double *lambda;   /**< [ncons] multipliers, NULL when ncons = 0 */
} plume_frame;

/** Reads the /frames attributes. */
PLUME_API plume_status plume_frames_info_read(const char *path, plume_frames_info *info, plume_err *err);

/** Reads frame k (k < 0: the last committed frame). PLUME_EINVAL when k >= count or the file has
 * no frame; PLUME_EFORMAT when a dataset has the wrong size. */
PLUME_API plume_status plume_frames_read(const char *path, long k, plume_frame *frame, plume_err *err);

/** Frees x, v and lambda of a frame read by plume_frames_read and sets them to NULL; NULL-safe. */
PLUME_API void plume_frame_free(plume_frame *frame);

#ifdef __cplusplus
}
#endif
#endif
