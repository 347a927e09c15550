/* plume: the flat interface for bindings (flat.h): what its requests share, reading a request's
 * keys and writing a result's JSON. The jobs are in flat_homogenize.c, flat_traction.c and
 * flat_fit.c; the scene handle and the glTF export in flat_scene.c. */
#include "flat.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "internal/flat_common.h"

plume_status plume_flat_finish(plume_status st, const plume_err *err, char *msg, long nmsg)
{
    if (msg && nmsg > 0) {
        if (st == PLUME_OK)
            msg[0] = '\0';
        else
            snprintf(msg, (size_t)nmsg, "%s", err->msg[0] ? err->msg : plume_strerror(st));
    }
    return st;
}

/* the request text as an object; every key of it must be in `allowed` (NULL-terminated) */
plume_status plume_flat_parse_request(const char *text, const char *what, const char *const *allowed, json_t **out,
                                      plume_err *err)
{
    *out = NULL;
    json_error_t je;
    json_t *doc = json_loads(text && *text ? text : "{}", JSON_REJECT_DUPLICATES, &je);
    if (!doc)
        return plume_err_set(err, PLUME_EFORMAT, "%s request:%d:%d: %s", what, je.line, je.column, je.text);
    if (!json_is_object(doc)) {
        json_decref(doc);
        return plume_err_set(err, PLUME_EFORMAT, "%s request: expected a JSON object", what);
    }
    const char *key;
    json_t *v;
    json_object_foreach(doc, key, v) {
        int known = 0;
        for (int k = 0; allowed[k] && !known; k++)
            known = strcmp(key, allowed[k]) == 0;
        if (!known) {
            plume_err_set(err, PLUME_EINVAL, "%s request: unknown key \"%s\"", what, key);
            json_decref(doc);
            return PLUME_EINVAL;
        }
    }
    *out = doc;
    return PLUME_OK;
}

/* obj[key] as a number into *out when present (kept otherwise) */
plume_status plume_flat_get_number(json_t *obj, const char *what, const char *key, double *out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_number(v))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be a number", what, key);
    *out = json_number_value(v);
    if (!isfinite(*out))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be finite", what, key);
    return PLUME_OK;
}

plume_status plume_flat_get_int(json_t *obj, const char *what, const char *key, int *out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_integer(v) || json_integer_value(v) < -1000000000 || json_integer_value(v) > 1000000000)
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be an integer", what, key);
    *out = (int)json_integer_value(v);
    return PLUME_OK;
}

plume_status plume_flat_get_bool(json_t *obj, const char *what, const char *key, int *out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_boolean(v))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be true or false", what, key);
    *out = json_is_true(v);
    return PLUME_OK;
}

plume_status plume_flat_get_string(json_t *obj, const char *what, const char *key, const char **out, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    if (!json_is_string(v))
        return plume_err_set(err, PLUME_EINVAL, "%s request: \"%s\" must be a string", what, key);
    *out = json_string_value(v);
    return PLUME_OK;
}

/* request.layout (an object of layout-file keys) applied to l */
plume_status plume_flat_get_layout(json_t *obj, const char *what, plume_layout *l, plume_err *err)
{
    json_t *v = json_object_get(obj, "layout");
    if (!v)
        return PLUME_OK;
    char where[64];
    snprintf(where, sizeof where, "%s request.layout", what);
    char *text = json_dumps(v, JSON_REAL_PRECISION(17));
    if (!text)
        return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", where);
    plume_status st = plume_layout_apply_json(text, where, l, err);
    free(text);
    return st == PLUME_EFORMAT ? PLUME_EINVAL : st; /* a bad key of a request, not a malformed file */
}

/* {"E_xx", "E_yy", "nu_xy", "G_xy"} at obj[key] into m: all four, or obj[key] absent (m kept). A
 * partial object is refused, naming the missing keys: filling them with defaults would run a
 * material nobody asked for. */
plume_status plume_flat_get_moduli(json_t *obj, const char *what, const char *key, plume_ortho *m, plume_err *err)
{
    json_t *v = json_object_get(obj, key);
    if (!v)
        return PLUME_OK;
    char where[64];
    snprintf(where, sizeof where, "%s request.%s", what, key);
    if (!json_is_object(v))
        return plume_err_set(err, PLUME_EINVAL, "%s: expected an object of E_xx, E_yy, nu_xy, G_xy", where);
    const char *k;
    json_t *x;
    json_object_foreach(v, k, x) {
        double *dst = strcmp(k, "E_xx") == 0 ? &m->E_xx : strcmp(k, "E_yy") == 0 ? &m->E_yy
                    : strcmp(k, "nu_xy") == 0 ? &m->nu_xy : strcmp(k, "G_xy") == 0 ? &m->G_xy : NULL;
        if (!dst)
            return plume_err_set(err, PLUME_EINVAL, "%s: unknown key \"%s\"", where, k);
        if (!json_is_number(x) || !isfinite(json_number_value(x)))
            return plume_err_set(err, PLUME_EINVAL, "%s: \"%s\" must be a finite number", where, k);
        *dst = json_number_value(x);
    }
    static const char *const names[] = {"E_xx", "E_yy", "nu_xy", "G_xy"};
    char missing[64] = "";
    for (int i = 0; i < 4; i++)
        if (!json_object_get(v, names[i]))
            snprintf(missing + strlen(missing), sizeof missing - strlen(missing), "%s%s", missing[0] ? ", " : "",
                     names[i]);
    if (missing[0])
        return plume_err_set(err, PLUME_EINVAL, "%s: missing %s (give all of E_xx, E_yy, nu_xy, G_xy)", where, missing);
    return PLUME_OK;
}

json_t *plume_flat_array_of(const double *v, plume_index n)
{
    json_t *a = json_array();
    for (plume_index i = 0; a && i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

json_t *plume_flat_curve_json(const plume_curve *c)
{
    return json_pack("{s:o, s:o, s:o, s:o}", "strain", plume_flat_array_of(c->strain, c->n), "stress", plume_flat_array_of(c->stress, c->n),
                     "wbar", plume_flat_array_of(c->wbar, c->n), "iterations", plume_flat_array_of(c->iterations, c->n));
}

/* the result object as text into *result (the object is released) */
plume_status plume_flat_emit(json_t *obj, char **result, plume_err *err)
{
    *result = obj ? json_dumps(obj, JSON_REAL_PRECISION(17) | JSON_COMPACT) : NULL;
    json_decref(obj);
    return *result ? PLUME_OK : plume_err_set(err, PLUME_ENOMEM, "out of memory");
}

void plume_flat_free(char *text)
{
    free(text);
}
