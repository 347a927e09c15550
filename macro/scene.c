/* plume: dynamic shell scenes from JSON (format in scene.h and README.md).
 *
 * jansson reports the line of a syntax error but keeps no position for decoded values, so a bad
 * value would otherwise be reported by its key alone. To name the line as well, the file's text
 * is kept and, when a value is refused, a small scanner walks it (already known to be valid JSON)
 * to the value's key path ("materials[1].density") and returns the line it starts on. */
#include "scene.h"

#include <jansson.h>

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/edge_length.h"
#include "../lib/membrane.h"
#include "feather_mesh.h"

enum { KEY_MAX = 256 };

/* ------------------------------------------------------------------ locating a key --- */

typedef struct {
    const char *s;       /* cursor */
    int line;
    const char *target;  /* key path searched */
    char path[KEY_MAX];  /* key path of the value at the cursor */
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
                char key[KEY_MAX];
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

typedef struct {
    const char *file;  /* scene path */
    char *text;        /* its contents */
    char dir[4096];    /* directory for relative paths ("" = current) */
    plume_err *err;
} ctx;

/* "<file>:<line>: <key> <message>", status st. */
static plume_status bad(const ctx *c, plume_status st, const char *key, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static plume_status bad(const ctx *c, plume_status st, const char *key, const char *fmt, ...)
{
    char msg[600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int line = locate(c->text, key);
    if (line > 0)
        return plume_err_set(c->err, st, "%s:%d: %s %s", c->file, line, key, msg);
    return plume_err_set(c->err, st, "%s: %s %s", c->file, key, msg);
}

/* Key paths are short in any real scene; one too long to fit is cut (it only names a key). */
static void subkey(char *out, const char *parent, const char *name)
{
    if (snprintf(out, KEY_MAX, "%s%s%s", parent, *parent ? "." : "", name) >= KEY_MAX)
        out[KEY_MAX - 1] = '\0';
}

static void subindex(char *out, const char *parent, size_t i)
{
    if (snprintf(out, KEY_MAX, "%s[%zu]", parent, i) >= KEY_MAX)
        out[KEY_MAX - 1] = '\0';
}

/* Unknown keys are refused (a typo would otherwise silently select a default); "note" is
 * allowed everywhere for comments. `allowed` is NULL-terminated. */
static plume_status check_keys(const ctx *c, json_t *obj, const char *where, const char *const *allowed)
{
    const char *key;
    json_t *v;
    json_object_foreach(obj, key, v) {
        int ok = strcmp(key, "note") == 0;
        for (int k = 0; allowed[k] && !ok; k++)
            ok = strcmp(key, allowed[k]) == 0;
        if (!ok) {
            char kp[KEY_MAX], list[400] = "";
            subkey(kp, where, key);
            for (int k = 0; allowed[k]; k++)
                snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", allowed[k]);
            return bad(c, PLUME_EFORMAT, kp, "is an unknown key (expected %s or note)", list);
        }
    }
    return PLUME_OK;
}

/* A number at obj[name]; *present = 0 when absent (then an error if required). */
static plume_status get_number(const ctx *c, json_t *obj, const char *where, const char *name, int required,
                               double *out, int *present)
{
    char kp[KEY_MAX];
    subkey(kp, where, name);
    json_t *v = json_object_get(obj, name);
    if (present)
        *present = v != NULL;
    if (!v) {
        if (required)
            return bad(c, PLUME_EFORMAT, kp, "is missing (a number is required)");
        return PLUME_OK;
    }
    if (!json_is_number(v))
        return bad(c, PLUME_EFORMAT, kp, "must be a number");
    *out = json_number_value(v);
    if (!isfinite(*out))
        return bad(c, PLUME_EINVAL, kp, "must be finite");
    return PLUME_OK;
}

/* A number that must be > 0 (or >= 0 when `zero_ok`). */
static plume_status get_positive(const ctx *c, json_t *obj, const char *where, const char *name, int required,
                                 int zero_ok, double *out, int *present)
{
    int have = 0;
    plume_status st = get_number(c, obj, where, name, required, out, &have);
    if (present)
        *present = have;
    if (st != PLUME_OK || !have)
        return st;
    if (zero_ok ? !(*out >= 0.0) : !(*out > 0.0)) {
        char kp[KEY_MAX];
        subkey(kp, where, name);
        return bad(c, PLUME_EINVAL, kp, "must be %s (got %g)", zero_ok ? ">= 0" : "> 0", *out);
    }
    return PLUME_OK;
}

/* An integer in [lo, hi]. */
static plume_status get_int(const ctx *c, json_t *obj, const char *where, const char *name, long lo, long hi,
                            long *out)
{
    char kp[KEY_MAX];
    subkey(kp, where, name);
    json_t *v = json_object_get(obj, name);
    if (!v)
        return PLUME_OK;
    double d = json_is_number(v) ? json_number_value(v) : NAN;
    if (!json_is_number(v) || d != floor(d) || !(d >= (double)lo && d <= (double)hi))
        return bad(c, json_is_number(v) ? PLUME_EINVAL : PLUME_EFORMAT, kp, "must be an integer in [%ld, %ld]", lo, hi);
    *out = (long)d;
    return PLUME_OK;
}

/* [a, b, ...] of exactly n finite numbers. */
static plume_status get_vector(const ctx *c, json_t *v, const char *kp, int n, double *out)
{
    if (!json_is_array(v) || (int)json_array_size(v) != n)
        return bad(c, PLUME_EFORMAT, kp, "must be an array of %d numbers", n);
    for (int k = 0; k < n; k++) {
        json_t *e = json_array_get(v, (size_t)k);
        if (!json_is_number(e) || !isfinite(json_number_value(e)))
            return bad(c, PLUME_EFORMAT, kp, "must be an array of %d finite numbers", n);
        out[k] = json_number_value(e);
    }
    return PLUME_OK;
}

/* A file name relative to the scene's directory; buf gets the path to open (cut if too long:
 * opening it then fails with a message showing it). */
static void resolve(const ctx *c, const char *name, char *buf, size_t n)
{
    int len = name[0] == '/' || !c->dir[0] ? snprintf(buf, n, "%s", name) : snprintf(buf, n, "%s/%s", c->dir, name);
    if (len < 0 || (size_t)len >= n)
        buf[n - 1] = '\0';
}

/* The whole file as a NUL-terminated string (malloc'ed), or NULL with *st and err set. */
static char *slurp(const char *path, plume_err *err, const char *what, plume_status *st)
{
    *st = PLUME_EIO;
    FILE *f = fopen(path, "rb");
    if (!f) {
        plume_err_set(err, PLUME_EIO, "%s '%s': cannot open: %s", what, path, strerror(errno));
        return NULL;
    }
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

/* -------------------------------------------------------------------- OBJ meshes --- */

typedef struct {
    double *v;             /* [2 nv] x, y */
    plume_index nv, vcap;
    plume_index *f;        /* [3 nf] 0-based */
    int *group;            /* [nf] group id, -1 none */
    plume_index nf, fcap;
    char **groups;         /* group names */
    int ngroups;
} obj_data;

static void obj_free(obj_data *o)
{
    free(o->v);
    free(o->f);
    free(o->group);
    for (int g = 0; g < o->ngroups; g++)
        free(o->groups[g]);
    free(o->groups);
    memset(o, 0, sizeof *o);
}

static int obj_group(obj_data *o, const char *name)
{
    for (int g = 0; g < o->ngroups; g++)
        if (strcmp(o->groups[g], name) == 0)
            return g;
    char **ng = realloc(o->groups, (size_t)(o->ngroups + 1) * sizeof *ng);
    if (!ng)
        return -2;
    o->groups = ng;
    size_t len = strlen(name);
    o->groups[o->ngroups] = malloc(len + 1);
    if (!o->groups[o->ngroups])
        return -2;
    memcpy(o->groups[o->ngroups], name, len + 1);
    return o->ngroups++;
}

/* Reads v / f / g (and o) lines of an OBJ file; faces of more than three vertices are split
 * into a fan. Other statements (vt, vn, s, usemtl, mtllib) are ignored. */
static plume_status obj_read(const char *path, obj_data *o, plume_err *err)
{
    memset(o, 0, sizeof *o);
    plume_status st;
    char *text = slurp(path, err, "mesh file", &st);
    if (!text)
        return st;
    int line = 0, current = -1;
    char *save = NULL;
    for (char *ln = text; ln; ln = save) {
        line++;
        save = strchr(ln, '\n');
        if (save)
            *save++ = '\0';
        char *p = ln;
        while (*p == ' ' || *p == '\t')
            p++;
        size_t L = strlen(p);
        while (L > 0 && (p[L - 1] == '\r' || p[L - 1] == ' ' || p[L - 1] == '\t'))
            p[--L] = '\0';
        if (p[0] == 'v' && (p[1] == ' ' || p[1] == '\t')) {
            char *end;
            double x = strtod(p + 2, &end), y = strtod(end, &end);
            if (end == p + 2 || !isfinite(x) || !isfinite(y)) {
                st = plume_err_set(err, PLUME_EFORMAT, "%s:%d: a vertex needs finite x and y", path, line);
                goto done;
            }
            if (o->nv == o->vcap) {
                o->vcap = o->vcap ? 2 * o->vcap : 256;
                double *nv = realloc(o->v, (size_t)(2 * o->vcap) * sizeof *nv);
                if (!nv)
                    goto nomem;
                o->v = nv;
            }
            o->v[2 * o->nv] = x;
            o->v[2 * o->nv + 1] = y;
            o->nv++;
        } else if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
            plume_index ids[64];
            int n = 0;
            char *q = p + 2;
            for (;;) {
                while (*q == ' ' || *q == '\t')
                    q++;
                if (!*q)
                    break;
                char *end;
                long id = strtol(q, &end, 10);
                if (end == q || n == 64) {
                    st = plume_err_set(err, PLUME_EFORMAT, "%s:%d: bad face (vertex numbers expected, at most 64)",
                                       path, line);
                    goto done;
                }
                while (*end && *end != ' ' && *end != '\t') /* skip /vt/vn */
                    end++;
                q = end;
                long k = id > 0 ? id - 1 : (long)o->nv + id;
                if (id == 0 || k < 0 || k >= (long)o->nv) {
                    st = plume_err_set(err, PLUME_EFORMAT, "%s:%d: face refers to vertex %ld, which is not defined above",
                                       path, line, id);
                    goto done;
                }
                ids[n++] = k;
            }
            if (n < 3) {
                st = plume_err_set(err, PLUME_EFORMAT, "%s:%d: a face needs at least 3 vertices", path, line);
                goto done;
            }
            for (int t = 0; t + 2 < n; t++) {
                if (o->nf == o->fcap) {
                    o->fcap = o->fcap ? 2 * o->fcap : 256;
                    plume_index *nf = realloc(o->f, (size_t)(3 * o->fcap) * sizeof *nf);
                    int *ng = realloc(o->group, (size_t)o->fcap * sizeof *ng);
                    if (nf)
                        o->f = nf;
                    if (ng)
                        o->group = ng;
                    if (!nf || !ng)
                        goto nomem;
                }
                o->f[3 * o->nf] = ids[0];
                o->f[3 * o->nf + 1] = ids[t + 1];
                o->f[3 * o->nf + 2] = ids[t + 2];
                o->group[o->nf] = current;
                o->nf++;
            }
        } else if ((p[0] == 'g' || p[0] == 'o') && (p[1] == ' ' || p[1] == '\t' || p[1] == '\0')) {
            char *q = p + 1;
            while (*q == ' ' || *q == '\t')
                q++;
            char *e = q;
            while (*e && *e != ' ' && *e != '\t')
                e++;
            *e = '\0';
            if (!*q) {
                current = -1;
            } else if ((current = obj_group(o, q)) < -1) {
                goto nomem;
            }
        }
    }
    if (o->nf == 0)
        st = plume_err_set(err, PLUME_EFORMAT, "%s: no faces (f lines) in this OBJ file", path);
    goto done;
nomem:
    st = plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", path);
done:
    free(text);
    if (st != PLUME_OK)
        obj_free(o);
    return st;
}

/* ------------------------------------------------------------------- the scene --- */

void plume_scene_destroy(plume_scene **ps)
{
    if (!ps || !*ps)
        return;
    plume_scene *s = *ps;
    free(s->path);
    plume_mesh_destroy(&s->mesh);
    free(s->mats);
    for (int h = 0; h < s->nhandles; h++) {
        free((void *)s->handles[h].vertices);
        free((void *)s->handles[h].times);
        free((void *)s->handles[h].offsets);
    }
    free(s->handles);
    free(s->barb_edges);
    free(s->render);
    free(s);
    *ps = NULL;
}

/* Mesh from an OBJ: x, y reference coordinates, material by group, constant barb direction.
 * *vertex_map gets, for every OBJ vertex (0-based), its mesh id or -1 if no face uses it. */
static plume_status mesh_from_obj(const ctx *c, json_t *m, plume_scene *s, plume_index **vertex_map,
                                  plume_index *nobj)
{
    static const char *const keys[] = {"obj", "materials_by_group", "barb_direction", NULL};
    plume_status st = check_keys(c, m, "mesh", keys);
    if (st != PLUME_OK)
        return st;
    json_t *jo = json_object_get(m, "obj");
    if (!json_is_string(jo))
        return bad(c, PLUME_EFORMAT, "mesh.obj", "must be a file name");
    double d[2] = {1.0, 0.0};
    json_t *jd = json_object_get(m, "barb_direction");
    if (jd) {
        if ((st = get_vector(c, jd, "mesh.barb_direction", 2, d)) != PLUME_OK)
            return st;
        double len = hypot(d[0], d[1]);
        if (!(len > 0.0))
            return bad(c, PLUME_EINVAL, "mesh.barb_direction", "must be a non-zero vector");
        d[0] /= len, d[1] /= len;
    }
    char path[4096];
    resolve(c, json_string_value(jo), path, sizeof path);
    obj_data o;
    plume_err e2 = {{0}};
    if ((st = obj_read(path, &o, &e2)) != PLUME_OK)
        return bad(c, st, "mesh.obj", "(%s)", e2.msg);
    /* material of each group */
    int *gmat = calloc((size_t)o.ngroups + 1, sizeof *gmat);
    plume_index *map = malloc((size_t)(o.nv + 1) * sizeof *map);
    if (!gmat || !map) {
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    json_t *jg = json_object_get(m, "materials_by_group");
    if (jg) {
        if (!json_is_object(jg)) {
            st = bad(c, PLUME_EFORMAT, "mesh.materials_by_group", "must be an object {\"group\": material id}");
            goto done;
        }
        const char *gname;
        json_t *gv;
        json_object_foreach(jg, gname, gv) {
            char kp[KEY_MAX];
            subkey(kp, "mesh.materials_by_group", gname);
            int g = 0;
            while (g < o.ngroups && strcmp(o.groups[g], gname) != 0)
                g++;
            if (g == o.ngroups) {
                st = bad(c, PLUME_EINVAL, kp, "names a group that %s does not have (its g/o lines)", path);
                goto done;
            }
            double id = json_is_number(gv) ? json_number_value(gv) : -1.0;
            if (!json_is_number(gv) || id != floor(id) || id < 0 || id > 1e6) {
                st = bad(c, PLUME_EINVAL, kp, "must be a material id (an integer >= 0)");
                goto done;
            }
            gmat[g] = (int)id;
        }
    }
    /* only vertices used by a face become mesh vertices */
    for (plume_index v = 0; v < o.nv; v++)
        map[v] = -1;
    for (plume_index k = 0; k < 3 * o.nf; k++)
        map[o.f[k]] = 0;
    plume_index nv = 0;
    for (plume_index v = 0; v < o.nv; v++)
        if (map[v] == 0)
            map[v] = nv++;
    if ((st = plume_mesh_create(nv, o.nf, 3, &s->mesh)) != PLUME_OK) {
        plume_err_set(c->err, st, "%s: out of memory", c->file);
        goto done;
    }
    plume_mesh *mesh = s->mesh;
    for (plume_index v = 0; v < o.nv; v++)
        if (map[v] >= 0) {
            mesh->X[2 * map[v]] = o.v[2 * v];
            mesh->X[2 * map[v] + 1] = o.v[2 * v + 1];
        }
    for (plume_index t = 0; t < o.nf; t++) {
        plume_index a = map[o.f[3 * t]], b = map[o.f[3 * t + 1]], cc = map[o.f[3 * t + 2]];
        const double *A = mesh->X + 2 * a, *B = mesh->X + 2 * b, *C = mesh->X + 2 * cc;
        double area2 = (B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0]);
        if (area2 < 0) { /* counter-clockwise in X, as plume_mesh expects */
            plume_index tmp = b;
            b = cc, cc = tmp;
        }
        mesh->tri[3 * t] = a, mesh->tri[3 * t + 1] = b, mesh->tri[3 * t + 2] = cc;
        mesh->material[t] = o.group[t] >= 0 ? gmat[o.group[t]] : 0;
        mesh->barb_dir[2 * t] = d[0];
        mesh->barb_dir[2 * t + 1] = d[1];
    }
    plume_mesh_reset_current(mesh);
    plume_err e3 = {{0}};
    if ((st = plume_mesh_build_topology(mesh, &e3)) != PLUME_OK) {
        st = bad(c, st, "mesh.obj", "(%s): %s", path, e3.msg);
        goto done;
    }
    *vertex_map = map;
    *nobj = o.nv;
    map = NULL;
done:
    free(gmat);
    free(map);
    obj_free(&o);
    return st;
}

/* A polyline [[x, y], ...] of at least 2 points; *pts malloc'ed. */
static plume_status get_polyline(const ctx *c, json_t *v, const char *kp, double **pts, plume_index *n)
{
    *pts = NULL;
    *n = 0;
    if (!json_is_array(v) || json_array_size(v) < 2)
        return bad(c, PLUME_EFORMAT, kp, "must be an array of at least 2 points [x, y]");
    size_t np = json_array_size(v);
    double *p = malloc(2 * np * sizeof *p);
    if (!p)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (size_t i = 0; i < np; i++) {
        char ki[KEY_MAX];
        subindex(ki, kp, i);
        plume_status st = get_vector(c, json_array_get(v, i), ki, 2, p + 2 * i);
        if (st != PLUME_OK) {
            free(p);
            return st;
        }
    }
    *pts = p;
    *n = (plume_index)np;
    return PLUME_OK;
}

/* Barb curves of one side: an array of polylines. */
static plume_status get_curves(const ctx *c, json_t *doc, const char *name, plume_polyline **lines, double ***store,
                               int *n)
{
    *lines = NULL;
    *store = NULL;
    *n = 0;
    json_t *v = json_object_get(doc, name);
    if (!json_is_array(v) || json_array_size(v) < 1)
        return bad(c, PLUME_EFORMAT, name, "must be an array of barb curves [[[x, y], ...], ...]");
    size_t nc = json_array_size(v);
    *lines = calloc(nc, sizeof **lines);
    *store = calloc(nc, sizeof **store);
    if (!*lines || !*store)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (size_t i = 0; i < nc; i++) {
        char ki[KEY_MAX];
        subindex(ki, name, i);
        plume_index np;
        plume_status st = get_polyline(c, json_array_get(v, i), ki, &(*store)[i], &np);
        if (st != PLUME_OK)
            return st;
        (*lines)[i].n = np;
        (*lines)[i].p = (*store)[i];
        (*n)++;
    }
    return PLUME_OK;
}

/* Mesh from the feather mesher: the shape file (data/feather/feather_shape.json: "rachis"
 * {"points", "width_base", "width_tip"}, "barbs_left", "barbs_right", "outline_obj", "edge"; the
 * flat form "rachis": [[x, y], ...] with "rachis_width_base"/"rachis_width_tip" is read too) and
 * the outline. The scene's "outline" and "edge" override the shape file's. Other keys of the shape
 * file (description, units, comments) are its author's business and are not checked. */
static plume_status mesh_from_feather(const ctx *c, json_t *m, plume_scene *s)
{
    static const char *const keys[] = {"feather", "outline", "edge", NULL};
    plume_status st = check_keys(c, m, "mesh", keys);
    if (st != PLUME_OK)
        return st;
    json_t *jf = json_object_get(m, "feather"), *jo = json_object_get(m, "outline");
    if (!json_is_string(jf))
        return bad(c, PLUME_EFORMAT, "mesh.feather", "must be a file name (the feather shape JSON)");
    if (jo && !json_is_string(jo))
        return bad(c, PLUME_EFORMAT, "mesh.outline", "must be a file name (an OBJ mesh whose boundary is the outline)");
    double edge = 0.0;
    int have_edge = 0;
    if ((st = get_positive(c, m, "mesh", "edge", 0, 0, &edge, &have_edge)) != PLUME_OK)
        return st;
    char shape_path[4096], outline_path[4096];
    resolve(c, json_string_value(jf), shape_path, sizeof shape_path);

    /* the shape file is parsed with its own context so that its errors name it */
    ctx sc = *c;
    sc.file = shape_path;
    plume_err e1 = {{0}};
    sc.text = slurp(shape_path, &e1, "feather shape", &st);
    if (!sc.text)
        return bad(c, st, "mesh.feather", "(%s)", e1.msg);
    const char *slash = strrchr(shape_path, '/');
    if (slash)
        snprintf(sc.dir, sizeof sc.dir, "%.*s", (int)(slash == shape_path ? 1 : slash - shape_path), shape_path);
    else
        sc.dir[0] = '\0';
    json_error_t je;
    json_t *doc = json_loads(sc.text, JSON_REJECT_DUPLICATES, &je);
    double *outline = NULL, *rachis = NULL, **left = NULL, **right = NULL;
    plume_polyline *lp = NULL, *rp = NULL;
    int nl = 0, nr = 0;
    plume_index no = 0, nra = 0, *barbs = NULL, nbarb = 0;
    double wb = 0.0, wt = 0.0;
    if (!doc) {
        st = plume_err_set(c->err, PLUME_EFORMAT, "%s:%d:%d: %s", shape_path, je.line, je.column, je.text);
        goto done;
    }
    if (!json_is_object(doc)) {
        st = plume_err_set(c->err, PLUME_EFORMAT, "%s: expected a JSON object", shape_path);
        goto done;
    }
    if (!have_edge) {
        if (!json_object_get(doc, "edge")) {
            st = bad(c, PLUME_EFORMAT, "mesh.edge", "is missing (the target edge length, m; the shape file has none)");
            goto done;
        }
        if ((st = get_positive(&sc, doc, "", "edge", 1, 0, &edge, NULL)) != PLUME_OK)
            goto done;
    }
    /* the outline: the scene's OBJ, else the shape file's "outline_obj" (or an "outline" polyline) */
    json_t *so = json_object_get(doc, "outline_obj"), *sp = json_object_get(doc, "outline");
    if (jo || so) {
        if (!jo && !json_is_string(so)) {
            st = bad(&sc, PLUME_EFORMAT, "outline_obj", "must be a file name");
            goto done;
        }
        if (jo)
            resolve(c, json_string_value(jo), outline_path, sizeof outline_path);
        else
            resolve(&sc, json_string_value(so), outline_path, sizeof outline_path);
        plume_err e2 = {{0}};
        if ((st = plume_obj_outline(outline_path, &outline, &no, &e2)) != PLUME_OK) {
            st = bad(jo ? c : &sc, st, jo ? "mesh.outline" : "outline_obj", "(%s)", e2.msg);
            goto done;
        }
    } else if (sp) {
        if ((st = get_polyline(&sc, sp, "outline", &outline, &no)) != PLUME_OK)
            goto done;
    } else {
        st = bad(c, PLUME_EFORMAT, "mesh.outline", "is missing (an OBJ file whose boundary is the feather outline; "
                                                   "or \"outline_obj\" in the shape file)");
        goto done;
    }
    json_t *jr = json_object_get(doc, "rachis");
    if (json_is_object(jr)) {
        if ((st = get_polyline(&sc, json_object_get(jr, "points"), "rachis.points", &rachis, &nra)) != PLUME_OK ||
            (st = get_positive(&sc, jr, "rachis", "width_base", 1, 0, &wb, NULL)) != PLUME_OK ||
            (st = get_positive(&sc, jr, "rachis", "width_tip", 1, 0, &wt, NULL)) != PLUME_OK)
            goto done;
    } else if ((st = get_polyline(&sc, jr, "rachis", &rachis, &nra)) != PLUME_OK ||
               (st = get_positive(&sc, doc, "", "rachis_width_base", 1, 0, &wb, NULL)) != PLUME_OK ||
               (st = get_positive(&sc, doc, "", "rachis_width_tip", 1, 0, &wt, NULL)) != PLUME_OK) {
        goto done;
    }
    if ((st = get_curves(&sc, doc, "barbs_left", &lp, &left, &nl)) != PLUME_OK ||
        (st = get_curves(&sc, doc, "barbs_right", &rp, &right, &nr)) != PLUME_OK)
        goto done;
    plume_feather_input in;
    memset(&in, 0, sizeof in);
    in.outline.n = no;
    in.outline.p = outline;
    in.rachis.n = nra;
    in.rachis.p = rachis;
    in.rachis_width_base = wb;
    in.rachis_width_tip = wt;
    in.nbarbs_left = nl;
    in.nbarbs_right = nr;
    in.barbs_left = lp;
    in.barbs_right = rp;
    in.edge = edge;
    plume_err e3 = {{0}};
    if ((st = plume_feather_mesh(&in, 3, &s->mesh, &barbs, &nbarb, &e3)) != PLUME_OK) {
        st = plume_err_set(c->err, st, "%s: feather mesh from %s: %s", c->file, shape_path, e3.msg);
        goto done;
    }
    s->barb_edges = barbs; /* filtered by material later */
    s->nbarb = nbarb;
    barbs = NULL;
done:
    free(barbs);
    json_decref(doc);
    free(sc.text);
    free(outline);
    free(rachis);
    for (int i = 0; left && i < nl; i++)
        free(left[i]);
    for (int i = 0; right && i < nr; i++)
        free(right[i]);
    free(left);
    free(right);
    free(lp);
    free(rp);
    return st;
}

/* One material entry. */
static plume_status parse_material(const ctx *c, json_t *jm, const char *where, plume_scene_material *out)
{
    static const char *const keys[] = {"membrane", "bending", "density", "constraint", NULL};
    static const char *const ortho[] = {"E_xx", "E_yy", "nu_xy", "G_xy", "thickness", "kappa", NULL};
    static const char *const iso[] = {"E", "nu", "thickness", "kappa", NULL};
    static const char *const bend2[] = {"D_long", "D_trans", NULL};
    static const char *const bend1[] = {"D", NULL};
    char kp[KEY_MAX];
    plume_status st;
    if (!json_is_object(jm))
        return bad(c, PLUME_EFORMAT, where, "must be an object with membrane, bending, density, constraint");
    if ((st = check_keys(c, jm, where, keys)) != PLUME_OK)
        return st;
    memset(out, 0, sizeof *out);
    plume_membrane_material *mm = &out->membrane;
    subkey(kp, where, "membrane");
    json_t *mem = json_object_get(jm, "membrane");
    if (!json_is_object(mem))
        return bad(c, PLUME_EFORMAT, kp,
                   mem ? "must be an object {E_xx, E_yy, nu_xy, G_xy, thickness, kappa} or {E, nu, thickness, kappa}"
                       : "is missing (an object {E_xx, E_yy, nu_xy, G_xy, thickness, kappa} or {E, nu, thickness, kappa})");
    if (json_object_get(mem, "E")) {
        double E = 0.0, nu = 0.0;
        if ((st = check_keys(c, mem, kp, iso)) != PLUME_OK || (st = get_positive(c, mem, kp, "E", 1, 0, &E, NULL)) ||
            (st = get_number(c, mem, kp, "nu", 0, &nu, NULL)))
            return st;
        if (!(nu > -1.0 && nu < 0.5)) {
            char kn[KEY_MAX];
            subkey(kn, kp, "nu");
            return bad(c, PLUME_EINVAL, kn, "must be in (-1, 0.5) (got %g)", nu);
        }
        mm->E_xx = mm->E_yy = E;
        mm->nu_xy = nu;
        mm->G_xy = E / (2.0 * (1.0 + nu));
    } else {
        if ((st = check_keys(c, mem, kp, ortho)) != PLUME_OK ||
            (st = get_positive(c, mem, kp, "E_xx", 1, 0, &mm->E_xx, NULL)) ||
            (st = get_positive(c, mem, kp, "E_yy", 1, 0, &mm->E_yy, NULL)) ||
            (st = get_number(c, mem, kp, "nu_xy", 0, &mm->nu_xy, NULL)) ||
            (st = get_positive(c, mem, kp, "G_xy", 1, 0, &mm->G_xy, NULL)))
            return st;
    }
    if ((st = get_positive(c, mem, kp, "thickness", 1, 0, &mm->h, NULL)) ||
        (st = get_positive(c, mem, kp, "kappa", 0, 1, &mm->kappa, NULL)))
        return st;
    plume_err e2 = {{0}};
    if ((st = plume_membrane_material_check(mm, &e2)) != PLUME_OK)
        return bad(c, st, kp, "is not a valid material: %s", e2.msg);

    /* bending: explicit, or that of a plate of the membrane's moduli and thickness */
    subkey(kp, where, "bending");
    json_t *jb = json_object_get(jm, "bending");
    if (!jb || (json_is_string(jb) && strcmp(json_string_value(jb), "from_membrane") == 0)) {
        double nu_yx = mm->nu_xy * mm->E_yy / mm->E_xx, h3 = mm->h * mm->h * mm->h;
        double den = 12.0 * (1.0 - mm->nu_xy * nu_yx);
        out->bending.D_long = mm->E_xx * h3 / den;
        out->bending.D_trans = mm->E_yy * h3 / den;
    } else if (json_is_object(jb) && json_object_get(jb, "D")) {
        double D = 0.0;
        if ((st = check_keys(c, jb, kp, bend1)) != PLUME_OK || (st = get_positive(c, jb, kp, "D", 1, 1, &D, NULL)))
            return st;
        out->bending.D_long = out->bending.D_trans = D;
    } else if (json_is_object(jb)) {
        if ((st = check_keys(c, jb, kp, bend2)) != PLUME_OK ||
            (st = get_positive(c, jb, kp, "D_long", 1, 1, &out->bending.D_long, NULL)) ||
            (st = get_positive(c, jb, kp, "D_trans", 1, 1, &out->bending.D_trans, NULL)))
            return st;
    } else {
        return bad(c, PLUME_EFORMAT, kp, "must be {\"D_long\", \"D_trans\"}, {\"D\"} or \"from_membrane\"");
    }
    if ((st = get_positive(c, jm, where, "density", 1, 0, &out->density, NULL)) != PLUME_OK)
        return st;
    json_t *jc = json_object_get(jm, "constraint");
    subkey(kp, where, "constraint");
    if (jc && !json_is_boolean(jc))
        return bad(c, PLUME_EFORMAT, kp, "must be true or false");
    out->constraint = jc ? json_is_true(jc) : 0;
    return PLUME_OK;
}

/* One handle: its selector and keyframes. map/nobj translate OBJ vertex numbers (NULL: mesh ids). */
static plume_status parse_handle(const ctx *c, json_t *jh, const char *where, const plume_scene *s,
                                 const plume_index *map, plume_index nobj, plume_handle *h)
{
    static const char *const keys[] = {"near", "radius", "vertices", "box", "keyframes", NULL};
    char kp[KEY_MAX];
    plume_status st;
    if (!json_is_object(jh))
        return bad(c, PLUME_EFORMAT, where, "must be an object with a selector (near/radius, vertices or box) and keyframes");
    if ((st = check_keys(c, jh, where, keys)) != PLUME_OK)
        return st;
    const plume_mesh *m = s->mesh;
    json_t *jn = json_object_get(jh, "near"), *jv = json_object_get(jh, "vertices"), *jb = json_object_get(jh, "box");
    if ((jn != NULL) + (jv != NULL) + (jb != NULL) != 1)
        return bad(c, PLUME_EFORMAT, where, "needs exactly one selector: \"near\" (with \"radius\"), \"vertices\" or \"box\"");
    plume_index *ids = malloc((size_t)(m->nv + 1) * sizeof *ids), n = 0;
    if (!ids)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    h->vertices = ids;
    double tol = 1e-12 * s->length;
    if (jn) {
        double p[2], r = -1.0;
        int have_r = 0;
        subkey(kp, where, "near");
        if ((st = get_vector(c, jn, kp, 2, p)) != PLUME_OK ||
            (st = get_positive(c, jh, where, "radius", 0, 1, &r, &have_r)) != PLUME_OK)
            return st;
        plume_index best = 0;
        double dbest = INFINITY;
        for (plume_index v = 0; v < m->nv; v++) {
            double dist = hypot(m->X[2 * v] - p[0], m->X[2 * v + 1] - p[1]);
            if (dist < dbest)
                dbest = dist, best = v;
            if (have_r && dist <= r + tol)
                ids[n++] = v;
        }
        if (!have_r) /* no radius: the nearest vertex */
            ids[n++] = best;
        if (n == 0)
            return bad(c, PLUME_EINVAL, kp,
                       "with radius %g selects no vertex (the nearest one, %ld, is %g m away)", r, (long)best, dbest);
    } else if (jb) {
        double b[4];
        subkey(kp, where, "box");
        if ((st = get_vector(c, jb, kp, 4, b)) != PLUME_OK)
            return st;
        if (!(b[2] >= b[0] && b[3] >= b[1]))
            return bad(c, PLUME_EINVAL, kp, "must be [x_min, y_min, x_max, y_max] with min <= max");
        for (plume_index v = 0; v < m->nv; v++) {
            double x = m->X[2 * v], y = m->X[2 * v + 1];
            if (x >= b[0] - tol && x <= b[2] + tol && y >= b[1] - tol && y <= b[3] + tol)
                ids[n++] = v;
        }
        if (n == 0)
            return bad(c, PLUME_EINVAL, kp, "selects no vertex");
    } else {
        subkey(kp, where, "vertices");
        if (!json_is_array(jv) || json_array_size(jv) < 1)
            return bad(c, PLUME_EFORMAT, kp, "must be a non-empty array of vertex ids");
        plume_index limit = map ? nobj : m->nv;
        for (size_t i = 0; i < json_array_size(jv); i++) {
            json_t *e = json_array_get(jv, i);
            double d = json_is_number(e) ? json_number_value(e) : -1.0;
            if (!json_is_number(e) || d != floor(d) || d < 0 || d >= (double)limit)
                return bad(c, PLUME_EINVAL, kp, "entry %zu must be a vertex id in [0, %ld)", i, (long)limit);
            plume_index id = map ? map[(plume_index)d] : (plume_index)d;
            if (id < 0)
                return bad(c, PLUME_EINVAL, kp, "entry %zu: OBJ vertex %ld belongs to no face", i, (long)d);
            int dup = 0;
            for (plume_index k = 0; k < n && !dup; k++)
                dup = ids[k] == id;
            if (!dup)
                ids[n++] = id;
        }
    }
    h->nvertices = n;
    /* keyframes [[t, dx, dy, dz], ...], times increasing */
    subkey(kp, where, "keyframes");
    json_t *jk = json_object_get(jh, "keyframes");
    if (!json_is_array(jk) || json_array_size(jk) < 1)
        return bad(c, PLUME_EFORMAT, kp, "must be a non-empty array of [t, dx, dy, dz]");
    size_t nk = json_array_size(jk);
    double *times = malloc(nk * sizeof *times), *off = malloc(3 * nk * sizeof *off);
    h->times = times;
    h->offsets = off;
    if (!times || !off)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    h->nkeys = (int)nk;
    for (size_t k = 0; k < nk; k++) {
        char kk[KEY_MAX];
        double row[4];
        subindex(kk, kp, k);
        if ((st = get_vector(c, json_array_get(jk, k), kk, 4, row)) != PLUME_OK)
            return st;
        if (k > 0 && !(row[0] > times[k - 1]))
            return bad(c, PLUME_EINVAL, kk, "time %g is not after the previous keyframe's %g (times must increase)",
                       row[0], times[k - 1]);
        times[k] = row[0];
        off[3 * k] = row[1], off[3 * k + 1] = row[2], off[3 * k + 2] = row[3];
    }
    return PLUME_OK;
}

/* The constrained barb edges: edges along the barb direction of an adjacent triangle whose
 * material is constrained. For the feather the mesher's list is the candidate set; for an OBJ
 * mesh every edge is a candidate (same test as plume_vane_barb_edges, tolerance 1e-6). */
static plume_status constrained_edges(plume_scene *s, plume_err *err)
{
    const plume_mesh *m = s->mesh;
    unsigned char *keep = calloc((size_t)m->ne + 1, 1);
    /* edges sorted by (i, j) for lookups of the mesher's list */
    plume_index *order = malloc((size_t)(m->ne + 1) * sizeof *order);
    if (!keep || !order) {
        free(keep);
        free(order);
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    const double tol = 1e-6;
    for (plume_index e = 0; e < m->ne; e++) {
        plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
        double ex = m->X[2 * b] - m->X[2 * a], ey = m->X[2 * b + 1] - m->X[2 * a + 1], len = hypot(ex, ey);
        for (int k = 0; k < 2; k++) {
            plume_index t = m->edge_tri[2 * e + k];
            if (t < 0 || !s->mats[m->material[t]].constraint)
                continue;
            const double *d = m->barb_dir + 2 * t;
            /* the mesher's edges are barb edges by construction; others must be aligned */
            if (s->barb_edges || fabs(ex * d[1] - ey * d[0]) <= tol * len * hypot(d[0], d[1]))
                keep[e] |= 1;
        }
    }
    if (s->barb_edges) { /* only the mesher's barb edges are candidates */
        unsigned char *listed = calloc((size_t)m->ne + 1, 1);
        if (!listed) {
            free(keep);
            free(order);
            return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        }
        /* mesh->edges hold i < j; find each listed pair by a scan of the vertex's edges */
        plume_index *start = calloc((size_t)m->nv + 2, sizeof *start);
        if (!start) {
            free(listed);
            free(keep);
            free(order);
            return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        }
        for (plume_index e = 0; e < m->ne; e++)
            start[m->edges[2 * e] + 1]++;
        for (plume_index v = 0; v < m->nv; v++)
            start[v + 1] += start[v];
        plume_index *fill = calloc((size_t)m->nv + 1, sizeof *fill);
        if (!fill) {
            free(start);
            free(listed);
            free(keep);
            free(order);
            return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        }
        for (plume_index e = 0; e < m->ne; e++) {
            plume_index a = m->edges[2 * e];
            order[start[a] + fill[a]++] = e;
        }
        for (plume_index k = 0; k < s->nbarb; k++) {
            plume_index a = s->barb_edges[2 * k], b = s->barb_edges[2 * k + 1];
            if (a > b) {
                plume_index t = a;
                a = b, b = t;
            }
            if (a < 0 || b >= m->nv)
                continue;
            for (plume_index q = start[a]; q < start[a + 1]; q++)
                if (m->edges[2 * order[q] + 1] == b)
                    listed[order[q]] = 1;
        }
        for (plume_index e = 0; e < m->ne; e++)
            keep[e] &= listed[e];
        free(fill);
        free(start);
        free(listed);
    }
    free(order);
    plume_index n = 0;
    for (plume_index e = 0; e < m->ne; e++)
        n += keep[e] ? 1 : 0;
    plume_index *out = malloc((size_t)(2 * n + 1) * sizeof *out);
    if (!out) {
        free(keep);
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    n = 0;
    for (plume_index e = 0; e < m->ne; e++)
        if (keep[e]) {
            out[2 * n] = m->edges[2 * e];
            out[2 * n + 1] = m->edges[2 * e + 1];
            n++;
        }
    free(keep);
    free(s->barb_edges);
    s->barb_edges = out;
    s->nbarb = n;
    return PLUME_OK;
}

static plume_status parse_scene(ctx *c, json_t *doc, plume_scene *s)
{
    static const char *const keys[] = {"mesh", "materials", "handles", "gravity", "dt", "duration", "solver",
                                       "max_halvings", "max_iter", "output_every", "render", "camera", NULL};
    plume_status st;
    plume_index *map = NULL, nobj = 0;
    if (!json_is_object(doc))
        return plume_err_set(c->err, PLUME_EFORMAT, "%s: expected a JSON object at the top level", c->file);
    if ((st = check_keys(c, doc, "", keys)) != PLUME_OK)
        return st;

    /* run settings first: cheap, and their errors need no mesh */
    s->gravity[0] = s->gravity[1] = 0.0;
    s->gravity[2] = -9.81;
    s->solver = PLUME_SOLVER_NEWTON;
    s->max_halvings = 6;
    s->max_iter = 100;
    s->output_every = 1;
    s->camera[0] = 60.0;
    s->camera[1] = 30.0;
    json_t *v;
    if ((v = json_object_get(doc, "gravity")) && (st = get_vector(c, v, "gravity", 3, s->gravity)) != PLUME_OK)
        return st;
    if ((st = get_positive(c, doc, "", "dt", 1, 0, &s->dt, NULL)) != PLUME_OK ||
        (st = get_positive(c, doc, "", "duration", 1, 0, &s->duration, NULL)) != PLUME_OK)
        return st;
    if ((v = json_object_get(doc, "solver"))) {
        if (!json_is_string(v) || plume_solver_kind_parse(json_string_value(v), &s->solver) != PLUME_OK)
            return bad(c, PLUME_EINVAL, "solver", "must be \"newton\", \"ipopt\" or \"linearized\" (got %s%s%s)",
                       json_is_string(v) ? "\"" : "", json_is_string(v) ? json_string_value(v) : "a non-string",
                       json_is_string(v) ? "\"" : "");
    }
    long lv = s->max_halvings;
    if ((st = get_int(c, doc, "", "max_halvings", 0, 30, &lv)) != PLUME_OK)
        return st;
    s->max_halvings = (int)lv;
    lv = s->max_iter;
    if ((st = get_int(c, doc, "", "max_iter", 1, 100000, &lv)) != PLUME_OK)
        return st;
    s->max_iter = (int)lv;
    lv = s->output_every;
    if ((st = get_int(c, doc, "", "output_every", 1, 1000000, &lv)) != PLUME_OK)
        return st;
    s->output_every = (int)lv;
    if ((v = json_object_get(doc, "render"))) {
        if (!json_is_array(v))
            return bad(c, PLUME_EFORMAT, "render", "must be an array of frame indices");
        s->render = malloc((json_array_size(v) + 1) * sizeof *s->render);
        if (!s->render)
            return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        for (size_t i = 0; i < json_array_size(v); i++) {
            json_t *e = json_array_get(v, i);
            double d = json_is_number(e) ? json_number_value(e) : -1.0;
            if (!json_is_number(e) || d != floor(d) || d < 0 || d > 1e9) {
                char kp[KEY_MAX];
                subindex(kp, "render", i);
                return bad(c, PLUME_EINVAL, kp, "must be a frame index (an integer >= 0)");
            }
            s->render[s->nrender++] = (long)d;
        }
    }
    if ((v = json_object_get(doc, "camera"))) {
        static const char *const ck[] = {"rot_x", "rot_z", NULL};
        if (!json_is_object(v))
            return bad(c, PLUME_EFORMAT, "camera", "must be an object {\"rot_x\": deg, \"rot_z\": deg}");
        if ((st = check_keys(c, v, "camera", ck)) != PLUME_OK ||
            (st = get_number(c, v, "camera", "rot_x", 0, &s->camera[0], NULL)) != PLUME_OK ||
            (st = get_number(c, v, "camera", "rot_z", 0, &s->camera[1], NULL)) != PLUME_OK)
            return st;
        if (!(s->camera[0] >= 0.0 && s->camera[0] <= 180.0))
            return bad(c, PLUME_EINVAL, "camera.rot_x", "must be in [0, 180] degrees (got %g)", s->camera[0]);
        if (!(s->camera[1] >= 0.0 && s->camera[1] <= 360.0))
            return bad(c, PLUME_EINVAL, "camera.rot_z", "must be in [0, 360] degrees (got %g)", s->camera[1]);
    }

    /* materials */
    json_t *jm = json_object_get(doc, "materials");
    if (!json_is_array(jm) || json_array_size(jm) < 1)
        return bad(c, PLUME_EFORMAT, "materials", jm ? "must be a non-empty array of materials (indexed by material id)"
                                                     : "is missing (an array of materials indexed by material id)");
    s->nmat = (int)json_array_size(jm);
    s->mats = calloc((size_t)s->nmat, sizeof *s->mats);
    if (!s->mats)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (int k = 0; k < s->nmat; k++) {
        char kp[KEY_MAX];
        subindex(kp, "materials", (size_t)k);
        if ((st = parse_material(c, json_array_get(jm, (size_t)k), kp, s->mats + k)) != PLUME_OK)
            return st;
    }

    /* mesh */
    json_t *mesh = json_object_get(doc, "mesh");
    if (!json_is_object(mesh))
        return bad(c, PLUME_EFORMAT, "mesh", mesh ? "must be an object {\"obj\": ...} or {\"feather\": ...}"
                                                  : "is missing ({\"obj\": \"file.obj\"} or {\"feather\": \"shape.json\", ...})");
    int feather = json_object_get(mesh, "feather") != NULL;
    if (!feather && !json_object_get(mesh, "obj"))
        return bad(c, PLUME_EFORMAT, "mesh", "needs \"obj\" (a triangle mesh) or \"feather\" (a feather shape file)");
    st = feather ? mesh_from_feather(c, mesh, s) : mesh_from_obj(c, mesh, s, &map, &nobj);
    if (st != PLUME_OK)
        goto done;
    const plume_mesh *m = s->mesh;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (plume_index i = 0; i < m->nv; i++)
        for (int a = 0; a < 2; a++)
            lo[a] = fmin(lo[a], m->X[2 * i + a]), hi[a] = fmax(hi[a], m->X[2 * i + a]);
    s->length = hypot(hi[0] - lo[0], hi[1] - lo[1]);
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] < 0 || m->material[t] >= s->nmat) {
            st = bad(c, PLUME_EINVAL, feather ? "materials" : "mesh.materials_by_group",
                     "%s: triangle %ld has material %d, but materials has %d entr%s (ids 0 to %d)",
                     feather ? "the feather mesh uses material 0 (vane) and 1 (rachis)" : "material id without a material",
                     (long)t, m->material[t], s->nmat, s->nmat == 1 ? "y" : "ies", s->nmat - 1);
            goto done;
        }

    /* handles */
    json_t *jh = json_object_get(doc, "handles");
    if (jh) {
        if (!json_is_array(jh)) {
            st = bad(c, PLUME_EFORMAT, "handles", "must be an array of handles");
            goto done;
        }
        size_t nh = json_array_size(jh);
        s->handles = calloc(nh + 1, sizeof *s->handles);
        if (!s->handles) {
            st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
            goto done;
        }
        for (size_t k = 0; k < nh; k++) {
            char kp[KEY_MAX];
            subindex(kp, "handles", k);
            s->nhandles++;
            if ((st = parse_handle(c, json_array_get(jh, k), kp, s, map, nobj, s->handles + k)) != PLUME_OK)
                goto done;
        }
        /* a vertex in two handles would follow two paths */
        int *owner = malloc((size_t)m->nv * sizeof *owner);
        if (!owner) {
            st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
            goto done;
        }
        for (plume_index i = 0; i < m->nv; i++)
            owner[i] = -1;
        for (int h = 0; h < s->nhandles && st == PLUME_OK; h++)
            for (plume_index i = 0; i < s->handles[h].nvertices; i++) {
                plume_index vtx = s->handles[h].vertices[i];
                if (owner[vtx] >= 0 && owner[vtx] != h) {
                    char kp[KEY_MAX];
                    subindex(kp, "handles", (size_t)h);
                    st = bad(c, PLUME_EINVAL, kp, "shares vertex %ld with handles[%d]: a vertex can follow one handle only",
                             (long)vtx, owner[vtx]);
                    break;
                }
                owner[vtx] = h;
            }
        free(owner);
        if (st != PLUME_OK)
            goto done;
    }
    st = constrained_edges(s, c->err);
done:
    free(map);
    return st;
}

plume_status plume_scene_load(const char *path, plume_scene **out, plume_err *err)
{
    if (!path || !*path || !out)
        return plume_err_set(err, PLUME_EINVAL, "scene: no file given");
    *out = NULL;
    ctx c;
    memset(&c, 0, sizeof c);
    c.file = path;
    c.err = err;
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(c.dir, sizeof c.dir, "%.*s", (int)(slash == path ? 1 : slash - path), path);
    plume_status st;
    c.text = slurp(path, err, "scene", &st);
    if (!c.text)
        return st;
    json_error_t je;
    json_t *doc = json_loads(c.text, JSON_REJECT_DUPLICATES, &je);
    if (!doc) {
        free(c.text);
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", path, je.line, je.column, je.text);
    }
    plume_scene *s = calloc(1, sizeof *s);
    st = PLUME_ENOMEM;
    if (s && (s->path = malloc(strlen(path) + 1)) != NULL) {
        memcpy(s->path, path, strlen(path) + 1);
        st = parse_scene(&c, doc, s);
    } else {
        plume_err_set(err, st, "%s: out of memory", path);
    }
    json_decref(doc);
    free(c.text);
    if (st != PLUME_OK) {
        plume_scene_destroy(&s);
        return st;
    }
    *out = s;
    return PLUME_OK;
}

plume_status plume_scene_dynamics(const plume_scene *s, plume_problem **pp, plume_dynamics **pd, plume_err *err)
{
    if (!s || !s->mesh || !pp || !pd)
        return plume_err_set(err, PLUME_EINVAL, "scene: invalid arguments");
    *pp = NULL;
    *pd = NULL;
    const plume_mesh *m = s->mesh;
    plume_problem *p = NULL;
    plume_membrane_material *mm = malloc((size_t)s->nmat * sizeof *mm);
    plume_bending_material *bm = malloc((size_t)s->nmat * sizeof *bm);
    double *rho = malloc((size_t)s->nmat * sizeof *rho);
    plume_status st = PLUME_ENOMEM;
    if (!mm || !bm || !rho || (st = plume_problem_create(m->nv, 3, s->length, &p)) != PLUME_OK) {
        plume_err_set(err, st, "scene: out of memory");
        goto fail;
    }
    int bending = 0;
    for (int k = 0; k < s->nmat; k++) {
        mm[k] = s->mats[k].membrane;
        bm[k] = s->mats[k].bending;
        rho[k] = s->mats[k].density;
        bending |= bm[k].D_long > 0.0 || bm[k].D_trans > 0.0;
    }
    plume_term term;
    if ((st = plume_membrane_term_create(m, 3, mm, s->nmat, &term, err)) != PLUME_OK ||
        (st = plume_problem_add_term(p, &term)) != PLUME_OK)
        goto fail;
    if (bending && ((st = plume_bending_term_create(m, bm, s->nmat, NULL, &term, err)) != PLUME_OK ||
                    (st = plume_problem_add_term(p, &term)) != PLUME_OK))
        goto fail;
    if (s->nbarb > 0) {
        plume_constraint con;
        if ((st = plume_edge_length_create(s->barb_edges, s->nbarb, m->X, m->nv, &con, err)) != PLUME_OK ||
            (st = plume_problem_add_constraint(p, &con)) != PLUME_OK)
            goto fail;
    }
    memcpy(plume_problem_x(p), m->x, (size_t)(3 * m->nv) * sizeof(double));
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = s->dt;
    memcpy(o.gravity, s->gravity, sizeof o.gravity);
    o.max_halvings = s->max_halvings;
    o.solver = s->solver;
    o.solver_opts.max_iter = s->max_iter;
    o.solver_opts.verbose = s->verbose;
    if ((st = plume_dynamics_create(m, p, rho, s->nmat, s->handles, s->nhandles, &o, pd, err)) != PLUME_OK)
        goto fail;
    *pp = p;
    free(mm);
    free(bm);
    free(rho);
    return PLUME_OK;
fail:
    plume_problem_destroy(&p);
    free(mm);
    free(bm);
    free(rho);
    return st;
}
