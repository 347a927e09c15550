/* plume: broad phase of shell contact and the intersection audit (lib/contact/contact_broad.h): inputs,
 * edges, boxes and filters; the CGAL calls are in lib/contact/contact_cgal.cpp.
 *
 * Why inflating every primitive's box by r = dhat/2 finds every pair closer than dhat.
 * Let P and Q be two primitives (a point, a segment or a triangle: the convex hull of their
 * corners) and p in P, q in Q with |p - q| <= dhat. A primitive lies in the tight box [lo, hi]
 * of its corners (component-wise min and max), and its broad-phase box is [lo - r, hi + r]. On
 * every axis k, |p_k - q_k| <= |p - q| <= dhat = 2r. If the boxes were disjoint along k, say
 * hi^P_k + r < lo^Q_k - r, then q_k - p_k >= lo^Q_k - hi^P_k > 2r: a contradiction. So the closed
 * intervals overlap on all three axes and the closed boxes intersect (touching counts, so the
 * bound holds at d = dhat too). Floating point: lo - r and hi + r are rounded outward (nextafter),
 * so a stored box contains its exact inflated box and the argument holds for the exact distance
 * between the given coordinates.
 * Swept boxes: during a step a corner moves on the segment from x to x1, which lies in the box of
 * {x, x1}; at any time t in [0, 1] the primitive is the hull of its corners at t, so it lies in
 * the box of all its corners at both ends, and the argument above holds at every t.
 * The union of inflated corner boxes is the inflated union box (min(lo_i) - r = min(lo_i - r), and
 * rounding is monotone), so corners are inflated once and primitives take their min and max.
 *
 * Reuse (opts.reuse). The search is kept at a reference placement xr, each vertex's box inflated
 * by its own reach R_v. An update at x (and x1) with inflation r in which every vertex lies within
 * D_v of its reference position (max over axes and both ends) has every vertex box inside the
 * reference one when D_v + r <= R_v (up to rounding, which a guard of a few ulps covers); a
 * primitive's box is the union of its corners' boxes, so it lies inside its reference box too, and
 * two boxes that meet have reference boxes that meet: the update's pairs are among the kept ones.
 * Testing each kept pair's two boxes with the closed test CGAL applies gives exactly CGAL's
 * answer, and the kept lists are sorted, so the filtered ones come out in CGAL's order. A new
 * search is made at the update's placement when some vertex does not fit, with
 * R_v = r + s_v + max(rmax + s_v, drift_v / 2): s_v the vertex's sweep in this update (|x1 - x|),
 * rmax the largest inflation asked so far (a contact term alternates its stencil updates'
 * dhat + margin with CCD's 0) and drift_v how far the vertex had gone from its last reference (at
 * most its last R_v). A reach per vertex matters: on the wing a Newton step moves the feathers'
 * tips 5 mm and their roots far less, and one reach for all (the largest) kept 10^6 pairs where
 * an update finds 10^4; per vertex, 2-5 10^5, and about one search per time step. */
#include "contact_broad.h"

#include <float.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal/contact_cgal.h"
#include "../io/progress.h"

struct plume_contact_broad {
    plume_index nv, ntri, ne;
    plume_index *tri;    /* [3*ntri] copy */
    plume_index *edges;  /* [2*ne] unique undirected edges, i < j, sorted */
    int *body;           /* [nv] copy, or NULL (one body) */
    int self_contact;
    plume_index *weld;   /* [nv] or NULL (opts.weld) */
    plume_box *vbox;     /* [nv] vertex boxes (inflated), filled in vertex order each update */
    plume_box *tbox;     /* [ntri] */
    plume_box *ebox;     /* [ne] */
    plume_box *scratch;  /* [ne] CGAL's copy for the edge self intersection */
    plume_contact_pairs vt, ee;
    plume_pair_ws ws;    /* shared by the two searches */
    long updates, searches;
    double seconds;
    /* reuse: the pairs of the boxes at xref inflated by reach (valid when have_ref) */
    int reuse, have_ref;
    double *xref;        /* [3*nv] */
    double *vreach;      /* [nv] each vertex's reach R_v */
    double rmax;         /* the largest inflation asked so far */
    plume_contact_pairs rvt, ree;
};

