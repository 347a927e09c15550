/* plume (macro): split lines along chains of mesh edges, such as a feather's curved barbs
 * (split_lines.h, plume_split_lines_open_chains); the straight lines and the links are in
 * split_lines.c. */
#include "split_lines.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
