#include "mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

plume_status plume_mesh_create(plume_index nv, plume_index nt, int dim, plume_mesh **out, plume_err *err)
{
    if (out)
        *out = NULL;
    if (!out || nv < 0 || nt < 0 || (dim != 2 && dim != 3))
        return plume_err_set(err, PLUME_EINVAL,
                             "mesh: %ld vertices, %ld triangles in dimension %d: counts must be >= 0 and the "
                             "dimension 2 (planar) or 3 (shell)%s",
                             (long)nv, (long)nt, dim, out ? "" : " (and out is required)");
    plume_mesh *m = calloc(1, sizeof *m);
    if (!m)
        return plume_err_set(err, PLUME_ENOMEM, "mesh: out of memory");
    m->nv = nv;
    m->nt = nt;
    m->dim = dim;
    m->X = calloc((size_t)(2 * nv + 1), sizeof *m->X);
    m->x = calloc((size_t)(dim * nv + 1), sizeof *m->x);
    m->tri = calloc((size_t)(3 * nt + 1), sizeof *m->tri);
    m->barb_dir = calloc((size_t)(2 * nt + 1), sizeof *m->barb_dir);
    m->material = calloc((size_t)(nt + 1), sizeof *m->material);
    m->boundary = calloc((size_t)(nv + 1), sizeof *m->boundary);
    if (!m->X || !m->x || !m->tri || !m->barb_dir || !m->material || !m->boundary) {
        plume_mesh_destroy(&m);
        return plume_err_set(err, PLUME_ENOMEM, "mesh: out of memory for %ld vertices and %ld triangles", (long)nv,
                             (long)nt);
    }
    for (plume_index t = 0; t < nt; t++)
        m->barb_dir[2 * t] = 1.0;
    *out = m;
    return PLUME_OK;
}

void plume_mesh_destroy(plume_mesh **pm)
{
    if (!pm || !*pm)
        return;
    plume_mesh *m = *pm;
    free(m->X);
    free(m->x);
    free(m->tri);
    free(m->barb_dir);
    free(m->material);
    free(m->edges);
    free(m->edge_tri);
    free(m->hinges);
    free(m->boundary);
    free(m);
    *pm = NULL;
}

void plume_mesh_reset_current(plume_mesh *m)
{
    for (plume_index v = 0; v < m->nv; v++) {
        m->x[m->dim * v] = m->X[2 * v];
        m->x[m->dim * v + 1] = m->X[2 * v + 1];
        if (m->dim == 3)
            m->x[3 * v + 2] = 0.0;
    }
}

