/* plume (macro): barb lines that split and zip again (split_lines.h; docs/unzipping.md). */
#include "split_lines.h"

#include "../../include/plume/traction.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "patch_mesh.h"

void plume_split_lines_free(plume_split_lines *s)
{
    if (!s)
        return;
    plume_mesh_destroy(&s->mesh);
    free(s->offset);
    free(s->first);
    free(s->pairs);
    free(s->length);
    memset(s, 0, sizeof *s);
}

typedef struct {
    double t;
    plume_index v;
} along;

static int cmp_along(const void *a, const void *b)
{
    const double x = ((const along *)a)->t, y = ((const along *)b)->t;
    return (x > y) - (x < y);
}

/* the smallest and largest offset n . X of the mesh's vertices */
static void offset_range(const plume_mesh *m, const double n[2], double *lo, double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (plume_index v = 0; v < m->nv; v++) {
        const double o = n[0] * m->X[2 * v] + n[1] * m->X[2 * v + 1];
        *lo = fmin(*lo, o), *hi = fmax(*hi, o);
    }
}

plume_status plume_split_lines_open(const plume_mesh *m, const double d[2], const double *c, int nc,
                                    plume_split_lines *out, plume_err *err)
{
    return plume_split_lines_open_held(m, d, c, nc, NULL, out, err);
}

plume_status plume_split_lines_open_held(const plume_mesh *m, const double d[2], const double *c, int nc,
                                         const unsigned char *held, plume_split_lines *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no output");
    memset(out, 0, sizeof *out);
    if (!m || (m->dim != 2 && m->dim != 3) || !m->edges || !d || nc < 1 || !c)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a mesh with its topology, a barb direction and "
                             "at least one offset are required");
    const double n[2] = {d[1], -d[0]};
    double lo, hi;
    offset_range(m, n, &lo, &hi);
    const double tol = 1e-9 * fmax(hi - lo, 1e-300);
    /* each requested offset snaps to the line of the nearest vertex offset */
    plume_status st = PLUME_OK;
    out->offset = malloc((size_t)nc * sizeof *out->offset);
    out->first = calloc((size_t)nc + 1, sizeof *out->first);
    int *side = calloc((size_t)m->nv, sizeof *side);      /* line + 1 of a vertex on an opened line */
    plume_index *copy = malloc((size_t)m->nv * sizeof *copy);
    along *row = malloc((size_t)m->nv * sizeof *row);
    out->pairs = malloc((size_t)(2 * m->nv) * sizeof *out->pairs);
    out->length = malloc((size_t)m->nv * sizeof *out->length);
    if (!out->offset || !out->first || !side || !copy || !row || !out->pairs || !out->length) {
        st = plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
        goto done;
    }
    for (plume_index v = 0; v < m->nv; v++)
        copy[v] = -1;
    plume_index nv = m->nv;
    for (int l = 0; l < nc; l++) {
        double best = INFINITY, at = 0.0;
        for (plume_index v = 0; v < m->nv; v++) {
            const double o = n[0] * m->X[2 * v] + n[1] * m->X[2 * v + 1];
            if (fabs(o - c[l]) < best)
                best = fabs(o - c[l]), at = o;
        }
        if (at <= lo + tol || at >= hi - tol) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: offset %g m lies on the mesh's edge (offsets run from "
                               "%g to %g m): a line that splits must cross the vane", c[l], lo, hi);
            goto done;
        }
        out->offset[l] = at;
        plume_index k = 0;
        for (plume_index v = 0; v < m->nv; v++)
            if (fabs(n[0] * m->X[2 * v] + n[1] * m->X[2 * v + 1] - at) <= tol) {
                if (side[v]) {
                    st = plume_err_set(err, PLUME_EINVAL, "split lines: offsets %g and %g m fall on the same line",
                                       c[side[v] - 1], c[l]);
                    goto done;
                }
                side[v] = l + 1;
                row[k].t = d[0] * m->X[2 * v] + d[1] * m->X[2 * v + 1];
                row[k++].v = v;
            }
        if (k < 2) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: no line of mesh edges at offset %g m", c[l]);
            goto done;
        }
        qsort(row, (size_t)k, sizeof *row, cmp_along);
        for (plume_index i = 0; i + 1 < k; i++)
            if (plume_mesh_edge(m, row[i].v, row[i + 1].v) < 0) {
                st = plume_err_set(err, PLUME_EINVAL, "split lines: the line at offset %g m is not a chain of mesh "
                                   "edges (vertices %ld and %ld): split lines need a mesh aligned with the barbs",
                                   at, (long)row[i].v, (long)row[i + 1].v);
                goto done;
            }
        plume_index f = out->first[l];
        for (plume_index i = 0; i < k; i++) {
            if (held && held[row[i].v]) { /* stays whole: the line ends there (a crack tip) */
                side[row[i].v] = 0;
                continue;
            }
            const double prev = i > 0 ? row[i].t - row[i - 1].t : 0.0, next = i + 1 < k ? row[i + 1].t - row[i].t : 0.0;
            copy[row[i].v] = nv;
            out->pairs[2 * f] = nv++;
            out->pairs[2 * f + 1] = row[i].v;
            out->length[f++] = 0.5 * (prev + next);
        }
        if (f == out->first[l]) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: no vertex of the line at offset %g m may split (each "
                               "touches a material that does not split)", at);
            goto done;
        }
        out->first[l + 1] = f;
    }
    out->nlines = nc;
    out->npairs = out->first[nc];
    if ((st = plume_mesh_create(nv, m->nt, m->dim, &out->mesh, err)) != PLUME_OK)
        goto done;
    plume_mesh *om = out->mesh;
    const int dim = m->dim;
    memcpy(om->X, m->X, (size_t)(2 * m->nv) * sizeof *om->X);
    memcpy(om->x, m->x, (size_t)(dim * m->nv) * sizeof *om->x);
    for (plume_index v = 0; v < m->nv; v++)
        if (copy[v] >= 0) {
            memcpy(om->X + 2 * copy[v], m->X + 2 * v, 2 * sizeof *om->X);
            memcpy(om->x + dim * copy[v], m->x + dim * v, (size_t)dim * sizeof *om->x);
        }
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *tv = m->tri + 3 * t;
        double cn = 0.0;
        for (int k = 0; k < 3; k++)
            cn += (n[0] * m->X[2 * tv[k]] + n[1] * m->X[2 * tv[k] + 1]) / 3.0;
        for (int k = 0; k < 3; k++) {
            const plume_index v = tv[k];
            /* ahead of the vertex's line: the copy */
            om->tri[3 * t + k] = side[v] && copy[v] >= 0 && cn > out->offset[side[v] - 1] ? copy[v] : v;
        }
        om->material[t] = m->material[t];
        memcpy(om->barb_dir + 2 * t, m->barb_dir + 2 * t, 2 * sizeof *om->barb_dir);
    }
    st = plume_mesh_build_topology(om, err);