void plume_contact_pairs_free(plume_contact_pairs *pairs)
{
    if (!pairs)
        return;
    free(pairs->p);
    pairs->p = NULL;
    pairs->n = 0;
    pairs->cap = 0;
}

/* CGAL's segment tree starts from the interval [-DBL_MAX, DBL_MAX): coordinates must lie inside. */
static int in_range(double lo, double hi)
{
    return lo > -DBL_MAX && hi < DBL_MAX && lo <= hi;
}

/* Copies boxes (6 doubles each) into plume_box records, checking them. */
static plume_status load_boxes(const char *name, plume_index n, const double *in, plume_box *out, plume_err *err)
{
    for (plume_index i = 0; i < n; i++) {
        const double *b = in + 6 * i;
        for (int k = 0; k < 3; k++) {
            if (!isfinite(b[k]) || !isfinite(b[3 + k]))
                return plume_err_set(err, PLUME_EINVAL, "contact: box %ld of %s: coordinates are not finite", i,
                                     name);
            if (!in_range(b[k], b[3 + k]))
                return plume_err_set(err, PLUME_EINVAL,
                                     "contact: box %ld of %s: lo %g > hi %g on axis %d (or |coordinate| = DBL_MAX)",
                                     i, name, b[k], b[3 + k], k);
            out[i].lo[k] = b[k];
            out[i].hi[k] = b[3 + k];
        }
    }
    return PLUME_OK;
}

static plume_status check_set(const char *name, plume_index n, const double *boxes, plume_err *err)
{
    if (n < 0)
        return plume_err_set(err, PLUME_EINVAL, "contact: %s: count %ld is negative", name, n);
    if (n > 0 && !boxes)
        return plume_err_set(err, PLUME_EINVAL, "contact: %s: boxes is NULL with count %ld", name, n);
    if ((size_t)n > SIZE_MAX / 2 / sizeof(plume_box))
        return plume_err_set(err, PLUME_EINVAL, "contact: %s: count %ld is too large", name, n);
    return PLUME_OK;
}

plume_status plume_contact_box_pairs(plume_index na, const double *a, plume_index nb, const double *b,
                                     plume_contact_pairs *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "contact: box pairs: output list is NULL");
    out->n = 0;
    plume_status st = check_set("set a", na, a, err);
    if (st == PLUME_OK)
        st = check_set("set b", nb, b, err);
    if (st != PLUME_OK)
        return st;
    plume_box *ba = malloc((size_t)(na + nb) * sizeof *ba + 1);
    if (!ba)
        return plume_err_set(err, PLUME_ENOMEM, "contact: no memory for %ld boxes", na + nb);
    plume_box *bb = ba + na;
    st = load_boxes("set a", na, a, ba, err);
    if (st == PLUME_OK)
        st = load_boxes("set b", nb, b, bb, err);
    plume_pair_ws ws = {{0, 0, NULL}, {0, 0, NULL}, NULL, 0};
    if (st == PLUME_OK)
        st = plume_cgal_box_pairs(ba, na, bb, nb, NULL, NULL, &ws, out, err);
    plume_pair_ws_free(&ws);
    free(ba);
    return st;
}

