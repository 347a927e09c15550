/* plume: the CGAL side of contact (lib/contact/internal/contact_cgal.h): box pairs by CGAL's
 * box_intersection_d and exact triangle-triangle tests; the only contact file that sees CGAL.
 *
 * Boxes: CGAL's box_intersection_d runs directly on the caller's plume_box arrays through a box
 * traits class; the pair searches allocate nothing but the caller's lists and workspace, which
 * grow only when too small (the audit, once a frame, also keeps a byte per triangle). Ids matter
 * to CGAL: it breaks ties between equal lo coordinates by id and skips pairs of boxes with equal
 * ids (that is how a self intersection avoids (i, i)), so the two sets of a bipartite call get
 * disjoint ids (a: 0..na-1, b: na..na+nb-1) and a self call gives a box and its copy the same id.
 * CGAL's random pivot choice uses a generator local to each call with a fixed seed
 * (segment_tree.h), and the output is sorted anyway, so results are deterministic and no state
 * is shared between calls.
 *
 * Exact tests: Epick (exact predicates, inexact constructions); do_intersect on Triangle_3 and
 * friends only evaluates orientation predicates on the input doubles, so the answer is exact for
 * the coordinates given, coplanar and touching configurations included. */
#include "internal/contact_cgal.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <limits>
#include <new>
#include <vector>

