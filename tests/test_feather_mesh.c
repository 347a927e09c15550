/* Tests of the feather mesher (macro/feather/feather_mesh.h) on the shipped synthetic feather
 * (data/feather/), on a rectangular feather with straight barbs, where the barb direction is known
 * exactly, and on one whose barbs converge, fan out and curl: barb alignment of the vane
 * triangles, the outline kept exactly, the rachis strip widths, barb edges along the interpolated
 * barb curves (checked against an independent polyline reimplementation of supplementary §6) and
 * never crossing, every input error path, and the OBJ outline reader. Element counts and meshing
 * times are printed, never asserted. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "harness.h"
#include "../macro/feather/feather_mesh.h"

static const double pi = 3.14159265358979323846;
static const char *shape_path = "../data/feather/feather_shape.json";

/* ---------------------------------------------------------------- inputs */

typedef struct {
    double *outline; /* malloc'ed, from the OBJ or static */
    plume_index no;
    double *pts;     /* all curve points, malloc'ed */
    plume_polyline barbs[2][8];
    plume_feather_input in;
} feather;

static void feather_free(feather *f)
{
    free(f->outline);
    free(f->pts);
    memset(f, 0, sizeof *f);
}

static plume_index json_points(json_t *arr, double *dst)
{
    size_t i;
    json_t *pt;
    json_array_foreach(arr, i, pt)
    {
        dst[2 * i] = json_number_value(json_array_get(pt, 0));
        dst[2 * i + 1] = json_number_value(json_array_get(pt, 1));
    }
    return (plume_index)json_array_size(arr);
}

/* The shipped feather: data/feather/feather_shape.json and the OBJ it names. */
static int load_shipped(feather *f, double edge)
{
    memset(f, 0, sizeof *f);
    json_error_t je;
    json_t *root = json_load_file(shape_path, 0, &je);
    if (!root) {
        fprintf(stderr, "    %s:%d: %s\n", shape_path, je.line, je.text);
        return -1;
    }
    CHECK(strcmp(json_string_value(json_object_get(root, "units")), "m") == 0);
    char obj[512];
    snprintf(obj, sizeof obj, "../data/feather/%s", json_string_value(json_object_get(root, "outline_obj")));
    plume_err err = {""};
    if (plume_obj_outline(obj, &f->outline, &f->no, &err) != PLUME_OK) {
        fprintf(stderr, "    %s\n", err.msg);
        json_decref(root);
        return -1;
    }
    size_t npts = 2 * json_array_size(json_object_get(json_object_get(root, "rachis"), "points"));
    const char *names[2] = {"barbs_left", "barbs_right"};
    for (int s = 0; s < 2; s++) {
        json_t *arr = json_object_get(root, names[s]), *b;
        size_t i;
        if (json_array_size(arr) > 8) {
            fprintf(stderr, "    %s: more than 8 %s\n", shape_path, names[s]);
            json_decref(root);
            return -1;
        }
        json_array_foreach(arr, i, b) npts += 2 * json_array_size(b);
    }
    f->pts = malloc((npts + 1) * sizeof *f->pts);
    double *p = f->pts;
    json_t *rachis = json_object_get(root, "rachis");
    f->in.rachis.p = p;
    f->in.rachis.n = json_points(json_object_get(rachis, "points"), p);
    p += 2 * f->in.rachis.n;
    f->in.rachis_width_base = json_number_value(json_object_get(rachis, "width_base"));
    f->in.rachis_width_tip = json_number_value(json_object_get(rachis, "width_tip"));
    for (int s = 0; s < 2; s++) {
        json_t *arr = json_object_get(root, names[s]), *b;
        size_t i;
        json_array_foreach(arr, i, b)
        {
            f->barbs[s][i].p = p;
            f->barbs[s][i].n = json_points(b, p);
            p += 2 * f->barbs[s][i].n;
        }
        if (s == 0)
            f->in.nbarbs_left = (int)json_array_size(arr);
        else
            f->in.nbarbs_right = (int)json_array_size(arr);
    }
    f->in.barbs_left = f->barbs[0];
    f->in.barbs_right = f->barbs[1];
    f->in.outline.p = f->outline;
    f->in.outline.n = f->no;
    f->in.edge = edge > 0 ? edge : json_number_value(json_object_get(root, "edge"));
    json_decref(root);
    return 0;
}

/* A rectangle [-0.03, 0.02] x [0, 0.1] (given clockwise), a straight rachis along x = 0 that stops
 * short of both ends, straight barbs: 50 degrees to the rachis on the left (one curve), 40 degrees
 * on the right (two parallel curves). */
static const double synth_left_deg = 50, synth_right_deg = 40;
static void load_synthetic(feather *f, double edge)
{
    memset(f, 0, sizeof *f);
    static const double rect[8] = {-0.03, 0.0, -0.03, 0.1, 0.02, 0.1, 0.02, 0.0};
    f->no = 4;
    f->outline = malloc(sizeof rect);
    memcpy(f->outline, rect, sizeof rect);
    f->pts = malloc(128 * sizeof *f->pts);
    double *p = f->pts;
    p[0] = 0, p[1] = 0.01, p[2] = 0, p[3] = 0.09;
    f->in.rachis.p = p, f->in.rachis.n = 2;
    p += 4;
    double al = synth_left_deg * pi / 180, ar = synth_right_deg * pi / 180;
    p[0] = 0, p[1] = 0.04, p[2] = -0.01 * sin(al), p[3] = 0.04 + 0.01 * cos(al);
    f->barbs[0][0].p = p, f->barbs[0][0].n = 2;
    p += 4;
    for (int k = 0; k < 2; k++) {
        double y0 = 0.02 + 0.05 * k;
        p[0] = 0, p[1] = y0, p[2] = 0.005 * sin(ar), p[3] = y0 + 0.005 * cos(ar);
        p[4] = 0.01 * sin(ar), p[5] = y0 + 0.01 * cos(ar);
        f->barbs[1][k].p = p, f->barbs[1][k].n = 3;
        p += 6;
    }
    f->in.outline.p = f->outline, f->in.outline.n = 4;
    f->in.rachis_width_base = 3e-3, f->in.rachis_width_tip = 1e-3;
    f->in.nbarbs_left = 1, f->in.nbarbs_right = 2;
    f->in.barbs_left = f->barbs[0], f->in.barbs_right = f->barbs[1];
    f->in.edge = edge;
}

/* The rectangle with strongly varying barbs: on the left, 80 degrees to the rachis at y = 0.03 and
 * 25 degrees at y = 0.07, so that the interpolated barbs converge and must be cut; on the right a
 * barb that curls toward the tip (90 to 20 degrees). */
static void load_converging(feather *f, double edge)
{
    load_synthetic(f, edge);
    double *p = f->pts + 32;
    double a0 = 80 * pi / 180, a1 = 25 * pi / 180;
    p[0] = 0, p[1] = 0.03, p[2] = -0.02 * sin(a0), p[3] = 0.03 + 0.02 * cos(a0);
    p[4] = 0, p[5] = 0.07, p[6] = -0.02 * sin(a1), p[7] = 0.07 + 0.02 * cos(a1);
    f->barbs[0][0].p = p, f->barbs[0][0].n = 2;
    f->barbs[0][1].p = p + 4, f->barbs[0][1].n = 2;
    p += 8;
    for (int i = 0; i < 6; i++) { /* quarter-ish arc from (0, 0.04) */
        double a = (90 - 14.0 * i) * pi / 180;
        p[2 * i] = i == 0 ? 0 : p[2 * i - 2] + 0.004 * sin(a + 7 * pi / 180);
        p[2 * i + 1] = i == 0 ? 0.04 : p[2 * i - 1] + 0.004 * cos(a + 7 * pi / 180);
    }
    f->barbs[1][0].p = p, f->barbs[1][0].n = 6;
    f->in.nbarbs_left = 2, f->in.nbarbs_right = 1;
}