plume_status plume_contact_box_self_pairs(plume_index n, const double *boxes, plume_contact_pairs *out,
                                          plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "contact: box self pairs: output list is NULL");
    out->n = 0;
    plume_status st = check_set("boxes", n, boxes, err);
    if (st != PLUME_OK)
        return st;
    plume_box *bx = malloc(2 * (size_t)n * sizeof *bx + 1);
    if (!bx)
        return plume_err_set(err, PLUME_ENOMEM, "contact: no memory for %ld boxes", n);
    st = load_boxes("boxes", n, boxes, bx, err);
    plume_pair_ws ws = {{0, 0, NULL}, {0, 0, NULL}, NULL, 0};
    if (st == PLUME_OK)
        st = plume_cgal_box_self_pairs(bx, bx + n, n, NULL, NULL, &ws, out, err);
    plume_pair_ws_free(&ws);
    free(bx);
    return st;
}

/* --- The candidate handle ---------------------------------------------------------------------- */

void plume_contact_broad_opts_default(plume_contact_broad_opts *o)
{
    o->self_contact = 1;
    o->reuse = 0;
    o->weld = NULL;
}

static int edge_cmp(const void *x, const void *y)
{
    const plume_index *p = x, *q = y;
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return (p[1] > q[1]) - (p[1] < q[1]);
}

/* Checks the triangles; on success sets *ne and *edges (malloc'd, unique, sorted). */
static plume_status build_edges(plume_index nv, plume_index ntri, const plume_index *tri, const int *body,
                                plume_index *ne, plume_index **edges, plume_err *err)
{
    *ne = 0;
    *edges = NULL;
    for (plume_index t = 0; t < ntri; t++) {
        const plume_index *c = tri + 3 * t;
        for (int k = 0; k < 3; k++)
            if (c[k] < 0 || c[k] >= nv)
                return plume_err_set(err, PLUME_EINVAL, "contact: triangle %ld: vertex id %ld out of range [0, %ld)",
                                     t, c[k], nv);
        if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2])
            return plume_err_set(err, PLUME_EINVAL, "contact: triangle %ld: repeated vertex (%ld, %ld, %ld)", t,
                                 c[0], c[1], c[2]);
        if (body && (body[c[0]] != body[c[1]] || body[c[0]] != body[c[2]]))
            return plume_err_set(err, PLUME_EINVAL,
                                 "contact: triangle %ld: its corners %ld, %ld, %ld lie in bodies %d, %d, %d", t,
                                 c[0], c[1], c[2], body[c[0]], body[c[1]], body[c[2]]);
    }
    plume_index *e = malloc(6 * (size_t)ntri * sizeof *e + 1);
    if (!e)
        return plume_err_set(err, PLUME_ENOMEM, "contact: no memory for the edges of %ld triangles", ntri);
    for (plume_index t = 0; t < ntri; t++)
        for (int k = 0; k < 3; k++) {
            plume_index i = tri[3 * t + k], j = tri[3 * t + (k + 1) % 3];
            e[6 * t + 2 * k] = i < j ? i : j;
            e[6 * t + 2 * k + 1] = i < j ? j : i;
        }
    qsort(e, 3 * (size_t)ntri, 2 * sizeof *e, edge_cmp);
    plume_index n = 0;
    for (plume_index k = 0; k < 3 * ntri; k++)
        if (n == 0 || e[2 * k] != e[2 * (n - 1)] || e[2 * k + 1] != e[2 * (n - 1) + 1]) {
            e[2 * n] = e[2 * k];
            e[2 * n + 1] = e[2 * k + 1];
            n++;
        }
    plume_index *shrunk = realloc(e, 2 * (size_t)n * sizeof *e + 1);
    *edges = shrunk ? shrunk : e;
    *ne = n;
    return PLUME_OK;
}

