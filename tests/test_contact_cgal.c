/* Tests of the contact broad phase and the exact intersection audit (lib/contact/contact_broad.h):
 * box pairs against brute force (touching boxes included), candidate pairs against true
 * distances on random two-body meshes, swept boxes, exact audit counts, bad inputs, and the
 * timings at 10k and 50k triangles (printed, not asserted). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "test_rng.h"
#include "../lib/contact/contact_broad.h"
#include "../lib/io/progress.h"

/* --- helpers ------------------------------------------------------------------------------------- */

static int pair_cmp(const void *x, const void *y)
{
    const plume_contact_pair *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    return (p->b > q->b) - (p->b < q->b);
}

static int has_pair(const plume_contact_pair *p, plume_index n, plume_index a, plume_index b)
{
    plume_contact_pair key = {a, b};
    if (n == 0) /* p may be NULL then */
        return 0;
    return bsearch(&key, p, (size_t)n, sizeof key, pair_cmp) != NULL;
}

/* strictly increasing by (a, b): sorted and no duplicates */
static int strictly_sorted(const plume_contact_pair *p, plume_index n)
{
    for (plume_index k = 1; k < n; k++)
        if (pair_cmp(p + k - 1, p + k) >= 0)
            return 0;
    return 1;
}

static int boxes_meet(const double *a, const double *b)
{
    for (int k = 0; k < 3; k++)
        if (a[k] > b[3 + k] || b[k] > a[3 + k])
            return 0;
    return 1;
}

static int boxes_only_touch(const double *a, const double *b)
{
    for (int k = 0; k < 3; k++)
        if (a[k] == b[3 + k] || b[k] == a[3 + k])
            return 1;
    return 0;
}

/* Boxes on a coarse dyadic lattice, so that many pairs touch exactly; some have zero extent. */
static void lattice_boxes(rng64 *r, plume_index n, double *b)
{
    for (plume_index i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            b[6 * i + k] = floor(urand(r) * 8) / 4;
            b[6 * i + 3 + k] = b[6 * i + k] + floor(urand(r) * 3) / 4;
        }
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void sub(const double *a, const double *b, double *c)
{
    for (int k = 0; k < 3; k++)
        c[k] = a[k] - b[k];
}

static double clamp01(double t)
{
    return t < 0 ? 0 : (t > 1 ? 1 : t);
}

/* Distance from p to triangle abc: closest point by Voronoi regions (Ericson, Real-Time Collision
 * Detection, 5.1.5). */
static double dist_point_triangle(const double *p, const double *a, const double *b, const double *c)
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3], d[3];
    sub(b, a, ab);
    sub(c, a, ac);
    sub(p, a, ap);
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        sub(p, a, d);
        return sqrt(dot(d, d));
    }
    sub(p, b, bp);
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        sub(p, b, d);
        return sqrt(dot(d, d));
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + v * ab[k];
        sub(p, q, d);
        return sqrt(dot(d, d));
    }
    sub(p, c, cp);
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        sub(p, c, d);
        return sqrt(dot(d, d));
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + w * ac[k];
        sub(p, q, d);
        return sqrt(dot(d, d));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            q[k] = b[k] + w * (c[k] - b[k]);
        sub(p, q, d);
        return sqrt(dot(d, d));
    }
    double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int k = 0; k < 3; k++)
        q[k] = a[k] + ab[k] * v + ac[k] * w;
    sub(p, q, d);
    return sqrt(dot(d, d));
}

/* Distance between segments p1q1 and p2q2 (Ericson 5.1.9, parallel and degenerate cases). */
static double dist_segment_segment(const double *p1, const double *q1, const double *p2, const double *q2)
{
    double d1[3], d2[3], r[3], c1[3], c2[3], d[3];
    sub(q1, p1, d1);
    sub(q2, p2, d2);
    sub(p1, p2, r);
    double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), s, t;
    if (a <= 1e-300 && e <= 1e-300) {
        s = t = 0;
    } else if (a <= 1e-300) {
        s = 0;
        t = clamp01(f / e);
    } else {
        double c = dot(d1, r);
        if (e <= 1e-300) {
            t = 0;
            s = clamp01(-c / a);
        } else {
            double b = dot(d1, d2), den = a * e - b * b;
            s = den > 0 ? clamp01((b * f - c * e) / den) : 0;
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0;
                s = clamp01(-c / a);
            } else if (t > 1) {
                t = 1;
                s = clamp01((b - c) / a);
            }
        }
    }
    for (int k = 0; k < 3; k++) {
        c1[k] = p1[k] + d1[k] * s;
        c2[k] = p2[k] + d2[k] * t;
    }
    sub(c1, c2, d);
    return sqrt(dot(d, d));
}

/* An n x n grid of squares, each cut along one diagonal: (n+1)^2 vertices at (i/n, j/n, 0) times
 * size, 2 n^2 triangles; vertex ids offset by v0. */
static void grid(int n, double size, plume_index v0, double *x, plume_index *tri)
{
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double *p = x + 3 * (j * (n + 1) + i);
            p[0] = size * i / n;
            p[1] = size * j / n;
            p[2] = 0;
        }
    plume_index t = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            plume_index a = v0 + j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            plume_index *q = tri + 3 * t;
            q[0] = a, q[1] = b, q[2] = c; /* lower: below the diagonal a-c */
            q[3] = a, q[4] = c, q[5] = d; /* upper */
            t += 2;
        }
}

/* Rotates p about the x axis by ax, then about the y axis by ay, then adds shift. */
static void place(double *p, double ax, double ay, const double shift[3])
{
    double y = p[1] * cos(ax) - p[2] * sin(ax), z = p[1] * sin(ax) + p[2] * cos(ax);
    double x = p[0] * cos(ay) + z * sin(ay);
    z = -p[0] * sin(ay) + z * cos(ay);
    p[0] = x + shift[0];
    p[1] = y + shift[1];
    p[2] = z + shift[2];
}

/* Two n x n grids over the unit square: body 0 near z = 0 (perturbed by +-noise), body 1 tilted by
 * up to tilt radians and lifted by gap. Arrays are malloc'd; the caller frees them. */
typedef struct {
    plume_index nv, ntri;
    double *x;
    plume_index *tri;
    int *body;
} two_grids;