/* ---------------------------------------------------------------- geometry helpers */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double seg_dist(const double *p, const double *a, const double *b, double *tp)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
    t = fmin(1, fmax(0, t));
    if (tp)
        *tp = t;
    return hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

static double polygon_area(const double *p, plume_index n)
{
    double s = 0;
    for (plume_index i = 0, j = n - 1; i < n; j = i++)
        s += p[2 * j] * p[2 * i + 1] - p[2 * i] * p[2 * j + 1];
    return 0.5 * s;
}

static double outline_dist(const feather *f, const double *p)
{
    double d = INFINITY;
    for (plume_index i = 0; i < f->no; i++)
        d = fmin(d, seg_dist(p, f->outline + 2 * i, f->outline + 2 * ((i + 1) % f->no), NULL));
    return d;
}

/* Projection on a polyline: arc length s and signed distance d (> 0 on the left). */
static void project(const plume_polyline *c, const double *p, double *s_out, double *d_out)
{
    double best = INFINITY, s0 = 0;
    for (plume_index i = 0; i + 1 < c->n; i++) {
        const double *a = c->p + 2 * i, *b = c->p + 2 * i + 2;
        double len = hypot(b[0] - a[0], b[1] - a[1]);
        /* the end segments are extended: the mesher extends the rachis linearly */
        double dx = (b[0] - a[0]) / len, dy = (b[1] - a[1]) / len;
        double t = (p[0] - a[0]) * dx + (p[1] - a[1]) * dy;
        if (i > 0 && t < 0)
            t = 0;
        if (i + 2 < c->n && t > len)
            t = len;
        double fx = a[0] + t * dx, fy = a[1] + t * dy, dist = hypot(p[0] - fx, p[1] - fy);
        if (dist < best) {
            best = dist;
            *s_out = s0 + t;
            *d_out = dx * (p[1] - a[1]) - dy * (p[0] - a[0]);
        }
        s0 += len;
    }
}

static double polyline_length(const plume_polyline *c)
{
    double s = 0;
    for (plume_index i = 0; i + 1 < c->n; i++)
        s += hypot(c->p[2 * i + 2] - c->p[2 * i], c->p[2 * i + 3] - c->p[2 * i + 1]);
    return s;
}

/* angle in degrees between two lines (undirected) */
static double line_angle(const double *u, const double *v)
{
    /* atan2 of |cross| and |dot| keeps full precision near 0 (acos does not) */
    return atan2(fabs(u[0] * v[1] - u[1] * v[0]), fabs(u[0] * v[0] + u[1] * v[1])) * 180 / pi;
}

/* ---------------------------------------------------------------- the barb curves of §6, again */

/* An independent reimplementation of the interpolated barb curve of supplementary §6 on the raw
 * polylines (the mesher uses splines): the barb from a rachis-side point at station s blends the
 * two input barbs of that side whose roots bracket s, as tangent angles relative to the rachis
 * tangent at their roots, function of the arc length from the root (constant past their end). */

/* angle of the polyline segment containing arc length t (end segments extended) */
static double poly_angle(const plume_polyline *c, double t)
{
    double s0 = 0;
    for (plume_index i = 0; i + 1 < c->n; i++) {
        const double *a = c->p + 2 * i, *b = c->p + 2 * i + 2;
        double len = hypot(b[0] - a[0], b[1] - a[1]);
        if (t < s0 + len || i + 2 == c->n)
            return atan2(b[1] - a[1], b[0] - a[0]);
        s0 += len;
    }
    return 0;
}

static double wrap(double a)
{
    return remainder(a, 2 * pi);
}

/* theta_j(tau) of barb k of a side, relative to the rachis at its root; its root station */
static double barb_theta(const feather *f, int side, int k, double tau, double *s_root)
{
    const plume_polyline *b = &f->barbs[side][k];
    double d;
    project(&f->in.rachis, b->p, s_root, &d);
    return wrap(poly_angle(b, tau) - poly_angle(&f->in.rachis, *s_root));
}

/* Samples the interpolated barb from p (a rachis side vertex) every h, n samples into out[2 n]. */
static void blended_barb(const feather *f, int side, const double *p, double h, int n, double *out)
{
    int nb = side == 0 ? f->in.nbarbs_left : f->in.nbarbs_right;
    double s, d, roots[8];
    project(&f->in.rachis, p, &s, &d);
    for (int k = 0; k < nb; k++)
        barb_theta(f, side, k, 0, &roots[k]);
    int lo = -1, hi = -1; /* bracketing barbs by root station */
    for (int k = 0; k < nb; k++) {
        if (roots[k] <= s && (lo < 0 || roots[k] > roots[lo]))
            lo = k;
        if (roots[k] > s && (hi < 0 || roots[k] < roots[hi]))
            hi = k;
    }
    double w = 0;
    if (lo < 0)
        lo = hi;
    else if (hi < 0)
        hi = lo;
    else
        w = (s - roots[lo]) / (roots[hi] - roots[lo]);
    double phi = poly_angle(&f->in.rachis, s), x = p[0], y = p[1], r;
    for (int i = 0; i < n; i++) {
        out[2 * i] = x, out[2 * i + 1] = y;
        double tau = (i + 0.5) * h;
        double a = phi + (1 - w) * barb_theta(f, side, lo, tau, &r) + w * barb_theta(f, side, hi, tau, &r);
        x += h * cos(a), y += h * sin(a);
    }
}

static void centroid(const plume_mesh *m, plume_index t, double c[2])
{
    const plume_index *v = m->tri + 3 * t;
    for (int k = 0; k < 2; k++)
        c[k] = (m->X[2 * v[0] + k] + m->X[2 * v[1] + k] + m->X[2 * v[2] + k]) / 3;
}

/* the exact barb direction of the synthetic feather on a side */
static void synthetic_direction(int side, double d[2])
{
    double a = (side == 0 ? synth_left_deg : -synth_right_deg) * pi / 180 + pi / 2;
    d[0] = cos(a), d[1] = sin(a);
}

static plume_status mesh_it(const feather *f, plume_mesh **m, plume_index **be, plume_index *nb, double *secs)
{
    plume_err err = {""};
    double t0 = now();
    plume_status st = plume_feather_mesh(&f->in, 2, m, be, nb, &err);
    if (secs)
        *secs = now() - t0;
    if (st != PLUME_OK)
        fprintf(stderr, "    feather mesh failed: %s (%s)\n", plume_strerror(st), err.msg);
    return st;
}

/* ---------------------------------------------------------------- the checks */

/* (1) every vane triangle should have an edge within 10 degrees of the local barb direction: its
 * barb_dir (the direction the simulation uses), and for the synthetic feather the exact one.
 * Returns the first fraction; *frac_exact the second (synthetic only). */
static double aligned_fraction(const feather *f, int synthetic, const plume_mesh *m, double *frac_exact)
{
    plume_index nvane = 0, aligned = 0, exact = 0;
    for (plume_index t = 0; t < m->nt; t++) {
        if (m->material[t] != PLUME_FEATHER_VANE)
            continue;
        nvane++;
        const double *bd = m->barb_dir + 2 * t;
        CHECK_REL(hypot(bd[0], bd[1]), 1.0, 1e-12, 1.0);
        double ref[2] = {0, 0}, best = 180, best_ref = 180;
        if (synthetic) {
            double c[2];
            centroid(m, t, c);
            synthetic_direction(c[0] < 0 ? 0 : 1, ref);
            /* exact, except near a barb edge that ends on an outline corner (snapped by <= 0.1 e) */
            int corner = 0;
            for (int k = 0; k < 4; k++)
                corner |= hypot(c[0] - f->outline[2 * k], c[1] - f->outline[2 * k + 1]) < 2 * f->in.edge;
            CHECK(line_angle(bd, ref) < (corner ? 20 : 1e-9));
            CHECK(bd[0] * ref[0] + bd[1] * ref[1] > 0); /* pointing away from the rachis */
        }
        for (int k = 0; k < 3; k++) {
            plume_index i = m->tri[3 * t + k], j = m->tri[3 * t + (k + 1) % 3];
            double e[2] = {m->X[2 * j] - m->X[2 * i], m->X[2 * j + 1] - m->X[2 * i + 1]};
            best = fmin(best, line_angle(e, bd));
            if (synthetic)
                best_ref = fmin(best_ref, line_angle(e, ref));
        }
        aligned += best <= 10;
        exact += best_ref <= 10;
    }
    *frac_exact = synthetic ? (double)exact / (double)nvane : 0;
    return (double)aligned / (double)nvane;
}

