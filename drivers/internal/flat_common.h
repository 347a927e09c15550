/* plume (private, not installed): what the flat interface's files share (drivers/flat.c, its jobs
 * drivers/flat_homogenize.c, flat_traction.c, flat_fit.c, and drivers/flat_scene.c). */
#ifndef PLUME_DRIVERS_INTERNAL_FLAT_COMMON_H
#define PLUME_DRIVERS_INTERNAL_FLAT_COMMON_H

#include <jansson.h>

#include "../../include/plume/base.h"
#include "../../include/plume/plume.h"

/* A flat call's end: its message (err's, else the status' name; "" on success) into msg[nmsg];
 * returns st. */
plume_status plume_flat_finish(plume_status st, const plume_err *err, char *msg, long nmsg);

/* The result object as compact JSON text into *result (the object is released). */
plume_status plume_flat_emit(json_t *obj, char **result, plume_err *err);

/* The request text as an object; every key of it must be in `allowed` (NULL-terminated). */
plume_status plume_flat_parse_request(const char *text, const char *what, const char *const *allowed, json_t **out,
                                      plume_err *err);
/* obj[key] into *out when present (kept otherwise), checked for its type; `what` names the request. */
plume_status plume_flat_get_number(json_t *obj, const char *what, const char *key, double *out, plume_err *err);
plume_status plume_flat_get_int(json_t *obj, const char *what, const char *key, int *out, plume_err *err);
plume_status plume_flat_get_bool(json_t *obj, const char *what, const char *key, int *out, plume_err *err);
plume_status plume_flat_get_string(json_t *obj, const char *what, const char *key, const char **out, plume_err *err);
/* request.layout (an object of layout-file keys) applied to l. */
plume_status plume_flat_get_layout(json_t *obj, const char *what, plume_layout *l, plume_err *err);
/* {"E_xx", "E_yy", "nu_xy", "G_xy"} at obj[key] into m: all four, or obj[key] absent (m kept). */
plume_status plume_flat_get_moduli(json_t *obj, const char *what, const char *key, plume_ortho *m, plume_err *err);
/* A JSON array of v[0 .. n-1]; a curve's arrays as an object. */
json_t *plume_flat_array_of(const double *v, plume_index n);
json_t *plume_flat_curve_json(const plume_curve *c);

/* the macro traction keys shared by traction and fit */
typedef struct {
    double lx, ly, h, kappa, edge, strain_max;
    int constraint, steps;
    plume_patch_kind mesh;
    plume_solver_kind solver;
} plume_flat_traction_setup;

/* The macro traction keys of a request into t (drivers/flat_traction.c). */
plume_status plume_flat_get_traction_setup(json_t *req, const char *what, plume_flat_traction_setup *t, plume_err *err);

#endif