plume_status plume_contact_broad_create(plume_index nv, plume_index ntri, const plume_index *tri,
                                        const int *body, const plume_contact_broad_opts *opts,
                                        plume_contact_broad **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad: output handle pointer is NULL");
    *out = NULL;
    plume_contact_broad_opts o;
    plume_contact_broad_opts_default(&o);
    if (opts)
        o = *opts;
    if (nv < 0 || ntri < 0)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad: nv = %ld, ntri = %ld must be >= 0", nv, ntri);
    if ((size_t)nv > SIZE_MAX / 8 / sizeof(plume_box) || (size_t)ntri > SIZE_MAX / 8 / sizeof(plume_box))
        return plume_err_set(err, PLUME_EINVAL, "contact: broad: nv = %ld, ntri = %ld are too large", nv, ntri);
    if (ntri > 0 && !tri)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad: tri is NULL with ntri = %ld", ntri);
    if (o.self_contact != 0 && o.self_contact != 1)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad: self_contact = %d must be 0 or 1", o.self_contact);
    if (!o.self_contact && !body)
        return plume_err_set(err, PLUME_EINVAL,
                             "contact: broad: self_contact = 0 keeps pairs of different bodies: body is needed");

    plume_status st = PLUME_OK;
    plume_contact_broad *b = calloc(1, sizeof *b);
    if (!b)
        return plume_err_set(err, PLUME_ENOMEM, "contact: broad: no memory for the handle");
    b->nv = nv;
    b->ntri = ntri;
    b->self_contact = o.self_contact;
    b->reuse = o.reuse != 0;
    st = build_edges(nv, ntri, tri, body, &b->ne, &b->edges, err);
    if (st != PLUME_OK)
        goto fail;
    b->tri = malloc(3 * (size_t)ntri * sizeof *b->tri + 1);
    b->body = body ? malloc((size_t)nv * sizeof *b->body + 1) : NULL;
    b->weld = o.weld ? malloc((size_t)nv * sizeof *b->weld + 1) : NULL;
    b->vbox = malloc((size_t)nv * sizeof *b->vbox + 1);
    b->tbox = malloc((size_t)ntri * sizeof *b->tbox + 1);
    b->ebox = malloc((size_t)b->ne * sizeof *b->ebox + 1);
    b->scratch = malloc((size_t)b->ne * sizeof *b->scratch + 1);
    b->xref = b->reuse ? malloc(3 * (size_t)nv * sizeof *b->xref + 1) : NULL;
    b->vreach = b->reuse ? malloc((size_t)nv * sizeof *b->vreach + 1) : NULL;
    if (!b->tri || (body && !b->body) || (o.weld && !b->weld) || !b->vbox || !b->tbox || !b->ebox || !b->scratch ||
        (b->reuse && (!b->xref || !b->vreach))) {
        st = plume_err_set(err, PLUME_ENOMEM, "contact: broad: no memory for %ld vertices, %ld triangles", nv,
                           ntri);
        goto fail;
    }
    if (ntri > 0)
        memcpy(b->tri, tri, 3 * (size_t)ntri * sizeof *tri);
    if (body && nv > 0)
        memcpy(b->body, body, (size_t)nv * sizeof *body);
    if (b->weld)
        for (plume_index v = 0; v < nv; v++) {
            if (o.weld[v] < 0 || o.weld[v] >= nv) {
                st = plume_err_set(err, PLUME_EINVAL, "contact: broad: weld[%ld] = %ld is not a vertex", (long)v,
                                   (long)o.weld[v]);
                goto fail;
            }
            b->weld[v] = o.weld[v];
        }
    *out = b;
    return PLUME_OK;
fail:
    plume_contact_broad_destroy(&b);
    return st;
}

void plume_contact_broad_destroy(plume_contact_broad **pb)
{
    if (!pb || !*pb)
        return;
    plume_contact_broad *b = *pb;
    free(b->tri);
    free(b->edges);
    free(b->body);
    free(b->weld);
    free(b->vbox);
    free(b->tbox);
    free(b->ebox);
    free(b->scratch);
    free(b->xref);
    free(b->vreach);
    plume_contact_pairs_free(&b->vt);
    plume_contact_pairs_free(&b->ee);
    plume_contact_pairs_free(&b->rvt);
    plume_contact_pairs_free(&b->ree);
    plume_pair_ws_free(&b->ws);
    free(b);
    *pb = NULL;
}