/* (2) area and boundary: the outline kept exactly; a boundary edge is at most e long, or joins two
 * vertices that each end a barb or the strip (barb ends up to 2 e apart are left unsplit, since a
 * point between them would end no barb) and is at most 2 e long */
static void check_outline(const feather *f, const plume_mesh *m, const plume_index *be, plume_index nb)
{
    double area = fabs(polygon_area(f->outline, f->no));
    CHECK_REL(plume_mesh_total_area(m), area, 1e-9, 0);
    double size = sqrt(area);
    plume_index nbad = 0, nbnd = 0;
    for (plume_index v = 0; v < m->nv; v++) {
        if (!m->boundary[v])
            continue;
        nbnd++;
        nbad += !(outline_dist(f, m->X + 2 * v) <= 1e-12 * size);
    }
    CHECK(nbnd >= f->no);
    CHECK(nbad == 0);
    /* every outline vertex is a mesh vertex, and no boundary edge is longer than ~e */
    plume_index missing = 0;
    for (plume_index i = 0; i < f->no; i++) {
        int found = 0;
        for (plume_index v = 0; v < m->nv && !found; v++)
            found = m->X[2 * v] == f->outline[2 * i] && m->X[2 * v + 1] == f->outline[2 * i + 1];
        missing += !found;
    }
    CHECK(missing == 0);
    unsigned char *ends = calloc((size_t)m->nv, 1);
    for (plume_index k = 0; k < 2 * nb; k++)
        ends[be[k]] = 1;
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] == PLUME_FEATHER_RACHIS)
            for (int k = 0; k < 3; k++)
                ends[m->tri[3 * t + k]] = 1;
    double longest = 0;
    plume_index long_bad = 0;
    for (plume_index k = 0; k < m->ne; k++)
        if (m->edge_tri[2 * k + 1] < 0) {
            plume_index i = m->edges[2 * k], j = m->edges[2 * k + 1];
            const double *a = m->X + 2 * i, *b = m->X + 2 * j;
            double len = hypot(b[0] - a[0], b[1] - a[1]);
            longest = fmax(longest, len);
            long_bad += len > f->in.edge * (1 + 1e-9) && !(ends[i] && ends[j]);
        }
    free(ends);
    CHECK(longest <= 2 * f->in.edge * (1 + 1e-9));
    CHECK(long_bad == 0);
    for (plume_index t = 0; t < m->nt; t++)
        CHECK(plume_mesh_ref_area(m, t) > 0);
}

/* (3) rachis: vertices of rachis triangles within half the width (+ tol) of the centre line;
 * strip width at the base (before the first input point) and tip (past the last) within 5 %. */
static void check_rachis(const feather *f, const plume_mesh *m, double tol, double *wbase, double *wtip)
{
    const plume_polyline *r = &f->in.rachis;
    double len = polyline_length(r), wb = f->in.rachis_width_base, wt = f->in.rachis_width_tip;
    double bmin = INFINITY, bmax = -INFINITY, tmin = INFINITY, tmax = -INFINITY, worst = -INFINITY;
    plume_index nr = 0;
    for (plume_index t = 0; t < m->nt; t++) {
        if (m->material[t] != PLUME_FEATHER_RACHIS)
            continue;
        nr++;
        for (int k = 0; k < 3; k++) {
            const double *p = m->X + 2 * m->tri[3 * t + k];
            double s, d;
            project(r, p, &s, &d);
            double w = s <= 0 ? wb : s >= len ? wt : wb + (wt - wb) * s / len;
            worst = fmax(worst, fabs(d) - 0.5 * w);
            if (s <= 0)
                bmin = fmin(bmin, d), bmax = fmax(bmax, d);
            if (s >= len)
                tmin = fmin(tmin, d), tmax = fmax(tmax, d);
        }
        /* its barb direction is the rachis tangent */
        double c[2], s, d;
        centroid(m, t, c);
        project(r, c, &s, &d);
        CHECK(fabs(d) <= 0.5 * wb + tol);
    }
    CHECK(nr > 0);
    CHECK(worst <= tol);
    *wbase = bmax - bmin, *wtip = tmax - tmin;
    CHECK_REL(*wbase, wb, 0.05, 0);
    CHECK_REL(*wtip, wt, 0.05, 0);
    /* every vane triangle's centroid lies outside the strip */
    for (plume_index t = 0; t < m->nt; t++) {
        if (m->material[t] != PLUME_FEATHER_VANE)
            continue;
        double c[2], s, d;
        centroid(m, t, c);
        project(r, c, &s, &d);
        double w = s <= 0 ? wb : s >= len ? wt : wb + (wt - wb) * s / len;
        CHECK(fabs(d) >= 0.5 * w - tol);
    }
}

