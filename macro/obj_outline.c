/* plume: the outline of an OBJ triangle mesh (macro/obj_outline.h). */
#include "obj_outline.h"
#include "../lib/io/input_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal/feather_geom.h"

typedef struct {
    plume_index a, b; /* a < b */
    plume_index face;
} obj_edge;

static int cmp_obj_edge(const void *p, const void *q)
{
    const obj_edge *x = p, *y = q;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    if (x->b != y->b)
        return x->b < y->b ? -1 : 1;
    return (x->face > y->face) - (x->face < y->face);
}

typedef struct {
    double *v;        /* [2 nv] */
    long *vline;      /* [nv] line of each vertex */
    plume_index nv, vcap;
    plume_index *fv;  /* face vertex indices (0-based), concatenated */
    plume_index nfv, fvcap;
    plume_index *fstart; /* [nf + 1] */
    long *fline;      /* [nf] */
    plume_index nf, fcap;
} obj_data;

static void obj_free(obj_data *o)
{
    free(o->v), free(o->vline), free(o->fv), free(o->fstart), free(o->fline);
    memset(o, 0, sizeof *o);
}

static int grow(void **p, plume_index *cap, plume_index need, size_t size)
{
    if (need <= *cap)
        return 0;
    plume_index c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    void *r = realloc(*p, (size_t)c * size);
    if (!r)
        return -1;
    *p = r, *cap = c;
    return 0;
}

static plume_status obj_parse(const char *path, FILE *fp, obj_data *o, plume_err *err)
{
    char *line = NULL;
    size_t lcap = 0;
    long ln = 0;
    plume_status st = PLUME_OK;
    plume_index vcap2 = 0, fcap2 = 0;
    while (getline(&line, &lcap, fp) >= 0) {
        ln++;
        char *s = line;
        while (*s == ' ' || *s == '\t')
            s++;
        if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
            char *end;
            double x = strtod(s + 1, &end);
            char *e2;
            double y = end != s + 1 ? strtod(end, &e2) : 0;
            if (end == s + 1 || e2 == end || !isfinite(x) || !isfinite(y)) {
                st = plume_err_set(err, PLUME_EFORMAT, "%s:%ld: bad 'v' line: expected 'v x y [z]' with finite numbers",
                                   path, ln);
                goto done;
            }
            if (grow((void **)&o->v, &o->vcap, 2 * (o->nv + 1), sizeof *o->v) < 0 ||
                grow((void **)&o->vline, &vcap2, o->nv + 1, sizeof *o->vline) < 0) {
                st = PLUME_ENOMEM;
                goto done;
            }
            o->v[2 * o->nv] = x, o->v[2 * o->nv + 1] = y, o->vline[o->nv] = ln;
            o->nv++;
        } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
            char *p = s + 1;
            plume_index count = 0;
            for (;;) {
                while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
                    p++;
                if (!*p || *p == '#')
                    break;
                char *end;
                errno = 0;
                long idx = strtol(p, &end, 10);
                if (end == p || errno || idx == 0 || (*end && *end != '/' && *end != ' ' && *end != '\t' &&
                                                      *end != '\r' && *end != '\n')) {
                    st = plume_err_set(err, PLUME_EFORMAT,
                                       "%s:%ld: bad 'f' line: expected 'f i j k' with non-zero vertex indices", path,
                                       ln);
                    goto done;
                }
                while (*end && *end != ' ' && *end != '\t' && *end != '\r' && *end != '\n')
                    end++; /* skip /vt/vn */
                plume_index vi = idx > 0 ? idx - 1 : o->nv + idx; /* negative: relative to the end */
                if (vi < 0) {
                    st = plume_err_set(err, PLUME_EFORMAT, "%s:%ld: face index %ld out of range (%ld vertices so far)",
                                       path, ln, idx, (long)o->nv);
                    goto done;
                }
                if (grow((void **)&o->fv, &o->fvcap, o->nfv + 1, sizeof *o->fv) < 0) {
                    st = PLUME_ENOMEM;
                    goto done;
                }
                o->fv[o->nfv++] = vi;
                count++;
                p = end;
            }
            if (count < 3) {
                st = plume_err_set(err, PLUME_EFORMAT,
                                   "%s:%ld: bad 'f' line: a face needs at least 3 vertices (got %ld)", path, ln,
                                   (long)count);
                goto done;
            }
            if (grow((void **)&o->fstart, &o->fcap, o->nf + 2, sizeof *o->fstart) < 0 ||
                grow((void **)&o->fline, &fcap2, o->nf + 1, sizeof *o->fline) < 0) {
                st = PLUME_ENOMEM;
                goto done;
            }
            o->fstart[o->nf] = o->nfv - count;
            o->fstart[o->nf + 1] = o->nfv;
            o->fline[o->nf] = ln;
            o->nf++;
        }
        /* everything else (comments, vt, vn, g, o, s, usemtl, mtllib) is irrelevant to the outline */
    }
    if (ferror(fp))
        st = plume_err_set(err, PLUME_EIO, "%s: read error", path);
