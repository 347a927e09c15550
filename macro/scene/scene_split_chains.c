/* plume: a scene's split lines along a feather's curved barbs (scene_splits.c for the block): the
 * feather mesher's barb edges in the splitting materials, walked into chains from the rachis to
 * the outline, a choice of them opened (macro/shell/split_lines.h), and the mesher's barb edges
 * carried over to the copies. */
#include "internal/scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    plume_index first; /* its vertices are verts[first .. first + n - 1] */
    plume_index n;
    double key[2];     /* its side (the sign of its run along X: a feather's rachis runs along Y) and its
                          root's Y: chains sorted side by side, each along the rachis */
} chain;

static int cmp_chain(const void *a, const void *b)
{
    const chain *p = a, *q = b;
    for (int k = 0; k < 2; k++)
        if (p->key[k] != q->key[k])
            return (p->key[k] > q->key[k]) - (p->key[k] < q->key[k]);
    return (p->first > q->first) - (p->first < q->first);
}

/* 1 when the barb edge (a, b) of the mesher's list lies in the splitting materials */
static int splitting_edge(const plume_mesh *m, const unsigned char *split, plume_index a, plume_index b)
{
    const plume_index e = plume_mesh_edge(m, a, b);
    if (e < 0)
        return 0;
    const plume_index t0 = m->edge_tri[2 * e], t1 = m->edge_tri[2 * e + 1];
    return split[m->material[t0]] && (t1 < 0 || split[m->material[t1]]);
}

/* The chains of the barb edges in the splitting materials (vertices of degree 2 inside a chain;
 * a chain starts at a vertex of another degree, preferably a held one: the rachis), sorted side
 * by side, each along the rachis: *chains [*nc], *verts */
