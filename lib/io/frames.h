/** \file
 * plume: the frames of a dynamic run in HDF5 (docs/design.md "Data and files"), appended frame by frame
 * and readable for a restart:
 *
 *     /frames                 attributes count (frames committed), nv, ncons, dt, scene (string)
 *     /frames/<k>/x, v        [3 nv] positions and velocities (m, m/s), vertex-major
 *     /frames/<k>/lambda      [ncons] constraint multipliers of the step that produced the frame
 *     /frames/<k>/<name>      optional arrays of the state beyond the vertices (plume_frame_array:
 *                             midedge bending's edge unknowns "edge_angles" and frames "edge_frames")
 *     /frames/<k>             attributes t (s) and step, and the run's measures of the steps since
 *                             the previous frame (plume_frame_measures: iterations, halvings,
 *                             seconds, contact pairs, smallest distance, intersecting pairs), each a
 *                             double attribute named after its field
 *     /materials/<k>          attributes: what material k was made of (plume_frames_material_write)
 *
 * k, in the group names, is the frame number zero-padded to seven digits (0000000, 0000001, ...),
 * so that tools listing groups by name (h5py, h5ls) list them in frame order. Files written with
 * plain decimal names (0, 1, ...) are read as well; the first append to one rewrites it with padded
 * names (through a temporary file renamed over it, as for an interrupted append).
 *
 * Why not the temporary-file-and-rename protocol of lib/io/curves.c: it copies the whole file for
 * every frame, O(frames^2) bytes over a run. Instead each append opens the file read-write, adds
 * one group, raises the /frames "count" attribute last (the commit mark) and closes the file (a
 * full flush) and fsyncs it. Readers only trust groups below count, and an append first deletes
 * a stale group k = count left by an interrupted append. A crash therefore loses at most the frame
 * being written; the frames before it stay readable, except in the unlikely case that the crash
 * interrupts HDF5's own metadata write-back during the close (HDF5 has no journal). The file is
 * not kept open between frames, so between appends it is always a closed, consistent file. */
#ifndef PLUME_FRAMES_H
#define PLUME_FRAMES_H

#include "../../include/plume/scene.h"

#include "../core/export.h"
#include "../core/status.h"
#include "curves.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Creates `path` with an empty /frames (count 0); an existing file of that name is replaced, but
 * only once the new one is complete (built under a temporary name and renamed). Errors: nv < 1,
 * ncons < 0, dt not finite and > 0 (PLUME_EINVAL); the file cannot be written (PLUME_EIO). */
plume_status plume_frames_create(const char *path, plume_index nv, plume_index ncons, double dt, const char *scene,
                                           plume_err *err);

/** Appends frame number `count` (the next one) with time t, step, x and v (3 nv) and lambda
 * (ncons; may be NULL when ncons is 0). Errors: the file is missing or not a frames file, its
 * nv/ncons differ from the ones the caller gives (PLUME_EFORMAT), a write failure (PLUME_EIO). */
plume_status plume_frames_append(const char *path, plume_index nv, plume_index ncons, double t, long step,
                                           const double *x, const double *v, const double *lambda, plume_err *err);

/** What the steps since the previous frame did (apps/feather). Contact fields are -1 without
 * contact. */
typedef struct {
    double newton_iterations; /**< solver iterations */
    double steps_halved;      /**< halvings */
    double seconds;           /**< wall time of the steps */
    double contact_pairs;     /**< most contact stencils of an update (pairs within reach) */
    double min_distance;      /**< smallest distance between non-adjacent primitives (m, capped) */
    double intersecting_pairs;/**< most intersecting triangle pairs after a step (exact audit) */
} plume_frame_measures;

/** plume_frames_append, with the measures (may be NULL) as attributes of the frame's group. */
plume_status plume_frames_append_measured(const char *path, plume_index nv, plume_index ncons, double t, long step,
                                                    const double *x, const double *v, const double *lambda,
                                                    const plume_frame_measures *m, plume_err *err);

/** An array of a frame beyond x, v and lambda: more of the state a restart needs. */
typedef struct {
    const char *name;  /**< the dataset's name in the frame's group ("edge_angles", ...) */
    const double *v;   /**< [n] values */
    plume_index n;     /**< their count (0: nothing written) */
    const char *units; /**< its units attribute */
} plume_frame_array;

/** plume_frames_append_measured, with narrays more arrays in the frame's group (written before
 * the frame is committed, like the others). */
plume_status plume_frames_append_arrays(const char *path, plume_index nv, plume_index ncons, double t, long step,
                                        const double *x, const double *v, const double *lambda,
                                        const plume_frame_measures *m, const plume_frame_array *arrays, int narrays,
                                        plume_err *err);

/** Reads the array `name` of frame k (k < 0: the last) into out, which holds n values. PLUME_EFORMAT
 * when the frame has no such array or it holds another count (both named). */
plume_status plume_frames_read_array(const char *path, long k, const char *name, double *out, plume_index n,
                                     plume_err *err);

/** The measures of frame k (k < 0: the last); PLUME_EFORMAT when the frame has none. */
plume_status plume_frames_read_measures(const char *path, long k, plume_frame_measures *m, plume_err *err);

/** Records what material `k` of the run was made of: the group `/materials/<k>` (k in decimal,
 * beside /frames; replaced if it exists) with the numeric attributes `params`, the string
 * attributes `sparams` and a string attribute `units` (the caller's "name: unit; ..." for the
 * numeric ones; docs/hdf5-layout.md). The frames file must exist (plume_frames_create); an append
 * that rebuilds the file keeps /materials. Errors: k < 0, a name that is empty, repeated or
 * "units", a NULL array with a count > 0 (PLUME_EINVAL); not a frames file (PLUME_EFORMAT); a
 * write failure (PLUME_EIO). */
plume_status plume_frames_material_write(const char *path, int k, const plume_param *params, int nparams,
                                     const plume_sparam *sparams, int nsparams, const char *units,
                                     plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
