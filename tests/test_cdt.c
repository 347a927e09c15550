/* Tests of the CGAL shim (lib/core/cdt.h): exact areas, constrained edges kept, refinement bounds,
 * holes and exterior removal, orientation, and every input error path. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../lib/core/cdt.h"

static const double pi = 3.14159265358979323846;

static double tri_area(const plume_cdt_output *o, plume_index t)
{
    const plume_index *v = o->triangles + 3 * t;
    const double *a = o->points + 2 * v[0], *b = o->points + 2 * v[1], *c = o->points + 2 * v[2];
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

/* Signed total area; also checks every triangle is counter-clockwise and indexes valid points. */
static double total_area(const plume_cdt_output *o)
{
    double s = 0;
    for (plume_index t = 0; t < o->ntriangles; t++) {
        for (int k = 0; k < 3; k++)
            CHECK(o->triangles[3 * t + k] >= 0 && o->triangles[3 * t + k] < o->npoints);
        double a = tri_area(o, t);
        CHECK(a > 0);
        s += a;
    }
    return s;
}

static double dist(const plume_cdt_output *o, plume_index i, plume_index j)
{
    return hypot(o->points[2 * i] - o->points[2 * j], o->points[2 * i + 1] - o->points[2 * j + 1]);
}

static double max_edge_length(const plume_cdt_output *o)
{
    double m = 0;
    for (plume_index t = 0; t < o->ntriangles; t++)
        for (int k = 0; k < 3; k++) {
            double l = dist(o, o->triangles[3 * t + k], o->triangles[3 * t + (k + 1) % 3]);
            m = l > m ? l : m;
        }
    return m;
}

/* Smallest interior angle over the mesh, in degrees. */
static double min_angle_deg(const plume_cdt_output *o)
{
    double m = 180;
    for (plume_index t = 0; t < o->ntriangles; t++)
        for (int k = 0; k < 3; k++) {
            const plume_index *v = o->triangles + 3 * t;
            const double *a = o->points + 2 * v[k], *b = o->points + 2 * v[(k + 1) % 3],
                         *c = o->points + 2 * v[(k + 2) % 3];
            double ux = b[0] - a[0], uy = b[1] - a[1], wx = c[0] - a[0], wy = c[1] - a[1];
            double ang = atan2(fabs(ux * wy - uy * wx), ux * wx + uy * wy) * 180 / pi;
            m = ang < m ? ang : m;
        }
    return m;
}

typedef struct {
    plume_index a, b;
} edge;

static int edge_cmp(const void *x, const void *y)
{
    const edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    return (p->b > q->b) - (p->b < q->b);
}

/* Sorted undirected edges with repetitions (one per incident triangle); caller frees. */
static edge *mesh_edges(const plume_cdt_output *o)
{
    edge *e = malloc(3 * (size_t)o->ntriangles * sizeof *e);
    for (plume_index t = 0; t < o->ntriangles; t++)
        for (int k = 0; k < 3; k++) {
            plume_index i = o->triangles[3 * t + k], j = o->triangles[3 * t + (k + 1) % 3];
            e[3 * t + k].a = i < j ? i : j;
            e[3 * t + k].b = i < j ? j : i;
        }
    qsort(e, 3 * (size_t)o->ntriangles, sizeof *e, edge_cmp);
    return e;
}

static int has_edge(const edge *e, plume_index ne, plume_index i, plume_index j)
{
    edge k = {i < j ? i : j, i < j ? j : i};
    return bsearch(&k, e, (size_t)ne, sizeof *e, edge_cmp) != NULL;
}

/* The mesh is an edge-manifold surface (no edge in more than two triangles) and its Euler
 * characteristic V - E + F over the used vertices equals `euler` (1 for a disc, 0 for an annulus). */