static int edge_exists(const plume_mesh *m, plume_index i, plume_index j)
{
    plume_index a = i < j ? i : j, b = i < j ? j : i, lo = 0, hi = m->ne - 1;
    while (lo <= hi) {
        plume_index mid = (lo + hi) / 2;
        const plume_index *e = m->edges + 2 * mid;
        if (e[0] == a && e[1] == b)
            return 1;
        if (e[0] < a || (e[0] == a && e[1] < b))
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return 0;
}

static int is_outline_vertex(const feather *f, const double *p)
{
    for (plume_index i = 0; i < f->no; i++)
        if (p[0] == f->outline[2 * i] && p[1] == f->outline[2 * i + 1])
            return 1;
    return 0;
}

static int segments_cross(const double *a, const double *b, const double *c, const double *d)
{
    double d1 = (d[0] - c[0]) * (a[1] - c[1]) - (d[1] - c[1]) * (a[0] - c[0]);
    double d2 = (d[0] - c[0]) * (b[1] - c[1]) - (d[1] - c[1]) * (b[0] - c[0]);
    double d3 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    double d4 = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* (4) barb edges: mesh edges from the rachis outward, lengths ~e, never crossing; every barb that
 * leaves a rachis-side vertex follows the interpolated barb curve of that vertex (vertices within
 * *worst_dev, reported in units of e, of blended_barb's curve); consecutive edges turn little. */
static void check_barbs(const feather *f, int synthetic, const plume_mesh *m, const plume_index *be, plume_index nb,
                        double *worst_dev, double *worst_turn, double *worst_dir)
{
    double e = f->in.edge;
    *worst_dev = 0, *worst_turn = 0, *worst_dir = 0;
    CHECK(nb > 0);
    plume_index *next = malloc((size_t)m->nv * sizeof *next);
    unsigned char *target = calloc((size_t)m->nv, 1), *rachis = calloc((size_t)m->nv, 1);
    for (plume_index v = 0; v < m->nv; v++)
        next[v] = -1;
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] == PLUME_FEATHER_RACHIS)
            for (int k = 0; k < 3; k++)
                rachis[m->tri[3 * t + k]] = 1;
    for (plume_index k = 0; k < nb; k++) {
        plume_index i = be[2 * k], j = be[2 * k + 1];
        CHECK(i >= 0 && i < m->nv && j >= 0 && j < m->nv && i != j);
        CHECK(edge_exists(m, i, j));
        const double *a = m->X + 2 * i, *b = m->X + 2 * j;
        double len = hypot(b[0] - a[0], b[1] - a[1]);
        CHECK(len >= 0.29 * e && len <= 1.61 * e);
        double mid[2] = {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])}, s, d;
        project(&f->in.rachis, mid, &s, &d);
        double away[2] = {b[0] - a[0], b[1] - a[1]};
        CHECK(d * (away[0] * -sin(poly_angle(&f->in.rachis, s)) + away[1] * cos(poly_angle(&f->in.rachis, s))) > 0);
        if (synthetic) {
            double ref[2];
            synthetic_direction(d > 0 ? 0 : 1, ref);
            /* the last edge may end on an outline vertex within 0.1 e of the curve's exit */
            if (!is_outline_vertex(f, b))
                *worst_dir = fmax(*worst_dir, line_angle(away, ref));
        }
        CHECK(next[i] < 0); /* one barb edge leaves a vertex */
        next[i] = k;
        target[j] = 1;
    }
    plume_index nroots = 0;
    int nsamp = 4096;
    double *curve = malloc((size_t)(2 * nsamp) * sizeof *curve), h = e / 32;
    for (plume_index r = 0; r < m->nv; r++) {
        if (next[r] < 0 || target[r] || !rachis[r])
            continue;
        nroots++;
        double s, d;
        project(&f->in.rachis, m->X + 2 * r, &s, &d);
        blended_barb(f, d > 0 ? 0 : 1, m->X + 2 * r, h, nsamp, curve);
        for (plume_index k = next[r]; k >= 0; k = next[be[2 * k + 1]]) {
            const double *v = m->X + 2 * be[2 * k + 1];
            if (is_outline_vertex(f, v))
                break; /* snapped within 0.1 e */
            double dev = INFINITY;
            for (int i = 0; i + 1 < nsamp; i++)
                dev = fmin(dev, seg_dist(v, curve + 2 * i, curve + 2 * i + 2, NULL));
            *worst_dev = fmax(*worst_dev, dev / e);
        }
    }
    CHECK(nroots > 0);
    free(curve);
    for (plume_index k = 0; k < nb; k++) {
        plume_index j = be[2 * k + 1], k2 = next[j];
        if (k2 < 0 || is_outline_vertex(f, m->X + 2 * be[2 * k2 + 1]))
            continue;
        const double *a = m->X + 2 * be[2 * k], *b = m->X + 2 * j, *c = m->X + 2 * be[2 * k2 + 1];
        double u[2] = {b[0] - a[0], b[1] - a[1]}, w[2] = {c[0] - b[0], c[1] - b[1]};
        *worst_turn = fmax(*worst_turn, line_angle(u, w));
    }
    free(next), free(target), free(rachis);
    plume_index crossings = 0;
    for (plume_index k = 0; k < nb; k++)
        for (plume_index l = k + 1; l < nb; l++)
            crossings += segments_cross(m->X + 2 * be[2 * k], m->X + 2 * be[2 * k + 1], m->X + 2 * be[2 * l],
                                        m->X + 2 * be[2 * l + 1]);
    CHECK(crossings == 0);
}

static void count_materials(const plume_mesh *m, plume_index *vane, plume_index *rachis)
{
    *vane = *rachis = 0;
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] == PLUME_FEATHER_RACHIS)
            (*rachis)++;
        else
            (*vane)++;
}

static void run_all_checks(const char *label, const feather *f, int synthetic, double rachis_tol)
{
    plume_mesh *m = NULL;
    plume_index *be = NULL, nb = 0;
    double secs = 0;
    CHECK(mesh_it(f, &m, &be, &nb, &secs) == PLUME_OK);
    if (!m)
        return;
    plume_index nv, nr;
    count_materials(m, &nv, &nr);
    double frac_exact, frac = aligned_fraction(f, synthetic, m, &frac_exact);
    fprintf(stderr,
            "    %s, e = %g m: %ld vertices, %ld triangles (%ld vane, %ld rachis), %ld barb edges, %.3f s\n"
            "    vane triangles with an edge within 10 deg of their barb direction: %.1f %%",
            label, f->in.edge, (long)m->nv, (long)m->nt, (long)nv, (long)nr, (long)nb, secs, 100 * frac);
    if (synthetic)
        fprintf(stderr, " (of the exact barb direction: %.1f %%)", 100 * frac_exact);
    fprintf(stderr, "\n");
    CHECK(frac >= 0.9);
    if (synthetic)
        CHECK(frac_exact >= 0.9);
    check_outline(f, m, be, nb);
    double wb, wt;
    check_rachis(f, m, rachis_tol, &wb, &wt);
    double worst_dev, worst_turn, worst_dir;
    check_barbs(f, synthetic, m, be, nb, &worst_dev, &worst_turn, &worst_dir);
    fprintf(stderr,
            "    strip width base %.4g m (input %.4g), tip %.4g m (input %.4g); barb vertices off the interpolated "
            "barb curves by <= %.2g e, consecutive barb edges turn <= %.2g deg\n",
            wb, f->in.rachis_width_base, wt, f->in.rachis_width_tip, worst_dev, worst_turn);
    if (synthetic) {
        CHECK(worst_dir < 1e-9); /* straight barbs: exact */
        CHECK(worst_turn < 1e-9);
        CHECK(worst_dev < 1e-9);
    } else {
        /* consecutive edges turn by about the input barbs' own turning over one e (x 1.5), plus
         * the rachis' */
        double kappa = 0;
        for (int side = 0; side < 2; side++)
            for (int k = 0; k < (side ? f->in.nbarbs_right : f->in.nbarbs_left); k++) {
                const plume_polyline *b = &f->barbs[side][k];
                for (plume_index i = 1; i + 1 < b->n; i++) {
                    double u[2] = {b->p[2 * i] - b->p[2 * i - 2], b->p[2 * i + 1] - b->p[2 * i - 1]};
                    double w[2] = {b->p[2 * i + 2] - b->p[2 * i], b->p[2 * i + 3] - b->p[2 * i + 1]};
                    kappa = fmax(kappa, line_angle(u, w) / (0.5 * (hypot(u[0], u[1]) + hypot(w[0], w[1]))));
                }
            }
        fprintf(stderr, "    (input barbs turn by up to %.3g deg per e)\n", kappa * f->in.edge);
        CHECK(worst_dev < 0.1);
        CHECK(worst_turn < 1.5 * kappa * f->in.edge + 1);
    }
    plume_mesh_destroy(&m);
    free(be);
}

/* ---------------------------------------------------------------- tests */

void test_feather_mesh_shipped(void)
{
    feather f;
    if (load_shipped(&f, 0) != 0) {
        CHECK(!"shipped feather loads");
        feather_free(&f);
        return;
    }
    CHECK(f.in.edge == 5e-3);
    run_all_checks("shipped feather", &f, 0, 0.05 * f.in.rachis_width_tip);
    f.in.edge = 2.5e-3;
    run_all_checks("shipped feather", &f, 0, 0.05 * f.in.rachis_width_tip);
    f.in.corner_exact = 1;
    run_all_checks("shipped feather, corner-exact", &f, 0, 0.05 * f.in.rachis_width_tip);
    f.in.edge = 5e-3;
    run_all_checks("shipped feather, corner-exact", &f, 0, 0.05 * f.in.rachis_width_tip);
    feather_free(&f);
}

