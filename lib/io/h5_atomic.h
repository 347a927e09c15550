/* plume (private, not installed): the atomic-write protocol for HDF5 files, shared by the curves and
 * moduli files (lib/io/curves.c) and the sweep results (drivers/sweep.c). Includes hdf5.h. */
#ifndef PLUME_INTERNAL_H5_ATOMIC_H
#define PLUME_INTERNAL_H5_ATOMIC_H

#include <hdf5.h>

#include "../core/status.h"

/* Fills an open, writable file; returns a status with `err` set on failure. */
typedef plume_status (*plume_h5_fill_fn)(hid_t fid, const char *path, const void *ctx, plume_err *err);

/* Builds "<path>.tmp.<pid>" (a byte copy of `path` when it exists, so its other content
 * survives), lets `fill` edit it, closes, fsyncs and renames it over `path`. On any failure the
 * temporary file is removed and `path` is untouched; `what` names the file in messages
 * ("curves file"). A path that exists and is not an HDF5 file is refused (PLUME_EFORMAT). */
plume_status plume_h5_atomic_write(const char *path, const char *what, plume_h5_fill_fn fill, const void *ctx,
                                   plume_err *err);

/* As plume_h5_atomic_write, but `fill` starts from an empty file: the old content is replaced
 * whole (a checkpoint rewritten at every step, which would grow as an edited copy). */
plume_status plume_h5_atomic_replace(const char *path, const char *what, plume_h5_fill_fn fill, const void *ctx,
                                     plume_err *err);

#endif
