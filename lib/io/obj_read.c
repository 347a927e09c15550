/* Triangle meshes from OBJ files with their groups (lib/io/obj_read.h). */
#include "obj_read.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json_read.h"

void plume_obj_free(plume_obj_data *o)
{
    free(o->v);
    free(o->z);
    free(o->f);
    free(o->group);
    for (int g = 0; g < o->ngroups; g++)
        free(o->groups[g]);
    free(o->groups);
    memset(o, 0, sizeof *o);
}

static int obj_group(plume_obj_data *o, const char *name)
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

/* A line without its leading blanks and its trailing blanks and CR (cut in place). */
static char *trim_line(char *ln)
{
    char *p = ln;
    while (*p == ' ' || *p == '\t')
        p++;
    size_t L = strlen(p);
    while (L > 0 && (p[L - 1] == '\r' || p[L - 1] == ' ' || p[L - 1] == '\t'))
        p[--L] = '\0';
    return p;
}

/* A "v x y [z]" line (z is 0 when absent), appended to o->v and o->z. */
static plume_status obj_vertex(plume_obj_data *o, const char *p, const char *path, int line, plume_err *err)
{
    char *end;
    double x = strtod(p + 2, &end), y = strtod(end, &end);
    char *zend;
    double z = strtod(end, &zend); /* optional: 0 when absent */
    if (zend == end)
        z = 0.0;
    if (end == p + 2 || !isfinite(x) || !isfinite(y) || !isfinite(z))
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d: a vertex needs finite x and y", path, line);
    if (o->nv == o->vcap) {
        o->vcap = o->vcap ? 2 * o->vcap : 256;
        double *nv = realloc(o->v, (size_t)(2 * o->vcap) * sizeof *nv);
        if (!nv)
            return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", path);
        o->v = nv;
        double *nz = realloc(o->z, (size_t)o->vcap * sizeof *nz);
        if (!nz)
            return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", path);
        o->z = nz;
    }
    o->v[2 * o->nv] = x;
    o->v[2 * o->nv + 1] = y;
    o->z[o->nv] = z;
    o->nv++;
    return PLUME_OK;
}

/* The vertices of an "f" line's list q (numbers from 1, negative ones counted back from the last
 * vertex read, /vt/vn ignored) as 0-based ids, at least 3 and at most 64. */
static plume_status face_vertices(const plume_obj_data *o, char *q, plume_index ids[64], int *nids, const char *path,
                                  int line, plume_err *err)
{
    int n = 0;
    for (;;) {
        while (*q == ' ' || *q == '\t')
            q++;
        if (!*q)
            break;
        char *end;
        long id = strtol(q, &end, 10);
        if (end == q || n == 64)
            return plume_err_set(err, PLUME_EFORMAT, "%s:%d: bad face (vertex numbers expected, at most 64)", path,
                                 line);
        while (*end && *end != ' ' && *end != '\t') /* skip /vt/vn */
            end++;
        q = end;
        long k = id > 0 ? id - 1 : (long)o->nv + id;
        if (id == 0 || k < 0 || k >= (long)o->nv)
            return plume_err_set(err, PLUME_EFORMAT, "%s:%d: face refers to vertex %ld, which is not defined above",
                                 path, line, id);
        ids[n++] = k;
    }
    if (n < 3)
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d: a face needs at least 3 vertices", path, line);
    *nids = n;
    return PLUME_OK;
}

/* A face of n vertices as a fan of n - 2 triangles around its first vertex, in group current. */
static plume_status add_fan(plume_obj_data *o, const plume_index *ids, int n, int current, const char *path,
                            plume_err *err)
{
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
                return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", path);
        }
        o->f[3 * o->nf] = ids[0];
        o->f[3 * o->nf + 1] = ids[t + 1];
        o->f[3 * o->nf + 2] = ids[t + 2];
        o->group[o->nf] = current;
        o->nf++;
    }
    return PLUME_OK;
}

/* A "g name" or "o name" line: the faces that follow belong to that group (to none when the name
 * is missing); *current is its index. */
static plume_status group_line(plume_obj_data *o, char *p, int *current, const char *path, plume_err *err)
{
    char *q = p + 1;
    while (*q == ' ' || *q == '\t')
        q++;
    char *e = q;
    while (*e && *e != ' ' && *e != '\t')
        e++;
    *e = '\0';
    if (!*q)
        *current = -1;
    else if ((*current = obj_group(o, q)) < -1)
        return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", path);
    return PLUME_OK;
}

/* Reads v / f / g (and o) lines of an OBJ file; faces of more than three vertices are split
 * into a fan. Other statements (vt, vn, s, usemtl, mtllib) are ignored. */
plume_status plume_obj_read(const char *path, plume_obj_data *o, plume_err *err)
{
    memset(o, 0, sizeof *o);
    plume_status st;
    char *text = plume_read_text(path, err, "mesh file", &st);
    if (!text)
        return st;
    int line = 0, current = -1;
    char *save = NULL;
    for (char *ln = text; ln; ln = save) {
        line++;
        save = strchr(ln, '\n');
        if (save)
            *save++ = '\0';
        char *p = trim_line(ln);
        if (p[0] == 'v' && (p[1] == ' ' || p[1] == '\t')) {
            st = obj_vertex(o, p, path, line, err);
        } else if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
            plume_index ids[64];
            int n = 0;
            if ((st = face_vertices(o, p + 2, ids, &n, path, line, err)) == PLUME_OK)
                st = add_fan(o, ids, n, current, path, err);
        } else if ((p[0] == 'g' || p[0] == 'o') && (p[1] == ' ' || p[1] == '\t' || p[1] == '\0')) {
            st = group_line(o, p, &current, path, err);
        }
        if (st != PLUME_OK)
            goto done;
    }
    if (o->nf == 0)
        st = plume_err_set(err, PLUME_EFORMAT, "%s: no faces (f lines) in this OBJ file", path);
done:
    free(text);
    if (st != PLUME_OK)
        plume_obj_free(o);
    return st;
}