void plume_contact_broad_edges(const plume_contact_broad *b, plume_index *ne, const plume_index **edges)
{
    if (ne)
        *ne = b ? b->ne : 0;
    if (edges)
        *edges = b ? b->edges : NULL;
}

void plume_contact_broad_triangles(const plume_contact_broad *b, plume_index *ntri, const plume_index **tri)
{
    if (ntri)
        *ntri = b ? b->ntri : 0;
    if (tri)
        *tri = b ? b->tri : NULL;
}

void plume_contact_broad_stats(const plume_contact_broad *b, long *updates, double *seconds)
{
    if (updates)
        *updates = b ? b->updates : 0;
    if (seconds)
        *seconds = b ? b->seconds : 0.0;
}

long plume_contact_broad_searches(const plume_contact_broad *b)
{
    return b ? b->searches : 0;
}

/* The vertex v stands for in adjacency tests (opts.weld) */
static plume_index welded(const plume_contact_broad *b, plume_index v)
{
    return b->weld ? b->weld[v] : v;
}

/* v is not a corner of t (welded); and, for contact between bodies only, they lie in different
 * bodies. */
static int keep_vt(void *ctx, plume_index v, plume_index t)
{
    const plume_contact_broad *b = ctx;
    const plume_index *c = b->tri + 3 * t;
    const plume_index w = welded(b, v);
    if (w == welded(b, c[0]) || w == welded(b, c[1]) || w == welded(b, c[2]))
        return 0;
    return b->self_contact || b->body[v] != b->body[c[0]];
}

static int keep_ee(void *ctx, plume_index e, plume_index f)
{
    const plume_contact_broad *b = ctx;
    const plume_index *p = b->edges + 2 * e, *q = b->edges + 2 * f;
    const plume_index p0 = welded(b, p[0]), p1 = welded(b, p[1]), q0 = welded(b, q[0]), q1 = welded(b, q[1]);
    if (p0 == q0 || p0 == q1 || p1 == q0 || p1 == q1)
        return 0;
    return b->self_contact || b->body[p[0]] != b->body[q[0]];
}

/* Box of the union of the corner boxes c[0..n-1] (vertex boxes, still in vertex order). */
static void union_box(const plume_box *vbox, const plume_index *c, int n, plume_box *out)
{
    *out = vbox[c[0]];
    for (int i = 1; i < n; i++) {
        const plume_box *v = vbox + c[i];
        for (int k = 0; k < 3; k++) {
            out->lo[k] = v->lo[k] < out->lo[k] ? v->lo[k] : out->lo[k];
            out->hi[k] = v->hi[k] > out->hi[k] ? v->hi[k] : out->hi[k];
        }
    }
}

/* Vertex boxes over x and x1 (or x alone), inflated outward by r (see the comment at the top). */
static plume_status vertex_boxes(plume_index nv, const double *x, const double *x1, double r, plume_box *vbox,
                                 plume_err *err)
{
    for (plume_index v = 0; v < nv; v++) {
        for (int k = 0; k < 3; k++) {
            double a = x[3 * v + k], c = x1 ? x1[3 * v + k] : a;
            if (!isfinite(a) || !isfinite(c))
                return plume_err_set(err, PLUME_EINVAL, "contact: vertex %ld: %s coordinate %d is %g", v,
                                     isfinite(a) ? "end (x1)" : "start (x)", k, isfinite(a) ? c : a);
            double lo = a < c ? a : c, hi = a < c ? c : a;
            if (r > 0) {
                lo = nextafter(lo - r, -INFINITY);
                hi = nextafter(hi + r, INFINITY);
            }
            if (!in_range(lo, hi))
                return plume_err_set(err, PLUME_EINVAL,
                                     "contact: vertex %ld: coordinate %d (%g, %g) too large for boxes inflated by %g",
                                     v, k, a, c, r);
            vbox[v].lo[k] = lo;
            vbox[v].hi[k] = hi;
        }
    }
    return PLUME_OK;
}