done:
    free(side);
    free(copy);
    free(row);
    if (st != PLUME_OK)
        plume_split_lines_free(out);
    return st;
}

plume_status plume_split_lines_add(plume_problem *p, const plume_split_lines *s, const plume_separation_law *law,
                                   plume_hooks **hooks, plume_err *err)
{
    if (hooks)
        *hooks = NULL;
    if (!p || !s || !s->mesh || !law || s->npairs < 1)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a problem, opened lines and a law are required");
    if (!(law->strength > 0.0) || !(law->stiffness > 0.0) || !(law->capture >= 0.0) || !isfinite(law->strength) ||
        !isfinite(law->stiffness) || !isfinite(law->capture))
        return plume_err_set(err, PLUME_EINVAL, "split lines: the separation law needs strength > 0 (got %g N/m), "
                             "stiffness > 0 (got %g N/m^2) and capture >= 0 (got %g m)", law->strength, law->stiffness,
                             law->capture);
    /* one hook per pair, of the law per unit length, scaled by the pair's length */
    const plume_hook_law per_length = {.strength = law->strength, .opening = law->strength / law->stiffness,
                                       .slide = 0.0, .capture = law->capture};
    plume_index *first = malloc((size_t)(s->npairs + 1) * sizeof *first);
    if (!first)
        return plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
    for (plume_index k = 0; k <= s->npairs; k++)
        first[k] = k;
    plume_hooks *h = NULL;
    plume_status st = plume_hooks_create(s->mesh->nv, (int)s->npairs, first, s->pairs, &per_length, &h, err);
    free(first);
    if (st == PLUME_OK) {
        plume_hooks_set_overshoot(h, PLUME_SPLIT_OVERSHOOT);
        plume_hooks_set_seating(h, PLUME_SPLIT_SEATING * law->capture);
    }
    for (plume_index k = 0; st == PLUME_OK && k < s->npairs; k++)
        if (plume_hooks_set_scale(h, (int)k, s->length[k]) != PLUME_OK)
            st = plume_err_set(err, PLUME_EINVAL, "split lines: pair %ld has no length along its line", (long)k);
    if (st != PLUME_OK) {
        plume_hooks_destroy(&h);
        return st;
    }
    plume_term t;
    plume_hooks_term(h, 1, &t);
    t.name = "splits";
    if ((st = plume_problem_add_term(p, &t, err)) == PLUME_OK && hooks)
        *hooks = h; /* the problem owns it, also on failure */
    return st;
}

