/** \file
 * plume: the outline of a feather drawn as a triangle mesh in OBJ (the feather mesher's input). */
#ifndef PLUME_OBJ_OUTLINE_H
#define PLUME_OBJ_OUTLINE_H

#include "../lib/core/export.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Reads the boundary of a triangle mesh in OBJ (v x y [z] / f i j k; only x and y are used) as a
 * closed outline (the single boundary loop, counter-clockwise); *points malloc'ed [2 n].
 * Errors name the file and line. */
plume_status plume_obj_outline(const char *path, double **points, plume_index *n, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
