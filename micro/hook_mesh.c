/* plume (micro): a barbule specimen's mesh opened at the barbules' distal ends (micro/hook_mesh.h). */
#include "hook_mesh.h"

#include <stdlib.h>
#include <string.h>

#include "../include/plume/homogenize.h"

void plume_hook_mesh_free(plume_hook_mesh *h)
{
    if (!h)
        return;
    plume_mesh_destroy(&h->mesh);
    free(h->first);
    free(h->pairs);
    free(h->joins);
    free(h->join_hook);
    memset(h, 0, sizeof *h);
}

static double centroid_along(const plume_mesh *m, plume_index t, const double q[2])
{
    double s = 0.0;
    for (int k = 0; k < 3; k++) {
        const plume_index v = m->tri[3 * t + k];
        s += m->X[2 * v] * q[0] + m->X[2 * v + 1] * q[1];
    }
    return s / 3.0;
}

/* 1 when edge e joins a barbule triangle to the barb ahead of it along q */
static int distal_join(const plume_mesh *m, plume_index e, const double q[2])
{
    const plume_index t0 = m->edge_tri[2 * e], t1 = m->edge_tri[2 * e + 1];
    if (t1 < 0)
        return 0;
    const int m0 = m->material[t0], m1 = m->material[t1];
    if (!((m0 == PLUME_MAT_BARB && m1 == PLUME_MAT_BARBULE) || (m0 == PLUME_MAT_BARBULE && m1 == PLUME_MAT_BARB)))
        return 0;
    const plume_index barb = m0 == PLUME_MAT_BARB ? t0 : t1, barbule = m0 == PLUME_MAT_BARB ? t1 : t0;
    return centroid_along(m, barb, q) > centroid_along(m, barbule, q);
}

static plume_index find_root(plume_index *parent, plume_index v)
{
    while (parent[v] != v)
        v = parent[v] = parent[parent[v]];
    return v;
}

/* The opened mesh: the copies after the input's vertices, barbule triangles on the copies. */
static plume_status opened_mesh(const plume_mesh *m, const plume_index *copy, plume_index ncopy, plume_mesh **out,
                                plume_err *err)
{
    plume_mesh *o = NULL;
    plume_status st = plume_mesh_create(m->nv + ncopy, m->nt, 2, &o, err);
    if (st != PLUME_OK)
        return st;
    memcpy(o->X, m->X, 2 * (size_t)m->nv * sizeof *o->X);
    for (plume_index v = 0; v < m->nv; v++)
        if (copy[v] >= 0)
            o->X[2 * copy[v]] = m->X[2 * v], o->X[2 * copy[v] + 1] = m->X[2 * v + 1];
    for (plume_index t = 0; t < m->nt; t++) {
        for (int k = 0; k < 3; k++) {
            const plume_index v = m->tri[3 * t + k];
            o->tri[3 * t + k] = m->material[t] == PLUME_MAT_BARBULE && copy[v] >= 0 ? copy[v] : v;
        }
        o->material[t] = m->material[t];
        o->barb_dir[2 * t] = m->barb_dir[2 * t], o->barb_dir[2 * t + 1] = m->barb_dir[2 * t + 1];
    }
    plume_mesh_reset_current(o);
    if ((st = plume_mesh_build_topology(o, err)) != PLUME_OK) {
        plume_mesh_destroy(&o);
        return st;
    }
    *out = o;
    return PLUME_OK;
}

plume_status plume_hook_mesh_open(const plume_mesh *m, const double q[2], plume_hook_mesh *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "hook mesh: no output");
    memset(out, 0, sizeof *out);
    if (!m || !q || m->dim != 2 || !m->edges || !m->edge_tri || !(q[0] * q[0] + q[1] * q[1] > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "hook mesh: a planar mesh with its topology and a direction q are "
                             "required");
    plume_status st = PLUME_OK;
    plume_index *copy = malloc((size_t)m->nv * sizeof *copy), *parent = malloc((size_t)m->nv * sizeof *parent);
    plume_index *hook_of = malloc((size_t)m->nv * sizeof *hook_of), *count = NULL;
    unsigned char *join = malloc((size_t)m->ne + 1);
    if (!copy || !parent || !hook_of || !join) {
        st = plume_err_set(err, PLUME_ENOMEM, "hook mesh: out of memory");
        goto done;
    }
    for (plume_index v = 0; v < m->nv; v++)
        copy[v] = -1, parent[v] = v, hook_of[v] = -1;
    plume_index njoin = 0, ncopy = 0;
    for (plume_index e = 0; e < m->ne; e++)
        if ((join[e] = (unsigned char)distal_join(m, e, q))) {
            njoin++;
            const plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
            copy[a] = copy[b] = 0;
            parent[find_root(parent, a)] = find_root(parent, b);
        }
    int nhooks = 0; /* a hook per chain, numbered in the order of their first vertex */
    for (plume_index v = 0; v < m->nv; v++) {
        if (copy[v] < 0)
            continue;
        copy[v] = m->nv + ncopy++;
        const plume_index r = find_root(parent, v);
        if (hook_of[r] < 0)
            hook_of[r] = nhooks++;
        hook_of[v] = hook_of[r];
    }
    out->nhooks = nhooks, out->njoin = njoin;
    out->first = calloc((size_t)nhooks + 1, sizeof *out->first);
    out->pairs = malloc((2 * (size_t)ncopy + 1) * sizeof *out->pairs);
    out->joins = malloc((4 * (size_t)njoin + 1) * sizeof *out->joins);
    out->join_hook = malloc(((size_t)njoin + 1) * sizeof *out->join_hook);
    count = calloc((size_t)nhooks + 1, sizeof *count);
    if (!out->first || !out->pairs || !out->joins || !out->join_hook || !count) {
        st = plume_err_set(err, PLUME_ENOMEM, "hook mesh: out of memory");
        goto done;
    }
    for (plume_index v = 0; v < m->nv; v++)
        if (copy[v] >= 0)
            out->first[hook_of[v] + 1]++;
    for (int h = 0; h < nhooks; h++)
        out->first[h + 1] += out->first[h];
    for (plume_index v = 0; v < m->nv; v++)
        if (copy[v] >= 0) {
            const plume_index p = out->first[hook_of[v]] + count[hook_of[v]]++;
            out->pairs[2 * p] = copy[v], out->pairs[2 * p + 1] = v;
        }
    njoin = 0;
    for (plume_index e = 0; e < m->ne; e++)
        if (join[e]) {
            const plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
            plume_index *j = out->joins + 4 * njoin;
            j[0] = a, j[1] = b, j[2] = copy[a], j[3] = copy[b];
            out->join_hook[njoin++] = hook_of[a];
        }
    st = opened_mesh(m, copy, ncopy, &out->mesh, err);
done:
    free(copy);
    free(parent);
    free(hook_of);
    free(count);
    free(join);
    if (st != PLUME_OK)
        plume_hook_mesh_free(out);
    return st;
}

