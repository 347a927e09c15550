#include "layout_json.h"
#include "../lib/io/input_file.h"

#include <jansson.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct {
    const char *key;
    size_t offset;
} number_key;

static const number_key number_keys[] = {
    {"phi", offsetof(plume_layout, phi)},
    {"d_B", offsetof(plume_layout, d_B)},
    {"E_b", offsetof(plume_layout, E_b)},
    {"nu_b", offsetof(plume_layout, nu_b)},
    {"ratio", offsetof(plume_layout, ratio)},
    {"nu_B", offsetof(plume_layout, nu_B)},
    {"thickness", offsetof(plume_layout, h)},
    {"thickness_barb", offsetof(plume_layout, h_barb)},
    {"thickness_barbule", offsetof(plume_layout, h_barbule)},
    {"kappa", offsetof(plume_layout, kappa)},
    {"e_rel", offsetof(plume_layout, e_rel)},
    {"barbule_width", offsetof(plume_layout, barbule_width)},
    {"barbule_spacing", offsetof(plume_layout, barbule_spacing)},
    {"barbule_angle", offsetof(plume_layout, barbule_angle)},
};

/* applies the keys of the JSON object doc to l; where names the source in messages */
static plume_status apply_object(json_t *doc, const char *where, plume_layout *l, plume_err *err)
{
    double w_B = -1.0;
    if (!json_is_object(doc))
        return plume_err_set(err, PLUME_EFORMAT, "%s: expected a JSON object of layout keys", where);
    const char *key;
    json_t *v;
    json_object_foreach(doc, key, v) {
        if (strcmp(key, "layout") == 0) {
            const char *s = json_is_string(v) ? json_string_value(v) : "";
            if (strcmp(s, "strips") == 0)
                l->kind = PLUME_LAYOUT_STRIPS;
            else if (strcmp(s, "barbules") == 0)
                l->kind = PLUME_LAYOUT_BARBULES;
            else
                return plume_err_set(err, PLUME_EFORMAT, "%s: key \"layout\" must be \"strips\" or \"barbules\"", where);
            continue;
        }
        if (!json_is_number(v))
            return plume_err_set(err, PLUME_EFORMAT, "%s: key \"%s\" must be a number", where, key);
        if (strcmp(key, "w_B") == 0) {
            w_B = json_number_value(v);
            continue;
        }
        if (strcmp(key, "order") == 0) {
            double o = json_number_value(v);
            if (o != 1.0 && o != 2.0)
                return plume_err_set(err, PLUME_EFORMAT, "%s: key \"order\" must be 1 or 2 (got %g)", where, o);
            l->order = (int)o;
            continue;
        }
        size_t k = 0, n = sizeof number_keys / sizeof number_keys[0];
        while (k < n && strcmp(key, number_keys[k].key) != 0)
            k++;
        if (k == n)
            return plume_err_set(err, PLUME_EFORMAT, "%s: unknown key \"%s\"", where, key);
        double x = json_number_value(v);
        /* 0 means "the thickness h" inside the layout struct only: given here it is a mistake */
        if (strncmp(key, "thickness_", 10) == 0 && !(x > 0.0 && isfinite(x)))
            return plume_err_set(err, PLUME_EFORMAT, "%s: key \"%s\" must be a finite thickness > 0 (got %g m)", where,
                                 key, x);
        *(double *)((char *)l + number_keys[k].offset) = x;
    }
    if (w_B >= 0.0)
        l->d_B = l->phi > 0.0 ? w_B / l->phi : -1.0;
    return PLUME_OK;
}

plume_status plume_layout_load_json(const char *path, plume_layout *l, plume_err *err)
{
    if (!path || !l)
        return plume_err_set(err, PLUME_EINVAL, "layout file: invalid arguments");
    FILE *f = plume_input_fopen(path, "rb", NULL, err);
    if (!f)
        return PLUME_EIO;
    json_error_t je;
    json_t *doc = json_loadf(f, JSON_REJECT_DUPLICATES, &je);
    fclose(f);
    if (!doc)
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", path, je.line, je.column, je.text);
    plume_status st = apply_object(doc, path, l, err);
    json_decref(doc);
    return st;
}

plume_status plume_layout_apply_json(const char *text, const char *where, plume_layout *l, plume_err *err)
{
    if (!text || !l)
        return plume_err_set(err, PLUME_EINVAL, "layout: invalid arguments");
    if (!where)
        where = "layout";
    json_error_t je;
    json_t *doc = json_loads(text, JSON_REJECT_DUPLICATES, &je);
    if (!doc)
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", where, je.line, je.column, je.text);
    plume_status st = apply_object(doc, where, l, err);
    json_decref(doc);
    return st;
}
