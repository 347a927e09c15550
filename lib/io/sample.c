/* plume: traction-sample geometries from JSON (jansson). The whole file is validated on every
 * load, not just the requested entry, so a bad row is reported whichever sample is asked for. */
#include "sample.h"
#include "input_file.h"

#include <jansson.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* Parses `path` and checks its "samples" array; on success *root owns the document. */
static plume_status load_doc(const char *path, json_t **root, json_t **samples, plume_err *err)
{
    *root = NULL;
    *samples = NULL;
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "sample file: empty path");
    FILE *f = plume_input_fopen(path, "rb", NULL, err);
    if (!f)
        return PLUME_EIO;
    json_error_t je;
    json_t *doc = json_loadf(f, JSON_REJECT_DUPLICATES, &je);
    int read_error = ferror(f);
    fclose(f);
    if (!doc) {
        if (read_error)
            return plume_err_set(err, PLUME_EIO, "%s: read error", path);
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", path, je.line, je.column, je.text);
    }
    json_t *arr = json_is_object(doc) ? json_object_get(doc, "samples") : NULL;
    if (!json_is_array(arr)) {
        json_decref(doc);
        return plume_err_set(err, PLUME_EFORMAT,
                             "%s: expected an object with a \"samples\" array at the top level", path);
    }
    *root = doc;
    *samples = arr;
    return PLUME_OK;
}

/* Reads and validates entry `i` of the samples array into *out. */
static plume_status parse_entry(const char *path, size_t i, json_t *e, plume_sample *out,
                                plume_err *err)
{
    static const char *const dims[3] = {"lx_mm", "ly_mm", "h_um"};
    static const double to_m[3] = {1e-3, 1e-3, 1e-6};
    if (!json_is_object(e))
        return plume_err_set(err, PLUME_EFORMAT, "%s: sample %zu: not an object", path, i);
    json_t *id = json_object_get(e, "id");
    if (!json_is_string(id))
        return plume_err_set(err, PLUME_EFORMAT, "%s: sample %zu: missing string key \"id\"", path, i);
    const char *ids = json_string_value(id);
    if (!*ids || strlen(ids) >= sizeof out->id)
        return plume_err_set(err, PLUME_EFORMAT, "%s: sample %zu: id must have 1 to %zu characters",
                             path, i, sizeof out->id - 1);
    json_t *sc = json_object_get(e, "scenario");
    if (!json_is_string(sc))
        return plume_err_set(err, PLUME_EFORMAT, "%s: sample %s: missing string key \"scenario\"",
                             path, ids);
    const char *scs = json_string_value(sc);
    if (strcmp(scs, "longitudinal") != 0 && strcmp(scs, "transverse") != 0 &&
        strcmp(scs, "tilted") != 0)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s: sample %s: scenario must be longitudinal, transverse or tilted (got \"%s\")",
                             path, ids, scs);
    double v[3];
    for (int k = 0; k < 3; k++) {
        json_t *x = json_object_get(e, dims[k]);
        if (!json_is_number(x))
            return plume_err_set(err, PLUME_EFORMAT, "%s: sample %s: %s \"%s\"", path, ids,
                                 x ? "non-numeric key" : "missing key", dims[k]);
        v[k] = json_number_value(x);
        if (!isfinite(v[k]) || !(v[k] > 0))
            return plume_err_set(err, PLUME_EINVAL, "%s: sample %s: %s must be > 0 (got %g)", path,
                                 ids, dims[k], v[k]);
    }
    memset(out, 0, sizeof *out);
    snprintf(out->id, sizeof out->id, "%s", ids);
    snprintf(out->scenario, sizeof out->scenario, "%s", scs);
    out->lx = v[0] * to_m[0];
    out->ly = v[1] * to_m[1];
    out->h = v[2] * to_m[2];
    return PLUME_OK;
}

/* Validates every entry (and that ids are unique); returns the index of `id` in *found, or
 * (size_t)-1 if absent; `hit` receives that entry. */
static plume_status scan(const char *path, json_t *arr, const char *id, size_t *found,
                         plume_sample *hit, plume_err *err)
{
    *found = (size_t)-1;
    size_t n = json_array_size(arr);
    for (size_t i = 0; i < n; i++) {
        plume_sample s;
        plume_status st = parse_entry(path, i, json_array_get(arr, i), &s, err);
        if (st != PLUME_OK)
            return st;
        for (size_t j = 0; j < i; j++) {
            const char *other = json_string_value(json_object_get(json_array_get(arr, j), "id"));
            if (strcmp(other, s.id) == 0)
                return plume_err_set(err, PLUME_EFORMAT, "%s: sample id %s appears twice", path, s.id);
        }
        if (id && strcmp(s.id, id) == 0) {
            *found = i;
            if (hit)
                *hit = s;
        }
    }
    return PLUME_OK;
}

plume_status plume_sample_load(const char *path, const char *id, plume_sample *out, plume_err *err)
{
    if (!id || !*id || !out)
        return plume_err_set(err, PLUME_EINVAL, "%s: no sample id or output given",
                             path ? path : "(null)");
    json_t *root = NULL, *arr = NULL;
    plume_status s = load_doc(path, &root, &arr, err);
    if (s != PLUME_OK)
        return s;
    size_t found;
    plume_sample hit;
    s = scan(path, arr, id, &found, &hit, err);
    if (s == PLUME_OK && found == (size_t)-1)
        s = plume_err_set(err, PLUME_EINVAL, "%s: sample id \"%s\" not found (%zu samples in file)",
                          path, id, json_array_size(arr));
    if (s == PLUME_OK)
        *out = hit;
    json_decref(root);
    return s;
}

plume_status plume_sample_count(const char *path, int *count, plume_err *err)
{
    if (!count)
        return plume_err_set(err, PLUME_EINVAL, "%s: no output given", path ? path : "(null)");
    json_t *root = NULL, *arr = NULL;
    plume_status s = load_doc(path, &root, &arr, err);
    if (s != PLUME_OK)
        return s;
    size_t found;
    s = scan(path, arr, NULL, &found, NULL, err);
    if (s == PLUME_OK)
        *count = (int)json_array_size(arr);
    json_decref(root);
    return s;
}

plume_status plume_sample_at(const char *path, int index, plume_sample *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "%s: no output given", path ? path : "(null)");
    json_t *root = NULL, *arr = NULL;
    plume_status s = load_doc(path, &root, &arr, err);
    if (s != PLUME_OK)
        return s;
    size_t found;
    s = scan(path, arr, NULL, &found, NULL, err);
    if (s == PLUME_OK && (index < 0 || (size_t)index >= json_array_size(arr)))
        s = plume_err_set(err, PLUME_EINVAL, "%s: sample index %d out of range (%zu samples)", path,
                          index, json_array_size(arr));
    if (s == PLUME_OK)
        s = parse_entry(path, (size_t)index, json_array_get(arr, (size_t)index), out, err);
    json_decref(root);
    return s;
}