static two_grids make_two_grids(rng64 *r, int n, double gap, double tilt, double noise)
{
    two_grids g;
    plume_index nv1 = (plume_index)(n + 1) * (n + 1), nt1 = 2 * (plume_index)n * n;
    g.nv = 2 * nv1;
    g.ntri = 2 * nt1;
    g.x = malloc(3 * (size_t)g.nv * sizeof *g.x);
    g.tri = malloc(3 * (size_t)g.ntri * sizeof *g.tri);
    g.body = malloc((size_t)g.nv * sizeof *g.body);
    grid(n, 1.0, 0, g.x, g.tri);
    grid(n, 1.0, nv1, g.x + 3 * nv1, g.tri + 3 * nt1);
    double ax = urange(r, -tilt, tilt), ay = urange(r, -tilt, tilt);
    double shift[3] = {urange(r, -0.2, 0.2), urange(r, -0.2, 0.2), gap};
    for (plume_index v = 0; v < g.nv; v++) {
        g.body[v] = v < nv1 ? 0 : 1;
        g.x[3 * v + 2] += urange(r, -noise, noise);
        if (v >= nv1)
            place(g.x + 3 * v, ax, ay, shift);
    }
    return g;
}

static void free_two_grids(two_grids *g)
{
    free(g->x);
    free(g->tri);
    free(g->body);
}

/* --- generic box pairs ----------------------------------------------------------------------------- */

void test_contact_cgal_box_pairs_brute(void)
{
    rng64 r = {0x5eed1234abcdULL};
    plume_contact_pairs out = {0};
    plume_err err;
    long touching = 0;
    for (int trial = 0; trial < 12; trial++) {
        plume_index na = 1 + (plume_index)(urand(&r) * 300), nb = 1 + (plume_index)(urand(&r) * 200);
        if (trial == 0)
            nb = 1; /* a single box against many */
        double *a = malloc(6 * (size_t)na * sizeof *a), *b = malloc(6 * (size_t)nb * sizeof *b);
        lattice_boxes(&r, na, a);
        lattice_boxes(&r, nb, b);
        CHECK(plume_contact_box_pairs(na, a, nb, b, &out, &err) == PLUME_OK);
        CHECK(strictly_sorted(out.p, out.n));
        plume_index expected = 0;
        for (plume_index i = 0; i < na; i++)
            for (plume_index j = 0; j < nb; j++)
                if (boxes_meet(a + 6 * i, b + 6 * j)) {
                    expected++;
                    touching += boxes_only_touch(a + 6 * i, b + 6 * j);
                    CHECK(has_pair(out.p, out.n, i, j));
                }
        CHECK(out.n == expected);
        for (plume_index k = 0; k < out.n; k++)
            CHECK(out.p[k].a >= 0 && out.p[k].a < na && out.p[k].b >= 0 && out.p[k].b < nb);
        free(a);
        free(b);
    }
    CHECK(touching > 100); /* the lattice does exercise closed boxes */

    /* touching by a face, an edge and a corner; a gap of one ulp does not touch */
    double u[6] = {0, 0, 0, 1, 1, 1};
    double v[4][6] = {{1, 0.2, 0.2, 2, 0.8, 0.8}, {1, 1, 0.5, 2, 2, 0.7}, {1, 1, 1, 2, 2, 2},
                      {0, 0, 0, 0.5, 0.5, 0.5}};
    v[3][0] = nextafter(1.0, 2.0), v[3][3] = 2.0; /* just past the face x = 1 */
    CHECK(plume_contact_box_pairs(1, u, 4, &v[0][0], &out, &err) == PLUME_OK);
    CHECK(out.n == 3 && has_pair(out.p, out.n, 0, 0) && has_pair(out.p, out.n, 0, 1) &&
          has_pair(out.p, out.n, 0, 2));
    /* empty sets */
    CHECK(plume_contact_box_pairs(0, NULL, 4, &v[0][0], &out, &err) == PLUME_OK && out.n == 0);
    CHECK(plume_contact_box_pairs(1, u, 0, NULL, &out, &err) == PLUME_OK && out.n == 0);
    plume_contact_pairs_free(&out);
    CHECK(out.p == NULL && out.cap == 0);
}

void test_contact_cgal_box_self_pairs_brute(void)
{
    rng64 r = {0xfeedbeef77ULL};
    plume_contact_pairs out = {0};
    plume_err err;
    for (int trial = 0; trial < 12; trial++) {
        plume_index n = 1 + (plume_index)(urand(&r) * 400);
        double *b = malloc(6 * (size_t)n * sizeof *b);
        lattice_boxes(&r, n, b);
        if (n > 3)
            memcpy(b + 6 * (n - 1), b, 6 * sizeof *b); /* two identical boxes are still a pair */
        CHECK(plume_contact_box_self_pairs(n, b, &out, &err) == PLUME_OK);
        CHECK(strictly_sorted(out.p, out.n)); /* no duplicate */
        for (plume_index k = 0; k < out.n; k++)
            CHECK(out.p[k].a < out.p[k].b && out.p[k].a >= 0 && out.p[k].b < n); /* no (i, i) */
        plume_index expected = 0;
        for (plume_index i = 0; i < n; i++)
            for (plume_index j = i + 1; j < n; j++)
                if (boxes_meet(b + 6 * i, b + 6 * j)) {
                    expected++;
                    CHECK(has_pair(out.p, out.n, i, j));
                }
        CHECK(out.n == expected);
        if (n > 3)
            CHECK(has_pair(out.p, out.n, 0, n - 1));
        free(b);
    }
    /* thousands of boxes along a thin slab (x nearly constant), so that the segment tree recurses
     * deeply and the axes are reordered: against brute force too, self and bipartite */
    plume_index n = 3000;
    double *b = malloc(6 * (size_t)n * sizeof *b);
    for (plume_index i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            double c = k == 0 ? urange(&r, 0, 0.01) : urand(&r), w = urange(&r, 0, 0.03);
            b[6 * i + k] = c - w;
            b[6 * i + 3 + k] = c + w;
        }
    CHECK(plume_contact_box_self_pairs(n, b, &out, &err) == PLUME_OK);
    plume_index expected = 0;
    for (plume_index i = 0; i < n; i++)
        for (plume_index j = i + 1; j < n; j++)
            expected += boxes_meet(b + 6 * i, b + 6 * j);
    CHECK(out.n == expected && expected > 1000 && strictly_sorted(out.p, out.n));
    for (plume_index k = 0; k < out.n; k++)
        CHECK(boxes_meet(b + 6 * out.p[k].a, b + 6 * out.p[k].b));
    CHECK(plume_contact_box_pairs(n / 2, b, n - n / 2, b + 6 * (n / 2), &out, &err) == PLUME_OK);
    expected = 0;
    for (plume_index i = 0; i < n / 2; i++)
        for (plume_index j = n / 2; j < n; j++)
            expected += boxes_meet(b + 6 * i, b + 6 * j);
    CHECK(out.n == expected && strictly_sorted(out.p, out.n));
    for (plume_index k = 0; k < out.n; k++)
        CHECK(boxes_meet(b + 6 * out.p[k].a, b + 6 * (n / 2 + out.p[k].b)));
    free(b);

    CHECK(plume_contact_box_self_pairs(0, NULL, &out, &err) == PLUME_OK && out.n == 0);
    double one[6] = {0, 0, 0, 1, 1, 1};
    CHECK(plume_contact_box_self_pairs(1, one, &out, &err) == PLUME_OK && out.n == 0);
    plume_contact_pairs_free(&out);
}

