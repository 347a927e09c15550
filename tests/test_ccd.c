/* Continuous collision detection (lib/contact/ccd.h, Additive CCD): known crossings through a face, an
 * edge, a vertex, crossing and parallel edges, zero-length edges and motions; grazing passes;
 * options, cap and errors; and seeded random trajectories checked against brute-force time
 * sampling of the signed volume (a crossing must never be missed) and of the distance (the
 * guaranteed separation must hold everywhere before toi). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "contact_ref.h"
#include "harness.h"
#include "test_rng.h"
#include "../lib/contact/ccd.h"
#include "../lib/contact/contact_narrow.h"

static void lerp12(const double *x0, const double *x1, double t, double *x)
{
    for (int i = 0; i < 12; i++)
        x[i] = x0[i] + t * (x1[i] - x0[i]);
}

/* independent distance (long-double enumeration) at time t */
static double ref_dist_at(int ee, const double *x0, const double *x1, double t)
{
    double x[12];
    lerp12(x0, x1, t, x);
    return (double)sqrtl(ee ? ref_ee_d2(x) : ref_pt_d2(x));
}

static plume_status run_ccd(int ee, const double *x0, const double *x1, double t_max,
                            const plume_ccd_opts *o, double *toi, plume_ccd_report *rep)
{
    return ee ? plume_ccd_edge_edge(x0, x1, t_max, o, toi, rep)
              : plume_ccd_point_triangle(x0, x1, t_max, o, toi, rep);
}

/* A trajectory that touches (distance 0) at t_star: CCD must stop strictly before it, at a
 * positive distance, with the separation guarantee at 200 samples of [0, toi]. */