static void check_manifold(const plume_cdt_output *o, int euler)
{
    edge *e = mesh_edges(o);
    plume_index ne = 3 * o->ntriangles, nunique = 0;
    for (plume_index k = 0; k < ne;) {
        plume_index r = k;
        while (r < ne && e[r].a == e[k].a && e[r].b == e[k].b)
            r++;
        CHECK(r - k <= 2);
        nunique++;
        k = r;
    }
    char *used = calloc((size_t)o->npoints, 1);
    plume_index nv = 0;
    for (plume_index k = 0; k < 3 * o->ntriangles; k++)
        if (!used[o->triangles[k]]) {
            used[o->triangles[k]] = 1;
            nv++;
        }
    CHECK(nv - nunique + o->ntriangles == euler);
    free(used);
    free(e);
}

/* Segment p-q is covered by mesh edges: the edges whose two ends lie on it add up to its length
 * (refinement may split a constrained segment into collinear pieces). */
static void check_segment_covered(const plume_cdt_output *o, const edge *e, plume_index ne, const double *p,
                                  const double *q)
{
    double dx = q[0] - p[0], dy = q[1] - p[1], len = hypot(dx, dy), covered = 0;
    for (plume_index k = 0; k < ne; k++) {
        if (k > 0 && e[k].a == e[k - 1].a && e[k].b == e[k - 1].b)
            continue;
        int on = 1;
        plume_index ends[2] = {e[k].a, e[k].b};
        for (int m = 0; m < 2; m++) {
            const double *x = o->points + 2 * ends[m];
            double s = ((x[0] - p[0]) * dx + (x[1] - p[1]) * dy) / (len * len);
            double off = fabs((x[0] - p[0]) * dy - (x[1] - p[1]) * dx) / len;
            if (off > 1e-12 * len || s < -1e-12 || s > 1 + 1e-12)
                on = 0;
        }
        if (on)
            covered += dist(o, e[k].a, e[k].b);
    }
    CHECK_REL(covered, len, 1e-12, 1e-300);
}

static plume_cdt_input input(plume_index np, const double *pts, plume_index ns, const plume_index *seg)
{
    plume_cdt_input in;
    memset(&in, 0, sizeof in);
    in.npoints = np;
    in.points = pts;
    in.nsegments = ns;
    in.segments = seg;
    return in;
}

void test_cdt_square(void)
{
    const double p[] = {0, 0, 1, 0, 1, 1, 0, 1};
    plume_cdt_input in = input(4, p, 0, NULL);
    plume_cdt_output o;
    plume_err err;
    CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
    CHECK(o.npoints == 4);
    CHECK(o.ntriangles == 2);
    CHECK(memcmp(o.points, p, sizeof p) == 0);
    CHECK_REL(total_area(&o), 1.0, 1e-15, 1e-300);
    check_manifold(&o, 1);
    plume_cdt_output_free(&o);
    CHECK(o.points == NULL && o.triangles == NULL && o.npoints == 0 && o.ntriangles == 0);
    plume_cdt_output_free(&o);  /* twice is harmless */
    plume_cdt_output_free(NULL);
}

/* Unit square outline with a 45-degree barb ending on the boundary and a free interior barb. */
static const double barb_pts[] = {0, 0, 1, 0, 1, 1, 0.8, 1, 0, 1, 0, 0.2, 0.3, 0.1, 0.7, 0.5};
static const plume_index barb_seg[] = {0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 0, 5, 3, 6, 7};

void test_cdt_segments_are_edges(void)
{
    for (int refine = 0; refine < 2; refine++) {
        plume_cdt_input in = input(8, barb_pts, 8, barb_seg);
        in.remove_exterior = 1;
        in.max_edge = refine ? 0.1 : 0;
        plume_cdt_output o;
        plume_err err;
        CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
        CHECK(refine ? o.npoints > 8 : o.npoints == 8);
        CHECK_REL(total_area(&o), 1.0, 1e-12, 1e-300);
        check_manifold(&o, 1);
        edge *e = mesh_edges(&o);
        for (int s = 0; s < 8; s++) {
            plume_index i = barb_seg[2 * s], j = barb_seg[2 * s + 1];
            if (!refine)
                CHECK(has_edge(e, 3 * o.ntriangles, i, j));
            check_segment_covered(&o, e, 3 * o.ntriangles, barb_pts + 2 * i, barb_pts + 2 * j);
        }
        free(e);
        plume_cdt_output_free(&o);
    }
}