/* Vertex boxes of x inflated outward by r[v] each (the reuse's reference boxes). */
static plume_status vertex_boxes_each(plume_index nv, const double *x, const double *r, plume_box *vbox,
                                      plume_err *err)
{
    for (plume_index v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) {
            const double a = x[3 * v + k];
            const double lo = nextafter(a - r[v], -INFINITY), hi = nextafter(a + r[v], INFINITY);
            if (!in_range(lo, hi))
                return plume_err_set(err, PLUME_EINVAL,
                                     "contact: vertex %ld: coordinate %d (%g) too large for boxes inflated by %g", v,
                                     k, a, r[v]);
            vbox[v].lo[k] = lo;
            vbox[v].hi[k] = hi;
        }
    return PLUME_OK;
}

/* The vertex, triangle and edge boxes of x (and x1) inflated by r, in index order. */
static plume_status all_boxes(plume_contact_broad *b, const double *x, const double *x1, double r, plume_err *err)
{
    plume_status st = vertex_boxes(b->nv, x, x1, r, b->vbox, err);
    if (st != PLUME_OK)
        return st;
    for (plume_index t = 0; t < b->ntri; t++)
        union_box(b->vbox, b->tri + 3 * t, 3, b->tbox + t);
    for (plume_index e = 0; e < b->ne; e++)
        union_box(b->vbox, b->edges + 2 * e, 2, b->ebox + e);
    return PLUME_OK;
}

/* CGAL's search on the boxes all_boxes made, into vt and ee (it reorders the box arrays: they are
 * rebuilt before they are used again). */
static plume_status box_search(plume_contact_broad *b, plume_contact_pairs *vt, plume_contact_pairs *ee,
                               plume_err *err)
{
    b->searches++;
    plume_status st = plume_cgal_box_pairs(b->vbox, b->nv, b->tbox, b->ntri, keep_vt, b, &b->ws, vt, err);
    if (st == PLUME_OK)
        st = plume_cgal_box_self_pairs(b->ebox, b->scratch, b->ne, keep_ee, b, &b->ws, ee, err);
    return st;
}

/* closed boxes meet: CGAL's CLOSED test. Without branches: the kept pairs are filtered by tens of
 * thousands at every query, and whether two of them meet is not predictable. */
static int boxes_meet(const plume_box *a, const plume_box *c)
{
    return (a->lo[0] <= c->hi[0]) & (c->lo[0] <= a->hi[0]) & (a->lo[1] <= c->hi[1]) & (c->lo[1] <= a->hi[1]) &
           (a->lo[2] <= c->hi[2]) & (c->lo[2] <= a->hi[2]);
}

static plume_status room_for(plume_contact_pairs *l, plume_index n)
{
    if (n <= l->cap)
        return PLUME_OK;
    plume_index cap = n + n / 2 + 16;
    plume_contact_pair *q = realloc(l->p, (size_t)cap * sizeof *q);
    if (!q)
        return PLUME_ENOMEM;
    l->p = q;
    l->cap = cap;
    return PLUME_OK;
}

/* The update through the kept pairs (comment at the top): a new reference search when the boxes of
 * x (and x1) inflated by r do not fit, then the kept pairs whose boxes meet. */