double plume_mesh_ref_area(const plume_mesh *m, plume_index t)
{
    const plume_index *v = m->tri + 3 * t;
    const double *a = m->X + 2 * v[0], *b = m->X + 2 * v[1], *c = m->X + 2 * v[2];
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

double plume_mesh_total_area(const plume_mesh *m)
{
    double s = 0.0;
    for (plume_index t = 0; t < m->nt; t++)
        s += plume_mesh_ref_area(m, t);
    return s;
}

/* half-edge record used to pair the two sides of each edge */
typedef struct {
    plume_index a, b; /* a < b */
    plume_index tri;
    int local;        /* opposite local vertex */
} half_edge;

static int half_edge_cmp(const void *pa, const void *pb)
{
    const half_edge *x = pa, *y = pb;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    if (x->b != y->b)
        return x->b < y->b ? -1 : 1;
    return x->tri < y->tri ? -1 : (x->tri > y->tri);
}

plume_status plume_mesh_build_topology(plume_mesh *m, plume_err *err)
{
    return plume_mesh_build_topology_rigid(m, m ? m->nt : 0, err);
}

plume_status plume_mesh_build_topology_rigid(plume_mesh *m, plume_index first_rigid, plume_err *err)
{
    plume_status st = PLUME_OK;
    half_edge *he = NULL;
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        for (int k = 0; k < 3; k++)
            if (v[k] < 0 || v[k] >= m->nv)
                return plume_err_set(err, PLUME_EINVAL, "triangle %ld: vertex id %ld out of range [0, %ld)",
                                     (long)t, (long)v[k], (long)m->nv);
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            return plume_err_set(err, PLUME_EINVAL, "triangle %ld: repeated vertex", (long)t);
        double a = t < first_rigid ? plume_mesh_ref_area(m, t) : 1.0;
        if (!(a > 0.0))
            return plume_err_set(err, PLUME_EINVAL,
                                 "triangle %ld: reference area %g is not positive (clockwise or degenerate)",
                                 (long)t, a);
    }
    he = malloc((size_t)(3 * m->nt + 1) * sizeof *he);
    if (!he)
        return PLUME_ENOMEM;
    for (plume_index t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            plume_index i = m->tri[3 * t + (k + 1) % 3], j = m->tri[3 * t + (k + 2) % 3];
            half_edge *h = he + 3 * t + k;
            h->a = i < j ? i : j;
            h->b = i < j ? j : i;
            h->tri = t;
            h->local = k;
        }
    qsort(he, (size_t)(3 * m->nt), sizeof *he, half_edge_cmp);
    plume_index ne = 0, nh = 0;
    for (plume_index k = 0; k < 3 * m->nt;) {
        plume_index r = k + 1;
        while (r < 3 * m->nt && he[r].a == he[k].a && he[r].b == he[k].b)
            r++;
        if (r - k > 2) {
            st = plume_err_set(err, PLUME_EINVAL, "edge (%ld, %ld) is shared by %ld triangles (non-manifold)",
                               (long)he[k].a, (long)he[k].b, (long)(r - k));
            goto cleanup;
        }
        ne++;
        nh += (r - k == 2);
        k = r;
    }
    free(m->edges);
    free(m->edge_tri);
    free(m->hinges);
    m->edges = malloc((size_t)(2 * ne + 1) * sizeof *m->edges);
    m->edge_tri = malloc((size_t)(2 * ne + 1) * sizeof *m->edge_tri);
    m->hinges = malloc((size_t)(4 * nh + 1) * sizeof *m->hinges);
    if (!m->edges || !m->edge_tri || !m->hinges) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    memset(m->boundary, 0, (size_t)m->nv);
    m->ne = ne;
    m->nh = nh;
    ne = nh = 0;
    for (plume_index k = 0; k < 3 * m->nt;) {
        plume_index r = k + 1;
        while (r < 3 * m->nt && he[r].a == he[k].a && he[r].b == he[k].b)
            r++;
        m->edges[2 * ne] = he[k].a;
        m->edges[2 * ne + 1] = he[k].b;
        m->edge_tri[2 * ne] = he[k].tri;
        m->edge_tri[2 * ne + 1] = r - k == 2 ? he[k + 1].tri : -1;
        if (r - k == 2) {
            plume_index *h = m->hinges + 4 * nh++;
            h[0] = he[k].a;
            h[1] = he[k].b;
            h[2] = m->tri[3 * he[k].tri + he[k].local];
            h[3] = m->tri[3 * he[k + 1].tri + he[k + 1].local];
        } else {
            m->boundary[he[k].a] = m->boundary[he[k].b] = 1;
        }
        ne++;
        k = r;
    }
cleanup:
    free(he);
    return st;
}

plume_index plume_mesh_edge(const plume_mesh *m, plume_index u, plume_index v)
{
    const plume_index i = u < v ? u : v, j = u < v ? v : u;
    plume_index lo = 0, hi = m->ne - 1;
    while (lo <= hi) {
        const plume_index mid = lo + (hi - lo) / 2, a = m->edges[2 * mid], b = m->edges[2 * mid + 1];
        if (a == i && b == j)
            return mid;
        if (a < i || (a == i && b < j))
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}