void test_feather_mesh_synthetic(void)
{
    feather f;
    load_synthetic(&f, 5e-3);
    run_all_checks("rectangle, straight barbs", &f, 1, 1e-12);
    f.in.edge = 3e-3;
    run_all_checks("rectangle, straight barbs", &f, 1, 1e-12);
    f.in.corner_exact = 1;
    run_all_checks("rectangle, straight barbs, corner-exact", &f, 1, 1e-12);
    f.in.edge = 5e-3;
    run_all_checks("rectangle, straight barbs, corner-exact", &f, 1, 1e-12);
    f.in.corner_exact = 0, f.in.edge = 3e-3;
    /* shell mode: x = X with z = 0, same triangles */
    plume_mesh *m2 = NULL, *m3 = NULL;
    plume_index *b2 = NULL, *b3 = NULL, n2 = 0, n3 = 0;
    plume_err err = {""};
    CHECK(plume_feather_mesh(&f.in, 2, &m2, &b2, &n2, &err) == PLUME_OK);
    CHECK(plume_feather_mesh(&f.in, 3, &m3, &b3, &n3, &err) == PLUME_OK);
    if (m2 && m3) {
        CHECK(m3->dim == 3 && m2->nt == m3->nt && m2->nv == m3->nv && n2 == n3);
        CHECK(memcmp(m2->tri, m3->tri, (size_t)(3 * m2->nt) * sizeof *m2->tri) == 0); /* deterministic */
        int same = 1;
        for (plume_index v = 0; v < m3->nv; v++)
            same = same && m3->x[3 * v] == m3->X[2 * v] && m3->x[3 * v + 1] == m3->X[2 * v + 1] &&
                   m3->x[3 * v + 2] == 0;
        CHECK(same);
    }
    plume_mesh_destroy(&m2);
    plume_mesh_destroy(&m3);
    free(b2);
    free(b3);
    feather_free(&f);
}

void test_feather_mesh_converging(void)
{
    feather f;
    load_converging(&f, 5e-3);
    run_all_checks("rectangle, converging and curling barbs", &f, 0, 1e-12);
    f.in.corner_exact = 1;
    run_all_checks("rectangle, converging and curling barbs, corner-exact", &f, 0, 1e-12);
    feather_free(&f);
}

/* the message of a failing call, with the status checked */
static void expect_error(const plume_feather_input *in, const char *what1, const char *what2)
{
    plume_mesh *m = NULL;
    plume_index *be = NULL, nb = 0;
    plume_err err = {""};
    plume_status st = plume_feather_mesh(in, 2, &m, &be, &nb, &err);
    CHECK(st == PLUME_EINVAL);
    CHECK(m == NULL && be == NULL && nb == 0);
    int ok = strstr(err.msg, what1) && (!what2 || strstr(err.msg, what2));
    if (!ok)
        fprintf(stderr, "    unexpected message: '%s' (wanted '%s'%s%s)\n", err.msg, what1, what2 ? " and " : "",
                what2 ? what2 : "");
    CHECK(ok);
    plume_mesh_destroy(&m);
    free(be);
}

void test_feather_mesh_bad_inputs(void)
{
    feather f;
    load_synthetic(&f, 5e-3);
    plume_feather_input in = f.in;

    /* self-intersecting outline: a bow tie */
    static const double bowtie[8] = {-0.03, 0.0, 0.02, 0.1, -0.03, 0.1, 0.02, 0.0};
    in.outline.p = bowtie;
    expect_error(&in, "outline", "self-intersecting");
    in = f.in;

    /* a barb curve starting outside the outline */
    plume_polyline bl = f.barbs[0][0];
    double outside[4] = {-0.05, 0.04, -0.06, 0.05};
    bl.p = outside;
    in.barbs_left = &bl;
    expect_error(&in, "barbs_left[0]", "outside the outline");
    in = f.in;

    /* a barb point far out (5 for 0.05: fuzzing found a barb whose sampling and walks took minutes),
     * and a rachis point far out */
    double far[6] = {0, 0.04, -0.01, 0.045, -5.0, 0.05};
    bl.p = far, bl.n = 3;
    in.barbs_left = &bl;
    expect_error(&in, "barbs_left[0]: point 2 (-5, 0.05)", "outside the outline's bounding box");
    in = f.in;
    double r_far[6] = {0.0, 0.01, 0.0, 0.05, 0.0, 9.0};
    in.rachis.p = r_far, in.rachis.n = 3;
    expect_error(&in, "rachis: point 2", "outside the outline's bounding box");
    in = f.in;
    bl = f.barbs[0][0];

    /* a self-intersecting barb curve */
    double zigzag[8] = {0, 0.03, -0.01, 0.04, -0.01, 0.03, 0, 0.04};
    bl.p = zigzag, bl.n = 4;
    in.barbs_left = &bl;
    expect_error(&in, "barbs_left[0]", "self-intersecting");
    in = f.in;

    /* a barb on the wrong side */
    double wrong[4] = {0, 0.04, 0.01, 0.05};
    bl.p = wrong, bl.n = 2;
    in.barbs_left = &bl;
    expect_error(&in, "barbs_left[0]", "toward the right");
    in = f.in;

    /* an empty side */
    in.nbarbs_right = 0;
    expect_error(&in, "barbs_right", "no barb curve");
    in = f.in;
    in.barbs_left = NULL;
    expect_error(&in, "barbs_left", "no barb curve");
    in = f.in;

    /* a rachis of one point */
    in.rachis.n = 1;
    expect_error(&in, "rachis", "1 point");
    in = f.in;

    /* a rachis starting outside */
    double r_out[4] = {0.0, -0.01, 0.0, 0.05};
    in.rachis.p = r_out;
    expect_error(&in, "rachis", "outside the outline");
    in = f.in;

    /* NaN in a barb, in the outline */
    double nanbarb[4] = {0, 0.04, NAN, 0.05};
    bl = f.barbs[0][0];
    bl.p = nanbarb;
    in.barbs_left = &bl;
    expect_error(&in, "barbs_left[0]: point 1", "not finite");
    in = f.in;
    double nanrect[8] = {-0.03, 0.0, -0.03, 0.1, 0.02, NAN, 0.02, 0.0};
    in.outline.p = nanrect;
    expect_error(&in, "outline: point 2", "not finite");
    in = f.in;

    /* coincident consecutive points */
    double dup[6] = {0, 0.01, 0, 0.01, 0, 0.09};
    in.rachis.p = dup, in.rachis.n = 3;
    expect_error(&in, "rachis: points 0 and 1", "coincide");
    in = f.in;

    /* edge <= 0, non-finite, or too small for the outline */
    in.edge = 0;
    expect_error(&in, "edge", "> 0");
    in.edge = -1e-3;
    expect_error(&in, "edge", "> 0");
    in.edge = NAN;
    expect_error(&in, "edge", "> 0");
    in.edge = 2e-6;
    expect_error(&in, "edge", "triangles");
    in = f.in;

    /* widths */
    in.rachis_width_tip = 0;
    expect_error(&in, "rachis widths", "> 0");
    in = f.in;

    /* dim, NULL arguments */
    plume_mesh *m = NULL;
    plume_index *be = NULL, nb = 0;
    plume_err err = {""};
    CHECK(plume_feather_mesh(&in, 4, &m, &be, &nb, &err) == PLUME_EINVAL && strstr(err.msg, "dim"));
    CHECK(plume_feather_mesh(NULL, 2, &m, &be, &nb, &err) == PLUME_EINVAL);
    CHECK(plume_feather_mesh(&in, 2, NULL, &be, &nb, &err) == PLUME_EINVAL);
    CHECK(m == NULL && be == NULL);
    feather_free(&f);
}

/* ---------------------------------------------------------------- OBJ reader */

static char *write_temp(const char *text)
{
    char *path = malloc(64);
    strcpy(path, "/tmp/plume_obj_XXXXXX");
    int fd = mkstemp(path);
    if (fd < 0) {
        free(path);
        return NULL;
    }
    FILE *fp = fdopen(fd, "w");
    fputs(text, fp);
    fclose(fp);
    return path;
}