/* --- candidates ------------------------------------------------------------------------------------ */

static int shares_vertex_vt(const plume_index *tri, plume_index v, plume_index t)
{
    return tri[3 * t] == v || tri[3 * t + 1] == v || tri[3 * t + 2] == v;
}

static int shares_vertex_ee(const plume_index *e, plume_index a, plume_index b)
{
    return e[2 * a] == e[2 * b] || e[2 * a] == e[2 * b + 1] || e[2 * a + 1] == e[2 * b] ||
           e[2 * a + 1] == e[2 * b + 1];
}

/* Every pair closer than dhat (true distance, margin 1e-9 for the test's own rounding) is a
 * candidate; no candidate shares a vertex or, between bodies only, lies in one body. Returns the
 * number of close pairs checked. */
static long check_candidates(const two_grids *g, const plume_contact_broad *b, const plume_contact_candidates *c,
                             double dhat, int self_contact)
{
    plume_index ne;
    const plume_index *e;
    plume_contact_broad_edges(b, &ne, &e);
    const double *x = g->x;
    long close = 0;
    CHECK(strictly_sorted(c->vt, c->nvt));
    CHECK(strictly_sorted(c->ee, c->nee));
    for (plume_index k = 0; k < c->nvt; k++) {
        plume_index v = c->vt[k].a, t = c->vt[k].b;
        CHECK(!shares_vertex_vt(g->tri, v, t));
        if (!self_contact)
            CHECK(g->body[v] != g->body[g->tri[3 * t]]);
    }
    for (plume_index k = 0; k < c->nee; k++) {
        CHECK(c->ee[k].a < c->ee[k].b);
        CHECK(!shares_vertex_ee(e, c->ee[k].a, c->ee[k].b));
        if (!self_contact)
            CHECK(g->body[e[2 * c->ee[k].a]] != g->body[e[2 * c->ee[k].b]]);
    }
    for (plume_index v = 0; v < g->nv; v++)
        for (plume_index t = 0; t < g->ntri; t++) {
            if (shares_vertex_vt(g->tri, v, t) || (!self_contact && g->body[v] == g->body[g->tri[3 * t]]))
                continue;
            const plume_index *q = g->tri + 3 * t;
            double d = dist_point_triangle(x + 3 * v, x + 3 * q[0], x + 3 * q[1], x + 3 * q[2]);
            if (d < dhat * (1 - 1e-9)) {
                close++;
                CHECK(has_pair(c->vt, c->nvt, v, t));
            }
        }
    for (plume_index a = 0; a < ne; a++)
        for (plume_index bb = a + 1; bb < ne; bb++) {
            if (shares_vertex_ee(e, a, bb) || (!self_contact && g->body[e[2 * a]] == g->body[e[2 * bb]]))
                continue;
            double d = dist_segment_segment(x + 3 * e[2 * a], x + 3 * e[2 * a + 1], x + 3 * e[2 * bb],
                                            x + 3 * e[2 * bb + 1]);
            if (d < dhat * (1 - 1e-9)) {
                close++;
                CHECK(has_pair(c->ee, c->nee, a, bb));
            }
        }
    return close;
}

void test_contact_cgal_candidates_distance(void)
{
    rng64 r = {0xc0ffee42ULL};
    plume_err err;
    long close_between = 0, close_self = 0;
    for (int trial = 0; trial < 16; trial++) {
        int n = 2 + (int)(urand(&r) * 5);
        two_grids g = make_two_grids(&r, n, urange(&r, 0.0, 0.4), 0.6, 0.02);
        double dhat = urange(&r, 0.03, 0.35);
        for (int self = 0; self <= 1; self++) {
            plume_contact_broad_opts o;
            plume_contact_broad_opts_default(&o);
            CHECK(o.self_contact == 1);
            o.self_contact = self;
            plume_contact_broad *b = NULL;
            CHECK(plume_contact_broad_create(g.nv, g.ntri, g.tri, g.body, &o, &b, &err) == PLUME_OK);
            plume_index ne;
            const plume_index *e;
            plume_contact_broad_edges(b, &ne, &e);
            CHECK(ne == 2 * (2 * (plume_index)n * (n + 1) + (plume_index)n * n)); /* rows, columns, diagonals */
            for (plume_index k = 0; k < ne; k++) {
                CHECK(e[2 * k] < e[2 * k + 1]);
                if (k > 0)
                    CHECK(e[2 * k - 2] < e[2 * k] || (e[2 * k - 2] == e[2 * k] && e[2 * k - 1] < e[2 * k + 1]));
            }
            plume_contact_candidates c;
            CHECK(plume_contact_broad_update(b, g.x, NULL, dhat, &c, &err) == PLUME_OK);
            CHECK(c.seconds >= 0);
            long k = check_candidates(&g, b, &c, dhat, self);
            if (self)
                close_self += k;
            else
                close_between += k;
            plume_contact_broad_destroy(&b);
            CHECK(b == NULL);
        }
        free_two_grids(&g);
    }
    fprintf(stderr, "    close pairs checked: %ld between bodies, %ld with self-contact\n", close_between,
            close_self);
    CHECK(close_between > 500);
    CHECK(close_self > close_between);

    /* d == dhat exactly (an axis-aligned vertex over a triangle) is still a candidate: closed,
     * outward-rounded boxes; at 1.5 dhat it is not */
    double x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.25, 0.25, 0.1};
    plume_index tri[3] = {0, 1, 2};
    plume_contact_broad *b = NULL;
    CHECK(plume_contact_broad_create(4, 1, tri, NULL, NULL, &b, &err) == PLUME_OK);
    plume_contact_candidates c;
    CHECK(plume_contact_broad_update(b, x, NULL, 0.1, &c, &err) == PLUME_OK);
    CHECK(c.nvt == 1 && c.vt[0].a == 3 && c.vt[0].b == 0 && c.nee == 0);
    x[11] = 0.15;
    CHECK(plume_contact_broad_update(b, x, NULL, 0.1, &c, &err) == PLUME_OK);
    CHECK(c.nvt == 0);
    plume_contact_broad_destroy(&b);
    plume_contact_broad_destroy(&b); /* NULL-safe */
    plume_contact_broad_destroy(NULL);
}