done:
    free(line);
    return st;
}

/* Every face's edges (a < b, its face), sorted, into a new array *ed_out of *ne_out (the caller
 * frees it); faces with an index out of range or a repeated vertex are refused. */
static plume_status face_edges(const char *path, const obj_data *o, obj_edge **ed_out, plume_index *ne_out,
                               plume_err *err)
{
    obj_edge *ed = malloc((size_t)o->nfv * sizeof *ed);
    if (!ed)
        return PLUME_ENOMEM;
    *ed_out = ed;
    plume_index ne = 0;
    for (plume_index f = 0; f < o->nf; f++) {
        plume_index a0 = o->fstart[f], a1 = o->fstart[f + 1];
        for (plume_index k = a0; k < a1; k++) {
            plume_index i = o->fv[k], j = o->fv[k + 1 < a1 ? k + 1 : a0];
            if (i >= o->nv || j >= o->nv)
                return plume_err_set(err, PLUME_EFORMAT, "%s:%ld: face index %ld out of range [1, %ld]", path,
                                     o->fline[f], (long)(i >= o->nv ? i : j) + 1, (long)o->nv);
            if (i == j)
                return plume_err_set(err, PLUME_EFORMAT, "%s:%ld: face repeats vertex %ld", path, o->fline[f],
                                     (long)i + 1);
            ed[ne].a = i < j ? i : j, ed[ne].b = i < j ? j : i, ed[ne].face = f;
            ne++;
        }
    }
    qsort(ed, (size_t)ne, sizeof *ed, cmp_obj_edge);
    *ne_out = ne;
    return PLUME_OK;
}

/* The boundary edges (used by exactly one face; more than two faces is non-manifold) as a graph:
 * vertex v's boundary neighbours nb[2 v], nb[2 v + 1] (-1 on entry), deg[v] of them (0 on entry);
 * *nbe the boundary edges. */
static plume_status boundary_graph(const char *path, const obj_data *o, const obj_edge *ed, plume_index ne,
                                   plume_index *nb, plume_index *deg, plume_index *nbe_out, plume_err *err)
{
    plume_index nbe = 0;
    for (plume_index k = 0; k < ne;) {
        plume_index r = k + 1;
        while (r < ne && ed[r].a == ed[k].a && ed[r].b == ed[k].b)
            r++;
        if (r - k > 2)
            return plume_err_set(err, PLUME_EFORMAT,
                                 "%s:%ld: edge (%ld, %ld) is used by %ld faces: the mesh is non-manifold", path,
                                 o->fline[ed[k + 2].face], (long)ed[k].a + 1, (long)ed[k].b + 1, (long)(r - k));
        if (r - k == 1) {
            plume_index ends[2] = {ed[k].a, ed[k].b};
            for (int s = 0; s < 2; s++) {
                plume_index v = ends[s], w = ends[1 - s];
                if (deg[v] >= 2)
                    return plume_err_set(err, PLUME_EFORMAT,
                                         "%s:%ld: vertex %ld is on more than two boundary edges: the mesh is "
                                         "non-manifold there",
                                         path, o->vline[v], (long)v + 1);
                nb[2 * v + deg[v]++] = w;
            }
            nbe++;
        }
        k = r;
    }
    if (nbe == 0)
        return plume_err_set(err, PLUME_EFORMAT, "%s: no boundary edge: the faces form a closed surface", path);
    *nbe_out = nbe;
    return PLUME_OK;
}

/* The boundary loop from its first vertex into loop[0 .. *nl) (room for nbe + 1; seen zeroed by the
 * caller); a chain that ends, or boundary edges left over (a hole or a separate piece), are refused. */