void test_cdt_refine_rectangle(void)
{
    const double p[] = {0, 0, 1, 0, 1, 1.3, 0, 1.3};
    const plume_index seg[] = {0, 1, 1, 2, 2, 3, 3, 0};
    plume_cdt_input in = input(4, p, 4, seg);
    in.remove_exterior = 1;
    in.max_edge = 0.05;
    plume_cdt_output o, o2;
    plume_err err;
    CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
    CHECK(memcmp(o.points, p, sizeof p) == 0);
    CHECK(max_edge_length(&o) <= 0.05 * (1 + 1e-9));
    CHECK(min_angle_deg(&o) >= 20.7 - 0.1); /* default shape bound 0.125 = sin^2(20.7 deg) */
    CHECK_REL(total_area(&o), 1.3, 1e-12, 1e-300);
    /* at least area / equilateral(0.05) = 1201; Delaunay refinement stays within a few times it */
    CHECK(o.ntriangles >= 1201 && o.ntriangles <= 6000);
    CHECK(o.npoints >= 600 && o.npoints <= 3100);
    for (plume_index i = 4; i < o.npoints; i++)
        CHECK(o.points[2 * i] >= 0 && o.points[2 * i] <= 1 && o.points[2 * i + 1] >= 0 &&
              o.points[2 * i + 1] <= 1.3);
    check_manifold(&o, 1);
    /* deterministic: a second run gives the same mesh */
    CHECK(plume_cdt_triangulate(&in, &o2, &err) == PLUME_OK);
    CHECK(o2.npoints == o.npoints && o2.ntriangles == o.ntriangles);
    if (o2.npoints == o.npoints && o2.ntriangles == o.ntriangles) {
        CHECK(memcmp(o.points, o2.points, 2 * (size_t)o.npoints * sizeof *o.points) == 0);
        CHECK(memcmp(o.triangles, o2.triangles, 3 * (size_t)o.ntriangles * sizeof *o.triangles) == 0);
    }
    plume_cdt_output_free(&o2);
    /* a stricter shape bound (25 deg) is honoured too */
    in.min_angle_bound = pow(sin(25 * pi / 180), 2);
    CHECK(plume_cdt_triangulate(&in, &o2, &err) == PLUME_OK);
    CHECK(min_angle_deg(&o2) >= 25 - 0.1);
    CHECK_REL(total_area(&o2), 1.3, 1e-12, 1e-300);
    plume_cdt_output_free(&o2);
    plume_cdt_output_free(&o);
}

void test_cdt_hole(void)
{
    /* [0,2]^2 minus [0.5,1.5]^2, plus an isolated point 8 inside the hole */
    const double p[] = {0, 0, 2, 0, 2, 2, 0, 2, 0.5, 0.5, 1.5, 0.5, 1.5, 1.5, 0.5, 1.5, 1, 1.2};
    const plume_index seg[] = {0, 1, 1, 2, 2, 3, 3, 0, 4, 5, 5, 6, 6, 7, 7, 4};
    const double hole[] = {1, 1};
    for (int refine = 0; refine < 2; refine++) {
        plume_cdt_input in = input(9, p, 8, seg);
        in.nholes = 1;
        in.holes = hole;
        in.remove_exterior = refine; /* the outline is the convex hull: same domain either way */
        in.max_edge = refine ? 0.2 : 0;
        plume_cdt_output o;
        plume_err err;
        CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
        CHECK(o.npoints >= 9);
        CHECK(memcmp(o.points, p, sizeof p) == 0);
        CHECK_REL(total_area(&o), 3.0, 1e-12, 1e-300);
        if (refine)
            CHECK(max_edge_length(&o) <= 0.2 * (1 + 1e-9));
        check_manifold(&o, 0);
        for (plume_index t = 0; t < o.ntriangles; t++) {
            const plume_index *v = o.triangles + 3 * t;
            CHECK(v[0] != 8 && v[1] != 8 && v[2] != 8);
            double cx = (o.points[2 * v[0]] + o.points[2 * v[1]] + o.points[2 * v[2]]) / 3;
            double cy = (o.points[2 * v[0] + 1] + o.points[2 * v[1] + 1] + o.points[2 * v[2] + 1]) / 3;
            CHECK(!(cx > 0.5 && cx < 1.5 && cy > 0.5 && cy < 1.5));
        }
        plume_cdt_output_free(&o);
    }
}