static plume_status reused_search(plume_contact_broad *b, const double *x, const double *x1, double r, plume_err *err)
{
    const plume_index nv = b->nv;
    double xmax = 0.0;
    for (plume_index i = 0; i < 3 * nv; i++)
        xmax = fmax(xmax, fmax(fabs(x[i]), x1 ? fabs(x1[i]) : 0.0));
    if (!isfinite(xmax))
        return all_boxes(b, x, x1, r, err); /* names the vertex */
    b->rmax = fmax(b->rmax, r);
    const double guard = 16.0 * DBL_EPSILON * (xmax + b->rmax);
    int fits = b->have_ref;
    for (plume_index v = 0; v < nv && fits; v++) {
        double D = 0.0; /* the vertex's largest move from its reference, both ends */
        for (int k = 0; k < 3; k++) {
            const double a = x[3 * v + k], c = x1 ? x1[3 * v + k] : a, o = b->xref[3 * v + k];
            D = fmax(D, fmax(fabs(a - o), fabs(c - o)));
        }
        fits = D + r + guard + 16.0 * DBL_EPSILON * b->vreach[v] <= b->vreach[v];
    }
    plume_status st;
    if (!fits) {
        /* R_v = r + s_v + max(rmax + s_v, drift_v / 2), s_v the vertex's sweep, rmax the largest
         * inflation asked so far (the stencil updates' dhat + margin beside CCD's 0), drift_v its
         * move from the last reference (at most its last R_v) */
        for (plume_index v = 0; v < nv; v++) {
            double sweep = 0.0, drift = 0.0;
            for (int k = 0; k < 3; k++) {
                const double a = x[3 * v + k], c = x1 ? x1[3 * v + k] : a;
                sweep = fmax(sweep, fabs(c - a));
                if (b->have_ref)
                    drift = fmax(drift, fabs(a - b->xref[3 * v + k]));
            }
            drift = b->have_ref ? fmin(drift, b->vreach[v]) : 0.0;
            b->vreach[v] = r + sweep + fmax(b->rmax + sweep, 0.5 * drift);
        }
        b->have_ref = 0;
        if ((st = vertex_boxes_each(nv, x, b->vreach, b->vbox, err)) != PLUME_OK)
            return st;
        for (plume_index t = 0; t < b->ntri; t++)
            union_box(b->vbox, b->tri + 3 * t, 3, b->tbox + t);
        for (plume_index e = 0; e < b->ne; e++)
            union_box(b->vbox, b->edges + 2 * e, 2, b->ebox + e);
        if ((st = box_search(b, &b->rvt, &b->ree, err)) != PLUME_OK)
            return st;
        memcpy(b->xref, x, 3 * (size_t)nv * sizeof *x);
        b->have_ref = 1;
    }
    if ((st = all_boxes(b, x, x1, r, err)) != PLUME_OK)
        return st;
    if (room_for(&b->vt, b->rvt.n) != PLUME_OK || room_for(&b->ee, b->ree.n) != PLUME_OK)
        return plume_err_set(err, PLUME_ENOMEM, "contact: broad: no memory for %ld pairs", (long)(b->rvt.n + b->ree.n));
    plume_index n = 0; /* every pair written, the count advanced where the boxes meet */
    for (plume_index k = 0; k < b->rvt.n; k++) {
        const plume_contact_pair q = b->rvt.p[k];
        b->vt.p[n] = q;
        n += boxes_meet(b->vbox + q.a, b->tbox + q.b);
    }
    b->vt.n = n;
    n = 0;
    for (plume_index k = 0; k < b->ree.n; k++) {
        const plume_contact_pair q = b->ree.p[k];
        b->ee.p[n] = q;
        n += boxes_meet(b->ebox + q.a, b->ebox + q.b);
    }
    b->ee.n = n;
    return PLUME_OK;
}

