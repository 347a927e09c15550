/* plume (private, not installed): reading JSON inputs with errors that name the file, the line and
 * the key path ("scene.json:12: materials[0].density must be finite and > 0 (got -1)").
 *
 * jansson reports the line of a syntax error but keeps no position for decoded values, so a bad
 * value would otherwise be reported by its key alone. To name the line as well, the file's text
 * is kept in the context and, when a value is refused, a small scanner walks it (already known to
 * be valid JSON) to the value's key path and returns the line it starts on. */
#ifndef PLUME_INTERNAL_JSON_READ_H
#define PLUME_INTERNAL_JSON_READ_H

#include <jansson.h>
#include <stddef.h>

#include "../core/status.h"

enum { PLUME_JSON_KEY_MAX = 256 };

/* What an error message needs: the file, its text (for the line) and its directory. */
typedef struct {
    const char *file;  /* path as given */
    char *text;        /* its contents */
    char dir[4096];    /* directory for relative paths ("" = current) */
    plume_err *err;
    const char *prefix; /* NULL, or a key path every key is under ("objects[2]": an object's mesh,
                           parsed by the functions that parse the top-level "mesh") */
} plume_json_ctx;

/* "<file>:<line>: <key> <message>", status st. */
plume_status plume_json_bad(const plume_json_ctx *c, plume_status st, const char *key, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Key paths: parent.name and parent[i] (cut at PLUME_JSON_KEY_MAX; they only name a key). */
void plume_json_subkey(char *out, const char *parent, const char *name);
void plume_json_subindex(char *out, const char *parent, size_t i);

/* Refuses keys not in `allowed` (NULL-terminated); "note" is always allowed. */
plume_status plume_json_check_keys(const plume_json_ctx *c, json_t *obj, const char *where, const char *const *allowed);

/* A finite number at obj[name]; *present = 0 when absent (an error if required). */
plume_status plume_json_number(const plume_json_ctx *c, json_t *obj, const char *where, const char *name,
                               int required, double *out, int *present);
/* A number that must be > 0 (>= 0 when zero_ok). */
plume_status plume_json_positive(const plume_json_ctx *c, json_t *obj, const char *where, const char *name,
                                 int required, int zero_ok, double *out, int *present);
/* An integer in [lo, hi]; *out unchanged when absent. */
plume_status plume_json_int(const plume_json_ctx *c, json_t *obj, const char *where, const char *name, long lo,
                            long hi, long *out);
/* [a, b, ...] of exactly n finite numbers at key path kp. */
plume_status plume_json_vector(const plume_json_ctx *c, json_t *v, const char *kp, int n, double *out);
/* A polyline [[x, y], ...] of at least 2 points; *pts malloc'ed. */
plume_status plume_json_polyline(const plume_json_ctx *c, json_t *v, const char *kp, double **pts, plume_index *n);

/* A file name relative to the context's directory (buf cut if too long: opening it then fails
 * with a message showing it). */
void plume_json_resolve(const plume_json_ctx *c, const char *name, char *buf, size_t n);

/* The whole file as a NUL-terminated malloc'ed string, or NULL with *st and err set ("<what>
 * '<path>': cannot open: ..."). */
char *plume_read_text(const char *path, plume_err *err, const char *what, plume_status *st);

#endif