static void check_crossing(const char *what, int ee, const double *x0, const double *x1, double t_star,
                           double min_fraction)
{
    plume_ccd_opts o;
    plume_ccd_opts_default(&o);
    double toi = -1;
    plume_ccd_report rep;
    CHECK(run_ccd(ee, x0, x1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(ref_dist_at(ee, x0, x1, t_star) <= 1e-12); /* the test's premise */
    CHECK(toi > 0 && toi < t_star && rep.hit && !rep.capped);
    const double d_toi = ref_dist_at(ee, x0, x1, toi), gap0 = ref_dist_at(ee, x0, x1, 0);
    CHECK(d_toi > 0 && d_toi >= o.s * gap0 * (1 - 1e-12));
    double dmin = INFINITY;
    for (int k = 0; k <= 200; k++)
        dmin = fmin(dmin, ref_dist_at(ee, x0, x1, toi * k / 200));
    CHECK(dmin >= (1 - o.eta) * o.s * gap0 * (1 - 1e-12));
    CHECK(toi >= min_fraction * t_star); /* not absurdly conservative */
    fprintf(stderr, "    %-40s t* = %.3f  toi = %.4f  d(toi) = %.3g  (%ld evaluations)\n", what, t_star, toi,
            d_toi, rep.iterations);
}

void test_contact_narrow_ccd_point_triangle_crossings(void)
{
    /* triangle (0,0,0) (1,0,0) (0,1,0) static; the point passes through the face interior, an
     * edge, a vertex, all at t = 0.5 */
    const double T[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    double x0[12], x1[12];
    memcpy(x0 + 3, T, sizeof T);
    memcpy(x1 + 3, T, sizeof T);
    const double face[6] = {0.25, 0.25, 1, 0.25, 0.25, -1};
    const double edge[6] = {0.5, -0.5, 0.5, 0.5, 0.5, -0.5};
    const double vert[6] = {-0.5, -0.5, 1, 0.5, 0.5, -1};
    const double *paths[3] = {face, edge, vert};
    const char *names[3] = {"point through the face (head-on)", "point through an edge", "point through a vertex"};
    for (int i = 0; i < 3; i++) {
        memcpy(x0, paths[i], 3 * sizeof(double));
        memcpy(x1, paths[i] + 3, 3 * sizeof(double));
        /* head-on the relative speed equals l_p: ACCD stops at 0.9 t* exactly (paper's first
         * step (1 - s) = 0.9 of the gap, the next one would leave less than s gap0) */
        check_crossing(names[i], 0, x0, x1, 0.5, i == 0 ? 0.899 : 0.5);
    }
    /* the triangle moving onto a static point, and both moving */
    double y0[12] = {0.2, 0.3, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1};
    double y1[12] = {0.2, 0.3, 0, 0, 0, -1, 1, 0, -1, 0, 1, -1};
    check_crossing("triangle moving through a static point", 0, y0, y1, 0.5, 0.5);
    double z0[12] = {0.2, 0.3, 1.5, 0, 0, 0.5, 1, 0, 0.5, 0, 1, 0.5};
    double z1[12] = {0.2, 0.3, -1.5, 0.1, 0, -0.5, 1.1, 0, -0.5, 0.1, 1, -0.5};
    check_crossing("point and triangle moving towards each other", 0, z0, z1, 0.5, 0.5);
    /* a triangle crossed while it rotates: t1 sweeps down through the point's path */
    double r0[12] = {0.5, 0.1, 0.2, 0, 0, 0, 1, 0, 0.6, 0, 1, 0};
    double r1[12] = {0.5, 0.1, 0.2, 0, 0, 0, 1, 0, -0.6, 0, 1, 0};
    /* the plane z = (0.6 - 1.2 t) x through t0, t2 and t1(t) reaches p = (0.5, 0.1, 0.2) at t = 1/6 */
    check_crossing("point swept by a rotating triangle", 0, r0, r1, 1.0 / 6.0, 0.3);
}

void test_contact_narrow_ccd_edge_edge_crossings(void)
{
    /* ea static on the x axis; eb along y descending through it at t = 0.5 */
    double a0[12] = {-1, 0, 0, 1, 0, 0, 0.2, -1, 1, 0.2, 1, 1};
    double a1[12] = {-1, 0, 0, 1, 0, 0, 0.2, -1, -1, 0.2, 1, -1};
    check_crossing("edges crossing (perpendicular)", 1, a0, a1, 0.5, 0.899);
    /* exactly parallel edges: eb parallel to ea sliding sideways onto it */
    double p0[12] = {0, 0, 0, 1, 0, 0, 0.2, 1, 0, 0.8, 1, 0};
    double p1[12] = {0, 0, 0, 1, 0, 0, 0.2, -1, 0, 0.8, -1, 0};
    check_crossing("exactly parallel edges sliding together", 1, p0, p1, 0.5, 0.899);
    /* collinear edges sliding along their common line until the ends meet at t = 0.5 */
    double c0[12] = {0, 0, 0, 1, 0, 0, 1.5, 0, 0, 2.5, 0, 0};
    double c1[12] = {0, 0, 0, 1, 0, 0, 0.5, 0, 0, 1.5, 0, 0};
    check_crossing("collinear edges sliding end to end", 1, c0, c1, 0.5, 0.899);
    /* parallel but not collinear, overlapping: one above the other, closing vertically */
    double v0[12] = {0, 0, 0, 1, 0, 0, -0.5, 0, 1, 0.5, 0, 1};
    double v1[12] = {0, 0, 0, 1, 0, 0, -0.5, 0, -1, 0.5, 0, -1};
    check_crossing("parallel edges closing face to face", 1, v0, v1, 0.5, 0.899);
    /* a zero-length edge (a point) moving through an edge */
    double z0[12] = {-1, 0, 0, 1, 0, 0, 0.3, 0.5, 0.5, 0.3, 0.5, 0.5};
    double z1[12] = {-1, 0, 0, 1, 0, 0, 0.3, -0.5, -0.5, 0.3, -0.5, -0.5};
    check_crossing("zero-length edge through an edge", 1, z0, z1, 0.5, 0.5);
    /* both edges moving, one rotating */
    double m0[12] = {-1, 0, 0.5, 1, 0, 0.5, 0, -1, -0.5, 0, 1, -0.5};
    double m1[12] = {-1, 0, -0.5, 1, 0.2, -0.5, 0, -1, 0.5, 0, 1, 0.5};
    check_crossing("edges moving through each other", 1, m0, m1, 0.5, 0.5);
}

/* No relative motion, rigid translation, a pass at a comfortable distance: toi = t_max, no hit.
 * A close pass (the gap dips under s gap0 but stays positive): a hit before the closest
 * approach, distance positive everywhere before toi. A long slide at constant gap: toi = 1 after
 * about l_p / (eta gap) evaluations. */
void test_contact_narrow_ccd_no_contact(void)
{
    plume_ccd_opts o;
    plume_ccd_opts_default(&o);
    plume_ccd_report rep;
    double toi;
    double x0[12] = {0.25, 0.25, 0.3, 0, 0, 0, 1, 0, 0, 0, 1, 0}, x1[12];
    memcpy(x1, x0, sizeof x1);
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(toi == 1.0 && !rep.hit && rep.iterations == 0 && rep.gap_start == rep.gap_toi);
    CHECK(plume_ccd_edge_edge(x0, x1, 0.7, &o, &toi, &rep) == PLUME_OK && toi == 0.7 && !rep.hit);
    for (int i = 0; i < 12; i++) /* rigid translation by (3, -2, 5) */
        x1[i] = x0[i] + (i % 3 == 0 ? 3 : i % 3 == 1 ? -2 : 5);
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, &toi, &rep) == PLUME_OK && toi == 1.0 && !rep.hit);
    CHECK(plume_ccd_edge_edge(x0, x1, 1.0, &o, &toi, &rep) == PLUME_OK && toi == 1.0 && !rep.hit);

    /* comfortable pass: height 0.5 over the face, gap never below s gap0 */
    double g0[12] = {-0.2, 0.25, 0.5, 0, 0, 0, 1, 0, 0, 0, 1, 0}, g1[12];
    memcpy(g1, g0, sizeof g1);
    g1[0] = 1.2;
    CHECK(plume_ccd_point_triangle(g0, g1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(toi == 1.0 && !rep.hit);
    /* grazing: height 1e-4 starting 1 away; the gap falls below s gap0 = 0.1: a conservative hit */
    double h0[12] = {-1, 0.25, 1e-4, 0, 0, 0, 1, 0, 0, 0, 1, 0}, h1[12];
    memcpy(h1, h0, sizeof h1);
    h1[0] = 2;
    CHECK(plume_ccd_point_triangle(h0, h1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(toi > 0 && toi < 1 && rep.hit);
    CHECK(ref_dist_at(0, h0, h1, toi) >= 0.1 * (1 - 1e-12));
    for (int k = 0; k <= 100; k++)
        CHECK(ref_dist_at(0, h0, h1, toi * k / 100) > 0.0);
    /* sliding over the face at constant height 0.05: the gap never shrinks, toi = 1 */
    double s0[12] = {0.1, 0.1, 0.05, 0, 0, 0, 2, 0, 0, 0, 2, 0}, s1[12];
    memcpy(s1, s0, sizeof s1);
    s1[0] = 1.1;
    CHECK(plume_ccd_point_triangle(s0, s1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(toi == 1.0 && !rep.hit && !rep.capped);
    /* l_p = 1 (3/4 + 1/4 after removing the mean), steps 0.9 * 0.05 */
    CHECK(rep.iterations >= 20 && rep.iterations <= 25);
    fprintf(stderr, "    slide at constant gap 0.05 over length 1: toi = 1 after %ld evaluations\n", rep.iterations);

    /* the cap: the same slide with 5 evaluations stops early, flagged, still safe */
    o.max_iter = 5;
    CHECK(plume_ccd_point_triangle(s0, s1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(rep.capped && rep.hit && rep.iterations == 5 && toi > 0 && toi < 1);
    CHECK(ref_dist_at(0, s0, s1, toi) >= 0.05 * (1 - 1e-12));
    o.max_iter = 1;
    CHECK(plume_ccd_point_triangle(s0, s1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(rep.capped && toi > 0); /* the first step is certified without a look: toi > 0 always */
}

/* t_max, thickness (min_distance), s and eta, and every error path. */
void test_contact_narrow_ccd_options(void)
{
    plume_ccd_opts o;
    plume_ccd_opts_default(&o);
    plume_ccd_opts_default(NULL);
    CHECK(o.s == 0.1 && o.min_distance == 0 && o.eta == 0.9 && o.max_iter == 1000000);
    plume_ccd_report rep;
    double toi;
    /* head-on, contact at t = 0.5 */
    double x0[12] = {0.25, 0.25, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0}, x1[12];
    memcpy(x1, x0, sizeof x1);
    x1[2] = -1;
    CHECK(plume_ccd_point_triangle(x0, x1, 0.3, &o, &toi, &rep) == PLUME_OK && toi == 0.3 && !rep.hit);
    CHECK(plume_ccd_point_triangle(x0, x1, 0.48, &o, &toi, &rep) == PLUME_OK && toi < 0.48 && rep.hit);
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, NULL, &toi, &rep) == PLUME_OK && fabs(toi - 0.45) < 1e-12);
    /* thickness 0.2: the gap is d - 0.2, contact of the thick point at t = 0.4 */
    o.min_distance = 0.2;
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, &toi, &rep) == PLUME_OK);
    CHECK(toi < 0.4 && rep.hit && fabs(rep.gap_start - 0.8) < 1e-15);
    CHECK(ref_dist_at(0, x0, x1, toi) - 0.2 >= 0.1 * 0.8 * (1 - 1e-12));
    /* a larger s stops earlier, a smaller one later */
    double toi_s5, toi_s01;
    o.min_distance = 0;
    o.s = 0.5;
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, &toi_s5, &rep) == PLUME_OK);
    o.s = 0.01;
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, &toi_s01, &rep) == PLUME_OK);
    CHECK(toi_s5 < 0.45 && toi_s01 > 0.45 && toi_s01 < 0.5);
    CHECK(ref_dist_at(0, x0, x1, toi_s01) >= 0.01 * (1 - 1e-12));
    plume_ccd_opts_default(&o);
    /* already in contact: infeasible, toi = 0 */
    double c0[12] = {0.25, 0.25, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    CHECK(plume_ccd_point_triangle(c0, x1, 1.0, &o, &toi, &rep) == PLUME_EINFEASIBLE && toi == 0);
    o.min_distance = 2.0; /* thicker than the start distance */
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, &toi, &rep) == PLUME_EINFEASIBLE && toi == 0);
    double e0[12] = {-1, 0, 0, 1, 0, 0, 0, -1, 0, 0, 1, 0}; /* crossing edges */
    plume_ccd_opts_default(&o);
    CHECK(plume_ccd_edge_edge(e0, e0, 1.0, &o, &toi, NULL) == PLUME_EINFEASIBLE && toi == 0);
    /* bad inputs */
    CHECK(plume_ccd_point_triangle(NULL, x1, 1.0, &o, &toi, NULL) == PLUME_EINVAL);
    CHECK(plume_ccd_point_triangle(x0, NULL, 1.0, &o, &toi, NULL) == PLUME_EINVAL);
    CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &o, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_ccd_edge_edge(x0, x1, 0.0, &o, &toi, NULL) == PLUME_EINVAL);
    CHECK(plume_ccd_edge_edge(x0, x1, 1.5, &o, &toi, NULL) == PLUME_EINVAL);
    CHECK(plume_ccd_edge_edge(x0, x1, NAN, &o, &toi, NULL) == PLUME_EINVAL);
    double bad[12];
    memcpy(bad, x1, sizeof bad);
    bad[7] = INFINITY;
    CHECK(plume_ccd_point_triangle(x0, bad, 1.0, &o, &toi, NULL) == PLUME_EINVAL);
    CHECK(plume_ccd_edge_edge(bad, x1, 1.0, &o, &toi, NULL) == PLUME_EINVAL);
    const struct {
        double s, xi, eta;
        long it;
    } opts[] = {{0, 0, 0.9, 10}, {1, 0, 0.9, 10}, {NAN, 0, 0.9, 10}, {0.1, -1, 0.9, 10},
                {0.1, INFINITY, 0.9, 10}, {0.1, 0, 0, 10}, {0.1, 0, 1, 10}, {0.1, 0, 0.9, 0}};
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++) {
        plume_ccd_opts b = {opts[i].s, opts[i].xi, opts[i].eta, opts[i].it};
        CHECK(plume_ccd_point_triangle(x0, x1, 1.0, &b, &toi, NULL) == PLUME_EINVAL);
        CHECK(plume_ccd_edge_edge(x0, x1, 1.0, &b, &toi, NULL) == PLUME_EINVAL);
    }
}

