/* Narrow-phase contact (lib/contact/contact_narrow.h): squared distances against an independent
 * long-double enumeration and brute-force sampling, finite differences of every gradient and
 * Hessian (distances, mollifier, pair energies), PSD projection, the scalar barrier and penalty,
 * and the error paths. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "contact_ref.h"
#include "harness.h"
#include "test_rng.h"
#include "../lib/contact/contact_narrow.h"
#include "../lib/core/dense.h"

static double norm3d(const double *a)
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

static double dist3(const double *a, const double *b)
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return norm3d(d);
}

static void unit_normal(const double *t0, const double *t1, const double *t2, double *n)
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++)
        e1[k] = t1[k] - t0[k], e2[k] = t2[k] - t0[k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double l = norm3d(n);
    for (int k = 0; k < 3; k++)
        n[k] /= l;
}

static double longest_edge(const double *x, int tri)
{
    /* triangle x+3..x+11, or the two segments of an edge pair */
    if (tri) {
        double l = dist3(x + 3, x + 6), m = dist3(x + 6, x + 9), n = dist3(x + 9, x + 3);
        return fmax(l, fmax(m, n));
    }
    return fmax(dist3(x, x + 3), dist3(x + 6, x + 9));
}

/* ---- distances against references -------------------------------------------------------- */

/* 20000 seeded point–triangle configurations of four kinds: generic, thin triangles (width
 * 1e-3..1e-11 of the long edge, both sides of the flat threshold), points exactly above a vertex
 * or an edge point (region boundaries), points close to the triangle's plane. Every type must
 * occur; the distance must match the long-double enumeration, and brute-force sampling. */
void test_contact_narrow_pt_distance(void)
{
    rng64 rng = {0x9e3779b97f4a7c15ULL};
    int count[PLUME_CONTACT_PT_NTYPES] = {0};
    double max_err_generic = 0, max_err_thin = 0, max_brute_gap = 0;
    int brute_done = 0;
    for (int it = 0; it < 20000; it++) {
        double x[12];
        const int kind = it % 4;
        rand_vec(&rng, -1, 1, x + 3);
        rand_vec(&rng, -1, 1, x + 6);
        rand_vec(&rng, -1, 1, x + 9);
        if (kind == 1) { /* thin: t2 near the segment t0 t1 (or beyond it: a flat cap or needle) */
            const double lam = urange(&rng, -0.5, 1.5), w = pow(10.0, -urange(&rng, 3, 11));
            double dir[3];
            rand_unit(&rng, dir);
            const double L = dist3(x + 3, x + 6);
            for (int k = 0; k < 3; k++)
                x[9 + k] = x[3 + k] + lam * (x[6 + k] - x[3 + k]) + w * L * dir[k];
        }
        if (kind == 2) { /* exactly above a vertex or an edge point along the normal */
            double n[3];
            unit_normal(x + 3, x + 6, x + 9, n);
            const int i = (int)(urand(&rng) * 3), j = (i + 1) % 3;
            const double lam = (it / 4) % 2 ? 0.0 : urand(&rng), h = urange(&rng, -1, 1);
            for (int k = 0; k < 3; k++)
                x[k] = x[3 + 3 * i + k] + lam * (x[3 + 3 * j + k] - x[3 + 3 * i + k]) + h * n[k];
        } else if (kind == 3) { /* near the plane, anywhere around the triangle */
            double n[3];
            unit_normal(x + 3, x + 6, x + 9, n);
            const double u = urange(&rng, -0.5, 1.5), v = urange(&rng, -0.5, 1.5), h = urange(&rng, -1e-3, 1e-3);
            for (int k = 0; k < 3; k++)
                x[k] = x[3 + k] + u * (x[6 + k] - x[3 + k]) + v * (x[9 + k] - x[3 + k]) + h * n[k];
        } else if (kind == 1 && (it / 4) % 2) { /* over the thin triangle's face */
            double n[3];
            unit_normal(x + 3, x + 6, x + 9, n);
            double u = urand(&rng), v = urand(&rng);
            if (u + v > 1)
                u = 1 - u, v = 1 - v;
            const double h = urange(&rng, -1, 1) * pow(10.0, -urange(&rng, 0, 8));
            for (int k = 0; k < 3; k++)
                x[k] = x[3 + k] + u * (x[6 + k] - x[3 + k]) + v * (x[9 + k] - x[3 + k]) + h * n[k];
        } else if (kind != 2) {
            rand_vec(&rng, -2, 2, x);
        }
        plume_contact_pt_type t;
        double d2, d2b;
        CHECK(plume_contact_pt_classify(x, &t) == PLUME_OK);
        CHECK(plume_contact_pt_distance2(x, t, &d2, NULL, NULL) == PLUME_OK);
        CHECK(plume_contact_pt_dist2(x, &d2b) == PLUME_OK && d2b == d2);
        count[t]++;
        const double ref = (double)sqrtl(ref_pt_d2(x)), d = sqrt(d2);
        const double L = longest_edge(x, 1), err = fabs(d - ref) / L;
        if (kind == 1)
            max_err_thin = fmax(max_err_thin, err);
        else
            max_err_generic = fmax(max_err_generic, err);
        if (it % 20 == 0) { /* brute force on a 121-per-side barycentric grid */
            const int n = 120;
            const double bf = sqrt(brute_pt_d2(x, n));
            CHECK(d <= bf + 1e-12 * L);
            CHECK(bf - d <= L / n);
            max_brute_gap = fmax(max_brute_gap, (bf - d) / L);
            brute_done++;
        }
    }
    /* generic: rounding; thin: the flat fallback may overestimate by the width (< 1e-8 L) */
    CHECK(max_err_generic <= 1e-13);
    CHECK(max_err_thin <= 2e-8);
    for (int t = 0; t < PLUME_CONTACT_PT_NTYPES; t++)
        CHECK(count[t] >= 100);
    fprintf(stderr,
            "    point-triangle: types T0..FACE %d %d %d %d %d %d %d; max |d - d_ref|/L generic %.2e, "
            "thin %.2e; %d brute-force checks, max (d_bf - d)/L %.2e\n",
            count[0], count[1], count[2], count[3], count[4], count[5], count[6], max_err_generic,
            max_err_thin, brute_done, max_brute_gap);
}

/* Hand-made point–triangle cases with exact answers: each Voronoi region, points exactly above a
 * vertex / an edge / the face, a collinear triangle, coincident vertices, a needle. */
