/* plume: quadratic triangles over a linear mesh (lib/core/mesh_quadratic.h). */
#include "mesh_quadratic.h"

#include <stdlib.h>
#include <string.h>

void plume_quadratic_mesh_free(plume_quadratic_mesh *q)
{
    if (!q)
        return;
    plume_mesh_destroy(&q->split);
    free(q->tri6);
    free(q->material);
    free(q->barb_dir);
    memset(q, 0, sizeof *q);
}

/* The local edge (0: v0 v1, 1: v1 v2, 2: v2 v0) of triangle t joining a and b, or -1. */
static int local_edge(const plume_index *v, plume_index a, plume_index b)
{
    for (int k = 0; k < 3; k++) {
        plume_index p = v[k], r = v[(k + 1) % 3];
        if ((p == a && r == b) || (p == b && r == a))
            return k;
    }
    return -1;
}

plume_status plume_mesh_quadratic(const plume_mesh *m, plume_quadratic_mesh *q, plume_err *err)
{
    if (!q)
        return plume_err_set(err, PLUME_EINVAL, "quadratic mesh: output is NULL");
    memset(q, 0, sizeof *q);
    if (!m || m->dim < 2 || m->dim > 3)
        return plume_err_set(err, PLUME_EINVAL, "quadratic mesh: invalid mesh");
    if (m->nt > 0 && (!m->edges || !m->edge_tri))
        return plume_err_set(err, PLUME_EINVAL, "quadratic mesh: the mesh's topology is not built");
    const plume_index nv = m->nv, nt = m->nt, ne = m->ne;
    const int dim = m->dim;
    plume_status st = plume_mesh_create(nv + ne, 4 * nt, dim, &q->split, err);
    q->nt = nt;
    q->tri6 = malloc((size_t)(6 * nt + 1) * sizeof *q->tri6);
    q->material = malloc((size_t)(nt + 1) * sizeof *q->material);
    q->barb_dir = malloc((size_t)(2 * nt + 1) * sizeof *q->barb_dir);
    if (st != PLUME_OK || !q->tri6 || !q->material || !q->barb_dir) {
        plume_quadratic_mesh_free(q);
        return plume_err_set(err, PLUME_ENOMEM, "quadratic mesh: out of memory");
    }
    plume_mesh *s = q->split;
    memcpy(s->X, m->X, (size_t)(2 * nv) * sizeof *s->X);
    memcpy(s->x, m->x, (size_t)(dim * nv) * sizeof *s->x);
    for (plume_index t = 0; t < 6 * nt; t++)
        q->tri6[t] = -1;
    for (plume_index e = 0; e < ne; e++) {
        const plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1], node = nv + e;
        for (int i = 0; i < 2; i++)
            s->X[2 * node + i] = 0.5 * (m->X[2 * a + i] + m->X[2 * b + i]);
        for (int i = 0; i < dim; i++)
            s->x[dim * node + i] = 0.5 * (m->x[dim * a + i] + m->x[dim * b + i]);
        for (int side = 0; side < 2; side++) {
            plume_index t = m->edge_tri[2 * e + side];
            if (t < 0)
                continue;
            int k = local_edge(m->tri + 3 * t, a, b);
            if (k < 0) {
                plume_quadratic_mesh_free(q);
                return plume_err_set(err, PLUME_EINVAL, "quadratic mesh: edge %ld is not an edge of its triangle %ld",
                                     (long)e, (long)t);
            }
            q->tri6[6 * t + 3 + k] = node;
        }
    }
    for (plume_index t = 0; t < nt; t++) {
        plume_index *v = q->tri6 + 6 * t;
        for (int k = 0; k < 3; k++)
            v[k] = m->tri[3 * t + k];
        if (v[3] < 0 || v[4] < 0 || v[5] < 0) {
            plume_quadratic_mesh_free(q);
            return plume_err_set(err, PLUME_EINVAL, "quadratic mesh: triangle %ld misses an edge in the topology",
                                 (long)t);
        }
        q->material[t] = m->material[t];
        q->barb_dir[2 * t] = m->barb_dir[2 * t];
        q->barb_dir[2 * t + 1] = m->barb_dir[2 * t + 1];
        /* corner triangles, then the middle one: all counter-clockwise like the parent */
        const plume_index sub[4][3] = {{v[0], v[3], v[5]}, {v[3], v[1], v[4]}, {v[5], v[4], v[2]}, {v[3], v[4], v[5]}};
        for (int k = 0; k < 4; k++) {
            memcpy(s->tri + 3 * (4 * t + k), sub[k], sizeof sub[k]);
            s->material[4 * t + k] = m->material[t];
            s->barb_dir[2 * (4 * t + k)] = m->barb_dir[2 * t];
            s->barb_dir[2 * (4 * t + k) + 1] = m->barb_dir[2 * t + 1];
        }
    }
    if ((st = plume_mesh_build_topology(s, err)) != PLUME_OK)
        plume_quadratic_mesh_free(q);
    return st;
}