/* signed volume of the four points at time t: point–plane (pt) or line–line (ee) orientation */
static ldbl signed_volume(int ee, const double *x0, const double *x1, ldbl t)
{
    ldbl y[12];
    for (int i = 0; i < 12; i++)
        y[i] = (ldbl)x0[i] + t * ((ldbl)x1[i] - (ldbl)x0[i]);
    ldbl a[3], b[3], c[3], n[3];
    for (int k = 0; k < 3; k++) {
        if (ee) { /* (eb0 - ea0) . (u x v) */
            a[k] = y[3 + k] - y[k], b[k] = y[9 + k] - y[6 + k], c[k] = y[6 + k] - y[k];
        } else { /* (p - t0) . ((t1 - t0) x (t2 - t0)) */
            a[k] = y[6 + k] - y[3 + k], b[k] = y[9 + k] - y[3 + k], c[k] = y[k] - y[3 + k];
        }
    }
    ref_cross(a, b, n);
    return ref_dot(c, n);
}

/* At a coplanarity time t: is the point inside the triangle (pt) or do the segments intersect
 * (ee)? Parameters by Cramer's rule with cross products, with a margin so that a touch of the
 * boundary, where sampling cannot decide, does not count. */
static int inside_at(int ee, const double *x0, const double *x1, double t, double margin)
{
    double x[12];
    lerp12(x0, x1, t, x);
    ldbl e1[3], e2[3], w[3], n[3], c1[3], c2[3];
    if (ee) {
        ref_sub(x + 3, x, e1);
        ref_sub(x + 9, x + 6, e2);
        ref_sub(x + 6, x, w);
    } else {
        ref_sub(x + 6, x + 3, e1);
        ref_sub(x + 9, x + 3, e2);
        ref_sub(x, x + 3, w);
    }
    ref_cross(e1, e2, n);
    const ldbl N = ref_dot(n, n);
    if (!(N > 0))
        return 0;
    if (ee) { /* a0 + s u = b0 + t v (+ l n) */
        ref_cross(w, e2, c1);
        ref_cross(w, e1, c2);
        const ldbl s = ref_dot(c1, n) / N, r = ref_dot(c2, n) / N;
        return s > margin && s < 1 - margin && r > margin && r < 1 - margin;
    }
    ref_cross(w, e2, c1);
    ref_cross(e1, w, c2);
    const ldbl u = ref_dot(c1, n) / N, v = ref_dot(c2, n) / N;
    return u > margin && v > margin && u + v < 1 - margin;
}

