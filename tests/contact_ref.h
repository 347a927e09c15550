/* Reference distances for the contact tests, written independently of lib/contact/contact_narrow.c:
 * exhaustive candidate enumeration in long double (every vertex, clamped segment, and the interior
 * solution when it lies inside) and brute-force sampling on a parameter grid. */
#ifndef PLUME_TEST_CONTACT_REF_H
#define PLUME_TEST_CONTACT_REF_H

#include <math.h>

#include "test_rng.h"

typedef long double ldbl;

static inline ldbl ref_dot(const ldbl a[3], const ldbl b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void ref_cross(const ldbl a[3], const ldbl b[3], ldbl c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline void ref_sub(const double *a, const double *b, ldbl c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = (ldbl)a[k] - (ldbl)b[k];
}

/* squared distance of p to the segment (a, b), clamped parameter */
static inline ldbl ref_seg_d2(const double *p, const double *a, const double *b)
{
    ldbl e[3], r[3];
    ref_sub(b, a, e);
    ref_sub(p, a, r);
    ldbl ee = ref_dot(e, e), t = ee > 0 ? ref_dot(r, e) / ee : 0;
    if (t < 0)
        t = 0;
    if (t > 1)
        t = 1;
    ldbl q[3] = {r[0] - t * e[0], r[1] - t * e[1], r[2] - t * e[2]};
    return ref_dot(q, q);
}

/* point–triangle, x = (p, t0, t1, t2) */
static inline ldbl ref_pt_d2(const double *x)
{
    const double *p = x, *a = x + 3, *b = x + 6, *c = x + 9;
    ldbl best = ref_seg_d2(p, a, b);
    ldbl d = ref_seg_d2(p, b, c);
    if (d < best)
        best = d;
    d = ref_seg_d2(p, c, a);
    if (d < best)
        best = d;
    /* the face: barycentrics by Cramer's rule with cross products (w = u e1 + v e2 + l n), which
     * keeps thin triangles accurate where the normal equations' A C - B^2 would cancel */
    ldbl e1[3], e2[3], w[3], n[3], c1[3], c2[3];
    ref_sub(b, a, e1);
    ref_sub(c, a, e2);
    ref_sub(p, a, w);
    ref_cross(e1, e2, n);
    const ldbl N = ref_dot(n, n);
    if (N > 0) {
        ref_cross(w, e2, c1);
        ref_cross(e1, w, c2);
        const ldbl u = ref_dot(c1, n) / N, v = ref_dot(c2, n) / N;
        if (u >= 0 && v >= 0 && u + v <= 1) {
            d = ref_dot(w, n) * ref_dot(w, n) / N;
            if (d < best)
                best = d;
        }
    }
    return best;
}

/* edge–edge, x = (ea0, ea1, eb0, eb1) */
static inline ldbl ref_ee_d2(const double *x)
{
    const double *a0 = x, *a1 = x + 3, *b0 = x + 6, *b1 = x + 9;
    ldbl best = ref_seg_d2(a0, b0, b1), d;
    if ((d = ref_seg_d2(a1, b0, b1)) < best)
        best = d;
    if ((d = ref_seg_d2(b0, a0, a1)) < best)
        best = d;
    if ((d = ref_seg_d2(b1, a0, a1)) < best)
        best = d;
    /* the interiors: a0 + s u + l n = b0 + t v solved with cross products (no a c - b^2) */
    ldbl u[3], v[3], w[3], n[3], c1[3], c2[3];
    ref_sub(a1, a0, u);
    ref_sub(b1, b0, v);
    ref_sub(b0, a0, w);
    ref_cross(u, v, n);
    const ldbl N = ref_dot(n, n);
    if (N > 0) {
        ref_cross(w, v, c1);
        ref_cross(w, u, c2);
        const ldbl s = ref_dot(c1, n) / N, t = ref_dot(c2, n) / N;
        if (s >= 0 && s <= 1 && t >= 0 && t <= 1) {
            d = ref_dot(w, n) * ref_dot(w, n) / N;
            if (d < best)
                best = d;
        }
    }
    return best;
}

/* brute force: minimum over an (n+1)-per-side barycentric grid of the triangle */
static inline double brute_pt_d2(const double *x, int n)
{
    double best = INFINITY;
    for (int i = 0; i <= n; i++)
        for (int j = 0; i + j <= n; j++) {
            const double u = (double)i / n, v = (double)j / n;
            double d2 = 0;
            for (int k = 0; k < 3; k++) {
                const double y = x[3 + k] + u * (x[6 + k] - x[3 + k]) + v * (x[9 + k] - x[3 + k]);
                d2 += (x[k] - y) * (x[k] - y);
            }
            if (d2 < best)
                best = d2;
        }
    return best;
}

/* brute force: minimum over an (n+1) x (n+1) grid of the two segments' parameters */
static inline double brute_ee_d2(const double *x, int n)
{
    double best = INFINITY;
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++) {
            const double s = (double)i / n, t = (double)j / n;
            double d2 = 0;
            for (int k = 0; k < 3; k++) {
                const double ya = x[k] + s * (x[3 + k] - x[k]);
                const double yb = x[6 + k] + t * (x[9 + k] - x[6 + k]);
                d2 += (ya - yb) * (ya - yb);
            }
            if (d2 < best)
                best = d2;
        }
    return best;
}

static inline void rand_vec(rng64 *r, double lo, double hi, double *v)
{
    for (int k = 0; k < 3; k++)
        v[k] = urange(r, lo, hi);
}

/* a random unit vector */
static inline void rand_unit(rng64 *r, double *v)
{
    double n;
    do {
        rand_vec(r, -1, 1, v);
        n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (n < 0.1 || n > 1);
    for (int k = 0; k < 3; k++)
        v[k] /= n;
}

#endif