void test_contact_cgal_candidates_swept(void)
{
    plume_err err;
    /* body 0: triangle 0 in z = 0; body 1: triangle 1 whose vertex 3 falls from z = 1 to z = -1
     * through triangle 0 while 4 and 5 stay far above */
    double x0[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 1, 0.2, 0.3, 3, 0.4, 0.2, 3};
    double x1[18];
    memcpy(x1, x0, sizeof x0);
    x1[11] = -1;
    plume_index tri[6] = {0, 1, 2, 3, 4, 5};
    int body[6] = {0, 0, 0, 1, 1, 1};
    plume_contact_broad_opts o;
    plume_contact_broad_opts_default(&o);
    o.self_contact = 0;
    plume_contact_broad *b = NULL;
    CHECK(plume_contact_broad_create(6, 2, tri, body, &o, &b, &err) == PLUME_OK);
    plume_contact_candidates c;
    CHECK(plume_contact_broad_update(b, x0, NULL, 0.01, &c, &err) == PLUME_OK);
    CHECK(!has_pair(c.vt, c.nvt, 3, 0)); /* at the start, far apart */
    CHECK(plume_contact_broad_update(b, x1, NULL, 0.01, &c, &err) == PLUME_OK);
    CHECK(!has_pair(c.vt, c.nvt, 3, 0)); /* at the end too */
    CHECK(plume_contact_broad_update(b, x0, x1, 0.01, &c, &err) == PLUME_OK);
    CHECK(has_pair(c.vt, c.nvt, 3, 0)); /* but it crosses triangle 0 during the step */
    CHECK(plume_contact_broad_update(b, x1, x0, 0.01, &c, &err) == PLUME_OK);
    CHECK(has_pair(c.vt, c.nvt, 3, 0)); /* and on the way back */

    /* edge 3-4 (x = 0.5, y from -0.5 to 0.5) falls from z = 1 to z = -1 through edge 0-1 (y = 0) */
    plume_index ne;
    const plume_index *e;
    plume_contact_broad_edges(b, &ne, &e);
    CHECK(ne == 6);
    plume_index e01 = -1, e34 = -1;
    for (plume_index k = 0; k < ne; k++) {
        if (e[2 * k] == 0 && e[2 * k + 1] == 1)
            e01 = k;
        if (e[2 * k] == 3 && e[2 * k + 1] == 4)
            e34 = k;
    }
    CHECK(e01 == 0 && e34 >= 0); /* edges are sorted */
    double y0[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, -0.5, 1, 0.5, 0.5, 1, 3, 3, 3};
    double y1[18];
    memcpy(y1, y0, sizeof y0);
    y1[11] = y1[14] = -1;
    CHECK(plume_contact_broad_update(b, y0, NULL, 0.01, &c, &err) == PLUME_OK);
    CHECK(!has_pair(c.ee, c.nee, e01, e34));
    CHECK(plume_contact_broad_update(b, y1, NULL, 0.01, &c, &err) == PLUME_OK);
    CHECK(!has_pair(c.ee, c.nee, e01, e34));
    CHECK(plume_contact_broad_update(b, y0, y1, 0.01, &c, &err) == PLUME_OK);
    CHECK(has_pair(c.ee, c.nee, e01, e34));
    long updates;
    double secs;
    plume_contact_broad_stats(b, &updates, &secs);
    CHECK(updates == 7 && secs >= 0);
    plume_contact_broad_stats(NULL, &updates, &secs);
    CHECK(updates == 0 && secs == 0);
    plume_contact_broad_destroy(&b);
}

/* The candidate lists are reused: a second update with the same geometry does not reallocate. */
void test_contact_cgal_candidates_reuse(void)
{
    rng64 r = {0xabcdef01ULL};
    plume_err err;
    two_grids g = make_two_grids(&r, 6, 0.05, 0.1, 0.01);
    plume_contact_broad *b = NULL;
    CHECK(plume_contact_broad_create(g.nv, g.ntri, g.tri, g.body, NULL, &b, &err) == PLUME_OK);
    plume_contact_candidates c1, c2;
    CHECK(plume_contact_broad_update(b, g.x, NULL, 0.1, &c1, &err) == PLUME_OK);
    CHECK(c1.nvt > 0 && c1.nee > 0);
    plume_contact_pair *copy = malloc((size_t)c1.nvt * sizeof *copy);
    memcpy(copy, c1.vt, (size_t)c1.nvt * sizeof *copy);
    CHECK(plume_contact_broad_update(b, g.x, NULL, 0.1, &c2, &err) == PLUME_OK);
    CHECK(c2.vt == c1.vt && c2.ee == c1.ee); /* same memory */
    CHECK(c2.nvt == c1.nvt && c2.nee == c1.nee && memcmp(copy, c2.vt, (size_t)c1.nvt * sizeof *copy) == 0);
    /* a smaller dhat gives a subset */
    CHECK(plume_contact_broad_update(b, g.x, NULL, 0.02, &c2, &err) == PLUME_OK);
    CHECK(c2.nvt < c1.nvt);
    for (plume_index k = 0; k < c2.nvt; k++)
        CHECK(has_pair(copy, c1.nvt, c2.vt[k].a, c2.vt[k].b));
    free(copy);
    plume_contact_broad_destroy(&b);
    free_two_grids(&g);
}

/* With opts.reuse the handle answers from the pairs kept at a reference placement while the
 * vertices stay within their reach: every answer must be the fresh search's, pair for pair and in
 * its order, through drifts, sweeps of every size (a vertex-dependent share of a random motion, as
 * a Newton step moves a feather's tip more than its root), alternating inflations, and jumps that
 * force a new search. */