/* reads `text` as an OBJ; returns the status and leaves the message in err */
static plume_status read_obj(const char *text, double **pts, plume_index *n, plume_err *err, char **path_out)
{
    char *path = write_temp(text);
    if (!path)
        return PLUME_EIO;
    plume_status st = plume_obj_outline(path, pts, n, err);
    unlink(path);
    if (path_out)
        *path_out = path;
    else
        free(path);
    return st;
}

static void expect_obj_error(const char *text, plume_status want, const char *line_tag, const char *what)
{
    double *pts = NULL;
    plume_index n = 0;
    plume_err err = {""};
    char *path = NULL;
    plume_status st = read_obj(text, &pts, &n, &err, &path);
    CHECK(st == want);
    CHECK(pts == NULL && n == 0);
    char tag[128];
    snprintf(tag, sizeof tag, "%s%s", path ? path : "", line_tag);
    int ok = strstr(err.msg, tag) && strstr(err.msg, what);
    if (!ok)
        fprintf(stderr, "    unexpected message: '%s' (wanted '%s' and '%s')\n", err.msg, tag, what);
    CHECK(ok);
    free(path);
    free(pts);
}

void test_feather_mesh_obj_outline(void)
{
    /* good: a unit square as two clockwise triangles, with texture/normal indices, comments and a
     * vertex listed out of boundary order -> the loop comes back counter-clockwise */
    const char *good = "# square\n"
                       "o square\n"
                       "v 0 0 0\n"
                       "v 1 1 0\n"
                       "v 1 0 0\n"
                       "v 0 1 0.5\n"
                       "vt 0 0\n"
                       "f 1/1 4/1 2/1\n"
                       "f 1//1 2//1 3//1\n";
    double *pts = NULL;
    plume_index n = 0;
    plume_err err = {""};
    CHECK(read_obj(good, &pts, &n, &err, NULL) == PLUME_OK);
    CHECK(n == 4);
    if (pts && n == 4) {
        CHECK_REL(polygon_area(pts, n), 1.0, 1e-15, 1.0);
        for (plume_index i = 0; i < n; i++) /* consecutive points are square sides */
            CHECK_REL(hypot(pts[2 * ((i + 1) % n)] - pts[2 * i], pts[2 * ((i + 1) % n) + 1] - pts[2 * i + 1]), 1.0,
                      1e-15, 1.0);
    }
    free(pts);
    pts = NULL;

    /* negative (relative) indices and a quad */
    CHECK(read_obj("v 0 0\nv 2 0\nv 2 1\nv 0 1\nf -4 -3 -2 -1\n", &pts, &n, &err, NULL) == PLUME_OK);
    CHECK(n == 4 && pts && fabs(polygon_area(pts, n) - 2.0) < 1e-15);
    free(pts);
    pts = NULL;

    /* the shipped outline: one loop of 120 points around 0.2 m */
    CHECK(plume_obj_outline("../data/feather/outline.obj", &pts, &n, &err) == PLUME_OK);
    if (pts) {
        double ymin = INFINITY, ymax = -INFINITY, xmin = INFINITY, xmax = -INFINITY;
        for (plume_index i = 0; i < n; i++) {
            xmin = fmin(xmin, pts[2 * i]), xmax = fmax(xmax, pts[2 * i]);
            ymin = fmin(ymin, pts[2 * i + 1]), ymax = fmax(ymax, pts[2 * i + 1]);
        }
        CHECK(polygon_area(pts, n) > 0);
        CHECK_REL(ymax - ymin, 0.2, 1e-6, 0);
        CHECK(xmax - xmin > 0.04 && xmax - xmin < 0.06);
        fprintf(stderr, "    shipped outline: %ld points, %.4g x %.4g m, area %.4g m^2\n", (long)n, xmax - xmin,
                ymax - ymin, polygon_area(pts, n));
    }
    free(pts);
    pts = NULL;

    /* errors: the message names the file and the line */
    expect_obj_error("v 0 0\nv 1 0\nv 1.0 abc\nf 1 2 3\n", PLUME_EFORMAT, ":3:", "bad 'v' line");
    expect_obj_error("v 0 0\nv 1 0\nv 1 1\nf 1 2\n", PLUME_EFORMAT, ":4:", "bad 'f' line");
    expect_obj_error("v 0 0\nv 1 0\nv 1 1\nf 1 2 x\n", PLUME_EFORMAT, ":4:", "bad 'f' line");
    expect_obj_error("v 0 0\nv 1 0\nv 1 1\n\nf 1 2 7\n", PLUME_EFORMAT, ":5:", "out of range");
    expect_obj_error("v 0 0\nv 1 0\nv 1 1\nf 1 2 0\n", PLUME_EFORMAT, ":4:", "bad 'f' line");
    /* two separate triangles: two boundary loops */
    expect_obj_error("v 0 0\nv 1 0\nv 0 1\nv 5 0\nv 6 0\nv 5 1\nf 1 2 3\nf 4 5 6\n", PLUME_EFORMAT, ":4:",
                     "single loop");
    /* a square with a square hole (8 triangles): two loops */
    expect_obj_error("v 0 0\nv 3 0\nv 3 3\nv 0 3\nv 1 1\nv 2 1\nv 2 2\nv 1 2\n"
                     "f 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n",
                     PLUME_EFORMAT, ":", "single loop");
    /* three triangles on one edge */
    expect_obj_error("v 0 0\nv 1 0\nv 0 1\nv 0 -1\nv 1 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n", PLUME_EFORMAT, ":8:",
                     "non-manifold");
    expect_obj_error("# nothing\n", PLUME_EFORMAT, "", "no face");
    CHECK(plume_obj_outline("/nonexistent/plume.obj", &pts, &n, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, "/nonexistent/plume.obj") != NULL);
}

/* ---------------------------------------------------------------- barb coverage */

static int cmp_pair_cov(const void *p, const void *q)
{
    const plume_index *a = p, *b = q;
    return a[0] != b[0] ? (a[0] > b[0]) - (a[0] < b[0]) : (a[1] > b[1]) - (a[1] < b[1]);
}

/* Vane triangles owning one of the barb edges, counted here from the triangles' own edges. */
static plume_index covered_independently(const plume_mesh *m, const plume_index *be, plume_index nb, plume_index *nvane)
{
    plume_index *k = malloc((size_t)(2 * nb + 2) * sizeof *k), n = 0;
    for (plume_index e = 0; e < nb; e++) {
        plume_index a = be[2 * e], b = be[2 * e + 1];
        k[2 * e] = a < b ? a : b, k[2 * e + 1] = a < b ? b : a;
    }
    qsort(k, (size_t)nb, 2 * sizeof *k, cmp_pair_cov);
    *nvane = 0;
    for (plume_index t = 0; t < m->nt; t++) {
        if (m->material[t] != PLUME_FEATHER_VANE)
            continue;
        ++*nvane;
        int own = 0;
        for (int j = 0; j < 3 && !own; j++) {
            plume_index a = m->tri[3 * t + j], b = m->tri[3 * t + (j + 1) % 3];
            plume_index q[2] = {a < b ? a : b, a < b ? b : a};
            own = bsearch(q, k, (size_t)nb, 2 * sizeof *k, cmp_pair_cov) != NULL;
        }
        n += own;
    }
    free(k);
    return n;
}

/* Per-vertex facts for the reasons, found here independently of the library: on the outline (by
 * distance to it, not the mesh's boundary flags), used by a rachis triangle, barb edges at it. */
typedef struct {
    unsigned char *outline, *strip, *deg;
} vertex_facts;