/* First time in (0, 1] at which the primitives cross (a sign change of the signed volume, found on
 * n samples and refined by bisection, with the point inside the triangle / the segments
 * intersecting), or 2 when sampling finds none. */
static double first_crossing(int ee, const double *x0, const double *x1, int n)
{
    ldbl prev = signed_volume(ee, x0, x1, 0);
    for (int k = 1; k <= n; k++) {
        const ldbl t = (ldbl)k / n, cur = signed_volume(ee, x0, x1, t);
        if ((prev < 0 && cur >= 0) || (prev > 0 && cur <= 0)) {
            ldbl lo = (ldbl)(k - 1) / n, hi = t;
            for (int b = 0; b < 64; b++) {
                const ldbl mid = 0.5L * (lo + hi), sm = signed_volume(ee, x0, x1, mid);
                if ((sm < 0) == (prev < 0) && sm != 0)
                    lo = mid;
                else
                    hi = mid;
            }
            if (inside_at(ee, x0, x1, (double)hi, 1e-6))
                return (double)hi;
        }
        prev = cur;
    }
    return 2.0;
}

/* l_p as the paper defines it (the test's own copy: the bound the guarantees are stated with) */
static double lp_bound(int ee, const double *x0, const double *x1)
{
    double p[12], nrm[4];
    for (int a = 0; a < 3; a++) {
        double mean = 0;
        for (int v = 0; v < 4; v++)
            mean += 0.25 * (x1[3 * v + a] - x0[3 * v + a]);
        for (int v = 0; v < 4; v++)
            p[3 * v + a] = x1[3 * v + a] - x0[3 * v + a] - mean;
    }
    for (int v = 0; v < 4; v++)
        nrm[v] = sqrt(p[3 * v] * p[3 * v] + p[3 * v + 1] * p[3 * v + 1] + p[3 * v + 2] * p[3 * v + 2]);
    return ee ? fmax(nrm[0], nrm[1]) + fmax(nrm[2], nrm[3]) : nrm[0] + fmax(nrm[1], fmax(nrm[2], nrm[3]));
}