void test_contact_cgal_candidates_kept_pairs(void)
{
    rng64 r = {0x5eedf00dULL};
    plume_err err;
    long queries = 0, searches = 0;
    for (int self = 0; self <= 1; self++) {
        two_grids g = make_two_grids(&r, 7, 0.04, 0.2, 0.01);
        plume_contact_broad_opts o;
        plume_contact_broad_opts_default(&o);
        CHECK(o.reuse == 0);
        o.self_contact = self;
        plume_contact_broad *fresh = NULL, *kept = NULL;
        CHECK(plume_contact_broad_create(g.nv, g.ntri, g.tri, g.body, &o, &fresh, &err) == PLUME_OK);
        o.reuse = 1;
        CHECK(plume_contact_broad_create(g.nv, g.ntri, g.tri, g.body, &o, &kept, &err) == PLUME_OK);
        double *x1 = malloc(3 * (size_t)g.nv * sizeof *x1), *share = malloc((size_t)g.nv * sizeof *share);
        for (plume_index v = 0; v < g.nv; v++)
            share[v] = urand(&r);
        long nonempty = 0;
        for (int q = 0; q < 200; q++) {
            const int swept = q % 3 != 0;
            const double size = q % 37 == 36 ? 0.2 : pow(10.0, urange(&r, -9.0, -1.5)); /* now and then a jump */
            for (plume_index i = 0; i < 3 * g.nv; i++)
                x1[i] = g.x[i] + size * share[i / 3] * urange(&r, -1.0, 1.0);
            const double dhat = swept ? 0.0 : 0.03;
            plume_contact_candidates a, b;
            CHECK(plume_contact_broad_update(fresh, g.x, swept ? x1 : NULL, dhat, &a, &err) == PLUME_OK);
            CHECK(plume_contact_broad_update(kept, g.x, swept ? x1 : NULL, dhat, &b, &err) == PLUME_OK);
            CHECK(a.nvt == b.nvt && a.nee == b.nee);
            CHECK(a.nvt == b.nvt && (a.nvt == 0 || memcmp(a.vt, b.vt, (size_t)a.nvt * sizeof *a.vt) == 0));
            CHECK(a.nee == b.nee && (a.nee == 0 || memcmp(a.ee, b.ee, (size_t)a.nee * sizeof *a.ee) == 0));
            nonempty += a.nvt + a.nee > 0;
            if (q % 2) /* the iterate moves along part of the swept motion */
                for (plume_index i = 0; i < 3 * g.nv; i++)
                    g.x[i] += urand(&r) * (x1[i] - g.x[i]);
            queries++;
        }
        CHECK(nonempty > 100);
        CHECK(plume_contact_broad_searches(fresh) == 200);
        const long s = plume_contact_broad_searches(kept);
        CHECK(s >= 5 && s < 100); /* the jumps search anew; most updates do not */
        searches += s;
        free(x1);
        free(share);
        plume_contact_broad_destroy(&fresh);
        plume_contact_broad_destroy(&kept);
        free_two_grids(&g);
    }
    CHECK(plume_contact_broad_searches(NULL) == 0);
    fprintf(stderr, "    %ld updates answered as a fresh search would, %ld of them searched anew\n", queries, searches);
}

/* --- audit ------------------------------------------------------------------------------------------ */

static plume_index audit(plume_index nv, const double *x, plume_index ntri, const plume_index *tri,
                         plume_index *degenerate)
{
    plume_contact_audit a;
    plume_err err;
    plume_status st = plume_contact_count_intersections(nv, x, ntri, tri, NULL, &a, &err);
    CHECK(st == PLUME_OK);
    if (st != PLUME_OK)
        fprintf(stderr, "    %s\n", err.msg);
    if (degenerate)
        *degenerate = a.degenerate;
    return a.intersecting;
}

void test_contact_cgal_audit_pairs(void)
{
    plume_index tri[6] = {0, 1, 2, 3, 4, 5}, deg;
    /* triangle 0 in z = 0; triangle 1 vertical, crossing it */
    double cross[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, -0.5, 0.2, 0.2, 0.5, 0.6, 0.2, 0.5};
    CHECK(audit(6, cross, 2, tri, &deg) == 1 && deg == 0);
    /* parallel, separated */
    double par[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0.1, 1, 0, 0.1, 0, 1, 0.1};
    CHECK(audit(6, par, 2, tri, NULL) == 0);
    /* coplanar and overlapping */
    double cop[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0, 1.2, 0.2, 0, 0.2, 1.2, 0};
    CHECK(audit(6, cop, 2, tri, NULL) == 1);
    /* a corner of triangle 1 exactly on the interior of triangle 0: touching counts */
    double touch[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.25, 0.25, 0, 0.5, 0.25, 1, 0.25, 0.5, 1};
    CHECK(audit(6, touch, 2, tri, NULL) == 1);
    /* the same corner one ulp above the plane: exact predicates see the gap */
    touch[11] = nextafter(0.0, 1.0);
    CHECK(audit(6, touch, 2, tri, NULL) == 0);
    touch[11] = -nextafter(0.0, 1.0); /* one ulp below: it pierces */
    CHECK(audit(6, touch, 2, tri, NULL) == 1);
    /* a corner on an edge of the other, a corner on a corner of the other (no shared id) */
    double edge[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5, 0, 0, 0.5, -1, 1, 0.7, -1, 1};
    CHECK(audit(6, edge, 2, tri, NULL) == 1);
    double corner[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 2, 0, 1, 2, 1, 1};
    CHECK(audit(6, corner, 2, tri, NULL) == 1);

    /* one list with the pairs */
    plume_contact_pairs pairs = {0};
    plume_contact_audit a;
    plume_err err;
    CHECK(plume_contact_count_intersections(6, cross, 2, tri, &pairs, &a, &err) == PLUME_OK);
    CHECK(a.intersecting == 1 && pairs.n == 1 && pairs.p[0].a == 0 && pairs.p[0].b == 1 && a.seconds >= 0);
    CHECK(plume_contact_count_intersections(6, par, 2, tri, &pairs, &a, &err) == PLUME_OK);
    CHECK(a.intersecting == 0 && pairs.n == 0);
    plume_contact_pairs_free(&pairs);

    /* degenerate triangles: collinear corners (a segment) piercing triangle 0 count, and are
     * reported; a repeated id (a segment too) missing it does not count; a point on it counts */
    double segx[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, -1, 0.2, 0.2, 1, 0.2, 0.2, 0};
    CHECK(audit(6, segx, 2, tri, &deg) == 1 && deg == 1);
    plume_index rep[6] = {0, 1, 2, 3, 4, 4};
    double away[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 2, -1, 2, 2, 1, 0, 0, 0};
    CHECK(audit(6, away, 2, rep, &deg) == 0 && deg == 1);
    double pt[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.1, 0.1, 0, 0.1, 0.1, 0, 0.1, 0.1, 0};
    CHECK(audit(6, pt, 2, tri, &deg) == 1 && deg == 1);
    pt[11] = pt[14] = pt[17] = 1e-300; /* the point just above: apart */
    CHECK(audit(6, pt, 2, tri, &deg) == 0 && deg == 1);
    /* two degenerate ones crossing each other: segment-segment, segment-point */
    double two[18] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0.5, -1, 0, 0.5, 1, 0, 0.5, 0, 0};
    CHECK(audit(6, two, 2, tri, &deg) == 1 && deg == 2);
    double sp[18] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 1.5, 0, 0, 1.5, 0, 0, 1.5, 0, 0};
    CHECK(audit(6, sp, 2, tri, &deg) == 1 && deg == 2);
    /* zero or one triangle */
    CHECK(audit(0, NULL, 0, NULL, &deg) == 0 && deg == 0);
    CHECK(audit(6, sp, 1, tri, &deg) == 0 && deg == 1);
}