static void facts_make(const feather *f, const plume_mesh *m, const plume_index *be, plume_index nb, vertex_facts *vf)
{
    double size = sqrt(fabs(polygon_area(f->outline, f->no)));
    vf->outline = calloc((size_t)m->nv, 1);
    vf->strip = calloc((size_t)m->nv, 1);
    vf->deg = calloc((size_t)m->nv, 1);
    for (plume_index v = 0; v < m->nv; v++)
        vf->outline[v] = outline_dist(f, m->X + 2 * v) <= 1e-12 * size;
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] == PLUME_FEATHER_RACHIS)
            for (int k = 0; k < 3; k++)
                vf->strip[m->tri[3 * t + k]] = 1;
    for (plume_index k = 0; k < 2 * nb; k++)
        vf->deg[be[k]]++;
}

static void facts_free(vertex_facts *vf)
{
    free(vf->outline), free(vf->strip), free(vf->deg);
}

/* the reason of an uncovered vane triangle as feather_mesh.h defines it: the first that applies */
static int expected_reason(const vertex_facts *vf, const plume_mesh *m, plume_index t)
{
    int has[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        plume_index v = m->tri[3 * t + k];
        has[0] |= vf->strip[v] && vf->deg[v] == 0;
        has[1] |= vf->outline[v] && vf->deg[v] == 0;
        has[2] |= !vf->outline[v] && !vf->strip[v] && vf->deg[v] == 1;
    }
    return has[0] ? PLUME_FEATHER_UNCOVERED_RACHIS
           : has[1] ? PLUME_FEATHER_UNCOVERED_OUTLINE
           : has[2] ? PLUME_FEATHER_UNCOVERED_BARB_END
                    : PLUME_FEATHER_UNCOVERED_OTHER;
}

/* does triangle t own one of the barb edges? (a scan: few calls) */
static int owns_barb_edge(const plume_mesh *m, const plume_index *be, plume_index nb, plume_index t)
{
    for (int j = 0; j < 3; j++) {
        plume_index a = m->tri[3 * t + j], b = m->tri[3 * t + (j + 1) % 3];
        for (plume_index k = 0; k < nb; k++)
            if ((be[2 * k] == a && be[2 * k + 1] == b) || (be[2 * k] == b && be[2 * k + 1] == a))
                return 1;
    }
    return 0;
}

static double triangle_min_angle(const plume_mesh *m, plume_index t)
{
    double mn = 180;
    for (int k = 0; k < 3; k++) {
        const double *a = m->X + 2 * m->tri[3 * t + k], *b = m->X + 2 * m->tri[3 * t + (k + 1) % 3],
                     *c = m->X + 2 * m->tri[3 * t + (k + 2) % 3];
        double u[2] = {b[0] - a[0], b[1] - a[1]}, w[2] = {c[0] - a[0], c[1] - a[1]};
        mn = fmin(mn, line_angle(u, w));
    }
    return mn;
}

/* The mesher reports how many vane triangles own a barb edge and why each other one does not;
 * the counts match ones done here from the triangles' own edges. Measured on the shipped feather
 * at 5 / 3.5 / 2.5 mm: with stations every ds, 784 / 1500 / 2879 vane triangles, 89.0 / 93.1 /
 * 95.2 % owning a barb edge, every other one at an outline point that ends no barb (85 / 103 / 138
 * such points); with corner-exact stations, 837 / 1417 / 2798 vane triangles, 98.4 / 98.8 / 99.5 %,
 * the rest at the base and the tip (3 + 10, 2 + 15, 2 + 10 by rachis junction + outline) and two
 * fill-barb starts at 2.5 mm (input corner_exact; without it the mesh is the earlier one). Smallest vane angle 0.41 / 0.69 / 0.74 degrees before (a sliver at
 * the tip, where the vane is narrower than a barb spacing), 0.44 / 0.69 / 0.91 after; triangles
 * under 10 degrees 29 / 14 / 22 before, 5 / 4 / 4 after. */
