/* Reading JSON inputs with errors that name the file, line and key (lib/io/json_read.h). */
#include "json_read.h"
#include "input_file.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ locating a key --- */

typedef struct {
    const char *s;       /* cursor */
    int line;
    const char *target;  /* key path searched */
    char path[PLUME_JSON_KEY_MAX];  /* key path of the value at the cursor */
    int found;           /* line of the target, 0 until found */
    int depth;
} locator;

static void loc_ws(locator *l)
{
    while (*l->s == ' ' || *l->s == '\t' || *l->s == '\n' || *l->s == '\r') {
        if (*l->s == '\n')
            l->line++;
        l->s++;
    }
}

/* Skips a string at the cursor (on its opening quote); copies up to n-1 raw characters. */
static void loc_string(locator *l, char *out, size_t n)
{
    size_t k = 0;
    l->s++;
    while (*l->s && *l->s != '"') {
        if (*l->s == '\\' && l->s[1])
            l->s++;
        if (out && k + 1 < n)
            out[k++] = *l->s;
        l->s++;
    }
    if (*l->s == '"')
        l->s++;
    if (out)
        out[k] = '\0';
}

static void loc_value(locator *l)
{
    loc_ws(l);
    if (!l->found && strcmp(l->path, l->target) == 0)
        l->found = l->line;
    if (l->found || !*l->s || ++l->depth > 200)
        return;
    size_t plen = strlen(l->path);
    if (*l->s == '{' || *l->s == '[') {
        int object = *l->s == '{';
        char close = object ? '}' : ']';
        l->s++;
        for (long i = 0; !l->found; i++) {
            loc_ws(l);
            if (!*l->s || *l->s == close)
                break;
            if (object) {
                char key[PLUME_JSON_KEY_MAX];
                loc_string(l, key, sizeof key);
                loc_ws(l);
                if (*l->s == ':')
                    l->s++;
                snprintf(l->path + plen, sizeof l->path - plen, "%s%s", plen ? "." : "", key);
            } else {
                snprintf(l->path + plen, sizeof l->path - plen, "[%ld]", i);
            }
            loc_value(l);
            l->path[plen] = '\0';
            loc_ws(l);
            if (*l->s == ',')
                l->s++;
        }
        if (*l->s == close)
            l->s++;
    } else if (*l->s == '"') {
        loc_string(l, NULL, 0);
    } else {
        while (*l->s && !strchr(",]} \t\r\n", *l->s))
            l->s++;
    }
    l->depth--;
}

/* Line of the value at key path `key` in the JSON `text`, 0 when not found. */
static int locate(const char *text, const char *key)
{
    if (!text || !key)
        return 0;
    locator l;
    memset(&l, 0, sizeof l);
    l.s = text;
    l.line = 1;
    l.target = key;
    loc_value(&l);
    return l.found;
}

/* --------------------------------------------------------------------- context --- */