namespace {

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef K::Point_3 Point_3;
typedef K::Segment_3 Segment_3;
typedef K::Triangle_3 Triangle_3;

/* Cutoff of CGAL's segment tree (subproblems with fewer boxes than this are scanned directly):
 * kCutoffPerSqrt * sqrt(boxes per set), clamped. Measured on 75 000 to 300 000 boxes (planar
 * sheets, a thin strip, a uniform cloud): CGAL's default of 10 is 2 to 5 times slower than 600 to
 * 2000 on sheets, whose best value grows with the size; a strip prefers ~100. */
const double kCutoffPerSqrt = 3.0;
const double kCutoffMin = 100, kCutoffMax = 4000;

std::ptrdiff_t cutoff_for(plume_index n)
{
    double c = kCutoffPerSqrt * std::sqrt(static_cast<double>(n));
    return static_cast<std::ptrdiff_t>(std::min(kCutoffMax, std::max(kCutoffMin, c)));
}

struct Box_traits {
    typedef plume_box Box;
    typedef const plume_box &Box_parameter;
    typedef double NT;
    typedef std::size_t ID;
    static int dimension() { return 3; }
    static double min_coord(Box_parameter b, int d) { return b.lo[d]; }
    static double max_coord(Box_parameter b, int d) { return b.hi[d]; }
    static std::size_t id(Box_parameter b) { return static_cast<std::size_t>(b.id); }
};

/* Appends to a caller's list, growing it geometrically; a failed realloc throws (the only way to
 * stop box_intersection_d) and leaves the list as it was. */
void push(plume_contact_pairs *out, plume_index a, plume_index b)
{
    if (out->n == out->cap) {
        plume_index cap = out->cap < 64 ? 64 : 2 * out->cap;
        void *p = std::realloc(out->p, static_cast<size_t>(cap) * sizeof *out->p);
        if (!p)
            throw std::bad_alloc();
        out->p = static_cast<plume_contact_pair *>(p);
        out->cap = cap;
    }
    out->p[out->n].a = a;
    out->p[out->n].b = b;
    out->n++;
}

void sort_pairs(plume_contact_pairs *out)
{
    std::sort(out->p, out->p + out->n, [](const plume_contact_pair &x, const plume_contact_pair &y) {
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
}

template <class T> void reserve(T **p, plume_index *cap, plume_index n)
{
    if (*cap >= n)
        return;
    void *q = std::realloc(*p, static_cast<size_t>(n) * sizeof **p);
    if (!q)
        throw std::bad_alloc();
    *p = static_cast<T *>(q);
    *cap = n;
}

/* raw -> out sorted by (a, b), a in [0, na), b in [0, nb): two stable counting sorts, by b into
 * ws->tmp then by a into out (least significant key first). The same order as sorting each
 * bucket of a by b (no pair occurs twice), without the buckets' comparison sorts, which took 11 %
 * of the bird's profile where boxes swept over a wingbeat's step meet hundreds of others. */
void pair_sort(plume_pair_ws *ws, plume_index na, plume_index nb, plume_contact_pairs *out)
{
    const plume_contact_pairs &raw = ws->raw;
    reserve(&out->p, &out->cap, raw.n);
    reserve(&ws->tmp.p, &ws->tmp.cap, raw.n);
    reserve(&ws->count, &ws->count_cap, std::max(na, nb) + 1);
    plume_index *c = ws->count;
    plume_contact_pair *tmp = ws->tmp.p;
    std::fill(c, c + nb + 1, 0);
    for (plume_index k = 0; k < raw.n; k++)
        c[raw.p[k].b + 1]++;
    for (plume_index i = 0; i < nb; i++)
        c[i + 1] += c[i];
    for (plume_index k = 0; k < raw.n; k++)
        tmp[c[raw.p[k].b]++] = raw.p[k];
    std::fill(c, c + na + 1, 0);
    for (plume_index k = 0; k < raw.n; k++)
        c[tmp[k].a + 1]++;
    for (plume_index i = 0; i < na; i++)
        c[i + 1] += c[i];
    for (plume_index k = 0; k < raw.n; k++)
        out->p[c[tmp[k].a]++] = tmp[k];
    out->n = raw.n;
}

/* State of one enumeration; CGAL copies the callback by value, so the callback holds a pointer. */
struct Collector {
    plume_index na;  /* bipartite: ids >= na are boxes of b; self: -1 */
    plume_box_keep_fn keep;
    void *ctx;
    plume_contact_pairs *out;
};

struct Pair_callback {
    Collector *c;
    void operator()(const plume_box &x, const plume_box &y) const
    {
        plume_index i = x.id, j = y.id;
        if (c->na >= 0) { /* the first argument may come from either set (CGAL's second pass) */
            if (i >= c->na)
                std::swap(i, j);
            j -= c->na;
        } else if (i > j) {
            std::swap(i, j);
        }
        if (!c->keep || c->keep(c->ctx, i, j))
            push(c->out, i, j);
    }
};

/* A triangle as the exact test sees it: a triangle, or, when its corners are exactly collinear,
 * the segment between its extreme corners, or the point they all are. */
enum Kind : unsigned char { kTriangle, kSegment, kPoint };

struct Tri_shape {
    const double *x;
    const plume_index *tri;
    const std::vector<unsigned char> *kind;

    Point_3 corner(plume_index t, int k) const
    {
        const double *p = x + 3 * tri[3 * t + k];
        return Point_3(p[0], p[1], p[2]);
    }
    /* Endpoints of a degenerate triangle: collinear points sort along their line the way they sort
     * lexicographically, so the extremes are the lexicographic min and max (exact comparisons). */
    Segment_3 segment(plume_index t) const
    {
        Point_3 p[3] = {corner(t, 0), corner(t, 1), corner(t, 2)};
        std::sort(p, p + 3, [](const Point_3 &u, const Point_3 &v) {
            return CGAL::compare_xyz(u, v) == CGAL::SMALLER;
        });
        return Segment_3(p[0], p[2]);
    }
    Triangle_3 triangle(plume_index t) const { return Triangle_3(corner(t, 0), corner(t, 1), corner(t, 2)); }

    template <class G> bool with(plume_index s, const G &g) const
    {
        switch ((*kind)[static_cast<size_t>(s)]) {
        case kTriangle: return CGAL::do_intersect(triangle(s), g);
        case kSegment: return CGAL::do_intersect(segment(s), g);
        default: return CGAL::do_intersect(corner(s, 0), g);
        }
    }
    bool intersect(plume_index t, plume_index s) const
    {
        switch ((*kind)[static_cast<size_t>(t)]) {
        case kTriangle: return with(s, triangle(t));
        case kSegment: return with(s, segment(t));
        default: return with(s, corner(t, 0));
        }
    }
};

struct Tri_collector {
    Tri_shape shape;
    plume_contact_pairs *pairs; /* or NULL */
    plume_index count;
};

struct Tri_callback {
    Tri_collector *c;
    void operator()(const plume_box &x, const plume_box &y) const
    {
        plume_index t = std::min(x.id, y.id), s = std::max(x.id, y.id);
        const plume_index *u = c->shape.tri + 3 * t, *v = c->shape.tri + 3 * s;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                if (u[i] == v[j])
                    return; /* adjacent: not part of the audit */
        if (!c->shape.intersect(t, s))
            return;
        c->count++;
        if (c->pairs)
            push(c->pairs, t, s);
    }
};

void assign_ids(plume_box *b, plume_index n, plume_index offset)
{
    for (plume_index i = 0; i < n; i++)
        b[i].id = offset + i;
}

/* Axis order. CGAL's segment tree splits on its last dimension first and sweeps along dimension
 * 0; boxes along a surface (a sheet, a stack of feathers) overlap along its normal almost always.
 * Measured (75 000 boxes over a sheet, cutoff 1000): the thin axis as CGAL's dimension 1 takes
 * 0.024 s, as dimension 0 or 2 0.14 to 0.17 s; for a strip, the long axis as dimension 2, the
 * thin one as 1 is the fastest order. So: the axis along which boxes are widest relative to the
 * spread of the set (the flattest) goes to dimension 1, the most spread one to dimension 2. The
 * coordinates are permuted in place; the intersection relation does not depend on the order. */
void add_extent(const plume_box *b, plume_index n, double lo[3], double hi[3], double width[3])
{
    for (plume_index i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = std::min(lo[k], b[i].lo[k]);
            hi[k] = std::max(hi[k], b[i].hi[k]);
            width[k] += b[i].hi[k] - b[i].lo[k];
        }
}

void permute(plume_box *b, plume_index n, const int axis[3])
{
    for (plume_index i = 0; i < n; i++) {
        plume_box c = b[i];
        for (int d = 0; d < 3; d++) {
            b[i].lo[d] = c.lo[axis[d]];
            b[i].hi[d] = c.hi[axis[d]];
        }
    }
}

void order_axes(plume_box *a, plume_index na, plume_box *b, plume_index nb)
{
    double lo[3], hi[3], width[3] = {0, 0, 0}, spread[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = std::numeric_limits<double>::infinity();
        hi[k] = -lo[k];
    }
    add_extent(a, na, lo, hi, width);
    add_extent(b, nb, lo, hi, width);
    for (int k = 0; k < 3; k++) { /* extent over mean width: how many boxes fit along the axis */
        double extent = hi[k] - lo[k], mean = width[k] / static_cast<double>(na + nb);
        spread[k] = mean > 0 ? extent / mean : (extent > 0 ? std::numeric_limits<double>::infinity() : 0);
    }
    int by[3] = {0, 1, 2}; /* by increasing spread, ties by axis */
    std::stable_sort(by, by + 3, [&](int p, int q) { return spread[p] < spread[q]; });
    const int axis[3] = {by[1], by[0], by[2]}; /* CGAL dimension d reads axis[d] */
    if (axis[0] == 0 && axis[1] == 1)
        return;
    permute(a, na, axis);
    permute(b, nb, axis);
}

/* Runs f, mapping what it throws to a status and a message. */
template <class F> plume_status guarded(const char *what, plume_err *err, F f)
{
    try {
        f();
        return PLUME_OK;
    } catch (const std::bad_alloc &) {
        return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", what);
    } catch (const std::exception &e) {
        return plume_err_set(err, PLUME_EDEP, "%s: CGAL failed: %s", what, e.what());
    } catch (...) {
        return plume_err_set(err, PLUME_EDEP, "%s: CGAL failed with an unknown exception", what);
    }
}

} // namespace

extern "C" void plume_pair_ws_free(plume_pair_ws *ws)
{
    if (!ws)
        return;
    plume_contact_pairs_free(&ws->raw);
    plume_contact_pairs_free(&ws->tmp);
    std::free(ws->count);
    ws->count = nullptr;
    ws->count_cap = 0;
}

extern "C" plume_status plume_cgal_box_pairs(plume_box *a, plume_index na, plume_box *b, plume_index nb,
                                             plume_box_keep_fn keep, void *ctx, plume_pair_ws *ws,
                                             plume_contact_pairs *out, plume_err *err)
{
    out->n = 0;
    ws->raw.n = 0;
    if (na == 0 || nb == 0)
        return PLUME_OK;
    assign_ids(a, na, 0);
    assign_ids(b, nb, na);
    order_axes(a, na, b, nb);
    Collector c{na, keep, ctx, &ws->raw};
    plume_status st = guarded("contact: box pairs", err, [&] {
        CGAL::box_intersection_d(a, a + na, b, b + nb, Pair_callback{&c}, Box_traits(), cutoff_for(std::max(na, nb)),
                                 CGAL::Box_intersection_d::CLOSED, CGAL::Box_intersection_d::BIPARTITE);
        pair_sort(ws, na, nb, out);
    });
    if (st != PLUME_OK)
        out->n = 0;
    return st;
}

extern "C" plume_status plume_cgal_box_self_pairs(plume_box *boxes, plume_box *scratch, plume_index n,
                                                  plume_box_keep_fn keep, void *ctx, plume_pair_ws *ws,
                                                  plume_contact_pairs *out, plume_err *err)
{
    out->n = 0;
    ws->raw.n = 0;
    if (n < 2)
        return PLUME_OK;
    assign_ids(boxes, n, 0);
    order_axes(boxes, n, boxes, 0);
    std::copy(boxes, boxes + n, scratch);
    Collector c{-1, keep, ctx, &ws->raw};
    /* What CGAL's box_self_intersection_d does, with the copy in the caller's memory. */
    plume_status st = guarded("contact: box self pairs", err, [&] {
        CGAL::box_intersection_d(boxes, boxes + n, scratch, scratch + n, Pair_callback{&c}, Box_traits(),
                                 cutoff_for(n), CGAL::Box_intersection_d::CLOSED,
                                 CGAL::Box_intersection_d::COMPLETE);
        pair_sort(ws, n, n, out);
    });
    if (st != PLUME_OK)
        out->n = 0;
    return st;
}

extern "C" plume_status plume_cgal_triangle_intersections(plume_box *boxes, plume_box *scratch, plume_index ntri,
                                                          const double *x, const plume_index *tri,
                                                          plume_contact_pairs *pairs, plume_index *count,
                                                          plume_index *degenerate, plume_err *err)
{
    *count = 0;
    *degenerate = 0;
    if (pairs)
        pairs->n = 0;
    std::vector<unsigned char> kind;
    Tri_collector c{Tri_shape{x, tri, &kind}, pairs, 0};
    plume_index ndeg = 0;
    plume_status st = guarded("contact: intersection audit", err, [&] {
        kind.resize(static_cast<size_t>(ntri));
        for (plume_index t = 0; t < ntri; t++) {
            Point_3 p = c.shape.corner(t, 0), q = c.shape.corner(t, 1), r = c.shape.corner(t, 2);
            unsigned char k = kTriangle;
            if (CGAL::collinear(p, q, r)) {
                k = (p == q && q == r) ? kPoint : kSegment;
                ndeg++;
            }
            kind[static_cast<size_t>(t)] = k;
        }
        if (ntri < 2)
            return;
        assign_ids(boxes, ntri, 0);
        order_axes(boxes, ntri, boxes, 0);
        std::copy(boxes, boxes + ntri, scratch);
        CGAL::box_intersection_d(boxes, boxes + ntri, scratch, scratch + ntri, Tri_callback{&c}, Box_traits(),
                                 cutoff_for(ntri), CGAL::Box_intersection_d::CLOSED, CGAL::Box_intersection_d::COMPLETE);
        if (pairs)
            sort_pairs(pairs);
    });
    if (st != PLUME_OK) {
        if (pairs)
            pairs->n = 0;
        return st;
    }
    *count = c.count;
    *degenerate = ndeg;
    return PLUME_OK;
}