plume_status plume_contact_broad_update(plume_contact_broad *b, const double *x, const double *x1, double dhat,
                                        plume_contact_candidates *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad update: output is NULL");
    memset(out, 0, sizeof *out);
    if (!b)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad update: handle is NULL");
    if (!x && b->nv > 0)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad update: x is NULL with %ld vertices", b->nv);
    if (!isfinite(dhat) || dhat < 0)
        return plume_err_set(err, PLUME_EINVAL, "contact: broad update: dhat = %g must be finite and >= 0", dhat);
    double t0 = plume_wall_seconds();
    b->vt.n = 0;
    b->ee.n = 0;
    plume_status st = PLUME_OK;
    if (b->reuse) {
        st = reused_search(b, x, x1, 0.5 * dhat, err);
    } else {
        st = all_boxes(b, x, x1, 0.5 * dhat, err);
        if (st == PLUME_OK)
            st = box_search(b, &b->vt, &b->ee, err);
    }
    if (st != PLUME_OK) {
        b->vt.n = 0;
        b->ee.n = 0;
        return st;
    }
    double s = plume_wall_seconds() - t0;
    b->updates++;
    b->seconds += s;
    out->nvt = b->vt.n;
    out->vt = b->vt.p;
    out->nee = b->ee.n;
    out->ee = b->ee.p;
    out->seconds = s;
    return PLUME_OK;
}

/* --- The audit --------------------------------------------------------------------------------- */

plume_status plume_contact_count_intersections(plume_index nv, const double *x, plume_index ntri,
                                               const plume_index *tri, plume_contact_pairs *pairs,
                                               plume_contact_audit *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "contact: audit: output is NULL");
    memset(out, 0, sizeof *out);
    if (pairs)
        pairs->n = 0;
    if (nv < 0 || ntri < 0)
        return plume_err_set(err, PLUME_EINVAL, "contact: audit: nv = %ld, ntri = %ld must be >= 0", nv, ntri);
    if ((size_t)ntri > SIZE_MAX / 4 / sizeof(plume_box))
        return plume_err_set(err, PLUME_EINVAL, "contact: audit: ntri = %ld is too large", ntri);
    if (nv > 0 && !x)
        return plume_err_set(err, PLUME_EINVAL, "contact: audit: x is NULL with nv = %ld", nv);
    if (ntri > 0 && !tri)
        return plume_err_set(err, PLUME_EINVAL, "contact: audit: tri is NULL with ntri = %ld", ntri);
    for (plume_index v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(x[3 * v + k]) || !in_range(x[3 * v + k], x[3 * v + k]))
                return plume_err_set(err, PLUME_EINVAL, "contact: audit: vertex %ld: coordinate %d is %g", v, k,
                                     x[3 * v + k]);
    for (plume_index t = 0; t < ntri; t++)
        for (int k = 0; k < 3; k++)
            if (tri[3 * t + k] < 0 || tri[3 * t + k] >= nv)
                return plume_err_set(err, PLUME_EINVAL,
                                     "contact: audit: triangle %ld: vertex id %ld out of range [0, %ld)", t,
                                     tri[3 * t + k], nv);
    double t0 = plume_wall_seconds();
    plume_box *boxes = malloc(2 * (size_t)ntri * sizeof *boxes + 1);
    if (!boxes)
        return plume_err_set(err, PLUME_ENOMEM, "contact: audit: no memory for %ld boxes", ntri);
    /* Tight boxes, no inflation: min and max are exact, so a touching pair keeps touching boxes. */
    for (plume_index t = 0; t < ntri; t++) {
        const double *p = x + 3 * tri[3 * t];
        for (int k = 0; k < 3; k++)
            boxes[t].lo[k] = boxes[t].hi[k] = p[k];
        for (int c = 1; c < 3; c++) {
            p = x + 3 * tri[3 * t + c];
            for (int k = 0; k < 3; k++) {
                boxes[t].lo[k] = p[k] < boxes[t].lo[k] ? p[k] : boxes[t].lo[k];
                boxes[t].hi[k] = p[k] > boxes[t].hi[k] ? p[k] : boxes[t].hi[k];
            }
        }
    }
    plume_index count = 0, ndeg = 0;
    plume_status st =
        plume_cgal_triangle_intersections(boxes, boxes + ntri, ntri, x, tri, pairs, &count, &ndeg, err);
    free(boxes);
    if (st != PLUME_OK)
        return st;
    out->intersecting = count;
    out->degenerate = ndeg;
    out->seconds = plume_wall_seconds() - t0;
    return PLUME_OK;
}