void test_cdt_remove_exterior(void)
{
    /* L-shaped outline: area 3, convex hull area 3.5 */
    const double p[] = {0, 0, 2, 0, 2, 1, 1, 1, 1, 2, 0, 2};
    const plume_index seg[] = {0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 0};
    plume_cdt_input in = input(6, p, 6, seg);
    plume_cdt_output o;
    plume_err err;
    CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
    CHECK_REL(total_area(&o), 3.5, 1e-15, 1e-300);
    plume_cdt_output_free(&o);
    for (int refine = 0; refine < 2; refine++) {
        in.remove_exterior = 1;
        in.max_edge = refine ? 0.1 : 0;
        CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
        CHECK(refine || o.ntriangles == 4);
        CHECK_REL(total_area(&o), 3.0, 1e-12, 1e-300);
        check_manifold(&o, 1);
        for (plume_index t = 0; t < o.ntriangles; t++) {
            const plume_index *v = o.triangles + 3 * t;
            double cx = (o.points[2 * v[0]] + o.points[2 * v[1]] + o.points[2 * v[2]]) / 3;
            double cy = (o.points[2 * v[0] + 1] + o.points[2 * v[1] + 1] + o.points[2 * v[2] + 1]) / 3;
            CHECK(!(cx > 1 && cy > 1));
        }
        plume_cdt_output_free(&o);
    }
    /* without remove_exterior the refined mesh fills the convex hull and stays inside it */
    in.remove_exterior = 0;
    in.max_edge = 0.1;
    CHECK(plume_cdt_triangulate(&in, &o, &err) == PLUME_OK);
    CHECK_REL(total_area(&o), 3.5, 1e-12, 1e-300);
    CHECK(max_edge_length(&o) <= 0.1 * (1 + 1e-9));
    plume_cdt_output_free(&o);
}

/* A scattered cloud (deterministic LCG) with a few segments: every triangle counter-clockwise. */
void test_cdt_ccw(void)
{
    enum { N = 200 };
    double p[2 * N];
    unsigned long long s = 12345;
    for (int i = 0; i < 2 * N; i++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        p[i] = (double)(s >> 11) / 9007199254740992.0;
    }
    const plume_index seg[] = {0, 1, 2, 3};
    plume_err err;
    for (int refine = 0; refine < 2; refine++) {
        plume_cdt_input in = input(N, p, 2, seg);
        in.max_edge = refine ? 0.05 : 0;
        plume_cdt_output o;
        plume_status st = plume_cdt_triangulate(&in, &o, &err);
        if (st == PLUME_EINVAL) { /* the two random segments happen to cross: drop one */
            in.nsegments = 1;
            st = plume_cdt_triangulate(&in, &o, &err);
        }
        CHECK(st == PLUME_OK);
        CHECK(total_area(&o) > 0.5);
        check_manifold(&o, 1);
        CHECK(memcmp(o.points, p, sizeof p) == 0);
        plume_cdt_output_free(&o);
    }
}