/* "<file>:<line>: <key> <message>", status st. */
plume_status plume_json_bad(const plume_json_ctx *c, plume_status st, const char *key, const char *fmt, ...)
{
    char msg[600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    char full[PLUME_JSON_KEY_MAX];
    if (c->prefix && *c->prefix) {
        if (snprintf(full, sizeof full, "%s%s%s", c->prefix, key[0] == '[' || !*key ? "" : ".", key) >= (int)sizeof full)
            full[sizeof full - 1] = '\0';
        key = full;
    }
    int line = locate(c->text, key);
    if (line > 0)
        return plume_err_set(c->err, st, "%s:%d: %s %s", c->file, line, key, msg);
    return plume_err_set(c->err, st, "%s: %s %s", c->file, key, msg);
}

/* Key paths are short in any real scene; one too long to fit is cut (it only names a key). */
void plume_json_subkey(char *out, const char *parent, const char *name)
{
    if (snprintf(out, PLUME_JSON_KEY_MAX, "%s%s%s", parent, *parent ? "." : "", name) >= PLUME_JSON_KEY_MAX)
        out[PLUME_JSON_KEY_MAX - 1] = '\0';
}

void plume_json_subindex(char *out, const char *parent, size_t i)
{
    if (snprintf(out, PLUME_JSON_KEY_MAX, "%s[%zu]", parent, i) >= PLUME_JSON_KEY_MAX)
        out[PLUME_JSON_KEY_MAX - 1] = '\0';
}

/* Unknown keys are refused (a typo would otherwise silently select a default); "note" is
 * allowed everywhere for comments. `allowed` is NULL-terminated. */
plume_status plume_json_check_keys(const plume_json_ctx *c, json_t *obj, const char *where, const char *const *allowed)
{
    const char *key;
    json_t *v;
    json_object_foreach(obj, key, v) {
        int ok = strcmp(key, "note") == 0;
        for (int k = 0; allowed[k] && !ok; k++)
            ok = strcmp(key, allowed[k]) == 0;
        if (!ok) {
            char kp[PLUME_JSON_KEY_MAX], list[400] = "";
            plume_json_subkey(kp, where, key);
            for (int k = 0; allowed[k]; k++)
                snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", allowed[k]);
            return plume_json_bad(c, PLUME_EFORMAT, kp, "is an unknown key (expected %s or note)", list);
        }
    }
    return PLUME_OK;
}

/* A number at obj[name]; *present = 0 when absent (then an error if required). */
plume_status plume_json_number(const plume_json_ctx *c, json_t *obj, const char *where, const char *name, int required,
                               double *out, int *present)
{
    char kp[PLUME_JSON_KEY_MAX];
    plume_json_subkey(kp, where, name);
    json_t *v = json_object_get(obj, name);
    if (present)
        *present = v != NULL;
    if (!v) {
        if (required)
            return plume_json_bad(c, PLUME_EFORMAT, kp, "is missing (a number is required)");
        return PLUME_OK;
    }
    if (!json_is_number(v))
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be a number");
    *out = json_number_value(v);
    if (!isfinite(*out))
        return plume_json_bad(c, PLUME_EINVAL, kp, "must be finite");
    return PLUME_OK;
}

/* A number that must be > 0 (or >= 0 when `zero_ok`). */
plume_status plume_json_positive(const plume_json_ctx *c, json_t *obj, const char *where, const char *name, int required,
                                 int zero_ok, double *out, int *present)
{
    int have = 0;
    plume_status st = plume_json_number(c, obj, where, name, required, out, &have);
    if (present)
        *present = have;
    if (st != PLUME_OK || !have)
        return st;
    if (zero_ok ? !(*out >= 0.0) : !(*out > 0.0)) {
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subkey(kp, where, name);
        return plume_json_bad(c, PLUME_EINVAL, kp, "must be %s (got %g)", zero_ok ? ">= 0" : "> 0", *out);
    }
    return PLUME_OK;
}

/* An integer in [lo, hi]. */
plume_status plume_json_int(const plume_json_ctx *c, json_t *obj, const char *where, const char *name, long lo, long hi,
                            long *out)
{
    char kp[PLUME_JSON_KEY_MAX];
    plume_json_subkey(kp, where, name);
    json_t *v = json_object_get(obj, name);
    if (!v)
        return PLUME_OK;
    double d = json_is_number(v) ? json_number_value(v) : NAN;
    if (!json_is_number(v) || d != floor(d) || !(d >= (double)lo && d <= (double)hi))
        return plume_json_bad(c, json_is_number(v) ? PLUME_EINVAL : PLUME_EFORMAT, kp, "must be an integer in [%ld, %ld]", lo, hi);
    *out = (long)d;
    return PLUME_OK;
}

/* [a, b, ...] of exactly n finite numbers. */
plume_status plume_json_vector(const plume_json_ctx *c, json_t *v, const char *kp, int n, double *out)
{
    if (!json_is_array(v) || (int)json_array_size(v) != n)
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be an array of %d numbers", n);
    for (int k = 0; k < n; k++) {
        json_t *e = json_array_get(v, (size_t)k);
        if (!json_is_number(e) || !isfinite(json_number_value(e)))
            return plume_json_bad(c, PLUME_EFORMAT, kp, "must be an array of %d finite numbers", n);
        out[k] = json_number_value(e);
    }
    return PLUME_OK;
}

/* A file name relative to the scene's directory; buf gets the path to open (cut if too long:
 * opening it then fails with a message showing it). */
void plume_json_resolve(const plume_json_ctx *c, const char *name, char *buf, size_t n)
{
    int len = name[0] == '/' || !c->dir[0] ? snprintf(buf, n, "%s", name) : snprintf(buf, n, "%s/%s", c->dir, name);
    if (len < 0 || (size_t)len >= n)
        buf[n - 1] = '\0';
}

/* The whole file as a NUL-terminated string (malloc'ed), or NULL with *st and err set. */
char *plume_read_text(const char *path, plume_err *err, const char *what, plume_status *st)
{
    *st = PLUME_EIO;
    FILE *f = plume_input_fopen(path, "rb", what, err);
    if (!f)
        return NULL;
    size_t cap = 65536, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (n + 1 < cap)
            break;
        char *nb = realloc(buf, 2 * cap);
        if (!nb) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = nb;
        cap *= 2;
    }
    int bad_read = ferror(f);
    fclose(f);
    if (!buf) {
        *st = plume_err_set(err, PLUME_ENOMEM, "%s '%s': out of memory", what, path);
        return NULL;
    }
    if (bad_read) {
        free(buf);
        plume_err_set(err, PLUME_EIO, "%s '%s': read error", what, path);
        return NULL;
    }
    buf[n] = '\0';
    *st = PLUME_OK;
    return buf;
}

/* A polyline [[x, y], ...] of at least 2 points; *pts malloc'ed. */
plume_status plume_json_polyline(const plume_json_ctx *c, json_t *v, const char *kp, double **pts, plume_index *n)
{
    *pts = NULL;
    *n = 0;
    if (!json_is_array(v) || json_array_size(v) < 2)
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be an array of at least 2 points [x, y]");
    size_t np = json_array_size(v);
    double *p = malloc(2 * np * sizeof *p);
    if (!p)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (size_t i = 0; i < np; i++) {
        char ki[PLUME_JSON_KEY_MAX];
        plume_json_subindex(ki, kp, i);
        plume_status st = plume_json_vector(c, json_array_get(v, i), ki, 2, p + 2 * i);
        if (st != PLUME_OK) {
            free(p);
            return st;
        }
    }
    *pts = p;
    *n = (plume_index)np;
    return PLUME_OK;
}

