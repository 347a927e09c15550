/* plume (private, not installed): what the two halves of the flat interface share (drivers/flat.c,
 * drivers/flat_scene.c). */
#ifndef PLUME_DRIVERS_INTERNAL_FLAT_COMMON_H
#define PLUME_DRIVERS_INTERNAL_FLAT_COMMON_H

#include <jansson.h>

#include "../../include/plume/base.h"

/* A flat call's end: its message (err's, else the status' name; "" on success) into msg[nmsg];
 * returns st. */
plume_status plume_flat_finish(plume_status st, const plume_err *err, char *msg, long nmsg);

/* The result object as compact JSON text into *result (the object is released). */
plume_status plume_flat_emit(json_t *obj, char **result, plume_err *err);

#endif