/* Calls with one input defect; checks the status, the message, and that out is left empty. */
static void expect_einval(const plume_cdt_input *in, const char *word, const char *word2)
{
    plume_cdt_output o;
    plume_err err;
    err.msg[0] = '\0';
    CHECK(plume_cdt_triangulate(in, &o, &err) == PLUME_EINVAL);
    CHECK(o.points == NULL && o.triangles == NULL && o.npoints == 0 && o.ntriangles == 0);
    CHECK(err.msg[0] != '\0');
    if (!strstr(err.msg, word) || (word2 && !strstr(err.msg, word2))) {
        plume_test_failures++;
        fprintf(stderr, "    message \"%s\" lacks \"%s\"%s%s\n", err.msg, word, word2 ? " or " : "",
                word2 ? word2 : "");
    }
}

void test_cdt_bad_input(void)
{
    const double sq[] = {0, 0, 1, 0, 1, 1, 0, 1};
    const plume_index sqseg[] = {0, 1, 1, 2, 2, 3, 3, 0};
    plume_cdt_input in;

    in = input(0, sq, 0, NULL);
    expect_einval(&in, "npoints", NULL);
    in = input(2, sq, 0, NULL);
    expect_einval(&in, "npoints", NULL);

    double nan_pts[] = {0, 0, 1, 0, 1, NAN, 0, 1};
    in = input(4, nan_pts, 0, NULL);
    expect_einval(&in, "point 2", NULL);
    nan_pts[5] = INFINITY;
    expect_einval(&in, "point 2", NULL);

    const plume_index bad_seg[] = {0, 1, 1, 2, 2, 3, 3, 17};
    in = input(4, sq, 4, bad_seg);
    expect_einval(&in, "segment 3", "17");
    const plume_index neg_seg[] = {0, -1};
    in = input(4, sq, 1, neg_seg);
    expect_einval(&in, "segment 0", "-1");
    const plume_index loop_seg[] = {0, 1, 2, 2};
    in = input(4, sq, 2, loop_seg);
    expect_einval(&in, "segment 1", NULL);

    in = input(4, sq, 0, NULL);
    in.max_edge = -0.1;
    expect_einval(&in, "max_edge", NULL);
    in.max_edge = NAN;
    expect_einval(&in, "max_edge", NULL);
    in.max_edge = 1e-9; /* ~2e18 triangles */
    expect_einval(&in, "max_edge", NULL);
    in.max_edge = 0;
    in.min_angle_bound = 0.5;
    expect_einval(&in, "min_angle_bound", NULL);

    const double dup[] = {0, 0, 1, 0, 1, 1, 1, 0};
    in = input(4, dup, 0, NULL);
    expect_einval(&in, "1 and 3", NULL);

    const double line[] = {0, 0, 1, 1, 2, 2};
    in = input(3, line, 0, NULL);
    expect_einval(&in, "collinear", NULL);

    /* the diagonals of the square cross away from any input point */
    const plume_index cross[] = {0, 2, 1, 3};
    in = input(4, sq, 2, cross);
    expect_einval(&in, "segment 1", NULL);

    const double hole_on_edge[] = {0.5, 0};
    in = input(4, sq, 4, sqseg);
    in.nholes = 1;
    in.holes = hole_on_edge;
    expect_einval(&in, "hole 0", NULL);
    const double hole_nan[] = {NAN, 0};
    in.holes = hole_nan;
    expect_einval(&in, "hole 0", NULL);

    /* an open outline encloses nothing: remove_exterior leaves no triangle */
    in = input(4, sq, 3, sqseg);
    in.remove_exterior = 1;
    expect_einval(&in, "no triangle", NULL);
    /* a hole seeded inside the only region removes everything */
    const double hole_in[] = {0.5, 0.5};
    in = input(4, sq, 4, sqseg);
    in.nholes = 1;
    in.holes = hole_in;
    expect_einval(&in, "no triangle", NULL);

    in = input(4, NULL, 0, NULL);
    expect_einval(&in, "points", NULL);
    plume_cdt_output o;
    CHECK(plume_cdt_triangulate(NULL, &o, NULL) == PLUME_EINVAL);
    in = input(4, sq, 0, NULL);
    CHECK(plume_cdt_triangulate(&in, NULL, NULL) == PLUME_EINVAL);
}