static plume_status walk_boundary(const char *path, const obj_data *o, const plume_index *nb, const plume_index *deg,
                                  plume_index nbe, unsigned char *seen, plume_index *loop, plume_index *nl_out,
                                  plume_err *err)
{
    plume_index nl = 0, start = -1;
    for (plume_index v = 0; v < o->nv && start < 0; v++)
        if (deg[v] > 0)
            start = v;
    for (plume_index prev = -1, v = start;;) {
        if (deg[v] != 2)
            return plume_err_set(err, PLUME_EFORMAT,
                                 "%s:%ld: vertex %ld ends a boundary chain: the mesh is non-manifold", path,
                                 o->vline[v], (long)v + 1);
        seen[v] = 1;
        loop[nl++] = v;
        plume_index next = nb[2 * v] != prev ? nb[2 * v] : nb[2 * v + 1];
        if (nb[2 * v] == nb[2 * v + 1])
            next = nb[2 * v];
        prev = v, v = next;
        if (v == start || nl > nbe)
            break;
    }
    if (nl != nbe) {
        plume_index other = -1, loops = 1;
        for (plume_index v = 0; v < o->nv; v++)
            if (deg[v] > 0 && !seen[v]) {
                if (other < 0)
                    other = v;
                /* count the remaining loops */
                plume_index prev = -1, w = v;
                do {
                    seen[w] = 1;
                    plume_index next = nb[2 * w] != prev ? nb[2 * w] : nb[2 * w + 1];
                    prev = w, w = next;
                } while (w >= 0 && w != v && !seen[w]);
                loops++;
            }
        return plume_err_set(err, PLUME_EFORMAT,
                             "%s:%ld: vertex %ld starts boundary loop 2 of %ld: the outline must be a single loop "
                             "(a hole or a separate piece)",
                             path, other >= 0 ? o->vline[other] : 0L, (long)other + 1, (long)loops);
    }
    *nl_out = nl;
    return PLUME_OK;
}

/* The loop's points, counter-clockwise, in a new array (NULL on no memory). */
static double *loop_points(const obj_data *o, const plume_index *loop, plume_index nl)
{
    double *pts = malloc((size_t)(2 * nl) * sizeof *pts);
    if (!pts)
        return NULL;
    for (plume_index k = 0; k < nl; k++)
        pts[2 * k] = o->v[2 * loop[k]], pts[2 * k + 1] = o->v[2 * loop[k] + 1];
    if (polygon_area(pts, nl) < 0)
        for (plume_index k = 0; k < nl / 2; k++)
            for (int c = 0; c < 2; c++) {
                double tmp = pts[2 * k + c];
                pts[2 * k + c] = pts[2 * (nl - 1 - k) + c];
                pts[2 * (nl - 1 - k) + c] = tmp;
            }
    return pts;
}

plume_status plume_obj_outline(const char *path, double **points, plume_index *n, plume_err *err)
{
    if (!path || !points || !n)
        return plume_err_set(err, PLUME_EINVAL, "obj outline: NULL argument");
    *points = NULL, *n = 0;
    FILE *fp = plume_input_fopen(path, "r", NULL, err);
    if (!fp)
        return PLUME_EIO;
    obj_data o;
    memset(&o, 0, sizeof o);
    obj_edge *ed = NULL;
    plume_index *nb = NULL, *deg = NULL, *loop = NULL;
    unsigned char *seen = NULL;
    plume_status st = obj_parse(path, fp, &o, err);
    fclose(fp);
    if (st != PLUME_OK)
        goto cleanup;
    if (o.nf == 0) {
        st = plume_err_set(err, PLUME_EFORMAT, "%s: no face", path);
        goto cleanup;
    }
    plume_index ne = 0;
    if ((st = face_edges(path, &o, &ed, &ne, err)) != PLUME_OK)
        goto cleanup;
    nb = malloc((size_t)(2 * o.nv) * sizeof *nb);
    deg = calloc((size_t)o.nv, sizeof *deg);
    if (!nb || !deg) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    for (plume_index v = 0; v < 2 * o.nv; v++)
        nb[v] = -1;
    plume_index nbe = 0;
    if ((st = boundary_graph(path, &o, ed, ne, nb, deg, &nbe, err)) != PLUME_OK)
        goto cleanup;
    seen = calloc((size_t)o.nv, 1);
    loop = malloc((size_t)(nbe + 1) * sizeof *loop);
    if (!seen || !loop) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    plume_index nl = 0;
    if ((st = walk_boundary(path, &o, nb, deg, nbe, seen, loop, &nl, err)) != PLUME_OK)
        goto cleanup;
    double *pts = loop_points(&o, loop, nl);
    if (!pts) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    *points = pts, *n = nl;
cleanup:
    obj_free(&o);
    free(ed), free(nb), free(deg), free(loop), free(seen);
    return st;
}
