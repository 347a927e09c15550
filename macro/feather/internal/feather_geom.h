/* plume (private, not installed): small 2D geometry for the feather mesher (macro/feather_*.c)
 * and the OBJ outline reader; static inline because the mesher calls them in its innermost loops. */
#ifndef PLUME_MACRO_INTERNAL_FEATHER_GEOM_H
#define PLUME_MACRO_INTERNAL_FEATHER_GEOM_H

#include <math.h>

#include "../../../lib/core/status.h"
#include "../feather_mesh.h"

#define FM_PI 3.14159265358979323846

/* |(x, y)|: coordinates are lengths in metres, far from overflow, and hypot() is several times slower */
static inline double norm2(double x, double y)
{
    return sqrt(x * x + y * y);
}

static inline double orient(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static inline int in_box(const double *a, const double *b, const double *c)
{
    return c[0] >= fmin(a[0], b[0]) && c[0] <= fmax(a[0], b[0]) && c[1] >= fmin(a[1], b[1]) &&
           c[1] <= fmax(a[1], b[1]);
}

/* closed segments ab and cd share a point (validation) */
static inline int segs_touch(const double *a, const double *b, const double *c, const double *d)
{
    double d1 = orient(c, d, a), d2 = orient(c, d, b), d3 = orient(a, b, c), d4 = orient(a, b, d);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return 1;
    return (d1 == 0 && in_box(c, d, a)) || (d2 == 0 && in_box(c, d, b)) || (d3 == 0 && in_box(a, b, c)) ||
           (d4 == 0 && in_box(a, b, d));
}

/* Parametric intersection of p0p1 with q0q1 (closed): 1 and t (along p), u (along q), else 0.
 * Collinear overlaps count, at the first overlapping point of p. */
static inline int seg_intersect(const double *p0, const double *p1, const double *q0, const double *q1, double *t,
                         double *u)
{
    double rx = p1[0] - p0[0], ry = p1[1] - p0[1], sx = q1[0] - q0[0], sy = q1[1] - q0[1];
    double wx = q0[0] - p0[0], wy = q0[1] - p0[1];
    double den = rx * sy - ry * sx;
    double rn = norm2(rx, ry), sn = norm2(sx, sy);
    if (rn == 0 || sn == 0)
        return 0;
    if (fabs(den) <= 1e-13 * rn * sn) {
        if (fabs(wx * ry - wy * rx) > 1e-13 * rn * (rn + norm2(wx, wy)))
            return 0;
        double rr = rn * rn;
        double t0 = (wx * rx + wy * ry) / rr, t1 = ((q1[0] - p0[0]) * rx + (q1[1] - p0[1]) * ry) / rr;
        double lo = fmin(t0, t1), hi = fmax(t0, t1);
        if (hi < 0 || lo > 1)
            return 0;
        *t = fmax(lo, 0.0);
        double px = p0[0] + *t * rx - q0[0], py = p0[1] + *t * ry - q0[1];
        *u = fmin(1.0, fmax(0.0, (px * sx + py * sy) / (sn * sn)));
        return 1;
    }
    double tt = (wx * sy - wy * sx) / den, uu = (wx * ry - wy * rx) / den;
    if (tt < 0 || tt > 1 || uu < 0 || uu > 1)
        return 0;
    *t = tt, *u = uu;
    return 1;
}

/* distance from p to segment ab; *tp receives the foot parameter */
static inline double seg_dist(const double *p, const double *a, const double *b, double *tp)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
    t = fmin(1.0, fmax(0.0, t));
    if (tp)
        *tp = t;
    return norm2(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

/* distance between segments ab and cd (0 when they touch) */
static inline double segseg_dist(const double *a, const double *b, const double *c, const double *d)
{
    double t, u;
    if (seg_intersect(a, b, c, d, &t, &u))
        return 0;
    return fmin(fmin(seg_dist(a, c, d, NULL), seg_dist(b, c, d, NULL)),
                fmin(seg_dist(c, a, b, NULL), seg_dist(d, a, b, NULL)));
}

static inline int point_in_polygon(const double *poly, plume_index n, const double *p)
{
    int in = 0;
    for (plume_index i = 0, j = n - 1; i < n; j = i++) {
        const double *a = poly + 2 * i, *b = poly + 2 * j;
        if ((a[1] > p[1]) != (b[1] > p[1]) && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0])
            in = !in;
    }
    return in;
}

static inline double polygon_area(const double *p, plume_index n)
{
    double s = 0;
    for (plume_index i = 0, j = n - 1; i < n; j = i++)
        s += p[2 * j] * p[2 * i + 1] - p[2 * i] * p[2 * j + 1];
    return 0.5 * s;
}

#endif