/* ---- the public face (include/plume/traction.h) ---- */
struct plume_splits {
    plume_split_lines lines;
};

plume_status plume_splits_open(const plume_mesh *m, double angle_deg, int nlines, plume_splits **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no output");
    *out = NULL;
    if (!m || m->dim != 2 || !m->edges)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a planar mesh with its topology is required");
    if (nlines < 1)
        return plume_err_set(err, PLUME_EINVAL, "split lines: the number of lines must be >= 1 (got %d)", nlines);
    if (!(angle_deg >= 0.0 && angle_deg <= 180.0))
        return plume_err_set(err, PLUME_EINVAL, "split lines: the barb angle must be in [0, 180] (got %g)", angle_deg);
    double d[2];
    plume_patch_barb_direction(angle_deg, d);
    const double n[2] = {d[1], -d[0]};
    double lo, hi;
    offset_range(m, n, &lo, &hi);
    double *c = malloc((size_t)nlines * sizeof *c);
    plume_splits *s = calloc(1, sizeof *s);
    if (!c || !s) {
        free(c);
        free(s);
        return plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
    }
    for (int k = 0; k < nlines; k++)
        c[k] = lo + (hi - lo) * (double)(k + 1) / (double)(nlines + 1);
    plume_status st = plume_split_lines_open(m, d, c, nlines, &s->lines, err);
    free(c);
    if (st != PLUME_OK) {
        free(s);
        return st;
    }
    *out = s;
    return PLUME_OK;
}

const plume_mesh *plume_splits_mesh(const plume_splits *s)
{
    return s ? s->lines.mesh : NULL;
}

long plume_splits_pairs(const plume_splits *s)
{
    return s ? (long)s->lines.npairs : 0;
}

plume_status plume_splits_add(plume_problem *p, const plume_splits *s, const plume_separation_law *law, plume_err *err)
{
    if (!s)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no lines");
    return plume_split_lines_add(p, &s->lines, law, NULL, err);
}

void plume_splits_destroy(plume_splits **s)
{
    if (!s || !*s)
        return;
    plume_split_lines_free(&(*s)->lines);
    free(*s);
    *s = NULL;
}

/* ---- lines along chains of mesh edges (curved barbs) ---- */