/* Triangles sharing a vertex are never counted, even folded onto each other. */
void test_contact_cgal_audit_folded(void)
{
    /* two triangles sharing the edge 0-1, folded flat onto each other (coplanar, overlapping) */
    double fold[12] = {0, 0, 0, 1, 0, 0, 0.3, 1, 0, 0.6, 1, 0};
    plume_index ft[6] = {0, 1, 2, 1, 0, 3};
    CHECK(audit(4, fold, 2, ft, NULL) == 0);
    /* a fan around vertex 0 whose blades cross each other */
    double fan[15] = {0, 0, 0, 1, 0, -0.5, 1, 0, 0.5, 1, -0.5, 0, 1, 0.5, 0};
    plume_index fant[6] = {0, 1, 2, 0, 3, 4};
    CHECK(audit(5, fan, 2, fant, NULL) == 0);
    /* add a triangle with its own vertices crossing both blades: 2 */
    double fan2[24] = {0, 0, 0, 1, 0, -0.5, 1, 0, 0.5, 1, -0.5, 0, 1, 0.5, 0, 0.8, -1, -1, 0.8, 1, -1, 0.8, 0, 2};
    plume_index fant2[9] = {0, 1, 2, 0, 3, 4, 5, 6, 7};
    CHECK(audit(8, fan2, 3, fant2, NULL) == 2);

    /* a strip folded in zig-zag: vertices along two rows with x alternating 0, 1, 0, 1..., so every
     * cell covers the unit square of z = 0 and every two triangles of different cells meet (they
     * overlap, or touch along a diagonal). Cell k has vertices 2k..2k+3 and triangles
     * (2k, 2k+2, 2k+3), (2k, 2k+3, 2k+1). Cells k and k+2 or further share no vertex: 4 pairs
     * each. Neighbouring cells share 2k+2 and 2k+3, and only the pair (2k, 2k+3, 2k+1) -
     * (2k+2, 2k+4, 2k+5) shares none (one per neighbouring cells). The other coplanar
     * overlapping pairs share a vertex and are not counted. */
    enum { cells = 6 };
    double zz[3 * 2 * (cells + 1)];
    plume_index zt[3 * 2 * cells];
    for (int k = 0; k <= cells; k++) {
        double xk = (k % 2) ? 1.0 : 0.0;
        double *p = zz + 6 * k;
        p[0] = xk, p[1] = 0, p[2] = 0;
        p[3] = xk, p[4] = 1, p[5] = 0;
    }
    for (int k = 0; k < cells; k++) {
        plume_index a = 2 * k, b = 2 * k + 1, c = 2 * k + 2, d = 2 * k + 3;
        plume_index *q = zt + 6 * k;
        q[0] = a, q[1] = c, q[2] = d;
        q[3] = a, q[4] = d, q[5] = b;
    }
    plume_index expected = cells - 1;
    for (int k = 0; k < cells; k++)
        for (int j = k + 2; j < cells; j++)
            expected += 4;
    CHECK(expected == 45);
    CHECK(audit(2 * (cells + 1), zz, 2 * cells, zt, NULL) == expected);
}

/* Two grids of 2 n^2 triangles crossing along a line: n = 2^p so every coordinate is dyadic and
 * the crossing points are exactly where the count below assumes. A lies in z = 0 over [0, 1]^2;
 * B lies in the plane y = c, c = (j0 + 1/2)/n, spanning x in [1/(4n), 1 + 1/(4n)] and z such that
 * z = 0 is the middle of one of its rows. Along the line y = c, z = 0, A's triangles cover the
 * intervals [k, k + 1]/(2n), k = 0..2n-1 (each cell's diagonal crosses the line at its middle),
 * and B's cover [k + 1/2, k + 3/2]/(2n), k = 0..2n-1. No endpoints coincide, so each interval of B
 * overlaps two of A except the last, which overlaps one: 4n - 1 pairs. */
static plume_index crossing_grids(int n, int j0, double *x, plume_index *tri)
{
    plume_index nv1 = (plume_index)(n + 1) * (n + 1), nt1 = 2 * (plume_index)n * n;
    grid(n, 1.0, 0, x, tri);
    grid(n, 1.0, nv1, x + 3 * nv1, tri + 3 * nt1);
    double c = (j0 + 0.5) / n;
    for (plume_index v = nv1; v < 2 * nv1; v++) {
        double *p = x + 3 * v;
        double u = p[0], w = p[1];
        p[0] = u + 0.25 / n;
        p[1] = c;
        p[2] = w - (j0 + 0.5) / n;
    }
    return 4 * (plume_index)n - 1;
}

