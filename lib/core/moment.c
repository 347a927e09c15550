/* The end moment of lib/core/moment.h.
 *
 * With P = I - a a^T, s = P t (the part of t across the axis) and phi the angle of s about a,
 *     d phi / d t = (a x s) / |s|^2,
 *     d2 phi / d t2 = -(e1 e2^T + e2 e1^T) / |s|^2,  e1 = s / |s|, e2 = a x e1,
 * (differentiate (a x s)/|s|^2: [a]x / |s|^2 - 2 (a x s) s^T / |s|^4, whose antisymmetric part
 * cancels once written in the basis (e1, e2, a)). t is linear in x: dt/dx_i = I / nend on the
 * end, -I / nrow on the row, so the energy -M phi has gradient -M (dphi/dt) c_i and Hessian
 * blocks -M c_i c_j (d2 phi / dt2). The term is one stencil over all its vertices. */
#include "moment.h"
#include "vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
    plume_index n, nend;  /* stencil: end vertices first, then the row */
    plume_index *v;
    double axis[3], e0[3], f0[3]; /* axis; rest direction of s (unit) and a x e0 */
    double M, M0;         /* current and nominal moment */
    double phi;           /* angle at the last evaluation (continued across +-pi) */
} moment_ctx;

static void moment_destroy(void *ctx)
{
    moment_ctx *c = ctx;
    if (c)
        free(c->v);
    free(c);
}

/* t = mean(end) - mean(row) at positions x (3 per vertex, indexed by vertex id) */
static void end_direction(const moment_ctx *c, const double *x, double t[3])
{
    t[0] = t[1] = t[2] = 0.0;
    const double we = 1.0 / (double)c->nend, wr = 1.0 / (double)(c->n - c->nend);
    for (plume_index k = 0; k < c->n; k++) {
        double w = k < c->nend ? we : -wr;
        for (int a = 0; a < 3; a++)
            t[a] += w * x[3 * c->v[k] + a];
    }
}

static plume_status moment_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                                int project)
{
    moment_ctx *c = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    double t[3], s[3];
    end_direction(c, x, t);
    double ta = t[0] * c->axis[0] + t[1] * c->axis[1] + t[2] * c->axis[2];
    for (int a = 0; a < 3; a++)
        s[a] = t[a] - ta * c->axis[a];
    double s2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
    if (!(s2 > 0.0))
        return PLUME_ESINGULAR; /* the end turned onto the axis: phi is undefined */
    double cs = s[0] * c->e0[0] + s[1] * c->e0[1] + s[2] * c->e0[2];
    double sn = s[0] * c->f0[0] + s[1] * c->f0[1] + s[2] * c->f0[2];
    double raw = atan2(sn, cs);
    double turns = round((c->phi - raw) / (2.0 * M_PI)); /* continue from the last evaluation */
    double phi = raw + 2.0 * M_PI * turns;
    c->phi = phi;
    if (energy)
        *energy -= c->M * phi;
    double g[3]; /* d phi / d t */
    cross3(c->axis, s, g);
    for (int a = 0; a < 3; a++)
        g[a] /= s2;
    const double we = 1.0 / (double)c->nend, wr = -1.0 / (double)(c->n - c->nend);
    if (grad)
        for (plume_index k = 0; k < c->n; k++) {
            double w = k < c->nend ? we : wr;
            for (int a = 0; a < 3; a++)
                grad[3 * c->v[k] + a] -= c->M * w * g[a];
        }
    if (hblocks) {
        /* -M d2phi/dt2 = M (e1 e2^T + e2 e1^T) / |s|^2: indefinite (eigenvalues +-M/|s|^2);
         * projected, it keeps its positive part M (e1 + e2)(e1 + e2)^T / (2 |s|^2) for M > 0
         * (the negative part for M < 0) */
        double ls = sqrt(s2), e1[3], e2[3], T[3][3];
        for (int a = 0; a < 3; a++)
            e1[a] = s[a] / ls;
        cross3(c->axis, e1, e2);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                if (!project) {
                    T[a][b] = c->M * (e1[a] * e2[b] + e2[a] * e1[b]) / s2;
                } else {
                    double sg = c->M >= 0.0 ? 1.0 : -1.0;
                    double u = e1[a] + sg * e2[a], w = e1[b] + sg * e2[b];
                    T[a][b] = fabs(c->M) * u * w / (2.0 * s2);
                }
            }
        const plume_index k3 = 3 * c->n;
        for (plume_index i = 0; i < c->n; i++) {
            double wi = i < c->nend ? we : wr;
            for (plume_index j = 0; j < c->n; j++) {
                double wij = wi * (j < c->nend ? we : wr);
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++)
                        hblocks[(3 * i + a) * k3 + 3 * j + b] = wij * T[a][b];
            }
        }
    }
    return PLUME_OK;
}

plume_status plume_moment_term_create(const plume_index *end, plume_index nend, const plume_index *row,
                                      plume_index nrow, const double axis[3], double moment, const double *X3,
                                      plume_term *out, plume_err *err)
{
    if (!out || !end || !row || !axis || !X3 || nend < 1 || nrow < 1)
        return plume_err_set(err, PLUME_EINVAL, "moment: needs end vertices, a second row, an axis and rest positions");
    double al = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    if (!(al > 0.0) || !isfinite(al) || !isfinite(moment))
        return plume_err_set(err, PLUME_EINVAL, "moment: the axis must be non-zero and finite, the moment finite");
    for (plume_index i = 0; i < nend; i++)
        for (plume_index j = 0; j < nrow; j++)
            if (end[i] == row[j])
                return plume_err_set(err, PLUME_EINVAL, "moment: vertex %ld is in the end and in its second row",
                                     (long)end[i]);
    moment_ctx *c = calloc(1, sizeof *c);
    if (!c || !(c->v = malloc((size_t)(nend + nrow) * sizeof *c->v))) {
        free(c);
        return plume_err_set(err, PLUME_ENOMEM, "moment: out of memory");
    }
    c->n = nend + nrow;
    c->nend = nend;
    memcpy(c->v, end, (size_t)nend * sizeof *c->v);
    memcpy(c->v + nend, row, (size_t)nrow * sizeof *c->v);
    for (int a = 0; a < 3; a++)
        c->axis[a] = axis[a] / al;
    double t[3];
    end_direction(c, X3, t);
    double ta = t[0] * c->axis[0] + t[1] * c->axis[1] + t[2] * c->axis[2];
    for (int a = 0; a < 3; a++)
        c->e0[a] = t[a] - ta * c->axis[a];
    double l = sqrt(c->e0[0] * c->e0[0] + c->e0[1] * c->e0[1] + c->e0[2] * c->e0[2]);
    double tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    if (!(l > 1e-8 * tl)) {
        moment_destroy(c);
        return plume_err_set(err, PLUME_EINVAL, "moment: the end lies along the axis from its second row (no lever)");
    }
    for (int a = 0; a < 3; a++)
        c->e0[a] /= l;
    cross3(c->axis, c->e0, c->f0);
    c->M = c->M0 = moment;
    memset(out, 0, sizeof *out);
    out->name = "moment";
    out->arity = (int)c->n;
    out->nstencil = 1;
    out->stencil = c->v;
    out->size = sizeof *out;
    out->eval = moment_eval;
    out->destroy = moment_destroy;
    out->ctx = c;
    return PLUME_OK;
}

void plume_moment_scale(plume_term *t, double factor)
{
    moment_ctx *c = t->ctx;
    c->M = factor * c->M0;
}

double plume_moment_angle(const plume_term *t)
{
    return ((const moment_ctx *)t->ctx)->phi;
}