void test_contact_narrow_pt_exact(void)
{
    const double T[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    struct {
        double p[3];
        double d2;
        int type; /* -1: any */
    } cases[] = {
        {{0.25, 0.25, 0.7}, 0.49, PLUME_CONTACT_PT_FACE},
        {{-1, -1, 0}, 2.0, PLUME_CONTACT_PT_T0},
        {{2, -0.5, 0}, 1.25, PLUME_CONTACT_PT_T1},
        {{-0.5, 2, 0}, 1.25, PLUME_CONTACT_PT_T2},
        {{0.5, -1, 2}, 5.0, PLUME_CONTACT_PT_E01},
        {{1, 1, 0}, 0.5, PLUME_CONTACT_PT_E12},
        {{-1, 0.5, -3}, 10.0, PLUME_CONTACT_PT_E20},
        {{0, 0, 0.3}, 0.09, -1},    /* above a vertex: T0, E01, E20 or FACE all agree */
        {{0.5, 0, -0.3}, 0.09, -1}, /* above an edge point */
        {{0.5, 0.5, 0.3}, 0.09, -1},
        {{0, 0, 0}, 0.0, -1}, /* on the triangle */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double x[12], d2;
        memcpy(x, cases[i].p, sizeof cases[i].p);
        memcpy(x + 3, T, sizeof T);
        plume_contact_pt_type t;
        CHECK(plume_contact_pt_classify(x, &t) == PLUME_OK);
        CHECK(cases[i].type < 0 || (int)t == cases[i].type);
        CHECK(plume_contact_pt_distance2(x, t, &d2, NULL, NULL) == PLUME_OK);
        CHECK_REL(d2, cases[i].d2, 1e-14, 1e-300);
    }
    /* degenerate triangles: never FACE, distance to the union of the segments */
    struct {
        double x[12];
        double d2;
    } deg[] = {
        {{0.5, 1, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0}, 1.0},  /* collinear */
        {{3, 0, 1, 0, 0, 0, 1, 0, 0, 2, 0, 0}, 2.0},    /* collinear, beyond the end */
        {{0.5, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0}, 1.0},  /* t1 = t2 */
        {{1, 2, 5, 1, 2, 3, 1, 2, 3, 1, 2, 3}, 4.0},    /* all three coincide */
        {{0.5, 5e-11, 0.3, 0, 0, 0, 1, 0, 0, 0.5, 1e-10, 0}, 0.09}, /* needle, width 1e-10 */
    };
    for (size_t i = 0; i < sizeof deg / sizeof deg[0]; i++) {
        plume_contact_pt_type t;
        double d2;
        CHECK(plume_contact_pt_classify(deg[i].x, &t) == PLUME_OK);
        CHECK(t != PLUME_CONTACT_PT_FACE);
        CHECK(plume_contact_pt_distance2(deg[i].x, t, &d2, NULL, NULL) == PLUME_OK);
        CHECK(fabs(sqrt(d2) - sqrt(deg[i].d2)) <= 1e-10);
    }
}

/* 24000 seeded segment pairs: generic, nearly parallel (angles 1e-2..1e-12 rad, both sides of the
 * parallel threshold), exactly parallel (offset, collinear overlapping, collinear apart),
 * nearly intersecting, zero-length edges, and nearly parallel edges crossing over each other at a
 * known height h (closest points interior, d = |h| up to the rounding of the coordinates). */
void test_contact_narrow_ee_distance(void)
{
    rng64 rng = {0x2545f4914f6cdd1dULL};
    int count[PLUME_CONTACT_EE_NTYPES] = {0};
    double max_err[5] = {0}, max_err_h = 0;
    int brute_done = 0;
    double max_brute_gap = 0;
    for (int it = 0; it < 24000; it++) {
        double x[12], hknown = -1;
        const int kind = it % 6;
        rand_vec(&rng, -1, 1, x);
        rand_vec(&rng, -1, 1, x + 3);
        rand_vec(&rng, -1, 1, x + 6);
        rand_vec(&rng, -1, 1, x + 9);
        double u[3];
        for (int k = 0; k < 3; k++)
            u[k] = x[3 + k] - x[k];
        if (kind == 1 || kind == 2) {
            /* eb = eb0 + [lo, hi] * (u + small rotation), overlapping ea's extent or not */
            const double th = kind == 1 ? pow(10.0, -urange(&rng, 2, 12)) : 0.0;
            double perp[3];
            rand_unit(&rng, perp);
            const double lo = urange(&rng, -1, 1), hi = lo + urange(&rng, -1.5, 1.5);
            double off[3];
            rand_vec(&rng, -0.3, 0.3, off);
            if (it % 3 == 0) /* collinear or nearly: no offset across */
                for (int k = 0; k < 3; k++)
                    off[k] = 0;
            const double L = norm3d(u);
            for (int k = 0; k < 3; k++) {
                const double dir = u[k] + th * L * perp[k];
                x[6 + k] = x[k] + off[k] + lo * dir;
                x[9 + k] = x[k] + off[k] + hi * dir;
            }
        } else if (kind == 3) { /* through a common point, then pushed apart a little */
            double c[3], v[3], n[3];
            rand_vec(&rng, -0.5, 0.5, c);
            rand_vec(&rng, -1, 1, v);
            rand_unit(&rng, n);
            const double s = urange(&rng, -0.2, 1.2), t = urange(&rng, -0.2, 1.2), h = urange(&rng, -1e-6, 1e-6);
            for (int k = 0; k < 3; k++) {
                x[k] = c[k] - s * u[k];
                x[3 + k] = x[k] + u[k];
                x[6 + k] = c[k] - t * v[k] + h * n[k];
                x[9 + k] = x[6 + k] + v[k];
            }
        } else if (kind == 4) { /* one or both edges of zero length */
            memcpy(x + 3, x, 3 * sizeof *x);
            if (it % 2)
                memcpy(x + 9, x + 6, 3 * sizeof *x);
        } else if (kind == 5) {
            /* eb = ea turned by th about its point at s, in the plane of u and a unit w1 _|_ u,
             * then lifted by h along the unit normal nn = u x w1 / |u| */
            const double L = norm3d(u), th = pow(10.0, -urange(&rng, 0, 13));
            const double sa = urange(&rng, 0.2, 0.8), h = urange(&rng, -0.1, 0.1) * pow(10.0, -urange(&rng, 0, 6));
            double w1[3], nn[3];
            rand_unit(&rng, w1);
            const double uw = (w1[0] * u[0] + w1[1] * u[1] + w1[2] * u[2]) / (L * L);
            for (int k = 0; k < 3; k++)
                w1[k] -= uw * u[k];
            const double wl = norm3d(w1);
            for (int k = 0; k < 3; k++)
                w1[k] /= wl;
            nn[0] = (u[1] * w1[2] - u[2] * w1[1]) / L;
            nn[1] = (u[2] * w1[0] - u[0] * w1[2]) / L;
            nn[2] = (u[0] * w1[1] - u[1] * w1[0]) / L;
            for (int k = 0; k < 3; k++) {
                const double c = x[k] + sa * u[k], dir = cos(th) * u[k] / L + sin(th) * w1[k];
                x[6 + k] = c - 0.4 * L * dir + h * nn[k];
                x[9 + k] = c + 0.5 * L * dir + h * nn[k];
            }
            hknown = fabs(h);
        }
        plume_contact_ee_type t;
        double d2, d2b;
        CHECK(plume_contact_ee_classify(x, &t) == PLUME_OK);
        CHECK(plume_contact_ee_distance2(x, t, &d2, NULL, NULL) == PLUME_OK);
        CHECK(plume_contact_ee_dist2(x, &d2b) == PLUME_OK && d2b == d2);
        count[t]++;
        const double ref = (double)sqrtl(ref_ee_d2(x)), d = sqrt(d2);
        const double L = fmax(longest_edge(x, 0), 0.1); /* both edges may have zero length */
        /* the crossing construction is measured against its known h: below sin ~ 1e-12 even
         * the long-double reference loses digits in its normal */
        if (hknown >= 0)
            max_err_h = fmax(max_err_h, fabs(d - hknown) / L);
        else
            max_err[kind] = fmax(max_err[kind], fabs(d - ref) / L);
        if (it % 24 == 0) {
            const int n = 150;
            const double bf = sqrt(brute_ee_d2(x, n));
            CHECK(d <= bf + 1e-12 * L);
            CHECK(bf - d <= L / n);
            max_brute_gap = fmax(max_brute_gap, (bf - d) / L);
            brute_done++;
        }
    }
    CHECK(max_err[0] <= 1e-13);
    CHECK(max_err[1] <= 1e-13);
    CHECK(max_err[2] <= 1e-13);
    CHECK(max_err[3] <= 1e-13);
    CHECK(max_err[4] <= 1e-13);
    /* crossing nearly parallel: below sin^2 = PLUME_CONTACT_PARALLEL_SIN2 the endpoint fallback
     * overestimates by <= 0.5 L sin < 5e-9 L; just above it the line–line rounding error is
     * ~ h eps / sin < 1e-9 L */
    CHECK(max_err_h <= 1e-8);
    for (int t = 0; t < PLUME_CONTACT_EE_NTYPES; t++)
        CHECK(count[t] >= 100);
    fprintf(stderr,
            "    edge-edge: types %d %d %d %d | %d %d %d %d | %d; max |d - d_ref|/L generic %.2e, "
            "nearly parallel %.2e, parallel %.2e, crossing %.2e, zero-length %.2e, nearly parallel "
            "crossing (vs known h) %.2e; %d brute-force checks, max (d_bf - d)/L %.2e\n",
            count[0], count[1], count[2], count[3], count[4], count[5], count[6], count[7], count[8],
            max_err[0], max_err[1], max_err[2], max_err[3], max_err[4], max_err_h, brute_done, max_brute_gap);
}

/* Hand-made edge–edge cases: skew lines, exactly parallel at a known offset (no LINES), collinear
 * apart, touching at an endpoint, crossing. */
void test_contact_narrow_ee_exact(void)
{
    struct {
        double x[12];
        double d2;
        int type;
    } cases[] = {
        {{-1, 0, 0, 1, 0, 0, 0, -1, 2, 0, 1, 2}, 4.0, PLUME_CONTACT_EE_LINES},
        {{0, 0, 0, 1, 0, 0, 0.2, 0.5, 0, 0.8, 0.5, 0}, 0.25, -1}, /* parallel, overlapping */
        {{0, 0, 0, 1, 0, 0, 3, 0, 0, 2, 0, 0}, 1.0, PLUME_CONTACT_EE_A1B1}, /* collinear, apart */
        {{0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 1, 1}, 0.0, -1},                   /* share an endpoint */
        {{-1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1, 0}, 0.0, PLUME_CONTACT_EE_LINES}, /* crossing */
        {{0, 0, 0, 1, 0, 0, 2, -1, 1, 2, 1, 1}, 2.0, PLUME_CONTACT_EE_A1_EB},
        {{0, 0, 0, 1, 0, 0, 0.5, 1, 3, 0.5, 4, 3}, 10.0, PLUME_CONTACT_EE_B0_EA},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        plume_contact_ee_type t;
        double d2;
        CHECK(plume_contact_ee_classify(cases[i].x, &t) == PLUME_OK);
        CHECK(cases[i].type < 0 || (int)t == cases[i].type);
        CHECK(i != 1 || t != PLUME_CONTACT_EE_LINES);
        CHECK(plume_contact_ee_distance2(cases[i].x, t, &d2, NULL, NULL) == PLUME_OK);
        CHECK_REL(d2, cases[i].d2, 1e-14, 1e-300);
    }
}

/* ---- finite differences ----------------------------------------------------------------- */

/* f(x) with gradient and Hessian (either may be NULL) */
typedef plume_status (*fd_fn)(const void *ctx, const double *x, double *f, double *g, double *H);

typedef struct {
    double grad, hess; /* max |analytic - FD| / max |analytic| over the entries */
} fd_err;

/* Central differences: the gradient from values, the Hessian from gradients. The test must pick
 * x away from any switch of the function's formula within +-h. */
static fd_err fd_check(fd_fn fn, const void *ctx, const double *x, double h)
{
    double f, g[12], H[144], xp[12], xm[12], fp, fm, gp[12], gm[12];
    fd_err e = {0, 0};
    if (fn(ctx, x, &f, g, H) != PLUME_OK)
        return (fd_err){INFINITY, INFINITY};
    double gmax = 0, hmax = 0;
    for (int i = 0; i < 12; i++)
        gmax = fmax(gmax, fabs(g[i]));
    for (int i = 0; i < 144; i++)
        hmax = fmax(hmax, fabs(H[i]));
    for (int j = 0; j < 12; j++) {
        memcpy(xp, x, sizeof xp);
        memcpy(xm, x, sizeof xm);
        xp[j] += h;
        xm[j] -= h;
        if (fn(ctx, xp, &fp, gp, NULL) != PLUME_OK || fn(ctx, xm, &fm, gm, NULL) != PLUME_OK)
            return (fd_err){INFINITY, INFINITY};
        e.grad = fmax(e.grad, fabs((fp - fm) / (2 * h) - g[j]));
        for (int i = 0; i < 12; i++)
            e.hess = fmax(e.hess, fabs((gp[i] - gm[i]) / (2 * h) - H[12 * i + j]));
    }
    e.grad /= fmax(gmax, 1e-300);
    e.hess /= fmax(hmax, 1e-300);
    return e;
}

typedef struct {
    int ee, type;
} typed_ctx;

static plume_status fd_typed(const void *c, const double *x, double *f, double *g, double *H)
{
    const typed_ctx *t = c;
    return t->ee ? plume_contact_ee_distance2(x, (plume_contact_ee_type)t->type, f, g, H)
                 : plume_contact_pt_distance2(x, (plume_contact_pt_type)t->type, f, g, H);
}

/* A random pair configuration with every edge and the triangle well shaped (the typed formulas
 * are smooth away from zero-length edges and zero-area triangles / parallel lines). */
static void well_shaped(rng64 *rng, double *x)
{
    for (;;) {
        for (int i = 0; i < 12; i++)
            x[i] = urange(rng, -1, 1);
        double e1[3], e2[3], n[3], u[3], v[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = x[6 + k] - x[3 + k], e2[k] = x[9 + k] - x[3 + k];
            u[k] = x[3 + k] - x[k], v[k] = x[9 + k] - x[6 + k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double m[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        if (norm3d(n) > 0.2 && norm3d(m) > 0.2 && norm3d(u) > 0.3 && norm3d(v) > 0.3 &&
            dist3(x + 6, x + 9) > 0.3 && norm3d(e1) > 0.3 && norm3d(e2) > 0.3)
            return;
    }
}

/* Every point–triangle and edge–edge type's d^2: 40 random configurations each. */
void test_contact_narrow_fd_distance(void)
{
    rng64 rng = {777};
    fd_err worst = {0, 0};
    for (int ee = 0; ee < 2; ee++) {
        const int nt = ee ? PLUME_CONTACT_EE_NTYPES : PLUME_CONTACT_PT_NTYPES;
        for (int t = 0; t < nt; t++)
            for (int it = 0; it < 40; it++) {
                double x[12];
                well_shaped(&rng, x);
                typed_ctx c = {ee, t};
                fd_err e = fd_check(fd_typed, &c, x, 1e-6);
                CHECK(e.grad <= 1e-7);
                CHECK(e.hess <= 1e-7);
                worst.grad = fmax(worst.grad, e.grad);
                worst.hess = fmax(worst.hess, e.hess);
            }
    }
    fprintf(stderr, "    d^2, 16 types x 40: max rel FD error gradient %.2e, Hessian %.2e\n", worst.grad,
            worst.hess);
}

typedef struct {
    double eps_x;
} moll_ctx;

static plume_status fd_moll(const void *c, const double *x, double *f, double *g, double *H)
{
    return plume_contact_ee_mollifier(x, ((const moll_ctx *)c)->eps_x, f, g, H);
}

/* Nearly parallel edges (the mollifier's active range): m, its gradient and Hessian; m = 1 with zero
 * derivatives beyond the threshold; m and dm/dc continuous at c = eps_x. */
void test_contact_narrow_fd_mollifier(void)
{
    rng64 rng = {4242};
    fd_err worst = {0, 0};
    int active = 0;
    for (int it = 0; it < 300; it++) {
        double x[12], perp[3];
        rand_vec(&rng, -1, 1, x);
        rand_vec(&rng, -1, 1, x + 3);
        rand_unit(&rng, perp);
        const double th = urange(&rng, 0.002, 0.05);
        rand_vec(&rng, -0.5, 0.5, x + 6);
        const double len = urange(&rng, 0.5, 1.5);
        for (int k = 0; k < 3; k++)
            x[9 + k] = x[6 + k] + len * (x[3 + k] - x[k] + th * perp[k]);
        double eps_x, m, c;
        CHECK(plume_contact_ee_mollifier_threshold(x, &eps_x) == PLUME_OK);
        {
            double u[3], v[3];
            for (int k = 0; k < 3; k++)
                u[k] = x[3 + k] - x[k], v[k] = x[9 + k] - x[6 + k];
            double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
            c = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        }
        CHECK(plume_contact_ee_mollifier(x, eps_x, &m, NULL, NULL) == PLUME_OK);
        if (c >= eps_x) {
            double g[12], H[144];
            CHECK(plume_contact_ee_mollifier(x, eps_x, &m, g, H) == PLUME_OK);
            CHECK(m == 1.0);
            int zero = 1;
            for (int i = 0; i < 12; i++)
                zero &= g[i] == 0.0;
            for (int i = 0; i < 144; i++)
                zero &= H[i] == 0.0;
            CHECK(zero);
            continue;
        }
        if (c > 0.98 * eps_x) /* FD across the switch would see the kink in m'' */
            continue;
        active++;
        CHECK_REL(m, (2 - c / eps_x) * c / eps_x, 1e-12, 1e-300);
        moll_ctx mc = {eps_x};
        fd_err e = fd_check(fd_moll, &mc, x, 1e-7);
        CHECK(e.grad <= 1e-6);
        CHECK(e.hess <= 1e-6);
        worst.grad = fmax(worst.grad, e.grad);
        worst.hess = fmax(worst.hess, e.hess);
    }
    CHECK(active >= 100);
    fprintf(stderr, "    mollifier: %d active configurations, max rel FD error gradient %.2e, Hessian %.2e\n",
            active, worst.grad, worst.hess);
}

typedef struct {
    plume_contact_opts o;
    int ee;
    double eps_x;
} energy_ctx;

static plume_status fd_energy(const void *c, const double *x, double *f, double *g, double *H)
{
    const energy_ctx *e = c;
    return e->ee ? plume_contact_ee_energy(&e->o, x, e->eps_x, f, g, H, NULL)
                 : plume_contact_pt_energy(&e->o, x, f, g, H, NULL);
}

static int type_of(int ee, const double *x)
{
    if (ee) {
        plume_contact_ee_type t;
        return plume_contact_ee_classify(x, &t) == PLUME_OK ? (int)t : -1;
    }
    plume_contact_pt_type t;
    return plume_contact_pt_classify(x, &t) == PLUME_OK ? (int)t : -1;
}

/* the classification is the same at x +- h e_j for every j (FD stays on one formula) */
static int stable_type(int ee, const double *x, double h)
{
    const int t = type_of(ee, x);
    double y[12];
    for (int j = 0; j < 12; j++)
        for (int s = -1; s <= 1; s += 2) {
            memcpy(y, x, sizeof y);
            y[j] += s * 3 * h;
            if (type_of(ee, y) != t)
                return 0;
        }
    return 1;
}

static double pair_distance(int ee, const double *x)
{
    double d2;
    if (ee)
        plume_contact_ee_dist2(x, &d2);
    else
        plume_contact_pt_dist2(x, &d2);
    return sqrt(d2);
}

/* Barrier and penalty pair energies (unprojected), every point–triangle and edge–edge type,
 * mollifier off, on and active (nearly parallel edges), at distances 0.05..0.95 dhat. */
void test_contact_narrow_fd_energy(void)
{
    rng64 rng = {31337};
    const double h = 1e-7;
    for (int model = 0; model < 2; model++) {
        for (int ee = 0; ee < 2; ee++) {
            const int nt = ee ? PLUME_CONTACT_EE_NTYPES : PLUME_CONTACT_PT_NTYPES;
            int done[PLUME_CONTACT_EE_NTYPES] = {0}, moll_active = 0, tested = 0;
            fd_err worst = {0, 0};
            for (int it = 0; it < 40000 && tested < 600; it++) {
                energy_ctx c;
                plume_contact_opts_default(&c.o);
                c.o.model = model ? PLUME_CONTACT_PENALTY : PLUME_CONTACT_BARRIER;
                c.o.dhat = 0.2;
                c.o.stiffness = urange(&rng, 0.5, 100);
                c.o.project_psd = 0;
                c.ee = ee;
                c.eps_x = 0.0;
                double x[12];
                for (int i = 0; i < 12; i++)
                    x[i] = urange(&rng, -0.5, 0.5);
                if (ee && it % 3 == 0) { /* nearly parallel: the mollifier is active */
                    double perp[3];
                    rand_unit(&rng, perp);
                    const double th = urange(&rng, 0.001, 0.04), len = urange(&rng, 0.5, 1.2);
                    for (int k = 0; k < 3; k++)
                        x[9 + k] = x[6 + k] + len * (x[3 + k] - x[k] + th * perp[k]);
                }
                if (ee && it % 2 == 0) {
                    double xr[12];
                    memcpy(xr, x, sizeof xr);
                    CHECK(plume_contact_ee_mollifier_threshold(xr, &c.eps_x) == PLUME_OK);
                }
                const double d = pair_distance(ee, x);
                if (!(d > 0.05 * c.o.dhat && d < 0.95 * c.o.dhat) || longest_edge(x, !ee) < 0.2)
                    continue;
                const int t = type_of(ee, x);
                if (t < 0 || done[t] >= 600 / nt + 10 || !stable_type(ee, x, h))
                    continue;
                if (ee && c.eps_x > 0) { /* stay off the mollifier's switch too */
                    double m, y[12];
                    plume_contact_ee_mollifier(x, c.eps_x, &m, NULL, NULL);
                    int same = 1;
                    for (int j = 0; j < 12 && same; j++)
                        for (int s = -1; s <= 1; s += 2) {
                            double my;
                            memcpy(y, x, sizeof y);
                            y[j] += 3 * s * h;
                            plume_contact_ee_mollifier(y, c.eps_x, &my, NULL, NULL);
                            same &= (my < 1.0) == (m < 1.0);
                        }
                    if (!same)
                        continue;
                    moll_active += m < 1.0;
                }
                fd_err e = fd_check(fd_energy, &c, x, h);
                CHECK(e.grad <= 1e-6);
                CHECK(e.hess <= 1e-6);
                worst.grad = fmax(worst.grad, e.grad);
                worst.hess = fmax(worst.hess, e.hess);
                done[t]++;
                tested++;
            }
            int least = done[0];
            for (int t = 0; t < nt; t++) {
                CHECK(done[t] >= 5);
                least = done[t] < least ? done[t] : least;
            }
            if (ee)
                CHECK(moll_active >= 20);
            fprintf(stderr,
                    "    %s %s: %d configurations (at least %d per type, mollifier active in %d), max "
                    "rel FD error gradient %.2e, Hessian %.2e\n",
                    model ? "penalty" : "barrier", ee ? "edge-edge" : "point-triangle", tested, least,
                    moll_active, worst.grad, worst.hess);
        }
    }
}

/* ---- PSD projection ---------------------------------------------------------------------- */

/* The projected 12x12 blocks: no eigenvalue below -1e-12 max|eig|, equal to V max(L, 0) V^T of
 * the unprojected block, gradient untouched, and a projected block passes a second projection
 * unchanged (it is already PSD). */
void test_contact_narrow_psd(void)
{
    rng64 rng = {99};
    int tested = 0, indefinite = 0;
    double worst_neg = 0, worst_ref = 0, worst_idem = 0;
    for (int it = 0; it < 20000 && tested < 400; it++) {
        const int ee = it % 2;
        plume_contact_opts o;
        plume_contact_opts_default(&o);
        o.model = (it / 2) % 2 ? PLUME_CONTACT_PENALTY : PLUME_CONTACT_BARRIER;
        o.dhat = 0.3;
        o.stiffness = 10;
        double x[12];
        for (int i = 0; i < 12; i++)
            x[i] = urange(&rng, -0.5, 0.5);
        const double d = pair_distance(ee, x);
        if (!(d > 0.01 && d < 0.29))
            continue;
        double eps_x = 0;
        if (ee)
            plume_contact_ee_mollifier_threshold(x, &eps_x);
        double E0, E1, g0[12], g1[12], H0[144], H1[144];
        o.project_psd = 0;
        CHECK((ee ? plume_contact_ee_energy(&o, x, eps_x, &E0, g0, H0, NULL)
                  : plume_contact_pt_energy(&o, x, &E0, g0, H0, NULL)) == PLUME_OK);
        o.project_psd = 1;
        CHECK((ee ? plume_contact_ee_energy(&o, x, eps_x, &E1, g1, H1, NULL)
                  : plume_contact_pt_energy(&o, x, &E1, g1, H1, NULL)) == PLUME_OK);
        CHECK(E0 == E1 && memcmp(g0, g1, sizeof g0) == 0);
        double A[144], lam[12], V[144], lam1[12], V1[144];
        memcpy(A, H0, sizeof A);
        plume_dense_sym_eig(12, A, lam, V);
        const double big = fmax(fabs(lam[0]), fabs(lam[11]));
        indefinite += lam[0] < -1e-12 * big;
        double err = 0;
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++) {
                double r = 0;
                for (int k = 0; k < 12; k++)
                    r += V[12 * i + k] * fmax(lam[k], 0.0) * V[12 * j + k];
                err = fmax(err, fabs(r - H1[12 * i + j]));
            }
        worst_ref = fmax(worst_ref, err / big);
        CHECK(err <= 1e-10 * big);
        memcpy(A, H1, sizeof A);
        plume_dense_sym_eig(12, A, lam1, V1);
        worst_neg = fmax(worst_neg, -lam1[0] / big);
        CHECK(lam1[0] >= -1e-12 * big);
        memcpy(A, H1, sizeof A);
        plume_dense_project_psd(12, A);
        double idem = 0;
        for (int i = 0; i < 144; i++)
            idem = fmax(idem, fabs(A[i] - H1[i]));
        worst_idem = fmax(worst_idem, idem / big);
        CHECK(idem <= 1e-12 * big);
        tested++;
    }
    CHECK(tested >= 400);
    CHECK(indefinite >= tested / 2); /* the point: contact blocks are indefinite */
    fprintf(stderr,
            "    %d blocks (%d indefinite before projection): min eig after >= %.2e max|eig|, "
            "|P - V max(L,0) V^T| <= %.2e, reprojection change <= %.2e (relative to max|eig|)\n",
            tested, indefinite, -worst_neg, worst_ref, worst_idem);
}

/* ---- scalar potentials ------------------------------------------------------------------- */

void test_contact_narrow_barrier(void)
{
    const double dhat = 0.01;
    double b, b1, b2;
    CHECK(plume_contact_barrier(dhat, dhat, &b, &b1, &b2) == PLUME_OK);
    CHECK(b == 0 && b1 == 0 && b2 == 0);
    CHECK(plume_contact_barrier(2 * dhat, dhat, &b, &b1, &b2) == PLUME_OK && b == 0 && b1 == 0 && b2 == 0);
    /* C^2 at dhat from the left: at d = dhat (1 - e), b ~ e^3 dhat^2, b' ~ -3 e^2 dhat, b'' ~ 6 e */
    const double e = 1e-6;
    CHECK(plume_contact_barrier(dhat * (1 - e), dhat, &b, &b1, &b2) == PLUME_OK);
    CHECK_REL(b, e * e * e * dhat * dhat, 1e-5, 0);
    CHECK_REL(b1, -3 * e * e * dhat, 1e-5, 0);
    CHECK_REL(b2, 6 * e, 1e-5, 0);
    /* decreasing, convex, positive on (0, dhat); derivatives against central differences */
    const int n = 10000;
    double prev = INFINITY, worst1 = 0, worst2 = 0;
    int mono = 1, convex = 1;
    for (int i = 1; i < n; i++) {
        const double d = dhat * i / n, h = 1e-6 * d;
        double bp, bm, b1p, b1m;
        CHECK(plume_contact_barrier(d, dhat, &b, &b1, &b2) == PLUME_OK);
        plume_contact_barrier(d + h, dhat, &bp, &b1p, NULL);
        plume_contact_barrier(d - h, dhat, &bm, &b1m, NULL);
        mono &= b < prev && b > 0 && b1 < 0;
        convex &= b2 > 0;
        prev = b;
        if (i < n - 100) { /* near dhat b'' -> 0 and FD cancels */
            worst1 = fmax(worst1, fabs((bp - bm) / (2 * h) - b1) / fabs(b1));
            worst2 = fmax(worst2, fabs((b1p - b1m) / (2 * h) - b2) / fabs(b2));
        }
    }
    CHECK(mono);
    CHECK(convex);
    CHECK(worst1 <= 1e-6);
    CHECK(worst2 <= 1e-6);
    /* +inf as d -> 0: b(dhat 10^-k) > dhat^2 (k ln 10 - 2) and increasing, down to 1e-300 */
    prev = 0;
    for (int k = 1; k <= 300; k++) {
        CHECK(plume_contact_barrier(dhat * pow(10.0, -k), dhat, &b, NULL, NULL) == PLUME_OK);
        CHECK(b > prev && b > dhat * dhat * (k * log(10.0) - 2));
        prev = b;
    }
    /* d <= 0: infeasible */
    CHECK(plume_contact_barrier(0.0, dhat, &b, &b1, &b2) == PLUME_ESINGULAR && isinf(b) && b > 0);
    CHECK(plume_contact_barrier(-1e-3, dhat, &b, NULL, NULL) == PLUME_ESINGULAR && isinf(b));
    CHECK(plume_contact_barrier(NAN, dhat, &b, NULL, NULL) == PLUME_ESINGULAR);
    CHECK(plume_contact_barrier(0.5, 0.0, &b, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_barrier(0.5, -1, &b, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_barrier(0.5, INFINITY, &b, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_barrier(0.5, 1, NULL, NULL, NULL) == PLUME_EINVAL);
    fprintf(stderr, "    barrier: %d points, max rel FD error b' %.2e, b'' %.2e\n", n - 1, worst1, worst2);

    /* penalty */
    double p, p1, p2;
    CHECK(plume_contact_penalty(0.0, dhat, &p, &p1, &p2) == PLUME_OK);
    CHECK(p == 0.5 * dhat * dhat && p1 == -dhat && p2 == 1);
    CHECK(plume_contact_penalty(0.25 * dhat, dhat, &p, &p1, &p2) == PLUME_OK);
    CHECK_REL(p, 0.5 * 0.75 * 0.75 * dhat * dhat, 1e-15, 0);
    CHECK_REL(p1, -0.75 * dhat, 1e-15, 0);
    CHECK(plume_contact_penalty(dhat, dhat, &p, &p1, &p2) == PLUME_OK && p == 0 && p1 == 0 && p2 == 0);
    CHECK(plume_contact_penalty(-1e-9, dhat, &p, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_penalty(NAN, dhat, &p, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_penalty(INFINITY, dhat, &p, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_penalty(0.1, 0, &p, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_penalty(0.1, 1, NULL, NULL, NULL) == PLUME_EINVAL);
}

/* The chain rule at tiny distances: point–point pairs at d = 1e-9 .. 1e-14 dhat against the closed
 * forms grad_p E = k phi'(d) r/d and hess_pp E = k [phi'' r r^T/d^2 + phi'/d (I - r r^T/d^2)]. */
void test_contact_narrow_small_distance(void)
{
    double worst_g = 0, worst_h = 0;
    for (int model = 0; model < 2; model++)
        for (int k = 9; k <= 14; k++) {
            plume_contact_opts o;
            plume_contact_opts_default(&o);
            o.model = model ? PLUME_CONTACT_PENALTY : PLUME_CONTACT_BARRIER;
            o.dhat = 1e-3;
            o.stiffness = 3.0;
            o.project_psd = 0;
            const double d = o.dhat * pow(10.0, -k);
            /* p - t0 = (-0.6, -0.48, 0.64) d (|p - t0| = d) lies in the vertex region of t0 */
            double x[12] = {-0.6 * d, -0.48 * d, 0.64 * d, 0, 0, 0, 1, 0.2, 0, 0.3, 1, 0};
            double E, g[12], H[144];
            plume_contact_pt_type t;
            CHECK(plume_contact_pt_energy(&o, x, &E, g, H, &t) == PLUME_OK);
            CHECK(t == PLUME_CONTACT_PT_T0);
            double f, f1, f2;
            const double dd = sqrt(pow(x[0] - x[3], 2) + pow(x[1] - x[4], 2) + pow(x[2] - x[5], 2));
            if (model)
                plume_contact_penalty(dd, o.dhat, &f, &f1, &f2);
            else
                plume_contact_barrier(dd, o.dhat, &f, &f1, &f2);
            double rv[3] = {x[0] - x[3], x[1] - x[4], x[2] - x[5]};
            double gm = 0, hm = 0, ge = 0, he = 0;
            for (int a = 0; a < 3; a++) {
                const double ga = o.stiffness * f1 * rv[a] / dd;
                ge = fmax(ge, fabs(g[a] - ga));
                gm = fmax(gm, fabs(ga));
                for (int b = 0; b < 3; b++) {
                    const double P = rv[a] * rv[b] / (dd * dd);
                    const double ha = o.stiffness * (f2 * P + f1 / dd * ((a == b) - P));
                    he = fmax(he, fabs(H[12 * a + b] - ha));
                    hm = fmax(hm, fabs(ha));
                }
            }
            CHECK(isfinite(E) && ge <= 1e-12 * gm && he <= 1e-12 * hm);
            worst_g = fmax(worst_g, ge / gm);
            worst_h = fmax(worst_h, he / hm);
        }
    fprintf(stderr, "    d = 1e-9..1e-14 dhat: max rel error gradient %.2e, Hessian %.2e\n", worst_g, worst_h);
}

/* The mollified edge–edge energy is C^1 where the mollifier switches on (c = eps_x) and vanishes
 * as the edges turn exactly parallel, through the switch of the distance formula at
 * PLUME_CONTACT_PARALLEL_SIN2. */
void test_contact_narrow_mollifier_continuity(void)
{
    plume_contact_opts o;
    plume_contact_opts_default(&o);
    o.dhat = 0.5;
    o.stiffness = 1;
    o.project_psd = 0;
    /* ea along x; eb above it at height 0.1, turned by theta about z */
    double xr[12] = {0, 0, 0, 1, 0, 0, 0.1, 0.05, 0.1, 0.9, 0.05, 0.1};
    double eps_x;
    CHECK(plume_contact_ee_mollifier_threshold(xr, &eps_x) == PLUME_OK);
    CHECK_REL(eps_x, 1e-3 * 1.0 * 0.64, 1e-14, 0);
    double x[12];
#define SET_THETA(th)                                                                       \
    do {                                                                                    \
        memcpy(x, xr, sizeof x);                                                            \
        x[9] = 0.1 + 0.8 * cos(th);                                                         \
        x[10] = 0.05 + 0.8 * sin(th);                                                       \
    } while (0)
    /* c = |u x v|^2 = (0.8 sin th)^2: the switch is at sin th = sqrt(eps_x) / 0.8 */
    const double ths = asin(sqrt(eps_x) / 0.8);
    double Em, Ep, gm[12], gp[12], Hm[144], Hp[144];
    SET_THETA(ths * (1 - 1e-9));
    CHECK(plume_contact_ee_energy(&o, x, eps_x, &Em, gm, Hm, NULL) == PLUME_OK);
    SET_THETA(ths * (1 + 1e-9));
    CHECK(plume_contact_ee_energy(&o, x, eps_x, &Ep, gp, Hp, NULL) == PLUME_OK);
    double gj = 0, gmax = 0;
    for (int i = 0; i < 12; i++) {
        gj = fmax(gj, fabs(gp[i] - gm[i]));
        gmax = fmax(gmax, fabs(gp[i]));
    }
    CHECK(fabs(Ep - Em) <= 1e-7 * Ep);
    CHECK(gj <= 1e-6 * gmax);
    /* towards parallel: E ~ (2 c / eps_x) Eb -> 0, across the parallel threshold and at 0 */
    double prevE = Em;
    for (int k = 3; k <= 12; k++) {
        double E;
        SET_THETA(pow(10.0, -k));
        CHECK(plume_contact_ee_energy(&o, x, eps_x, &E, gp, NULL, NULL) == PLUME_OK);
        CHECK(E < prevE && E <= 2.0 * 0.64 * pow(10.0, -2 * k) / eps_x * 1.0);
        prevE = E;
    }
    double E;
    SET_THETA(0.0);
    plume_contact_ee_type t;
    CHECK(plume_contact_ee_energy(&o, x, eps_x, &E, gp, Hp, &t) == PLUME_OK);
    CHECK(E == 0.0 && t != PLUME_CONTACT_EE_LINES);
    for (int i = 0; i < 12; i++)
        CHECK(gp[i] == 0.0);
#undef SET_THETA
}

/* Pairs at or beyond dhat cost nothing and return exact zeros; the type is still reported. */
void test_contact_narrow_far_pairs(void)
{
    plume_contact_opts o;
    plume_contact_opts_default(&o);
    o.dhat = 0.1;
    double x[12] = {0.2, 0.2, 0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0}; /* d = dhat exactly */
    double E = -1, g[12], H[144];
    for (int i = 0; i < 12; i++)
        g[i] = NAN;
    for (int i = 0; i < 144; i++)
        H[i] = NAN;
    plume_contact_pt_type t;
    CHECK(plume_contact_pt_energy(&o, x, &E, g, H, &t) == PLUME_OK);
    CHECK(E == 0 && t == PLUME_CONTACT_PT_FACE);
    int zero = 1;
    for (int i = 0; i < 12; i++)
        zero &= g[i] == 0;
    for (int i = 0; i < 144; i++)
        zero &= H[i] == 0;
    CHECK(zero);
    double y[12] = {0, 0, 1, 1, 0, 1, 0, 0, 0, 0, 1, 0};
    CHECK(plume_contact_ee_energy(&o, y, 1e-3, &E, g, NULL, NULL) == PLUME_OK && E == 0);
    /* just inside: positive energy, and for the penalty also at contact */
    x[2] = 0.05;
    CHECK(plume_contact_pt_energy(&o, x, &E, NULL, NULL, NULL) == PLUME_OK && E > 0);
    x[2] = 0.0;
    CHECK(plume_contact_pt_energy(&o, x, &E, g, H, NULL) == PLUME_ESINGULAR && isinf(E));
    o.model = PLUME_CONTACT_PENALTY;
    o.stiffness = 4;
    CHECK(plume_contact_pt_energy(&o, x, &E, g, H, NULL) == PLUME_OK);
    CHECK_REL(E, 4 * 0.5 * 0.01, 1e-15, 0);
    zero = 1;
    for (int i = 0; i < 12; i++)
        zero &= g[i] == 0;
    CHECK(zero);
}

/* every error path */
void test_contact_narrow_bad_inputs(void)
{
    double x[12] = {0.2, 0.2, 0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0}, d2, m, e;
    plume_contact_pt_type pt;
    plume_contact_ee_type et;
    CHECK(plume_contact_pt_classify(NULL, &pt) == PLUME_EINVAL);
    CHECK(plume_contact_pt_classify(x, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_classify(NULL, &et) == PLUME_EINVAL);
    CHECK(plume_contact_ee_classify(x, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_distance2(NULL, PLUME_CONTACT_PT_FACE, &d2, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_distance2(x, PLUME_CONTACT_PT_FACE, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_distance2(x, (plume_contact_pt_type)-1, &d2, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_distance2(x, PLUME_CONTACT_PT_NTYPES, &d2, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_distance2(x, PLUME_CONTACT_EE_NTYPES, &d2, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_distance2(x, PLUME_CONTACT_EE_LINES, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_dist2(x, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_dist2(x, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_dist2(NULL, &d2) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier_threshold(NULL, &e) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier_threshold(x, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier(x, 0.0, &m, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier(x, -1.0, &m, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier(x, NAN, &m, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier(x, 1.0, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_mollifier(NULL, 1.0, &m, NULL, NULL) == PLUME_EINVAL);
    /* non-finite coordinates anywhere */
    for (int i = 0; i < 12; i += 5) {
        double y[12];
        memcpy(y, x, sizeof y);
        y[i] = i % 2 ? INFINITY : NAN;
        CHECK(plume_contact_pt_classify(y, &pt) == PLUME_EINVAL);
        CHECK(plume_contact_ee_classify(y, &et) == PLUME_EINVAL);
        CHECK(plume_contact_pt_distance2(y, PLUME_CONTACT_PT_T0, &d2, NULL, NULL) == PLUME_EINVAL);
        CHECK(plume_contact_ee_distance2(y, PLUME_CONTACT_EE_A0B0, &d2, NULL, NULL) == PLUME_EINVAL);
        CHECK(plume_contact_pt_dist2(y, &d2) == PLUME_EINVAL);
        CHECK(plume_contact_ee_mollifier_threshold(y, &e) == PLUME_EINVAL);
        CHECK(plume_contact_ee_mollifier(y, 1.0, &m, NULL, NULL) == PLUME_EINVAL);
    }
    /* singular formulas asked for explicitly */
    double flat[12] = {0, 1, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0}; /* collinear triangle */
    CHECK(plume_contact_pt_distance2(flat, PLUME_CONTACT_PT_FACE, &d2, NULL, NULL) == PLUME_ESINGULAR);
    double dup[12] = {0, 1, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0}; /* t0 = t1 */
    CHECK(plume_contact_pt_distance2(dup, PLUME_CONTACT_PT_E01, &d2, NULL, NULL) == PLUME_ESINGULAR);
    double par[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 1, 0};
    CHECK(plume_contact_ee_distance2(par, PLUME_CONTACT_EE_LINES, &d2, NULL, NULL) == PLUME_ESINGULAR);
    double pnt[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0}; /* eb of zero length */
    CHECK(plume_contact_ee_distance2(pnt, PLUME_CONTACT_EE_A0_EB, &d2, NULL, NULL) == PLUME_ESINGULAR);
    CHECK(plume_contact_ee_classify(pnt, &et) == PLUME_OK && et == PLUME_CONTACT_EE_A0B0);
    /* energies */
    plume_contact_opts o, bad;
    plume_contact_opts_default(&o);
    plume_contact_opts_default(NULL);
    CHECK(o.model == PLUME_CONTACT_BARRIER && o.dhat == 1e-3 && o.stiffness == 1 && o.project_psd);
    double E;
    CHECK(plume_contact_pt_energy(NULL, x, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_energy(&o, NULL, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_pt_energy(&o, x, NULL, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_energy(&o, x, -1e-3, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_energy(&o, x, NAN, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_energy(NULL, x, 0, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    bad = o;
    bad.model = (plume_contact_model)7;
    CHECK(plume_contact_pt_energy(&bad, x, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    bad = o;
    bad.dhat = 0;
    CHECK(plume_contact_pt_energy(&bad, x, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    bad.dhat = NAN;
    CHECK(plume_contact_ee_energy(&bad, x, 0, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    bad = o;
    bad.stiffness = -1;
    CHECK(plume_contact_pt_energy(&bad, x, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    bad.stiffness = INFINITY;
    CHECK(plume_contact_ee_energy(&bad, x, 0, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    double y[12];
    memcpy(y, x, sizeof y);
    y[4] = NAN;
    CHECK(plume_contact_pt_energy(&o, y, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_contact_ee_energy(&o, y, 0, &E, NULL, NULL, NULL) == PLUME_EINVAL);
    /* crossing edges with the barrier: infeasible, E = +inf */
    double cross[12] = {-1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1, 0};
    CHECK(plume_contact_ee_energy(&o, cross, 1e-3, &E, NULL, NULL, NULL) == PLUME_ESINGULAR && isinf(E));
}

/* The Gauss-Newton blocks (the default): phi''(d) grad d grad d^T, PSD and of rank one, the energy
 * and gradient those of the exact blocks; where the pair's distance is between two points (the
 * point in a corner region of the triangle) they equal the nearest PSD matrix, since Hess d is then
 * PSD and orthogonal to grad d. */
void test_contact_narrow_gauss_newton(void)
{
    rng64 rng = {1234};
    int tested = 0, corners = 0;
    double worst_neg = 0.0, worst_rank = 0.0, worst_corner = 0.0;
    for (int it = 0; it < 20000 && tested < 400; it++) {
        plume_contact_opts o;
        plume_contact_opts_default(&o);
        CHECK(o.project_psd == PLUME_CONTACT_PROJECT_GAUSS_NEWTON);
        o.model = it % 2 ? PLUME_CONTACT_PENALTY : PLUME_CONTACT_BARRIER;
        o.dhat = 0.3;
        o.stiffness = 10;
        double x[12];
        for (int i = 0; i < 12; i++)
            x[i] = urange(&rng, -0.5, 0.5);
        const double d = pair_distance(0, x);
        if (!(d > 0.01 && d < 0.29))
            continue;
        double E0, E2, g0[12], g2[12], H0[144], H2[144], H1[144], E1, g1[12];
        plume_contact_pt_type type;
        o.project_psd = 0;
        CHECK(plume_contact_pt_energy(&o, x, &E0, g0, H0, &type) == PLUME_OK);
        o.project_psd = PLUME_CONTACT_PROJECT_EIGEN;
        CHECK(plume_contact_pt_energy(&o, x, &E1, g1, H1, NULL) == PLUME_OK);
        o.project_psd = PLUME_CONTACT_PROJECT_GAUSS_NEWTON;
        CHECK(plume_contact_pt_energy(&o, x, &E2, g2, H2, NULL) == PLUME_OK);
        CHECK(E0 == E2 && memcmp(g0, g2, sizeof g0) == 0);
        double A[144], lam[12], V[144];
        memcpy(A, H2, sizeof A);
        plume_dense_sym_eig(12, A, lam, V);
        const double big = fmax(fabs(lam[0]), fabs(lam[11]));
        worst_neg = fmax(worst_neg, -lam[0] / big);
        worst_rank = fmax(worst_rank, fabs(lam[10]) / big);
        CHECK(lam[0] >= -1e-12 * big && fabs(lam[10]) <= 1e-12 * big);
        if (type == PLUME_CONTACT_PT_T0 || type == PLUME_CONTACT_PT_T1 || type == PLUME_CONTACT_PT_T2) {
            double err = 0.0;
            for (int i = 0; i < 144; i++)
                err = fmax(err, fabs(H2[i] - H1[i]));
            worst_corner = fmax(worst_corner, err / big);
            CHECK(err <= 1e-10 * big);
            corners++;
        }
        tested++;
    }
    fprintf(stderr, "    %d point-triangle blocks (%d at a corner): min eig >= %.2e, second eig <= %.2e, corner blocks "
                    "against the nearest PSD <= %.2e (relative to max|eig|)\n",
            tested, corners, -worst_neg, worst_rank, worst_corner);
    CHECK(tested >= 400 && corners >= 20);
    /* a projection mode out of range is refused */
    plume_contact_opts o;
    plume_contact_opts_default(&o);
    o.project_psd = 3;
    double x[12] = {0, 0, 0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0}, E;
    CHECK(plume_contact_pt_energy(&o, x, &E, NULL, NULL, NULL) == PLUME_EINVAL);
}