void test_contact_cgal_audit_grids(void)
{
    int sizes[3] = {2, 8, 32};
    for (int s = 0; s < 3; s++) {
        int n = sizes[s];
        plume_index nv = 2 * (plume_index)(n + 1) * (n + 1), ntri = 4 * (plume_index)n * n;
        double *x = malloc(3 * (size_t)nv * sizeof *x);
        plume_index *tri = malloc(3 * (size_t)ntri * sizeof *tri);
        for (int j0 = 0; j0 < n; j0 += (n > 2 ? n / 2 - 1 : 1)) {
            plume_index expected = crossing_grids(n, j0, x, tri);
            plume_contact_pairs pairs = {0};
            plume_contact_audit a;
            plume_err err;
            CHECK(plume_contact_count_intersections(nv, x, ntri, tri, &pairs, &a, &err) == PLUME_OK);
            CHECK(a.intersecting == expected && pairs.n == expected && a.degenerate == 0);
            if (a.intersecting != expected)
                fprintf(stderr, "    n = %d, j0 = %d: %ld intersecting, expected %ld\n", n, j0, a.intersecting,
                        expected);
            for (plume_index k = 0; k < pairs.n; k++)
                CHECK(pairs.p[k].a < ntri / 2 && pairs.p[k].b >= ntri / 2); /* one of A, one of B */
            /* lift B above A: no intersection */
            for (plume_index v = nv / 2; v < nv; v++)
                x[3 * v + 2] += 1.0;
            CHECK(plume_contact_count_intersections(nv, x, ntri, tri, &pairs, &a, &err) == PLUME_OK);
            CHECK(a.intersecting == 0 && pairs.n == 0);
            plume_contact_pairs_free(&pairs);
        }
        free(x);
        free(tri);
    }
}

/* --- bad inputs ---------------------------------------------------------------------------------- */

static void expect_einval(plume_status st, const plume_err *err, const char *word)
{
    CHECK(st == PLUME_EINVAL);
    CHECK(strstr(err->msg, word) != NULL);
    if (st != PLUME_EINVAL || !strstr(err->msg, word))
        fprintf(stderr, "    expected EINVAL with '%s', got %d: %s\n", word, (int)st, err->msg);
}

void test_contact_cgal_bad_inputs(void)
{
    plume_err err;
    plume_contact_pairs out = {0};
    double box[12] = {0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1};
    expect_einval(plume_contact_box_pairs(1, box, 1, box, NULL, &err), &err, "output");
    expect_einval(plume_contact_box_pairs(-1, box, 1, box, &out, &err), &err, "negative");
    expect_einval(plume_contact_box_pairs(1, box, 2, NULL, &out, &err), &err, "NULL");
    expect_einval(plume_contact_box_self_pairs(-3, box, &out, &err), &err, "negative");
    expect_einval(plume_contact_box_self_pairs(2, NULL, &out, &err), &err, "NULL");
    box[10] = NAN;
    expect_einval(plume_contact_box_self_pairs(2, box, &out, &err), &err, "box 1");
    expect_einval(plume_contact_box_pairs(1, box, 2, box, &out, &err), &err, "not finite");
    box[10] = 1;
    box[7] = 2; /* lo y > hi y */
    expect_einval(plume_contact_box_self_pairs(2, box, &out, &err), &err, "lo 2 > hi 1");
    box[7] = 0;
    box[9] = DBL_MAX;
    expect_einval(plume_contact_box_self_pairs(2, box, &out, &err), &err, "DBL_MAX");
    box[9] = 1;
    CHECK(plume_contact_box_self_pairs(2, box, &out, &err) == PLUME_OK && out.n == 1);
    plume_contact_pairs_free(&out);

    /* broad phase */
    double x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    plume_index tri[6] = {0, 1, 2, 0, 1, 3};
    int body[4] = {0, 0, 0, 1};
    plume_contact_broad *b = (plume_contact_broad *)1;
    plume_contact_broad_opts o;
    plume_contact_broad_opts_default(&o);
    expect_einval(plume_contact_broad_create(4, 1, tri, NULL, &o, NULL, &err), &err, "NULL");
    expect_einval(plume_contact_broad_create(-4, 1, tri, NULL, &o, &b, &err), &err, "nv = -4");
    CHECK(b == NULL);
    expect_einval(plume_contact_broad_create(4, -1, tri, NULL, &o, &b, &err), &err, "ntri = -1");
    expect_einval(plume_contact_broad_create(4, 1, NULL, NULL, &o, &b, &err), &err, "tri is NULL");
    plume_index bad[3] = {0, 1, 4};
    expect_einval(plume_contact_broad_create(4, 1, bad, NULL, &o, &b, &err), &err, "vertex id 4 out of range");
    bad[2] = -1;
    expect_einval(plume_contact_broad_create(4, 1, bad, NULL, &o, &b, &err), &err, "vertex id -1");
    bad[2] = 1;
    expect_einval(plume_contact_broad_create(4, 1, bad, NULL, &o, &b, &err), &err, "repeated vertex");
    expect_einval(plume_contact_broad_create(4, 2, tri, body, &o, &b, &err), &err, "triangle 1");
    CHECK(b == NULL);
    o.self_contact = 0;
    expect_einval(plume_contact_broad_create(4, 1, tri, NULL, &o, &b, &err), &err, "body is needed");
    o.self_contact = 2;
    expect_einval(plume_contact_broad_create(4, 1, tri, body, &o, &b, &err), &err, "self_contact = 2");
    plume_contact_broad_opts_default(&o);
    CHECK(plume_contact_broad_create(4, 1, tri, body, &o, &b, &err) == PLUME_OK && b != NULL);
    plume_contact_candidates c;
    expect_einval(plume_contact_broad_update(b, x, NULL, 0.1, NULL, &err), &err, "output");
    expect_einval(plume_contact_broad_update(NULL, x, NULL, 0.1, &c, &err), &err, "handle");
    expect_einval(plume_contact_broad_update(b, NULL, NULL, 0.1, &c, &err), &err, "x is NULL");
    expect_einval(plume_contact_broad_update(b, x, NULL, -0.1, &c, &err), &err, "dhat");
    expect_einval(plume_contact_broad_update(b, x, NULL, NAN, &c, &err), &err, "dhat");
    x[7] = NAN;
    expect_einval(plume_contact_broad_update(b, x, NULL, 0.1, &c, &err), &err, "vertex 2: start (x) coordinate 1");
    CHECK(c.nvt == 0 && c.vt == NULL);
    x[7] = 1;
    double x1[12];
    memcpy(x1, x, sizeof x);
    x1[9] = INFINITY;
    expect_einval(plume_contact_broad_update(b, x, x1, 0.1, &c, &err), &err, "vertex 3: end (x1) coordinate 0");
    x1[9] = 0;
    x1[0] = -DBL_MAX;
    expect_einval(plume_contact_broad_update(b, x, x1, 0.1, &c, &err), &err, "too large");
    x1[0] = 0;
    CHECK(plume_contact_broad_update(b, x, x1, 0.1, &c, &err) == PLUME_OK);
    CHECK(c.nvt == 0); /* vertex 3 stays 1 above triangle 0 */
    x1[9] = x1[10] = 0.2;
    x1[11] = -1; /* vertex 3 falls through triangle 0 during the step */
    CHECK(plume_contact_broad_update(b, x, x1, 0.1, &c, &err) == PLUME_OK);
    CHECK(c.nvt == 1 && c.vt[0].a == 3 && c.vt[0].b == 0);
    plume_contact_broad_destroy(&b);

    /* audit */
    plume_contact_audit a;
    expect_einval(plume_contact_count_intersections(4, x, 2, tri, NULL, NULL, &err), &err, "output");
    expect_einval(plume_contact_count_intersections(-1, x, 2, tri, NULL, &a, &err), &err, "nv = -1");
    expect_einval(plume_contact_count_intersections(4, x, -2, tri, NULL, &a, &err), &err, "ntri = -2");
    expect_einval(plume_contact_count_intersections(4, NULL, 2, tri, NULL, &a, &err), &err, "x is NULL");
    expect_einval(plume_contact_count_intersections(4, x, 2, NULL, NULL, &a, &err), &err, "tri is NULL");
    expect_einval(plume_contact_count_intersections(3, x, 2, tri, NULL, &a, &err), &err,
                  "triangle 1: vertex id 3 out of range");
    x[5] = NAN;
    plume_contact_pairs pairs = {0};
    expect_einval(plume_contact_count_intersections(4, x, 2, tri, &pairs, &a, &err), &err, "vertex 1: coordinate 2");
    CHECK(a.intersecting == 0 && pairs.n == 0);
    x[5] = 0;
    CHECK(plume_contact_count_intersections(4, x, 2, tri, &pairs, &a, &err) == PLUME_OK);
    CHECK(a.intersecting == 0); /* they share an edge */
    plume_contact_pairs_free(&pairs);
    plume_contact_pairs_free(NULL);
    CHECK(plume_contact_box_pairs(0, NULL, 0, NULL, &out, NULL) == PLUME_OK); /* err may be NULL */
    CHECK(plume_contact_box_pairs(-1, NULL, 0, NULL, &out, NULL) == PLUME_EINVAL);
}