/* Half of the trajectories are built to touch: at a random time tc the point (or a random point
 * of eb) sits exactly on a random interior point of the triangle (of ea) — eb then nearly
 * parallel to ea one time in four — so they cross at or before tc unless they only graze. */
static void touching_trajectory(int ee, rng64 *r, double *x0, double *x1)
{
    const double tc = urange(r, 0.02, 0.98);
    double xc[12]; /* positions at tc */
    for (int i = 0; i < 12; i++) {
        xc[i] = urange(r, -1, 1);
        x1[i] = xc[i] + urange(r, -0.8, 0.8);
    }
    if (!ee) {
        double u = urand(r), v = urand(r);
        if (u + v > 1)
            u = 1 - u, v = 1 - v;
        for (int k = 0; k < 3; k++)
            xc[k] = xc[3 + k] + u * (xc[6 + k] - xc[3 + k]) + v * (xc[9 + k] - xc[3 + k]);
    } else {
        const double sa = urand(r), tb = urand(r), len = urange(r, 0.3, 2);
        double dir[3];
        rand_unit(r, dir);
        if (urand(r) < 0.25) { /* nearly parallel to ea at the touch */
            double e[3], el = 0, pert[3];
            for (int k = 0; k < 3; k++)
                e[k] = xc[3 + k] - xc[k], el += e[k] * e[k];
            el = sqrt(el);
            rand_unit(r, pert);
            const double th = pow(10.0, -urange(r, 1, 8));
            for (int k = 0; k < 3; k++)
                dir[k] = e[k] / el + th * pert[k];
        }
        for (int k = 0; k < 3; k++) {
            const double P = xc[k] + sa * (xc[3 + k] - xc[k]);
            xc[6 + k] = P - tb * len * dir[k];
            xc[9 + k] = P + (1 - tb) * len * dir[k];
        }
        for (int i = 6; i < 12; i++)
            x1[i] = xc[i] + urange(r, -0.8, 0.8);
    }
    /* x(tc) = x0 + tc (x1 - x0) = xc */
    for (int i = 0; i < 12; i++)
        x0[i] = (xc[i] - tc * x1[i]) / (1 - tc);
}

