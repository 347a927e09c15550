/* Anchored edge frames of midedge bending (internal/midedge_anchor.h). */
#include "internal/midedge_anchor.h"
#include "../../lib/core/vec3.h"

#include <math.h>
#include <stdlib.h>

void plume_midedge_rest_point(const plume_mesh *m, const double *rest_x, plume_index v, double p[3])
{
    if (rest_x) {
        p[0] = rest_x[3 * v], p[1] = rest_x[3 * v + 1], p[2] = rest_x[3 * v + 2];
    } else {
        p[0] = m->X[2 * v], p[1] = m->X[2 * v + 1], p[2] = 0.0;
    }
}

/* The orthonormal frame F = [e1 e2 e3] (columns, row-major F[i][j] = e_j[i]) of points p0, p1, p2
 * of x; -1 when they lie within MIDEDGE_ANCHOR_MIN_SPREAD of one line. */
static int anchor_frame(const double *x, const plume_index p[3], double F[3][3])
{
    double a[3], b[3], n[3], e2[3];
    sub3(x + 3 * p[1], x + 3 * p[0], a);
    sub3(x + 3 * p[2], x + 3 * p[0], b);
    cross3(a, b, n);
    const double la = sqrt(dot3(a, a)), ln = sqrt(dot3(n, n));
    if (!(la > 0.0) || !(ln > MIDEDGE_ANCHOR_MIN_SPREAD * la * la))
        return -1;
    for (int i = 0; i < 3; i++)
        a[i] /= la, n[i] /= ln;
    cross3(n, a, e2);
    for (int i = 0; i < 3; i++)
        F[i][0] = a[i], F[i][1] = e2[i], F[i][2] = n[i];
    return 0;
}

int plume_midedge_group_anchors(const plume_mesh *m, const double *rest_x, const int *group, int ngroup,
                                plume_index *anchor)
{
    for (int g = 0; g < 3 * ngroup; g++)
        anchor[g] = -1;
    double *best = calloc((size_t)(ngroup > 0 ? ngroup : 1), sizeof *best);
    if (!best)
        return -1;
    for (int pass = 0; pass < 3; pass++) {
        for (int g = 0; g < ngroup; g++)
            best[g] = 0.0;
        for (plume_index v = 0; v < m->nv; v++) {
            const int g = group[v];
            if (g <= 0 || g >= ngroup)
                continue;
            plume_index *a = anchor + 3 * g;
            if (pass == 0) {
                if (a[0] < 0)
                    a[0] = v;
                continue;
            }
            double p[3], p0[3], d[3];
            plume_midedge_rest_point(m, rest_x, v, p);
            plume_midedge_rest_point(m, rest_x, a[0], p0);
            sub3(p, p0, d);
            double q = dot3(d, d);
            if (pass == 2 && a[1] >= 0) { /* the distance from line p0 p1, squared, times |p1 - p0|^2 */
                double p1[3], u[3], c[3];
                plume_midedge_rest_point(m, rest_x, a[1], p1);
                sub3(p1, p0, u);
                cross3(d, u, c);
                q = dot3(c, c);
            }
            if (q > best[g])
                best[g] = q, a[pass] = v;
        }
    }
    for (int g = 0; g < ngroup; g++) { /* three points off one line, or none */
        plume_index *a = anchor + 3 * g;
        double p0[3], p1[3], u[3];
        if (a[0] >= 0 && a[1] >= 0 && a[2] >= 0) {
            plume_midedge_rest_point(m, rest_x, a[0], p0);
            plume_midedge_rest_point(m, rest_x, a[1], p1);
            sub3(p1, p0, u);
            if (sqrt(best[g]) > MIDEDGE_ANCHOR_MIN_SPREAD * dot3(u, u))
                continue;
        }
        a[0] = a[1] = a[2] = -1;
    }
    free(best);
    return 0;
}

plume_status plume_midedge_anchors_init(plume_midedge_anchors *a, plume_index ne, plume_index nv,
                                        const plume_index *anchor, const double *rest, const double *r0,
                                        plume_err *err)
{
    a->ne = ne, a->vertex = NULL, a->local = NULL;
    if (!anchor)
        return PLUME_OK;
    a->vertex = malloc(3 * (size_t)(ne > 0 ? ne : 1) * sizeof *a->vertex);
    a->local = malloc(3 * (size_t)(ne > 0 ? ne : 1) * sizeof *a->local);
    if (!a->vertex || !a->local) {
        plume_midedge_anchors_free(a);
        return plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory for the edges' anchors");
    }
    for (plume_index e = 0; e < ne; e++) {
        const plume_index *p = anchor + 3 * e;
        a->vertex[3 * e] = -1;
        if (p[0] < 0)
            continue;
        for (int k = 0; k < 3; k++)
            if (p[k] < 0 || p[k] >= nv) {
                plume_midedge_anchors_free(a);
                return plume_err_set(err, PLUME_EINVAL, "midedge bending: edge %ld: anchor vertex %ld out of range [0, %ld)",
                                     (long)e, (long)p[k], (long)nv);
            }
        double F[3][3];
        if (anchor_frame(rest, p, F) != 0) {
            plume_midedge_anchors_free(a);
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: edge %ld: anchors %ld, %ld, %ld lie on one line",
                                 (long)e, (long)p[0], (long)p[1], (long)p[2]);
        }
        for (int j = 0; j < 3; j++) {
            a->vertex[3 * e + j] = p[j];
            a->local[3 * e + j] = F[0][j] * r0[3 * e] + F[1][j] * r0[3 * e + 1] + F[2][j] * r0[3 * e + 2];
        }
    }
    return PLUME_OK;
}

void plume_midedge_anchors_free(plume_midedge_anchors *a)
{
    free(a->vertex);
    free(a->local);
    a->vertex = NULL, a->local = NULL;
}

int plume_midedge_anchors_frame(const plume_midedge_anchors *a, const double *x, plume_index e, double out[3])
{
    double F[3][3];
    if (!a->vertex || a->vertex[3 * e] < 0 || anchor_frame(x, a->vertex + 3 * e, F) != 0)
        return 0;
    const double *l = a->local + 3 * e;
    for (int i = 0; i < 3; i++)
        out[i] = F[i][0] * l[0] + F[i][1] * l[1] + F[i][2] * l[2];
    return 1;
}