plume_status plume_split_lines_open_chains(const plume_mesh *m, int nchains, const plume_index *cfirst,
                                           const plume_index *cverts, const unsigned char *held,
                                           plume_split_lines *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no output");
    memset(out, 0, sizeof *out);
    if (!m || (m->dim != 2 && m->dim != 3) || !m->edges || nchains < 1 || !cfirst || !cverts)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a mesh with its topology and at least one chain are "
                             "required");
    const plume_index nv = m->nv, nt = m->nt;
    plume_status st = PLUME_OK;
    plume_index *tstart = calloc((size_t)nv + 2, sizeof *tstart), *tlist = malloc((size_t)(3 * nt + 1) * sizeof *tlist);
    plume_index *copy = malloc((size_t)(nv + 1) * sizeof *copy), *fill = calloc((size_t)nv + 1, sizeof *fill);
    int *line_of = malloc((size_t)(nv + 1) * sizeof *line_of);       /* the chain a vertex is on, or -1 */
    int *edge_line = malloc((size_t)(m->ne + 1) * sizeof *edge_line); /* the chain an edge is on, or -1 */
    unsigned char *bnd = calloc((size_t)nv + 1, 1);
    plume_index *stack = malloc((size_t)(nt + 1) * sizeof *stack);
    const plume_index nin = cfirst[nchains];
    out->offset = malloc((size_t)nchains * sizeof *out->offset);
    out->first = calloc((size_t)nchains + 1, sizeof *out->first);
    out->pairs = malloc((size_t)(2 * nin + 1) * sizeof *out->pairs);
    out->length = malloc((size_t)(nin + 1) * sizeof *out->length);
    if (!tstart || !tlist || !copy || !fill || !line_of || !edge_line || !bnd || !stack || !out->offset ||
        !out->first || !out->pairs || !out->length) {
        st = plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
        goto done;
    }
    for (plume_index v = 0; v < nv; v++)
        copy[v] = -1, line_of[v] = -1;
    for (plume_index e = 0; e < m->ne; e++) {
        edge_line[e] = -1;
        if (m->edge_tri[2 * e + 1] < 0)
            bnd[m->edges[2 * e]] = bnd[m->edges[2 * e + 1]] = 1;
    }
    /* each vertex's triangles */
    for (plume_index t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            tstart[m->tri[3 * t + k] + 1]++;
    for (plume_index v = 0; v < nv; v++)
        tstart[v + 1] += tstart[v];
    for (plume_index t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            const plume_index v = m->tri[3 * t + k];
            tlist[tstart[v] + fill[v]++] = t;
        }
    /* the chains: consecutive vertices mesh edges, no vertex on two chains (held ones aside) */
    for (int l = 0; l < nchains; l++) {
        if (cfirst[l + 1] - cfirst[l] < 2) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: chain %d has fewer than 2 vertices", l);
            goto done;
        }
        for (plume_index i = cfirst[l]; i < cfirst[l + 1]; i++) {
            const plume_index v = cverts[i];
            if (v < 0 || v >= nv) {
                st = plume_err_set(err, PLUME_EINVAL, "split lines: chain %d names vertex %ld, not in the mesh", l, (long)v);
                goto done;
            }
            if (i + 1 < cfirst[l + 1]) {
                const plume_index e = plume_mesh_edge(m, v, cverts[i + 1]);
                if (e < 0) {
                    st = plume_err_set(err, PLUME_EINVAL, "split lines: chain %d: vertices %ld and %ld are not a mesh "
                                       "edge", l, (long)v, (long)cverts[i + 1]);
                    goto done;
                }
                edge_line[e] = l;
            }
            if (held && held[v])
                continue;
            if (line_of[v] >= 0) {
                st = plume_err_set(err, PLUME_EINVAL, "split lines: vertex %ld is on chains %d and %d", (long)v,
                                   line_of[v], l);
                goto done;
            }
            line_of[v] = l;
        }
    }
    /* each splitting vertex: a copy for the triangles of its fan reached from the left of its chain
     * edges without crossing one; a chain's end inside the vane stays whole (a crack tip) */
    plume_index nvo = nv, np = 0;
    unsigned char *mark = calloc((size_t)nt + 1, 1);
    plume_index *tcopy = malloc((size_t)(3 * nt + 1) * sizeof *tcopy); /* the triangles, copies in place */
    if (!mark || !tcopy) {
        free(mark);
        free(tcopy);
        st = plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
        goto done;
    }
    for (plume_index i = 0; i < 3 * nt; i++)
        tcopy[i] = m->tri[i];
    for (int l = 0; l < nchains; l++) {
        out->first[l] = np;
        out->offset[l] = NAN;
        const plume_index f = cfirst[l], g = cfirst[l + 1];
        for (plume_index i = f; i < g; i++) {
            const plume_index v = cverts[i];
            const double prev = i > f ? hypot(m->X[2 * v] - m->X[2 * cverts[i - 1]], m->X[2 * v + 1] - m->X[2 * cverts[i - 1] + 1]) : 0.0;
            const double next = i + 1 < g ? hypot(m->X[2 * v] - m->X[2 * cverts[i + 1]], m->X[2 * v + 1] - m->X[2 * cverts[i + 1] + 1]) : 0.0;
            if ((held && held[v]) || ((i == f || i == g - 1) && !bnd[v]))
                continue;
            /* flood the fan from the left triangles of v's chain edges */
            plume_index ns = 0;
            for (plume_index k = tstart[v]; k < tstart[v + 1]; k++) {
                const plume_index t = tlist[k];
                mark[t] = 0;
                int seed = 0;
                for (int j = 0; j < 3; j++) { /* t left of the chain edge v - w, in the chain's order */
                    const plume_index w = m->tri[3 * t + j];
                    const plume_index e = w != v ? plume_mesh_edge(m, v, w) : -1;
                    if (e < 0 || edge_line[e] != l)
                        continue;
                    const int forward = i + 1 < g && cverts[i + 1] == w;
                    const plume_index a = forward ? v : w, b = forward ? w : v, c = m->tri[3 * t + (j + 1) % 3] == v
                                                                                     ? m->tri[3 * t + (j + 2) % 3]
                                                                                     : m->tri[3 * t + (j + 1) % 3];
                    const double *A = m->X + 2 * a, *B = m->X + 2 * b, *C = m->X + 2 * c;
                    if ((B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0]) > 0.0)
                        seed = 1;
                }
                if (seed)
                    stack[ns++] = t;
            }
            for (plume_index k = 0; k < ns; k++)
                mark[stack[k]] = 1;
            while (ns > 0) {
                const plume_index t = stack[--ns];
                for (int j = 0; j < 3; j++) {
                    const plume_index w = m->tri[3 * t + j];
                    if (w == v)
                        continue;
                    const plume_index e = plume_mesh_edge(m, v, w);
                    if (e < 0 || edge_line[e] == l)
                        continue;
                    const plume_index u = m->edge_tri[2 * e] == t ? m->edge_tri[2 * e + 1] : m->edge_tri[2 * e];
                    if (u >= 0 && !mark[u])
                        mark[u] = 1, stack[ns++] = u;
                }
            }
            plume_index moved = 0;
            for (plume_index k = tstart[v]; k < tstart[v + 1]; k++)
                moved += mark[tlist[k]];
            if (moved == 0 || moved == tstart[v + 1] - tstart[v])
                continue; /* nothing on one side: no split here */
            copy[v] = nvo;
            for (plume_index k = tstart[v]; k < tstart[v + 1]; k++) {
                const plume_index t = tlist[k];
                if (!mark[t])
                    continue;
                for (int j = 0; j < 3; j++)
                    if (m->tri[3 * t + j] == v)
                        tcopy[3 * t + j] = nvo;
            }
            out->pairs[2 * np] = nvo++;
            out->pairs[2 * np + 1] = v;
            out->length[np++] = 0.5 * (prev + next);
        }
        out->first[l + 1] = np;
    }
    free(mark);
    out->nlines = nchains;
    out->npairs = np;
    if (np == 0) {
        free(tcopy);
        st = plume_err_set(err, PLUME_EINVAL, "split lines: no vertex of the %d chain%s may split", nchains,
                           nchains == 1 ? "" : "s");
        goto done;
    }
    if ((st = plume_mesh_create(nvo, nt, m->dim, &out->mesh, err)) != PLUME_OK) {
        free(tcopy);
        goto done;
    }
    plume_mesh *om = out->mesh;
    const int dim = m->dim;
    memcpy(om->X, m->X, (size_t)(2 * nv) * sizeof *om->X);
    memcpy(om->x, m->x, (size_t)(dim * nv) * sizeof *om->x);
    for (plume_index v = 0; v < nv; v++)
        if (copy[v] >= 0) {
            memcpy(om->X + 2 * copy[v], m->X + 2 * v, 2 * sizeof *om->X);
            memcpy(om->x + dim * copy[v], m->x + dim * v, (size_t)dim * sizeof *om->x);
        }
    memcpy(om->tri, tcopy, (size_t)(3 * nt) * sizeof *om->tri);
    memcpy(om->material, m->material, (size_t)nt * sizeof *om->material);
    memcpy(om->barb_dir, m->barb_dir, (size_t)(2 * nt) * sizeof *om->barb_dir);
    free(tcopy);
    st = plume_mesh_build_topology(om, err);
done:
    free(tstart);
    free(tlist);
    free(copy);
    free(fill);
    free(line_of);
    free(edge_line);
    free(bnd);
    free(stack);
    if (st != PLUME_OK)
        plume_split_lines_free(out);
    return st;
}