static void random_trajectory(int ee, rng64 *r, double *x0, double *x1)
{
    if (urand(r) < 0.5) {
        touching_trajectory(ee, r, x0, x1);
        return;
    }
    const int kind = (int)(urand(r) * 4);
    if (!ee) {
        /* triangle near z = 0 with its vertices moving up to 0.3; the point from above to below
         * (kinds 0-2) or staying above (kind 3), starting 1e-4..1 above */
        for (int v = 1; v < 4; v++) {
            x0[3 * v] = urange(r, -1, 1), x0[3 * v + 1] = urange(r, -1, 1), x0[3 * v + 2] = urange(r, -0.1, 0.1);
            for (int k = 0; k < 3; k++)
                x1[3 * v + k] = x0[3 * v + k] + urange(r, -0.3, 0.3);
        }
        x0[0] = urange(r, -0.7, 0.7), x0[1] = urange(r, -0.7, 0.7);
        x0[2] = 0.1 + pow(10.0, -urange(r, 0, 4));
        x1[0] = urange(r, -0.7, 0.7), x1[1] = urange(r, -0.7, 0.7);
        x1[2] = kind == 3 ? urange(r, 0.0, 1.0) : -urange(r, 0.01, 1.0);
        if (kind == 2) /* a start very close to the plane */
            x0[2] = x0[3 + 2] + 1e-3 * urand(r);
        return;
    }
    /* edge pairs: ea in the plane z ~ 0.5, eb in z ~ -0.5 (kinds 0-1: random directions, kind 2:
     * nearly parallel, kind 3: exactly parallel), all four ends moving */
    for (int k = 0; k < 3; k++) {
        x0[k] = urange(r, -1, 1), x0[3 + k] = urange(r, -1, 1);
        x0[6 + k] = urange(r, -1, 1), x0[9 + k] = urange(r, -1, 1);
    }
    x0[2] = x0[5] = 0.5 + urange(r, -0.2, 0.2);
    x0[8] = x0[11] = -0.5 + urange(r, -0.2, 0.2);
    if (kind >= 2) {
        const double lo = urange(r, -1, 0.5), len = urange(r, 0.3, 1.5);
        double dir[3];
        rand_unit(r, dir);
        for (int k = 0; k < 3; k++) {
            const double u = x0[3 + k] - x0[k] + (kind == 2 ? 1e-5 * dir[k] : 0);
            x0[6 + k] = x0[6 + k] * 0.3 + lo * u;
            x0[9 + k] = x0[6 + k] + len * u;
        }
    }
    for (int i = 0; i < 12; i++)
        x1[i] = x0[i] + urange(r, -0.6, 0.6);
    for (int v = 2; v < 4; v++) /* eb rises through ea's height */
        x1[3 * v + 2] += 1.0;
    if (kind == 3) /* keep exactly parallel: the same displacement for both ends of each edge */
        for (int k = 0; k < 3; k++)
            x1[3 + k] = x0[3 + k] + (x1[k] - x0[k]), x1[9 + k] = x0[9 + k] + (x1[6 + k] - x0[6 + k]);
}