static plume_status barb_chains(const plume_scene *s, const unsigned char *split, const unsigned char *held,
                                chain **chains, int *nc, plume_index **verts, plume_err *err)
{
    const plume_mesh *m = s->mesh;
    const plume_index nv = m->nv;
    plume_index *nbr = malloc((size_t)(2 * nv + 1) * sizeof *nbr), *deg = calloc((size_t)nv + 1, sizeof *deg);
    unsigned char *seen = calloc((size_t)nv + 1, 1);
    *verts = malloc((size_t)(nv + 1) * sizeof **verts);
    *chains = malloc((size_t)(nv + 1) * sizeof **chains);
    *nc = 0;
    if (!nbr || !deg || !seen || !*verts || !*chains) {
        free(nbr), free(deg), free(seen);
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    for (plume_index k = 0; k < s->nbarb; k++) {
        const plume_index a = s->barb_edges[2 * k], b = s->barb_edges[2 * k + 1];
        if (!splitting_edge(m, split, a, b))
            continue;
        if (deg[a] < 2)
            nbr[2 * a + deg[a]] = b;
        if (deg[b] < 2)
            nbr[2 * b + deg[b]] = a;
        deg[a]++, deg[b]++;
    }
    plume_index used = 0;
    /* two passes: chains from held roots first (from the rachis outward), then any other end */
    for (int pass = 0; pass < 2; pass++)
        for (plume_index r = 0; r < nv; r++) {
            if (seen[r] || deg[r] == 0 || deg[r] == 2 || (pass == 0 && !(held && held[r])))
                continue;
            chain *ch = *chains + *nc;
            ch->first = used, ch->n = 0;
            ch->key[1] = m->X[2 * r + 1];
            plume_index v = r, prev = -1;
            for (;;) {
                seen[v] = 1;
                (*verts)[used + ch->n++] = v;
                if (deg[v] != 2 && v != r)
                    break; /* an end, or a junction (not walked through) */
                plume_index next = -1;
                for (int k = 0; k < (deg[v] < 2 ? (int)deg[v] : 2); k++)
                    if (nbr[2 * v + k] != prev && !seen[nbr[2 * v + k]])
                        next = nbr[2 * v + k];
                if (next < 0)
                    break;
                prev = v, v = next;
            }
            if (ch->n >= 2) {
                const plume_index end = (*verts)[used + ch->n - 1];
                ch->key[0] = m->X[2 * end] < m->X[2 * r] ? -1.0 : 1.0;
                used += ch->n, (*nc)++;
            }
        }
    free(nbr);
    free(deg);
    free(seen);
    qsort(*chains, (size_t)*nc, sizeof **chains, cmp_chain);
    return PLUME_OK;
}

plume_status plume_scene_split_chains(const plume_json_ctx *c, json_t *js, const plume_scene *s,
                                      const unsigned char *split, const unsigned char *held, plume_split_lines *out)
{
    if (!s->barb_edges)
        return plume_json_bad(c, PLUME_EINVAL, "splits", "need straight barbs (one \"barb_direction\" over the "
                              "materials that split) or the feather mesher's barbs; this mesh has neither");
    if (json_object_get(js, "offsets"))
        return plume_json_bad(c, PLUME_EINVAL, "splits.offsets", "are for straight barbs; a feather's lines are its "
                              "barbs: give \"lines\" (that many, spread along the rachis) or \"every\" (every k-th barb)");
    json_t *jn = json_object_get(js, "lines"), *je = json_object_get(js, "every");
    if ((jn != NULL) == (je != NULL))
        return plume_json_bad(c, PLUME_EINVAL, "splits", "on a feather need one of \"lines\" (a number of barbs "
                              "spread along the rachis) or \"every\" (every k-th barb: 1 for all)");
    long want = 0, every = 0;
    plume_status st = jn ? plume_json_int(c, js, "splits", "lines", 1, 1000000, &want)
                         : plume_json_int(c, js, "splits", "every", 1, 1000000, &every);
    if (st != PLUME_OK)
        return st;
    chain *chains = NULL;
    plume_index *verts = NULL;
    int nc = 0;
    if ((st = barb_chains(s, split, held, &chains, &nc, &verts, c->err)) != PLUME_OK)
        goto done;
    if (nc == 0) {
        st = plume_json_bad(c, PLUME_EINVAL, "splits.materials", "hold no barb of the feather mesher");
        goto done;
    }
    /* the chosen chains, in order along the rachis */
    int n = jn ? (int)(want < nc ? want : nc) : (int)((nc + every - 1) / every);
    plume_index *cfirst = malloc((size_t)(n + 1) * sizeof *cfirst), *cverts = malloc((size_t)(s->mesh->nv + 1) * sizeof *cverts);
    if (!cfirst || !cverts) {
        free(cfirst), free(cverts);
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    cfirst[0] = 0;
    for (int k = 0; k < n; k++) {
        const int i = jn ? (int)floor(((double)k + 0.5) * nc / n) : (int)(k * every);
        memcpy(cverts + cfirst[k], verts + chains[i].first, (size_t)chains[i].n * sizeof *cverts);
        cfirst[k + 1] = cfirst[k] + chains[i].n;
    }
    plume_err e2 = {{0}};
    if ((st = plume_split_lines_open_chains(s->mesh, n, cfirst, cverts, held, out, &e2)) != PLUME_OK)
        st = plume_json_bad(c, st, jn ? "splits.lines" : "splits.every", "%s", e2.msg);
    free(cfirst);
    free(cverts);
done:
    free(chains);
    free(verts);
    return st;
}

plume_status plume_scene_split_barb_edges(plume_scene *s, const plume_split_lines *sl, plume_err *err)
{
    if (!s->barb_edges || !sl->npairs)
        return PLUME_OK;
    const plume_index nin = sl->pairs[0]; /* the copies come after the input's vertices */
    plume_index *copy = malloc((size_t)(nin + 1) * sizeof *copy);
    plume_index *more = realloc(s->barb_edges, (size_t)(4 * s->nbarb + 1) * sizeof *more);
    if (!copy || !more) {
        free(copy);
        if (more)
            s->barb_edges = more;
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    s->barb_edges = more;
    for (plume_index v = 0; v < nin; v++)
        copy[v] = v;
    for (plume_index k = 0; k < sl->npairs; k++)
        copy[sl->pairs[2 * k + 1]] = sl->pairs[2 * k];
    const plume_index n = s->nbarb;
    for (plume_index k = 0; k < n; k++) {
        const plume_index a = s->barb_edges[2 * k], b = s->barb_edges[2 * k + 1];
        const plume_index ca = a < nin ? copy[a] : a, cb = b < nin ? copy[b] : b;
        if ((ca != a || cb != b) && plume_mesh_edge(s->mesh, ca, cb) >= 0) /* a lip's own barb edge */
            s->barb_edges[2 * s->nbarb] = ca, s->barb_edges[2 * s->nbarb + 1] = cb, s->nbarb++;
    }
    free(copy);
    return PLUME_OK;
}
