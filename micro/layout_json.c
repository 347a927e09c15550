#include "layout_json.h"
#include "../lib/io/input_file.h"

#include <jansson.h>

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* Every key a layout file may hold, in the order docs/layout-format.md's table lists them (a test
 * checks the table against this list, through the unknown-key message). */
typedef enum { KEY_LAYOUT, KEY_NUMBER, KEY_W_B, KEY_ORDER } key_kind;

typedef struct {
    const char *key;
    key_kind kind;
    size_t offset; /* KEY_NUMBER: the double it sets */
} layout_key;

static const layout_key layout_keys[] = {
    {"layout", KEY_LAYOUT, 0},
    {"phi", KEY_NUMBER, offsetof(plume_layout, phi)},
    {"d_B", KEY_NUMBER, offsetof(plume_layout, d_B)},
    {"w_B", KEY_W_B, 0},
    {"E_b", KEY_NUMBER, offsetof(plume_layout, E_b)},
    {"nu_b", KEY_NUMBER, offsetof(plume_layout, nu_b)},
    {"ratio", KEY_NUMBER, offsetof(plume_layout, ratio)},
    {"nu_B", KEY_NUMBER, offsetof(plume_layout, nu_B)},
    {"thickness", KEY_NUMBER, offsetof(plume_layout, h)},
    {"thickness_barb", KEY_NUMBER, offsetof(plume_layout, h_barb)},
    {"thickness_barbule", KEY_NUMBER, offsetof(plume_layout, h_barbule)},
    {"kappa", KEY_NUMBER, offsetof(plume_layout, kappa)},
    {"order", KEY_ORDER, 0},
    {"e_rel", KEY_NUMBER, offsetof(plume_layout, e_rel)},
    {"barbule_width", KEY_NUMBER, offsetof(plume_layout, barbule_width)},
    {"barbule_spacing", KEY_NUMBER, offsetof(plume_layout, barbule_spacing)},
    {"barbule_angle", KEY_NUMBER, offsetof(plume_layout, barbule_angle)},
    {"hook_strength", KEY_NUMBER, offsetof(plume_layout, hooks.strength)},
    {"hook_opening", KEY_NUMBER, offsetof(plume_layout, hooks.opening)},
    {"hook_slide", KEY_NUMBER, offsetof(plume_layout, hooks.slide)},
    {"hook_capture", KEY_NUMBER, offsetof(plume_layout, hooks.capture)},
};
#define NKEYS (sizeof layout_keys / sizeof layout_keys[0])

/* "unknown key" naming every key: the list a user (and the docs' test) can check against */
static plume_status unknown_key(const char *where, const char *key, plume_err *err)
{
    char list[640] = "";
    size_t n = 0;
    for (size_t k = 0; k < NKEYS && n < sizeof list; k++)
        n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", k ? ", " : "", layout_keys[k].key);
    return plume_err_set(err, PLUME_EFORMAT, "%s: unknown key \"%s\" (expected %s, or note)", where, key, list);
}

/* applies the keys of the JSON object doc to l; where names the source in messages. "note" (any
 * value) is a comment, as in scene files. */
static plume_status apply_object(json_t *doc, const char *where, plume_layout *l, plume_err *err)
{
    double w_B = -1.0;
    if (!json_is_object(doc))
        return plume_err_set(err, PLUME_EFORMAT, "%s: expected a JSON object of layout keys", where);
    const char *key;
    json_t *v;
    json_object_foreach(doc, key, v) {
        if (strcmp(key, "note") == 0)
            continue;
        size_t k = 0;
        while (k < NKEYS && strcmp(key, layout_keys[k].key) != 0)
            k++;
        if (k == NKEYS)
            return unknown_key(where, key, err);
        if (layout_keys[k].kind == KEY_LAYOUT) {
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
        double x = json_number_value(v);
        if (layout_keys[k].kind == KEY_W_B) {
            w_B = x;
            continue;
        }
        if (layout_keys[k].kind == KEY_ORDER) {
            if (x != 1.0 && x != 2.0)
                return plume_err_set(err, PLUME_EFORMAT, "%s: key \"order\" must be 1 or 2 (got %g)", where, x);
            l->order = (int)x;
            continue;
        }
        /* 0 means "the thickness h" inside the layout struct only: given here it is a mistake */
        if (strncmp(key, "thickness_", 10) == 0 && !(x > 0.0 && isfinite(x)))
            return plume_err_set(err, PLUME_EFORMAT, "%s: key \"%s\" must be a finite thickness > 0 (got %g m)", where,
                                 key, x);
        *(double *)((char *)l + layout_keys[k].offset) = x;
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