/* --- timings ----------------------------------------------------------------------------------- */

/* Two stacked perturbed grids (spacing h; body 0 at z = 0, body 1 at z = 0.6 h; noise +-0.1 h on
 * every coordinate): candidates with dhat = h / 2 between bodies and with self-contact, static and
 * swept (x1 = x + noise of 0.05 h), then the audit, separated and after body 1 has been pushed
 * into body 0. Figures printed (best of 3); the assertions check counts only. */
void test_contact_cgal_timing(void)
{
    int sizes[2] = {50, 112}; /* 2 x 2 n^2 = 10 000 and 50 176 triangles */
    rng64 r = {0x7135ULL};
    for (int s = 0; s < 2; s++) {
        int n = sizes[s];
        double h = 1.0 / n;
        two_grids g = make_two_grids(&r, n, 0.6 * h, 0.0, 0.1 * h);
        for (plume_index v = 0; v < g.nv; v++) /* in-plane jitter too */
            for (int k = 0; k < 2; k++)
                g.x[3 * v + k] += urange(&r, -0.1 * h, 0.1 * h);
        double *x1 = malloc(3 * (size_t)g.nv * sizeof *x1);
        for (plume_index v = 0; v < 3 * g.nv; v++)
            x1[v] = g.x[v] + urange(&r, -0.05 * h, 0.05 * h);
        plume_err err;
        for (int self = 0; self <= 1; self++) {
            plume_contact_broad_opts o;
            plume_contact_broad_opts_default(&o);
            o.self_contact = self;
            plume_contact_broad *b = NULL;
            double t0 = plume_wall_seconds();
            CHECK(plume_contact_broad_create(g.nv, g.ntri, g.tri, g.body, &o, &b, &err) == PLUME_OK);
            double tc = plume_wall_seconds() - t0;
            plume_contact_candidates c;
            double best = 1e30, best_swept = 1e30;
            for (int rep = 0; rep < 3; rep++) {
                CHECK(plume_contact_broad_update(b, g.x, NULL, 0.5 * h, &c, &err) == PLUME_OK);
                best = c.seconds < best ? c.seconds : best;
            }
            plume_index nvt = c.nvt, nee = c.nee;
            for (int rep = 0; rep < 3; rep++) {
                CHECK(plume_contact_broad_update(b, g.x, x1, 0.5 * h, &c, &err) == PLUME_OK);
                best_swept = c.seconds < best_swept ? c.seconds : best_swept;
            }
            CHECK(c.nvt >= nvt && nvt > 0);
            fprintf(stderr,
                    "    %ld triangles, %s: create %.4f s; candidates %.4f s (%ld vt, %ld ee), swept %.4f s "
                    "(%ld vt, %ld ee)\n",
                    g.ntri, self ? "self-contact" : "between bodies", tc, best, nvt, nee, best_swept, c.nvt,
                    c.nee);
            plume_contact_broad_destroy(&b);
        }
        plume_contact_audit a;
        double best = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            CHECK(plume_contact_count_intersections(g.nv, g.x, g.ntri, g.tri, NULL, &a, &err) == PLUME_OK);
            best = a.seconds < best ? a.seconds : best;
        }
        CHECK(a.intersecting == 0 && a.degenerate == 0);
        /* push body 1 down onto body 0: the two noisy sheets cross everywhere */
        for (plume_index v = g.nv / 2; v < g.nv; v++)
            g.x[3 * v + 2] -= 0.6 * h;
        double tcross = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            CHECK(plume_contact_count_intersections(g.nv, g.x, g.ntri, g.tri, NULL, &a, &err) == PLUME_OK);
            tcross = a.seconds < tcross ? a.seconds : tcross;
        }
        CHECK(a.intersecting > g.ntri / 4);
        fprintf(stderr, "    %ld triangles: audit %.4f s separated, %.4f s interpenetrating (%ld pairs)\n", g.ntri,
                best, tcross, a.intersecting);
        free(x1);
        free_two_grids(&g);
    }
}