void test_feather_mesh_coverage(void)
{
    feather f;
    if (load_shipped(&f, 0) != 0) {
        CHECK(!"shipped feather loads");
        feather_free(&f);
        return;
    }
    const double edges[] = {5e-3, 3.5e-3, 2.5e-3};
    const double floors[2][3] = {{0.885, 0.925, 0.945}, {0.98, 0.985, 0.99}}; /* [corner_exact] */
    const plume_index uniform_vane[] = {784, 1500, 2879}; /* with stations every ds */
    for (int mode = 0; mode < 2; mode++)
    for (int k = 0; k < 3; k++) {
        f.in.edge = edges[k];
        f.in.corner_exact = mode;
        plume_mesh *m = NULL;
        plume_index *be = NULL, nb = 0, nvane = 0;
        plume_feather_stats stats;
        plume_err err = {""};
        CHECK(plume_feather_mesh_with_stats(&f.in, 3, &m, &be, &nb, &stats, &err) == PLUME_OK);
        if (!m)
            continue;
        plume_index cov = covered_independently(m, be, nb, &nvane);
        plume_index nu = stats.vane_triangles - stats.vane_covered;
        fprintf(stderr,
                "    shipped feather%s, e = %g m: %ld of %ld vane triangles own a barb edge (%.1f %%), %ld rachis; "
                "uncovered: %ld rachis junction, %ld outline, %ld barb end, %ld other; smallest angle %.2f deg "
                "(vane), %.2f deg (rachis)\n",
                mode ? ", corner-exact" : "", edges[k], (long)stats.vane_covered, (long)stats.vane_triangles,
                100.0 * (double)stats.vane_covered / (double)stats.vane_triangles, (long)stats.rachis_triangles,
                (long)stats.uncovered[PLUME_FEATHER_UNCOVERED_RACHIS], (long)stats.uncovered[PLUME_FEATHER_UNCOVERED_OUTLINE],
                (long)stats.uncovered[PLUME_FEATHER_UNCOVERED_BARB_END], (long)stats.uncovered[PLUME_FEATHER_UNCOVERED_OTHER],
                stats.vane_min_angle, stats.rachis_min_angle);
        CHECK(stats.vane_triangles == nvane);
        CHECK(stats.vane_covered == cov);
        CHECK(stats.rachis_triangles == m->nt - nvane);
        CHECK((double)stats.vane_covered >= floors[mode][k] * (double)stats.vane_triangles);
        /* the uniform layout is the one of earlier versions; corner-exact has about as many elements */
        if (mode == 0)
            CHECK(nvane == uniform_vane[k]);
        else
            CHECK(fabs((double)(nvane - uniform_vane[k])) <= 0.1 * (double)uniform_vane[k]);

        /* every uncovered vane triangle is listed once with the reason that applies to it */
        plume_index *tri = NULL, n = -1, counts[PLUME_FEATHER_UNCOVERED_REASONS] = {0};
        unsigned char *why = NULL;
        CHECK(plume_feather_uncovered(m, be, nb, &tri, &why, &n, &err) == PLUME_OK);
        CHECK(n == nu);
        plume_index sum = 0, wrong = 0;
        for (int r = 0; r < PLUME_FEATHER_UNCOVERED_REASONS; r++)
            sum += stats.uncovered[r];
        CHECK(sum == nu);
        vertex_facts vf;
        facts_make(&f, m, be, nb, &vf);
        unsigned char *seen = calloc((size_t)m->nt, 1);
        for (plume_index i = 0; i < n && tri && why; i++) {
            plume_index t = tri[i];
            CHECK(t >= 0 && t < m->nt && !seen[t]);
            if (t < 0 || t >= m->nt)
                continue;
            seen[t] = 1;
            CHECK(m->material[t] == PLUME_FEATHER_VANE && !owns_barb_edge(m, be, nb, t));
            CHECK(why[i] < PLUME_FEATHER_UNCOVERED_REASONS);
            if (why[i] < PLUME_FEATHER_UNCOVERED_REASONS)
                counts[why[i]]++;
            wrong += why[i] != expected_reason(&vf, m, t);
        }
        CHECK(wrong == 0);
        for (int r = 0; r < PLUME_FEATHER_UNCOVERED_REASONS; r++)
            CHECK(counts[r] == stats.uncovered[r]);
        /* all are forced by the outline or the strip's ends, but for at most two barb ends */
        CHECK(stats.uncovered[PLUME_FEATHER_UNCOVERED_OTHER] == 0);
        CHECK(stats.uncovered[PLUME_FEATHER_UNCOVERED_BARB_END] <= 2);
        if (mode == 0) /* every one at an outline point that ends no barb or at the strip */
            CHECK(stats.uncovered[PLUME_FEATHER_UNCOVERED_OUTLINE] + stats.uncovered[PLUME_FEATHER_UNCOVERED_RACHIS] >=
                  nu - 2);

        /* quality: the reported smallest angles, and few vane triangles under 10 degrees */
        double vmin = 180, rmin = 180;
        plume_index thin = 0;
        for (plume_index t = 0; t < m->nt; t++) {
            double a = triangle_min_angle(m, t);
            if (m->material[t] == PLUME_FEATHER_VANE)
                vmin = fmin(vmin, a), thin += a < 10;
            else
                rmin = fmin(rmin, a);
        }
        CHECK_REL(stats.vane_min_angle, vmin, 1e-9, 1e-9);
        CHECK_REL(stats.rachis_min_angle, rmin, 1e-9, 1e-9);
        CHECK(stats.vane_min_angle >= 0.4); /* the tip sliver, no worse than with stations every ds */
        if (mode == 1) /* the fans at outline points were the slivers: 3.7 / 0.9 / 0.8 % with stations every ds */
            CHECK((double)thin <= 0.01 * (double)nvane);
        fprintf(stderr, "      %ld vane triangles under 10 degrees\n", (long)thin);

        /* the reasons can be told apart: a barb edge dropped from the list in the middle of a barb,
         * at its root on the strip and at its end on the outline leaves its two triangles uncovered
         * for the reason of its ends */
        if (k == 0 && mode == 1) {
            const int want[3] = {PLUME_FEATHER_UNCOVERED_BARB_END, PLUME_FEATHER_UNCOVERED_RACHIS,
                                 PLUME_FEATHER_UNCOVERED_OUTLINE};
            for (int c = 0; c < 3; c++) {
                plume_index pick = -1;
                for (plume_index q = 0; q < nb && pick < 0; q++) {
                    plume_index a = be[2 * q], b = be[2 * q + 1];
                    int mid_a = !vf.outline[a] && !vf.strip[a] && vf.deg[a] == 2;
                    int mid_b = !vf.outline[b] && !vf.strip[b] && vf.deg[b] == 2;
                    int ok = c == 0 ? mid_a && mid_b
                             : c == 1 ? vf.strip[a] && vf.deg[a] == 1 && mid_b
                                      : mid_a && vf.outline[b] && vf.deg[b] == 1;
                    /* both triangles beside it covered otherwise, and touching nothing else */
                    for (plume_index t = 0; t < m->nt && ok; t++) {
                        const plume_index *v = m->tri + 3 * t;
                        int has_a = v[0] == a || v[1] == a || v[2] == a, has_b = v[0] == b || v[1] == b || v[2] == b;
                        if (has_a && has_b)
                            ok = m->material[t] == PLUME_FEATHER_VANE &&
                                 expected_reason(&vf, m, t) == PLUME_FEATHER_UNCOVERED_OTHER;
                    }
                    if (ok)
                        pick = q;
                }
                CHECK(pick >= 0);
                if (pick < 0)
                    continue;
                plume_index *be2 = malloc((size_t)(2 * nb) * sizeof *be2), n2 = 0, *tri2 = NULL;
                unsigned char *why2 = NULL;
                memcpy(be2, be, (size_t)(2 * pick) * sizeof *be2);
                memcpy(be2 + 2 * pick, be + 2 * (pick + 1), (size_t)(2 * (nb - pick - 1)) * sizeof *be2);
                CHECK(plume_feather_uncovered(m, be2, nb - 1, &tri2, &why2, &n2, &err) == PLUME_OK);
                CHECK(n2 == n + 2);
                plume_index got = 0;
                for (plume_index i = 0; i < n2 && tri2; i++) {
                    const plume_index *v = m->tri + 3 * tri2[i];
                    plume_index a = be[2 * pick], b = be[2 * pick + 1];
                    if ((v[0] == a || v[1] == a || v[2] == a) && (v[0] == b || v[1] == b || v[2] == b))
                        got += why2[i] == want[c];
                }
                CHECK(got == 2);
                free(be2), free(tri2), free(why2);
            }
        }
        facts_free(&vf);
        free(seen);
        free(tri);
        free(why);

        /* the plain entry point gives the same mesh */
        plume_mesh *m2 = NULL;
        plume_index *be2 = NULL, nb2 = 0;
        CHECK(plume_feather_mesh(&f.in, 3, &m2, &be2, &nb2, &err) == PLUME_OK);
        CHECK(m2 && m2->nt == m->nt && nb2 == nb);
        plume_mesh_destroy(&m2);
        free(be2);
        plume_mesh_destroy(&m);
        free(be);
    }
    feather_free(&f);

    /* errors: names, NULL arguments, a mesh without topology, a barb vertex out of range */
    CHECK(strcmp(plume_feather_uncovered_name(PLUME_FEATHER_UNCOVERED_RACHIS), "rachis junction") == 0);
    CHECK(strcmp(plume_feather_uncovered_name(PLUME_FEATHER_UNCOVERED_OTHER), "other") == 0);
    CHECK(plume_feather_uncovered_name(-1) == NULL && plume_feather_uncovered_name(PLUME_FEATHER_UNCOVERED_REASONS) == NULL);
    plume_err err = {""};
    plume_index n = 7, *tri = NULL;
    unsigned char *why = NULL;
    CHECK(plume_feather_uncovered(NULL, NULL, 0, &tri, &why, &n, &err) == PLUME_EINVAL);
    plume_mesh *m = NULL;
    CHECK(plume_mesh_create(3, 1, 2, &m, &err) == PLUME_OK);
    if (m) {
        const double X[6] = {0, 0, 1, 0, 0, 1};
        memcpy(m->X, X, sizeof X);
        m->tri[0] = 0, m->tri[1] = 1, m->tri[2] = 2;
        m->material[0] = PLUME_FEATHER_VANE;
        plume_mesh_reset_current(m);
        CHECK(plume_feather_uncovered(m, NULL, 0, &tri, &why, &n, &err) == PLUME_EINVAL); /* no topology */
        CHECK(strstr(err.msg, "topology") != NULL);
        CHECK(plume_mesh_build_topology(m, &err) == PLUME_OK);
        const plume_index bad[2] = {0, 3};
        CHECK(plume_feather_uncovered(m, bad, 1, &tri, &why, &n, &err) == PLUME_EINVAL);
        CHECK(strstr(err.msg, "vertex 3") != NULL);
        CHECK(plume_feather_uncovered(m, NULL, 0, &tri, &why, &n, &err) == PLUME_OK);
        /* a lone triangle with no barb edge, all vertices on the boundary: the outline's */
        CHECK(n == 1 && tri && why && tri[0] == 0 && why[0] == PLUME_FEATHER_UNCOVERED_OUTLINE);
        free(tri), free(why);
        const plume_index ok[2] = {0, 1};
        CHECK(plume_feather_uncovered(m, ok, 1, &tri, &why, &n, &err) == PLUME_OK);
        CHECK(n == 0 && tri == NULL && why == NULL);
        plume_mesh_destroy(&m);
    }
}