static void random_ccd(int ee, unsigned long long seed, int ntraj)
{
    rng64 rng = {seed};
    plume_ccd_opts o;
    plume_ccd_opts_default(&o);
    const int n = 1000;
    int crossings = 0, missed = 0, hits = 0, full = 0, too_early = 0, unsafe = 0, infeasible = 0;
    long evals = 0, max_evals = 0;
    double worst_margin = INFINITY; /* min over t <= toi of gap(t) / ((1 - eta) s gap0) */
    double worst_ratio = INFINITY;  /* min toi / t_cross */
    for (int it = 0; it < ntraj; it++) {
        double x0[12], x1[12], toi;
        random_trajectory(ee, &rng, x0, x1);
        plume_ccd_report rep;
        plume_status st = run_ccd(ee, x0, x1, 1.0, &o, &toi, &rep);
        if (st == PLUME_EINFEASIBLE) { /* started in contact: only possible with a zero start gap */
            infeasible++;
            CHECK(ref_dist_at(ee, x0, x1, 0) <= 1e-12);
            continue;
        }
        CHECK(st == PLUME_OK);
        CHECK(toi > 0 && toi <= 1 && !rep.capped);
        evals += rep.iterations;
        if (rep.iterations > max_evals)
            max_evals = rep.iterations;
        hits += rep.hit;
        const double tc = first_crossing(ee, x0, x1, n);
        if (tc <= 1) {
            crossings++;
            if (!(toi < tc) || !rep.hit) {
                missed++;
                fprintf(stderr, "    MISSED: trajectory %d crosses at %.9f, toi %.9f\n", it, tc, toi);
            }
            worst_ratio = fmin(worst_ratio, toi / tc);
        }
        /* the separation guarantee on [0, toi], and no needless stop: if the sampled gap (less
         * what can hide between samples) stays above s gap0, toi must be 1 */
        const double gap0 = ref_dist_at(ee, x0, x1, 0), floor_gap = (1 - o.eta) * o.s * gap0;
        const double lp = lp_bound(ee, x0, x1);
        double gmin_before = INFINITY, gmin_all = INFINITY;
        for (int k = 0; k <= n; k++) {
            const double t = (double)k / n, g = ref_dist_at(ee, x0, x1, t);
            gmin_all = fmin(gmin_all, g);
            if (t <= toi)
                gmin_before = fmin(gmin_before, g);
        }
        gmin_before = fmin(gmin_before, ref_dist_at(ee, x0, x1, toi));
        if (!(gmin_before >= floor_gap * (1 - 1e-9)))
            unsafe++;
        worst_margin = fmin(worst_margin, gmin_before / floor_gap);
        if (gmin_all - 0.5 * lp / n > o.s * gap0 * (1 + 1e-9) && toi != 1.0)
            too_early++;
        full += toi == 1.0;
    }
    CHECK(missed == 0);
    CHECK(unsafe == 0);
    CHECK(too_early == 0);
    CHECK(crossings >= ntraj / 3);
    CHECK(infeasible == 0);
    fprintf(stderr,
            "    %s: %d trajectories, %d cross (first crossing found on %d samples + bisection), "
            "%d missed; %d hits, %d toi = 1; min toi / t_cross %.3f; min gap before toi %.3g x "
            "the guaranteed (1 - eta) s gap0; %.1f evaluations on average, %ld at most\n",
            ee ? "edge-edge" : "point-triangle", ntraj, crossings, n, missed, hits, full, worst_ratio,
            worst_margin, (double)evals / ntraj, max_evals);
}

void test_contact_narrow_ccd_random_point_triangle(void)
{
    random_ccd(0, 0xacc0ccdULL, 10000);
}

void test_contact_narrow_ccd_random_edge_edge(void)
{
    random_ccd(1, 0xeeccd2021ULL, 10000);
}