/* edges sorted by their (smaller, larger) vertex ids, for lookups */
typedef struct {
    plume_index a, b, e;
} edge_key;

static int edge_key_cmp(const void *pa, const void *pb)
{
    const edge_key *x = pa, *y = pb;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    return x->b < y->b ? -1 : x->b > y->b;
}

static plume_index edge_of(const edge_key *keys, plume_index n, plume_index a, plume_index b)
{
    edge_key k = {a < b ? a : b, a < b ? b : a, 0};
    const edge_key *f = bsearch(&k, keys, (size_t)n, sizeof *keys, edge_key_cmp);
    return f ? f->e : -1;
}

plume_status plume_hook_mesh_quadratic_pairs(const plume_hook_mesh *h, plume_index **first, plume_index **pairs,
                                             plume_err *err)
{
    if (!h || !h->mesh || !first || !pairs)
        return plume_err_set(err, PLUME_EINVAL, "hook mesh: invalid arguments");
    *first = NULL, *pairs = NULL;
    const plume_mesh *m = h->mesh;
    const plume_index nvp = h->first[h->nhooks]; /* vertex pairs */
    edge_key *keys = malloc(((size_t)m->ne + 1) * sizeof *keys);
    plume_index *f = calloc((size_t)h->nhooks + 1, sizeof *f), *count = calloc((size_t)h->nhooks + 1, sizeof *count);
    plume_index *p = malloc((2 * ((size_t)nvp + (size_t)h->njoin) + 1) * sizeof *p);
    plume_status st = PLUME_OK;
    if (!keys || !f || !p || !count) {
        st = plume_err_set(err, PLUME_ENOMEM, "hook mesh: out of memory");
        goto done;
    }
    for (plume_index e = 0; e < m->ne; e++)
        keys[e] = (edge_key){m->edges[2 * e], m->edges[2 * e + 1], e};
    qsort(keys, (size_t)m->ne, sizeof *keys, edge_key_cmp);
    for (int k = 0; k < h->nhooks; k++) /* a hook's vertex pairs, then its joins' midpoints */
        f[k + 1] = h->first[k + 1] - h->first[k];
    for (plume_index j = 0; j < h->njoin; j++)
        f[h->join_hook[j] + 1]++;
    for (int k = 0; k < h->nhooks; k++)
        f[k + 1] += f[k];
    for (int k = 0; k < h->nhooks; k++)
        for (plume_index q = h->first[k]; q < h->first[k + 1]; q++) {
            const plume_index at = f[k] + count[k]++;
            p[2 * at] = h->pairs[2 * q], p[2 * at + 1] = h->pairs[2 * q + 1];
        }
    for (plume_index j = 0; j < h->njoin; j++) {
        const plume_index *e = h->joins + 4 * j;
        const plume_index orig = edge_of(keys, m->ne, e[0], e[1]), cp = edge_of(keys, m->ne, e[2], e[3]);
        if (orig < 0 || cp < 0) {
            st = plume_err_set(err, PLUME_EINVAL, "hook mesh: join %ld is not an edge of the opened mesh", (long)j);
            goto done;
        }
        const int k = h->join_hook[j];
        const plume_index at = f[k] + count[k]++;
        p[2 * at] = m->nv + cp, p[2 * at + 1] = m->nv + orig;
    }
    *first = f, *pairs = p;
    f = NULL, p = NULL;
done:
    free(keys);
    free(f);
    free(p);
    free(count);
    return st;
}
