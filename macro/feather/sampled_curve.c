/* plume: sampled curves and spline sampling (macro/feather/internal/sampled_curve.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_spline.h>

#include "internal/feather_geom.h"
#include "internal/sampled_curve.h"

void plume_sampled_curve_free(plume_sampled_curve *c)
{
    free(c->x), free(c->y), free(c->s), free(c->a);
    memset(c, 0, sizeof *c);
}

int plume_sampled_curve_push(plume_sampled_curve *c, double x, double y)
{
    if (c->n == c->cap) {
        plume_index cap = c->cap ? 2 * c->cap : 64;
        double *v[4] = {c->x, c->y, c->s, c->a};
        for (int k = 0; k < 4; k++) {
            double *r = realloc(v[k], (size_t)cap * sizeof *r);
            if (!r)
                return -1;
            v[k] = r;
            if (k == 0)
                c->x = r;
            else if (k == 1)
                c->y = r;
            else if (k == 2)
                c->s = r;
            else
                c->a = r;
        }
        c->cap = cap;
    }
    c->x[c->n] = x, c->y[c->n] = y;
    c->n++;
    return 0;
}

/* Arc length from the first sample and tangent angles by central differences, unwrapped. */
void plume_sampled_curve_finish(plume_sampled_curve *c)
{
    c->s[0] = 0;
    for (plume_index i = 1; i < c->n; i++)
        c->s[i] = c->s[i - 1] + norm2(c->x[i] - c->x[i - 1], c->y[i] - c->y[i - 1]);
    for (plume_index i = 0; i < c->n; i++) {
        plume_index i0 = i > 0 ? i - 1 : 0, i1 = i + 1 < c->n ? i + 1 : c->n - 1;
        double a = atan2(c->y[i1] - c->y[i0], c->x[i1] - c->x[i0]);
        if (i > 0) {
            while (a - c->a[i - 1] > FM_PI)
                a -= 2 * FM_PI;
            while (a - c->a[i - 1] < -FM_PI)
                a += 2 * FM_PI;
        }
        c->a[i] = a;
    }
}

/* Samples the natural cubic spline through a validated polyline (no coincident neighbours) about
 * every h (at least 16 samples, every input point among them).
 * The chord-length parameter is strictly increasing, and evaluation stays inside its range: GSL's
 * default error handler would abort otherwise, and changing it is process-wide state. */
plume_status plume_sample_spline(const plume_polyline *pl, double h, plume_sampled_curve *out)
{
    plume_index n = pl->n;
    const double *p = pl->p;
    plume_status st = PLUME_OK;
    double *u = malloc((size_t)n * sizeof *u), *xs = malloc((size_t)n * sizeof *xs),
           *ys = malloc((size_t)n * sizeof *ys);
    gsl_spline *sx = NULL, *sy = NULL;
    gsl_interp_accel *acc = NULL;
    if (!u || !xs || !ys) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    u[0] = 0;
    for (plume_index i = 0; i < n; i++) {
        xs[i] = p[2 * i], ys[i] = p[2 * i + 1];
        if (i > 0)
            u[i] = u[i - 1] + norm2(xs[i] - xs[i - 1], ys[i] - ys[i - 1]);
    }
    const gsl_interp_type *type = n >= 3 ? gsl_interp_cspline : gsl_interp_linear;
    sx = gsl_spline_alloc(type, (size_t)n);
    sy = gsl_spline_alloc(type, (size_t)n);
    acc = gsl_interp_accel_alloc();
    if (!sx || !sy || !acc) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    gsl_spline_init(sx, u, xs, (size_t)n);
    gsl_spline_init(sy, u, ys, (size_t)n);
    if (!(h > 0) || u[n - 1] / h < 16)
        h = u[n - 1] / 16;
    for (plume_index i = 0; i + 1 < n; i++) {
        long m = (long)ceil((u[i + 1] - u[i]) / h);
        if (m < 2)
            m = 2;
        for (long j = 0; j < m; j++) {
            double uu = u[i] + (u[i + 1] - u[i]) * (double)j / (double)m;
            if (j == 0) {
                if (plume_sampled_curve_push(out, xs[i], ys[i]) < 0) {
                    st = PLUME_ENOMEM;
                    goto cleanup;
                }
                continue;
            }
            if (plume_sampled_curve_push(out, gsl_spline_eval(sx, uu, acc), gsl_spline_eval(sy, uu, acc)) < 0) {
                st = PLUME_ENOMEM;
                goto cleanup;
            }
        }
    }
    if (plume_sampled_curve_push(out, xs[n - 1], ys[n - 1]) < 0)
        st = PLUME_ENOMEM;
cleanup:
    gsl_spline_free(sx);
    gsl_spline_free(sy);
    gsl_interp_accel_free(acc);
    free(u), free(xs), free(ys);
    return st;
}
