/* plume: the feather mesher of supplementary §6 (contract in macro/feather_mesh.h).
 * Helpers live beside it: small 2D geometry (macro/internal/feather_geom.h), input validation
 * (feather_check.c), the spatial grid (bins.c), sampled curves and splines (sampled_curve.c); the
 * OBJ outline reader is obj_outline.c.
 *
 * Steps and the decisions behind them:
 * 1. Curves. The rachis and every barb curve are interpolated through their points with GSL natural
 *    cubic splines (x(u), y(u), u the chord length; linear for two points): C2, so barb angles and
 *    their rate of turn are continuous, and chord-length parameters keep the overshoot small. (GSL's
 *    Steffen spline, monotone per coordinate, forces a zero derivative at every extremum of x(u)
 *    or y(u), which kinks an S-shaped rachis.) The rachis is extended linearly (end tangents) to
 *    the outline at both ends, or clipped at its first exit; its width is linear in arc length
 *    between its first and last input points and constant beyond them (no extrapolation to a
 *    negative width).
 * 2. Rachis strip. Stations ds = L/N apart (N = round(L/e)) place a vertex on either side at half
 *    the width along the normal. Each side runs from the middle station outward while its vertices
 *    stay GAP_POINT e inside the outline, and is then closed by following the side's offset curve
 *    to the outline. Side edges are constrained, so the strip is a region of its own and splits
 *    the feather into the two vanes. Each side has its own stations (step 3b), so the two sides'
 *    vertices need not face each other.
 * 3. Barbs. An input barb is stored as the angle of its tangent relative to the rachis tangent at
 *    its root, as a function of the arc length from the root (constant past its end: the linear
 *    extension). The barb of a station blends the two input barbs of the same side whose roots
 *    bracket the station (weights linear in the stations' arc length; the nearest one alone
 *    outside the bracket) and turns with the local rachis tangent, so barbs follow a curved rachis
 *    and neighbouring barbs of similar shape keep their spacing. Blending angles keeps the curve
 *    unit-speed: walking it in steps of e is walking its arc length. It is integrated with SUBSTEPS
 *    midpoint steps per e, a vertex every e and constrained edges between them; the last vertex is
 *    where the curve leaves the outline (on an outline vertex closer than SNAP_OUTLINE e). A point
 *    closer than GAP_POINT e to the outline is dropped (the barb goes on to the outline); a point
 *    closer than GAP_POINT e to another vertex or GAP_SEGMENT e to another constrained edge, or a
 *    step that would cross a constrained edge, cuts the barb there: barbs never cross, and
 *    converging barbs end on their neighbour instead of making slivers. Each side is walked base to
 *    tip, rachis-rooted barbs first, so later barbs yield to earlier ones.
 * 3b. Corner-exact stations (input corner_exact; docs/design.md, "Meshes that respect the fibres"; the
 *    patch mesher's rule). Without it, the stations are k ds and outline gaps over e get points.
 *    In a strip between two barbs, every boundary vertex that ends no barb adds a triangle and no
 *    barb edge, so it forces one vane triangle without a barb edge: with stations every ds, 85 of
 *    the shipped outline's 100 vertices did, and they were all of the 11 % uncovered at 5 mm. So
 *    each outline vertex gets a barb through it where one can pass: the station whose barb leaves
 *    (or, past the strip ends, enters) the outline exactly there is found by bisection on where
 *    the barb meets the outline, followed with the same steps as the walk (fm_trace; the family is
 *    sampled every ds/2 to bracket it). A corner station may extend the strip run to where the
 *    side stops being GAP_POINT e inside the outline (fm_run_extent). Corners closer than
 *    CORNER_GAP ds to a kept station are dropped. Between consecutive kept stations the others are
 *    spaced evenly: round(gap / ds) of them with the rounding error carried on (so the count stays
 *    about L / ds), more where their barbs would meet the outline over OUTLINE_GAP e apart, and
 *    never closer than CORNER_GAP ds. What is left uncovered is where the outline runs along the
 *    barbs (the base of the feather, where they skim it), wraps round the strip's end, or the tip,
 *    narrower than a barb spacing; plume_feather_uncovered reports each with its reason.
 *    Not the default: the shipped dynamic scene (data/feather/scene_anisotropic.json, 91 steps)
 *    needs more Newton iterations on these meshes, old / corner-exact at e = 4.6 4.7 4.8 4.9 5.0
 *    5.1 5.2 5.3 mm: 3358 / >500 s, 3074 / 11666, 1131 / 55251, 1708 / 3915, 1893 / 4016,
 *    2026 / 2142, 993 / 2646, 1136 / 1579 (the scene without the barb constraint: 246 / 258 at
 *    5 mm, so it is the constraint layout; the count swings with small mesh changes on either
 *    layout, e.g. 1398 / 3356 at 5.0 / 5.2 mm with stations jittered by 0.3 ds). Not yet
 *    explained: neither the denser stations at the tip, nor the barb edges on outline vertices,
 *    nor barbs held at both ends by the scene's handles account for it.
 * 4. Where no rachis-rooted barb reaches. (a) Where the outline leaves the rachis more steeply than
 *    the barbs (the base of a vane) the family is continued from stations past the strip ends and
 *    from the strip ends themselves: those barbs enter through the outline and are walked the same
 *    way. (b) Where neighbouring barbs diverge, fill barbs from half (then quarter, eighth)
 *    stations start where the gap has opened to 2 FILL_CLEAR e. The vane is covered by barb lines
 *    about e sin(barb angle) apart and no gap wider than ~1.4 e is left between two barbs.
 * 5. Triangulation. All outline vertices are kept (the area is exact); barb and side ends split
 *    outline edges, and points no more than e apart are added in every gap longer than e, or than
 *    OUTLINE_GAP e between two barb or side ends. (Each such point ends no barb, so forces an
 *    uncovered triangle: with points in every gap over e there were 27 at 3.5 mm and 54 at 2.5 mm
 *    on the shipped feather. A gap up to 2 e between barb ends matches barbs up to ~1.4 e apart
 *    meeting the outline at 45 degrees or more.) Constrained Delaunay (lib/core/cdt.h) with
 *    remove_exterior and *no refinement*. CGAL's Delaunay refinement splits every
 *    encroached constrained segment whatever the size and shape criteria: the rachis sides (5 mm
 *    stations, the other side 1-3 mm away) and barb edges at shallow angles get split, and the
 *    Steiner points it adds are on no barb. Measured on the shipped feather at e = 5 mm: max_edge
 *    1.5 e with a negligible shape bound gave 35 % more triangles, with the default 20.7 deg bound
 *    77 % more, most of the new ones without a barb edge. The layout above already bounds the
 *    edges (e along barbs, barbs < ~1.4 e apart) and every triangle between two barbs has a barb
 *    edge; the unaligned rest is at outline points that are not barb ends, at the strip's ends and
 *    at the start of fill barbs (step 3b). So *barb_edges are exactly the constrained barb
 *    segments, unsplit. (Edge flips cannot do better: no triangle owns two barb edges, so a flip
 *    only moves which of the two triangles lacks one.)
 * 6. Output. A triangle is rachis when its centroid lies within half the local width of the centre
 *    line; its barb direction is then the rachis tangent. A vane triangle takes the direction of
 *    its barb edge(s) (oriented away from the rachis), else the inverse-distance-weighted direction
 *    of the barb edges of its side within IDW_RADIUS e. */
#include "feather_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/cdt.h"
#include "../lib/core/pslg.h"
#include "vane.h"
#include "internal/bins.h"
#include "internal/feather_geom.h"
#include "internal/sampled_curve.h"

/* Tolerances, as fractions of the target edge e (the header has no options struct; these are the
 * knobs to expose if callers need them). */
#define GAP_POINT 0.3      /* a barb point nearer the outline or another vertex is dropped */
#define GAP_SEGMENT 0.2    /* ... nearer another constrained edge (and a new edge nearer a vertex) */
#define SNAP_OUTLINE 0.1   /* a barb end this close to an outline vertex ends on the vertex */
#define SNAP_SIDE 1e-3     /* a rachis side end this close to an outline vertex ends on it */
#define SUBSTEPS 16        /* integration steps per e along barbs and strip sides */
#define LAST_ARC 1.6       /* longest arc (in e) one barb edge may bridge */
#define SAMPLES 8          /* curve samples per e (at least 16 per curve) */
#define MAX_TRIANGLES 5e6  /* refuse edges that would give more (estimate area / (0.43 e^2)) */
#define MAX_OUTLINE_SPREAD 40 /* bounding-box diagonal over sqrt(area) of an outline (fm_validate) */
#define IDW_RADIUS 1.5     /* radius (in e) of the barb edges averaged for a triangle without one */
#define PROJECT_COARSE 512 /* coarse samples of the centre line scanned by a projection */
#define FILL_CLEAR 0.7     /* a fill barb starts where it is this far from every vertex and barb */
#define FILL_LEVELS 3      /* fill barbs from half, quarter and eighth stations */
#define CORNER_GAP 0.5     /* a corner station closer than this (in station spacings) to a kept one is dropped */
#define CORNER_TOL 1e-6    /* a corner barb must meet its outline vertex within this (in e) */
#define CORNER_BISECT 64   /* bisection steps of a corner station (stops earlier once exact) */
#define OUTLINE_GAP 2.0    /* an outline gap up to this (in e) between barb ends is left whole */

/* ------------------------------------------------------------------ mesher state */

enum { SEG_OUTLINE, SEG_SIDE, SEG_BARB };

typedef struct {
    double a[2], b[2];
    plume_index v0, v1; /* vertex ids (constrained segments), -1 otherwise */
    int kind, side;     /* side +1 left, -1 right */
    plume_index tag;    /* outline: edge index; barb: barb number; side: 0 left, 1 right */
    double t0, t1;      /* outline: parameter range of the piece on its edge */
} fseg;

/* An input barb as relative angle theta(tau), tau the arc length from its root. */
typedef struct {
    double s_root;
    double *tau, *theta;
    plume_index n;
} shape;

typedef struct {
    plume_index edge; /* outline edge (from vertex edge to edge+1) */
    double t;
    plume_index id;
} anchor;

typedef struct {
    const plume_feather_input *in;
    plume_err *err;
    double e;
    /* outline, counter-clockwise */
    double *o;
    plume_index no;
    double *ocum, per; /* [no + 1] arc length of the outline at each vertex; its perimeter */
    double bb[4], diag; /* bounding box (x0, y0, x1, y1) and its diagonal */
    /* output vertices and constrained segments (ids in g.p order) */
    plume_pslg g;
    unsigned char *outline_used; /* [no] outline vertex already ends a barb or side */
    /* geometric segments */
    fseg *s;
    plume_index ns, scap;
    unsigned *stamp;
    unsigned qid;
    plume_bins pg, sg;
    anchor *anc;
    plume_index nanc, anccap;
    /* centre line: samples with s = 0 at the base exit, L at the tip exit, margins beyond */
    plume_sampled_curve c;
    double L, s_in0, s_in1;
    /* input barb shapes per side (0 left, 1 right), sorted by root station */
    shape *sh[2];
    int nsh[2];
    double max_barb_len;
    /* barb constrained segments: pslg segment indices */
    plume_index *barb_seg;
    plume_index nbarb_seg, barb_cap;
} fm;

static int fm_add_seg(fm *f, const double *a, const double *b, plume_index v0, plume_index v1, int kind, int side,
                      plume_index tag, double t0, double t1)
{
    if (f->ns == f->scap) {
        plume_index cap = f->scap ? 2 * f->scap : 1024;
        fseg *s = realloc(f->s, (size_t)cap * sizeof *s);
        if (!s)
            return -1;
        f->s = s;
        unsigned *stp = realloc(f->stamp, (size_t)cap * sizeof *stp);
        if (!stp)
            return -1;
        f->stamp = stp, f->scap = cap;
    }
    fseg *s = f->s + f->ns;
    s->a[0] = a[0], s->a[1] = a[1], s->b[0] = b[0], s->b[1] = b[1];
    s->v0 = v0, s->v1 = v1, s->kind = kind, s->side = side, s->tag = tag, s->t0 = t0, s->t1 = t1;
    f->stamp[f->ns] = 0;
    if (plume_bins_add(&f->sg, f->ns, a[0], a[1], b[0], b[1]) < 0)
        return -1;
    f->ns++;
    return 0;
}

/* New output vertex, registered in the point grid; its id or -1 (no memory). */
static plume_index fm_add_vertex(fm *f, const double *p)
{
    plume_index id = plume_pslg_point(&f->g, p[0], p[1]);
    if (id < 0 || plume_bins_add(&f->pg, id, p[0], p[1], p[0], p[1]) < 0)
        return -1;
    return id;
}

/* A constrained edge between vertices (side or barb). */
static int fm_add_constraint(fm *f, plume_index v0, plume_index v1, int kind, int side, plume_index tag)
{
    if (plume_pslg_segment(&f->g, v0, v1) < 0)
        return -1;
    if (kind == SEG_BARB) {
        if (f->nbarb_seg == f->barb_cap) {
            plume_index cap = f->barb_cap ? 2 * f->barb_cap : 256;
            plume_index *b = realloc(f->barb_seg, (size_t)cap * sizeof *b);
            if (!b)
                return -1;
            f->barb_seg = b, f->barb_cap = cap;
        }
        f->barb_seg[f->nbarb_seg++] = f->g.ns - 1;
    }
    return fm_add_seg(f, f->g.p + 2 * v0, f->g.p + 2 * v1, v0, v1, kind, side, tag, 0, 0);
}

/* A vertex on outline edge `edge` at parameter t (snapped to an edge end closer than `snap`). */
static plume_index fm_outline_vertex(fm *f, plume_index edge, double t, double snap)
{
    plume_index j = (edge + 1) % f->no;
    const double *a = f->o + 2 * edge, *b = f->o + 2 * j;
    double len = norm2(b[0] - a[0], b[1] - a[1]);
    if (t * len < snap || (1 - t) * len < snap) {
        plume_index v = t * len < snap ? edge : j;
        if (!f->outline_used[v] &&
            plume_bins_add(&f->pg, v, f->o[2 * v], f->o[2 * v + 1], f->o[2 * v], f->o[2 * v + 1]) < 0)
            return -1;
        f->outline_used[v] = 1;
        return v;
    }
    double p[2] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
    plume_index id = fm_add_vertex(f, p);
    if (id < 0)
        return -1;
    if (f->nanc == f->anccap) {
        plume_index cap = f->anccap ? 2 * f->anccap : 256;
        anchor *an = realloc(f->anc, (size_t)cap * sizeof *an);
        if (!an)
            return -1;
        f->anc = an, f->anccap = cap;
    }
    f->anc[f->nanc].edge = edge, f->anc[f->nanc].t = t, f->anc[f->nanc].id = id;
    f->nanc++;
    return id;
}

/* The outline vertex a snapped end would use, or -1 (not snapped). */
static plume_index fm_snap_target(const fm *f, plume_index edge, double t, double snap)
{
    plume_index j = (edge + 1) % f->no;
    const double *a = f->o + 2 * edge, *b = f->o + 2 * j;
    double len = norm2(b[0] - a[0], b[1] - a[1]);
    if (t * len < snap)
        return edge;
    if ((1 - t) * len < snap)
        return j;
    return -1;
}

#define FOR_CELLS(gr, xa, ya, xb, yb, node)                                                                         \
    long r_[4];                                                                                                    \
    plume_bins_range(gr, xa, ya, xb, yb, r_);                                                                      \
    for (long j_ = r_[2]; j_ <= r_[3]; j_++)                                                                        \
        for (long i_ = r_[0]; i_ <= r_[1]; i_++)                                                                    \
            for (plume_index node = (gr)->head[j_ * (gr)->nx + i_]; node >= 0; node = (gr)->next[node])

/* Earliest crossing of p->q with the outline: 1 and t along pq, the edge and its parameter. */
static int fm_outline_cross(const fm *f, const double *p, const double *q, double *t, plume_index *edge, double *u)
{
    int found = 0;
    double best = INFINITY;
    FOR_CELLS(&f->sg, p[0], p[1], q[0], q[1], nd)
    {
        const fseg *s = f->s + f->sg.item[nd];
        if (s->kind != SEG_OUTLINE)
            continue;
        double tt, uu;
        if (seg_intersect(p, q, s->a, s->b, &tt, &uu) && tt < best) {
            best = tt, found = 1;
            *t = tt, *edge = s->tag, *u = s->t0 + uu * (s->t1 - s->t0);
        }
    }
    return found;
}

/* Any segment of one of the kinds (bit mask) within r of p, ignoring those incident to vertex `skip`. */
static int fm_near_segment(const fm *f, const double *p, double r, unsigned kinds, plume_index skip)
{
    FOR_CELLS(&f->sg, p[0] - r, p[1] - r, p[0] + r, p[1] + r, nd)
    {
        const fseg *s = f->s + f->sg.item[nd];
        if (!(kinds & (1u << s->kind)) || (skip >= 0 && (s->v0 == skip || s->v1 == skip)))
            continue;
        if (seg_dist(p, s->a, s->b, NULL) < r)
            return 1;
    }
    return 0;
}

/* Any constrained (side, barb) segment crossing or within r of ab, ignoring those incident to `skip`. */
static int fm_blocked(const fm *f, const double *a, const double *b, double r, plume_index skip)
{
    FOR_CELLS(&f->sg, fmin(a[0], b[0]) - r, fmin(a[1], b[1]) - r, fmax(a[0], b[0]) + r, fmax(a[1], b[1]) + r, nd)
    {
        const fseg *s = f->s + f->sg.item[nd];
        if ((s->kind != SEG_SIDE && s->kind != SEG_BARB) || (skip >= 0 && (s->v0 == skip || s->v1 == skip)))
            continue;
        if (segseg_dist(a, b, s->a, s->b) <= r)
            return 1;
    }
    return 0;
}

/* Any vertex within r of segment ab (a point when a == b), ignoring `skip`. */
static int fm_near_vertex(const fm *f, const double *a, const double *b, double r, plume_index skip)
{
    FOR_CELLS(&f->pg, fmin(a[0], b[0]) - r, fmin(a[1], b[1]) - r, fmax(a[0], b[0]) + r, fmax(a[1], b[1]) + r, nd)
    {
        plume_index v = f->pg.item[nd];
        if (v == skip)
            continue;
        if (seg_dist(f->g.p + 2 * v, a, b, NULL) < r)
            return 1;
    }
    return 0;
}

/* ------------------------------------------------------------------ centre line */

static double fm_width(const fm *f, double s)
{
    const plume_feather_input *in = f->in;
    if (s <= f->s_in0 || f->s_in1 <= f->s_in0)
        return in->rachis_width_base;
    if (s >= f->s_in1)
        return in->rachis_width_tip;
    return in->rachis_width_base +
           (in->rachis_width_tip - in->rachis_width_base) * (s - f->s_in0) / (f->s_in1 - f->s_in0);
}

/* Centre point and tangent angle at arc length s; linear beyond the samples. */
static void fm_centre(const fm *f, double s, double p[2], double *ang)
{
    const plume_sampled_curve *c = &f->c;
    plume_index n = c->n;
    if (s <= c->s[0] || s >= c->s[n - 1]) {
        plume_index i = s <= c->s[0] ? 0 : n - 1;
        double a = c->a[i], d = s - c->s[i];
        p[0] = c->x[i] + d * cos(a), p[1] = c->y[i] + d * sin(a);
        *ang = a;
        return;
    }
    plume_index lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        plume_index mid = (lo + hi) / 2;
        if (c->s[mid] <= s)
            lo = mid;
        else
            hi = mid;
    }
    double ds = c->s[hi] - c->s[lo], w = ds > 0 ? (s - c->s[lo]) / ds : 0;
    p[0] = c->x[lo] + w * (c->x[hi] - c->x[lo]);
    p[1] = c->y[lo] + w * (c->y[hi] - c->y[lo]);
    *ang = c->a[lo] + w * (c->a[hi] - c->a[lo]);
}

/* Point of side sigma (+1 left, -1 right) at half the width from the centre line. */
static void fm_offset(const fm *f, double s, int sigma, double p[2])
{
    double a;
    fm_centre(f, s, p, &a);
    double h = 0.5 * sigma * fm_width(f, s);
    p[0] -= h * sin(a), p[1] += h * cos(a);
}

/* Arc length s of the nearest centre-line point and the signed distance (> 0 on the left). The
 * centre line is smooth and long: the nearest of ~PROJECT_COARSE evenly strided samples locates
 * the foot to within a stride, then the segments two strides around it are searched exactly. */
static void fm_project(const fm *f, const double *p, double *s_out, double *d_out)
{
    const plume_sampled_curve *c = &f->c;
    plume_index stride = c->n / PROJECT_COARSE + 1, best_i = 0;
    double best = INFINITY;
    for (plume_index i = 0; i < c->n; i += stride) {
        double dx = p[0] - c->x[i], dy = p[1] - c->y[i], d = dx * dx + dy * dy;
        if (d < best)
            best = d, best_i = i;
    }
    plume_index i0 = best_i > 2 * stride ? best_i - 2 * stride : 0;
    plume_index i1 = best_i + 2 * stride < c->n - 1 ? best_i + 2 * stride : c->n - 1;
    best = INFINITY;
    for (plume_index i = i0; i < i1; i++) {
        double a[2] = {c->x[i], c->y[i]}, b[2] = {c->x[i + 1], c->y[i + 1]}, t;
        double d = seg_dist(p, a, b, &t);
        if (d < best) {
            best = d;
            *s_out = c->s[i] + t * (c->s[i + 1] - c->s[i]);
            double dx = b[0] - a[0], dy = b[1] - a[1];
            *d_out = (dx * (p[1] - a[1]) - dy * (p[0] - a[0])) / norm2(dx, dy);
        }
    }
}

/* Nearest exit of the ray p + t d (t > 0) through the outline; the hit point, or 0 if none. */
static int fm_ray_hit(const fm *f, const double *p, double ang, double hit[2])
{
    double D = 4 * f->diag + 1;
    double q[2] = {p[0] + D * cos(ang), p[1] + D * sin(ang)};
    double best = INFINITY;
    for (plume_index i = 0; i < f->no; i++) {
        double t, u;
        const double *a = f->o + 2 * i, *b = f->o + 2 * ((i + 1) % f->no);
        if (seg_intersect(p, q, a, b, &t, &u) && t * D > 1e-12 * f->diag && t < best)
            best = t;
    }
    if (!(best < INFINITY))
        return 0;
    hit[0] = p[0] + best * (q[0] - p[0]), hit[1] = p[1] + best * (q[1] - p[1]);
    return 1;
}

/* Appends the straight run from `from` toward `to` (exclusive of from, inclusive of to) every h. */
static int push_line(plume_sampled_curve *c, const double *from, const double *to, double h)
{
    double len = norm2(to[0] - from[0], to[1] - from[1]);
    long m = (long)ceil(len / h);
    if (m < 1)
        m = 1;
    for (long j = 1; j <= m; j++) {
        double w = (double)j / (double)m;
        if (plume_sampled_curve_push(c, from[0] + w * (to[0] - from[0]), from[1] + w * (to[1] - from[1])) < 0)
            return -1;
    }
    return 0;
}

/* Rachis centre line from the input: spline, clipped at its first exit or extended linearly to the
 * outline at the tip, extended backward to the outline at the base, plus straight margins. */
static plume_status fm_build_centre(fm *f)
{
    const plume_polyline *r = &f->in->rachis;
    double h = f->e / SAMPLES;
    plume_sampled_curve raw = {0}, c = {0};
    plume_status st = PLUME_OK;
    if ((st = plume_sample_spline(r, h, &raw)) != PLUME_OK)
        goto cleanup;
    /* forward: first exit */
    plume_index nkeep = raw.n;
    double exitp[2] = {0, 0};
    int clipped = 0;
    for (plume_index i = 0; i + 1 < raw.n && !clipped; i++) {
        double p[2] = {raw.x[i], raw.y[i]}, q[2] = {raw.x[i + 1], raw.y[i + 1]}, t, u;
        plume_index edge;
        if (fm_outline_cross(f, p, q, &t, &edge, &u)) {
            exitp[0] = p[0] + t * (q[0] - p[0]), exitp[1] = p[1] + t * (q[1] - p[1]);
            nkeep = i + 1;
            clipped = 1;
        }
    }
    double start_ang = atan2(raw.y[0] - raw.y[1], raw.x[0] - raw.x[1]);
    double base[2], p0[2] = {raw.x[0], raw.y[0]};
    if (!fm_ray_hit(f, p0, start_ang, base)) {
        st = plume_err_set(f->err, PLUME_EINVAL, "rachis: its backward extension from point 0 never meets the outline");
        goto cleanup;
    }
    double margin = fmax(f->in->rachis_width_base, f->in->rachis_width_tip) + 2 * f->e;
    double pre[2] = {base[0] + margin * cos(start_ang), base[1] + margin * sin(start_ang)};
    if (plume_sampled_curve_push(&c, pre[0], pre[1]) < 0 || push_line(&c, pre, base, h) < 0 ||
        push_line(&c, base, p0, h) < 0) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    plume_index i_in0 = c.n - 1;
    for (plume_index i = 1; i < nkeep; i++)
        if (plume_sampled_curve_push(&c, raw.x[i], raw.y[i]) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    plume_index i_in1 = c.n - 1;
    double tip[2];
    if (clipped) {
        double last[2] = {c.x[c.n - 1], c.y[c.n - 1]};
        if (norm2(exitp[0] - last[0], exitp[1] - last[1]) > 1e-12 * f->diag &&
            plume_sampled_curve_push(&c, exitp[0], exitp[1]) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
        tip[0] = c.x[c.n - 1], tip[1] = c.y[c.n - 1];
        i_in1 = c.n - 1;
    } else {
        double end_ang = atan2(raw.y[raw.n - 1] - raw.y[raw.n - 2], raw.x[raw.n - 1] - raw.x[raw.n - 2]);
        double pe[2] = {raw.x[raw.n - 1], raw.y[raw.n - 1]};
        if (!fm_ray_hit(f, pe, end_ang, tip)) {
            st = plume_err_set(f->err, PLUME_EINVAL,
                               "rachis: its extension from its last point never meets the outline");
            goto cleanup;
        }
        if (push_line(&c, pe, tip, h) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    }
    plume_index i_tip = c.n - 1;
    double ta = atan2(c.y[c.n - 1] - c.y[c.n - 2], c.x[c.n - 1] - c.x[c.n - 2]);
    double post[2] = {tip[0] + margin * cos(ta), tip[1] + margin * sin(ta)};
    if (push_line(&c, tip, post, h) < 0) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    plume_sampled_curve_finish(&c);
    /* s = 0 at the base exit */
    plume_index i_base = 0;
    for (plume_index i = 0; i < c.n; i++)
        if (c.x[i] == base[0] && c.y[i] == base[1]) {
            i_base = i;
            break;
        }
    double s0 = c.s[i_base];
    for (plume_index i = 0; i < c.n; i++)
        c.s[i] -= s0;
    f->L = c.s[i_tip];
    f->s_in0 = c.s[i_in0];
    f->s_in1 = c.s[i_in1];
    f->c = c;
    c = (plume_sampled_curve){0};
    if (!(f->L > 0))
        st = plume_err_set(f->err, PLUME_EINVAL, "rachis: the centre line has no length inside the outline");
cleanup:
    plume_sampled_curve_free(&raw);
    plume_sampled_curve_free(&c);
    return st;
}

/* ------------------------------------------------------------------ barb shapes */

static double shape_theta(const shape *sh, double tau)
{
    if (tau <= 0)
        return sh->theta[0];
    if (tau >= sh->tau[sh->n - 1])
        return sh->theta[sh->n - 1];
    plume_index lo = 0, hi = sh->n - 1;
    while (hi - lo > 1) {
        plume_index mid = (lo + hi) / 2;
        if (sh->tau[mid] <= tau)
            lo = mid;
        else
            hi = mid;
    }
    double d = sh->tau[hi] - sh->tau[lo], w = d > 0 ? (tau - sh->tau[lo]) / d : 0;
    return sh->theta[lo] + w * (sh->theta[hi] - sh->theta[lo]);
}

static int cmp_shape(const void *a, const void *b)
{
    double x = ((const shape *)a)->s_root, y = ((const shape *)b)->s_root;
    return (x > y) - (x < y);
}

static plume_status fm_build_shapes(fm *f)
{
    const plume_feather_input *in = f->in;
    for (int side = 0; side < 2; side++) {
        int nb = side == 0 ? in->nbarbs_left : in->nbarbs_right;
        const plume_polyline *bs = side == 0 ? in->barbs_left : in->barbs_right;
        f->sh[side] = calloc((size_t)nb, sizeof(shape));
        if (!f->sh[side])
            return PLUME_ENOMEM;
        f->nsh[side] = nb;
        for (int k = 0; k < nb; k++) {
            plume_sampled_curve c = {0};
            plume_status st = plume_sample_spline(bs + k, f->e / SAMPLES, &c);
            if (st != PLUME_OK) {
                plume_sampled_curve_free(&c);
                return st;
            }
            plume_sampled_curve_finish(&c);
            shape *sh = f->sh[side] + k;
            double p0[2] = {c.x[0], c.y[0]}, d, cp[2], phi;
            fm_project(f, p0, &sh->s_root, &d);
            fm_centre(f, sh->s_root, cp, &phi);
            double th0 = remainder(c.a[0] - phi, 2 * FM_PI);
            double shift = th0 - (c.a[0] - phi);
            int sigma = side == 0 ? 1 : -1;
            if (!(sigma * sin(th0) > 1e-3)) {
                plume_sampled_curve_free(&c);
                const char *nm = side == 0 ? "left" : "right";
                return plume_err_set(f->err, PLUME_EINVAL,
                                     "barbs_%s[%d]: it starts %s (%.1f degrees from the rachis tangent): a %s barb "
                                     "must leave the rachis toward the %s",
                                     nm, k,
                                     fabs(sin(th0)) <= 1e-3 ? "along the rachis"
                                     : sin(th0) > 0         ? "toward the left of the rachis"
                                                            : "toward the right of the rachis",
                                     th0 * 180 / FM_PI, nm, nm);
            }
            sh->n = c.n;
            sh->tau = c.s, c.s = NULL;
            sh->theta = c.a, c.a = NULL;
            for (plume_index i = 0; i < sh->n; i++)
                sh->theta[i] += shift - phi; /* relative to the rachis tangent at the root */
            f->max_barb_len = fmax(f->max_barb_len, sh->tau[sh->n - 1]);
            plume_sampled_curve_free(&c);
        }
        qsort(f->sh[side], (size_t)nb, sizeof(shape), cmp_shape);
    }
    return PLUME_OK;
}

/* The blend of a station: shapes j and j+1 with weight w on j+1. */
typedef struct {
    const shape *a, *b;
    double w, phi;
} blend;

static void fm_blend(const fm *f, int side, double s, blend *bl)
{
    const shape *sh = f->sh[side];
    int n = f->nsh[side], j = 0;
    while (j + 1 < n && sh[j + 1].s_root <= s)
        j++;
    bl->a = sh + j;
    if (s <= sh[0].s_root || j + 1 >= n) {
        bl->b = bl->a, bl->w = 0;
    } else {
        bl->b = sh + j + 1;
        double den = bl->b->s_root - bl->a->s_root;
        bl->w = den > 1e-12 * f->e ? (s - bl->a->s_root) / den : 0.5;
    }
    double p[2];
    fm_centre(f, s, p, &bl->phi);
}

static double blend_angle(const blend *bl, double tau)
{
    return bl->phi + (1 - bl->w) * shape_theta(bl->a, tau) + bl->w * shape_theta(bl->b, tau);
}

/* ------------------------------------------------------------------ barb walk */

/* Past every input barb's end a barb curve is straight (direction a): jump from p to a sub-step h
 * before the outline, advancing tau by the jump and q to the next sub-step. 0 when the ray misses
 * the outline (the barb never enters the vane). */
static int fm_jump_to_outline(const fm *f, double a, double h, double p[2], double q[2], double *tau)
{
    double hit[2];
    if (!fm_ray_hit(f, p, a, hit))
        return 0;
    double dist = norm2(hit[0] - p[0], hit[1] - p[1]);
    if (dist > 2 * h) {
        double jmp = dist - h;
        p[0] += jmp * cos(a), p[1] += jmp * sin(a);
        *tau += jmp;
        q[0] = p[0] + h * cos(a), q[1] = p[1] + h * sin(a);
    }
    return 1;
}

/* Walks the barb of a station from `root` (a vertex id, or -1 when the start is not a vertex),
 * adding vertices and constrained barb edges until the outline or a collision. */
static plume_status fm_walk(fm *f, int side, const double *start, plume_index root, int root_on_outline, int fill,
                            const blend *bl, plume_index tag)
{
    const double e = f->e, h = e / SUBSTEPS;
    const int sigma = side == 0 ? 1 : -1;
    double p[2] = {start[0], start[1]};
    int inside = root >= 0 || point_in_polygon(f->o, f->no, p);
    plume_index last = root;
    double lastp[2] = {p[0], p[1]};
    long since = 0; /* sub-steps since the last vertex (or the entry) */
    double tau_max = f->max_barb_len + 3 * f->diag + 2 * e;
    int jumped = 0;
    for (double tau = 0; tau < tau_max; tau += h) {
        double a = blend_angle(bl, tau + 0.5 * h);
        double q[2] = {p[0] + h * cos(a), p[1] + h * sin(a)};
        double t, u;
        plume_index edge;
        if (!inside) {
            if (tau > f->max_barb_len && !jumped) {
                jumped = 1;
                if (!fm_jump_to_outline(f, a, h, p, q, &tau))
                    return PLUME_OK;
            }
            if (fm_outline_cross(f, p, q, &t, &edge, &u)) {
                inside = 1;
                double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])}, s, d;
                fm_project(f, x, &s, &d);
                plume_index snap = fm_snap_target(f, edge, u, SNAP_OUTLINE * e);
                const double *xp = snap >= 0 ? f->o + 2 * snap : x;
                last = -1;
                if (sigma * d >= 0.5 * fm_width(f, s) && !(snap >= 0 && f->outline_used[snap]) &&
                    !fm_near_vertex(f, xp, xp, GAP_POINT * e, -1) &&
                    !fm_near_segment(f, xp, GAP_SEGMENT * e, 1u << SEG_SIDE | 1u << SEG_BARB, -1)) {
                    if ((last = fm_outline_vertex(f, edge, u, SNAP_OUTLINE * e)) < 0)
                        return PLUME_ENOMEM;
                    lastp[0] = f->g.p[2 * last], lastp[1] = f->g.p[2 * last + 1];
                } else if (sigma * d < 0.5 * fm_width(f, s)) {
                    return PLUME_OK; /* entering through the strip end or the other side */
                }
                since = 0;
            }
            p[0] = q[0], p[1] = q[1];
            continue;
        }
        if (tau == 0 && root >= 0 && root_on_outline) {
            /* from a strip end on the outline: go on only if the barb heads into the feather */
            if (!point_in_polygon(f->o, f->no, q))
                return PLUME_OK;
        } else if (fm_outline_cross(f, p, q, &t, &edge, &u)) {
            /* the barb leaves the feather: its last edge ends on the outline */
            if (last < 0 || ((double)since + t) * h > LAST_ARC * e)
                return PLUME_OK;
            double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
            plume_index snap = fm_snap_target(f, edge, u, SNAP_OUTLINE * e);
            const double *xp = snap >= 0 ? f->o + 2 * snap : x;
            if (norm2(xp[0] - lastp[0], xp[1] - lastp[1]) < GAP_POINT * e ||
                (snap >= 0 && f->outline_used[snap]) || fm_near_vertex(f, xp, xp, GAP_POINT * e, last) ||
                fm_near_vertex(f, lastp, xp, GAP_SEGMENT * e, last) || fm_blocked(f, lastp, xp, 0, last))
                return PLUME_OK;
            plume_index id = fm_outline_vertex(f, edge, u, SNAP_OUTLINE * e);
            if (id < 0 || fm_add_constraint(f, last, id, SEG_BARB, sigma, tag) < 0)
                return PLUME_ENOMEM;
            return PLUME_OK;
        }
        if (fm_blocked(f, p, q, 0, last) && !(fill && tau == 0))
            return PLUME_OK; /* it would cross another barb or the strip: cut (a fill barb starts on a side) */
        p[0] = q[0], p[1] = q[1];
        since++;
        if (fill && last < 0) {
            /* a fill barb starts where the gap between its neighbours opens to 2 FILL_CLEAR e */
            if (!fm_near_segment(f, p, GAP_POINT * e, 1u << SEG_OUTLINE, -1) &&
                !fm_near_vertex(f, p, p, FILL_CLEAR * e, -1) &&
                !fm_near_segment(f, p, FILL_CLEAR * e, 1u << SEG_SIDE | 1u << SEG_BARB, -1)) {
                if ((last = fm_add_vertex(f, p)) < 0)
                    return PLUME_ENOMEM;
                lastp[0] = p[0], lastp[1] = p[1];
                since = 0;
            }
            continue;
        }
        if (since < SUBSTEPS)
            continue;
        if (fm_near_segment(f, p, GAP_POINT * e, 1u << SEG_OUTLINE, -1)) {
            if ((double)since * h > LAST_ARC * e)
                return PLUME_OK; /* grazing the outline: end here */
            continue;            /* dropped: go on to the outline */
        }
        if ((double)since * h > LAST_ARC * e && last >= 0)
            return PLUME_OK;
        if (fm_near_vertex(f, p, p, GAP_POINT * e, last) ||
            fm_near_segment(f, p, GAP_SEGMENT * e, 1u << SEG_SIDE | 1u << SEG_BARB, last))
            return PLUME_OK; /* converging on another barb: cut */
        if (last >= 0 && (fm_near_vertex(f, lastp, p, GAP_SEGMENT * e, last) || fm_blocked(f, lastp, p, 0, last)))
            return PLUME_OK;
        plume_index id = fm_add_vertex(f, p);
        if (id < 0 || (last >= 0 && fm_add_constraint(f, last, id, SEG_BARB, sigma, tag) < 0))
            return PLUME_ENOMEM;
        last = id;
        lastp[0] = p[0], lastp[1] = p[1];
        since = 0;
    }
    return PLUME_OK;
}

/* ------------------------------------------------------------------ rachis strip */

/* Follows the side offset curve from station s toward ds sign until the outline: the end vertex. */
static plume_status fm_side_end(fm *f, int sigma, double s, double dir, plume_index from, plume_index *end)
{
    double h = f->e / SUBSTEPS, p[2], q[2];
    fm_offset(f, s, sigma, p);
    double smax = f->L + f->diag + f->e, smin = -f->diag - f->e;
    for (double ss = s; ss <= smax && ss >= smin; ss += dir * h) {
        fm_offset(f, ss + dir * h, sigma, q);
        double t, u;
        plume_index edge;
        if (fm_outline_cross(f, p, q, &t, &edge, &u)) {
            const double *fp = f->g.p + 2 * from;
            double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
            double tt, uu;
            plume_index e2;
            double xin[2] = {fp[0] + (1 - 1e-9) * (x[0] - fp[0]), fp[1] + (1 - 1e-9) * (x[1] - fp[1])};
            if (fm_outline_cross(f, fp, xin, &tt, &e2, &uu))
                return plume_err_set(f->err, PLUME_EINVAL,
                                     "rachis: the %s side of the strip cannot be closed on the outline near (%g, %g): "
                                     "edge = %g m is too coarse for the outline there",
                                     sigma > 0 ? "left" : "right", x[0], x[1], f->e);
            plume_index id = fm_outline_vertex(f, edge, u, SNAP_SIDE * f->e);
            if (id < 0)
                return PLUME_ENOMEM;
            *end = id;
            return PLUME_OK;
        }
        p[0] = q[0], p[1] = q[1];
    }
    return plume_err_set(f->err, PLUME_EINVAL, "rachis: the %s side of the strip never meets the outline",
                         sigma > 0 ? "left" : "right");
}

/* ------------------------------------------------------------------ corner-exact stations */

/* Where a barb meets the outline, followed without meshing it (no collisions): the same steps as
 * fm_walk, so a station found here meets the outline at the same point when it is walked. */
typedef struct {
    int valid;            /* 0: it enters through the strip end or the other side, or starts
                             inside the feather off the strip (the walk would be blocked) */
    int has[2];           /* [0] it enters through the outline (virtual stations), [1] it leaves */
    double U[2], x[2][2]; /* outline arc-length position and point of each crossing */
} ftrace;

static double fm_outline_pos(const fm *f, plume_index edge, double u)
{
    return f->ocum[edge] + u * (f->ocum[edge + 1] - f->ocum[edge]);
}

/* x wrapped into [-per/2, per/2]: the signed shortest way along the outline */
static double fm_wrap(const fm *f, double x)
{
    return x - f->per * round(x / f->per);
}

static void fm_trace(const fm *f, int side, double s, int rooted, ftrace *tr)
{
    const double e = f->e, h = e / SUBSTEPS;
    const int sigma = side == 0 ? 1 : -1;
    blend bl;
    double p[2];
    memset(tr, 0, sizeof *tr);
    fm_blend(f, side, s, &bl);
    fm_offset(f, s, sigma, p);
    int inside = rooted;
    if (!rooted && point_in_polygon(f->o, f->no, p))
        return;
    double tau_max = f->max_barb_len + 3 * f->diag + 2 * e;
    int jumped = 0;
    for (double tau = 0; tau < tau_max; tau += h) {
        double a = blend_angle(&bl, tau + 0.5 * h);
        double q[2] = {p[0] + h * cos(a), p[1] + h * sin(a)};
        double t, u;
        plume_index edge;
        if (!inside && tau > f->max_barb_len && !jumped) {
            jumped = 1;
            if (!fm_jump_to_outline(f, a, h, p, q, &tau))
                return;
        }
        if (fm_outline_cross(f, p, q, &t, &edge, &u)) {
            double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
            int k = inside ? 1 : 0;
            if (!inside) {
                double ss, d;
                fm_project(f, x, &ss, &d);
                if (sigma * d < 0.5 * fm_width(f, ss))
                    return;
                inside = 1;
            }
            tr->has[k] = 1;
            tr->U[k] = fm_outline_pos(f, edge, u);
            tr->x[k][0] = x[0], tr->x[k][1] = x[1];
            if (k == 1) {
                tr->valid = 1;
                return;
            }
        }
        p[0] = q[0], p[1] = q[1];
    }
    tr->valid = inside && tr->has[0];
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The station in (lo, hi) whose barb crosses the outline (crossing k of ftrace) at outline vertex
 * i, by bisection on the crossing's position along the outline; 1 and *s, or 0 (the crossing
 * jumps past the vertex, or the barb stops meeting the outline in between). */
static int fm_corner_bisect(const fm *f, int side, int rooted, int k, double lo, double hi, double sgn, plume_index i,
                            double *s)
{
    const double *c = f->o + 2 * i;
    ftrace tr;
    double best = INFINITY;
    for (int it = 0; it < CORNER_BISECT; it++) {
        double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi))
            break;
        fm_trace(f, side, mid, rooted, &tr);
        if (!tr.valid || !tr.has[k])
            return 0;
        double dist = norm2(tr.x[k][0] - c[0], tr.x[k][1] - c[1]);
        if (dist < best)
            best = dist, *s = mid;
        if (dist <= 1e-9 * f->e)
            break;
        if (sgn * fm_wrap(f, tr.U[k] - f->ocum[i]) < 0)
            lo = mid;
        else
            hi = mid;
    }
    return best <= CORNER_TOL * f->e;
}

/* The side point of station s is a possible barb root: inside the outline, GAP_POINT e clear of
 * it, and reached from the run's end station `from` without crossing it. */
static int fm_rootable(const fm *f, int sigma, double from, double s)
{
    double p[2], q[2], t, u;
    plume_index edge;
    fm_offset(f, from, sigma, p);
    fm_offset(f, s, sigma, q);
    return point_in_polygon(f->o, f->no, q) && !fm_near_segment(f, q, GAP_POINT * f->e, 1u << SEG_OUTLINE, -1) &&
           !fm_outline_cross(f, p, q, &t, &edge, &u);
}

/* How far past the run's end station s (toward dir = -1 or +1, at most one station spacing ds)
 * the side stays rootable: the run stops at whole stations, a corner station may go further. */
static double fm_run_extent(const fm *f, int sigma, double s, double ds, int dir)
{
    double ok = s, bad = s + dir * ds;
    if (fm_rootable(f, sigma, s, bad))
        return bad;
    for (int it = 0; it < 40; it++) {
        double mid = 0.5 * (ok + bad);
        if (fm_rootable(f, sigma, s, mid))
            ok = mid;
        else
            bad = mid;
    }
    return ok;
}

/* Stations of one side, sorted (malloc'ed *out, *n of them; [*r0, *r1] the rooted ones, those of
 * the strip run [s0, s1], which a corner station may extend to ext[0] <= s0 and ext[1] >= s1, the
 * extent of the strip's side inside the outline (fm_run_extent)). A station whose barb meets the outline exactly at an outline vertex is a
 * corner station (docs/design.md, "Meshes that respect the fibres": a barb line through every corner);
 * corners closer than CORNER_GAP ds to a kept station are dropped, and the others are spaced evenly
 * between consecutive kept ones, round(gap / ds) - 1 of them, so that the density stays ~1/ds.
 * Without corners the stations are k ds, kmin <= k <= kmax, as before. */
static plume_status fm_stations(fm *f, int side, double ds, long kmin, long kmax, double s0, double s1,
                                const double ext[2], double **out, long *n, long *r0, long *r1)
{
    plume_status st = PLUME_OK;
    if (!f->in->corner_exact) { /* every ds, as before corner-exact stations */
        long a = lround(s0 / ds), b = lround(s1 / ds);
        if (!(*out = malloc((size_t)(kmax - kmin + 1) * sizeof **out)))
            return PLUME_ENOMEM;
        for (long k = kmin; k <= kmax; k++)
            (*out)[k - kmin] = (double)k * ds;
        *n = kmax - kmin + 1, *r0 = a - kmin, *r1 = b - kmin;
        return PLUME_OK;
    }
    long ns = 2 * (kmax - kmin) + 1 + 2;
    ftrace *tr = malloc((size_t)ns * sizeof *tr), *ftf = NULL;
    double *ss = malloc((size_t)ns * sizeof *ss);
    double *cs = NULL, *fixed = NULL, *sta = NULL;
    unsigned char *found = calloc((size_t)f->no, 1);
    long nc = 0, ccap = 64, nf = 0, nsta = 0;
    cs = malloc((size_t)ccap * sizeof *cs);
    if (!tr || !ss || !found || !cs) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    const double tol = 1e-9 * ds;
    /* the crossings of the family sampled every ds/2 and at the ends of the strip's extent */
    for (long j = 0; j < ns - 2; j++)
        ss[j] = (double)kmin * ds + 0.5 * (double)j * ds;
    ss[ns - 2] = ext[0], ss[ns - 1] = ext[1];
    qsort(ss, (size_t)ns, sizeof *ss, cmp_double);
    for (long j = 0; j < ns; j++)
        fm_trace(f, side, ss[j], ss[j] >= ext[0] - tol && ss[j] <= ext[1] + tol, tr + j);
    for (long j = 0; j + 1 < ns; j++) {
        double sl = ss[j], sh = ss[j + 1];
        int rl = sl >= ext[0] - tol && sl <= ext[1] + tol, rh = sh >= ext[0] - tol && sh <= ext[1] + tol;
        if (!tr[j].valid || !tr[j + 1].valid || rl != rh || !(sh > sl))
            continue;
        for (int k = 1; k >= 0; k--) {
            if (!tr[j].has[k] || !tr[j + 1].has[k])
                continue;
            double d = fm_wrap(f, tr[j + 1].U[k] - tr[j].U[k]);
            if (d == 0 || fabs(d) > 0.25 * f->per)
                continue;
            for (plume_index i = 0; i < f->no; i++) {
                double w = fm_wrap(f, f->ocum[i] - tr[j].U[k]);
                if (found[i] || !(d > 0 ? w > 0 && w <= d : w < 0 && w >= d))
                    continue;
                double s = sl;
                if (!fm_corner_bisect(f, side, rl, k, sl, sh, d > 0 ? 1 : -1, i, &s))
                    continue;
                if (nc == ccap) {
                    double *c2 = realloc(cs, (size_t)(2 * ccap) * sizeof *cs);
                    if (!c2) {
                        st = PLUME_ENOMEM;
                        goto cleanup;
                    }
                    cs = c2, ccap *= 2;
                }
                cs[nc++] = s;
                found[i] = 1;
            }
        }
    }
    qsort(cs, (size_t)nc, sizeof *cs, cmp_double);
    /* the strip run's end stations, moved onto the outermost corner of the strip's extent near them */
    for (long c = 0; c < nc; c++)
        if (cs[c] >= ext[0] - tol && cs[c] < s0 + CORNER_GAP * ds) {
            s0 = cs[c];
            break;
        }
    for (long c = nc - 1; c >= 0; c--)
        if (cs[c] <= ext[1] + tol && cs[c] > s1 - CORNER_GAP * ds) {
            s1 = cs[c];
            break;
        }
    fixed = malloc((size_t)(nc + 2) * sizeof *fixed);
    if (!fixed) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    fixed[nf++] = s0;
    if (s1 > s0)
        fixed[nf++] = s1;
    for (long c = 0; c < nc; c++) {
        int ok = 1;
        for (long q = 0; q < nf && ok; q++) /* tens of corners: a scan is enough */
            ok = fabs(cs[c] - fixed[q]) >= CORNER_GAP * ds;
        if (ok)
            fixed[nf++] = cs[c];
    }
    qsort(fixed, (size_t)nf, sizeof *fixed, cmp_double);
    if (!(ftf = malloc((size_t)nf * sizeof *ftf))) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    for (long q = 0; q < nf; q++)
        fm_trace(f, side, fixed[q], fixed[q] >= s0 && fixed[q] <= s1, ftf + q);
    /* stations: below the first fixed one every ds, between fixed ones evenly, above every ds
     * (counted in the first pass, stored in the second) */
    double lo_end = (double)kmin * ds - tol, hi_end = (double)kmax * ds + tol;
    for (int pass = 0; pass < 2; pass++) {
        double carry = 0;
        nsta = 0;
        for (long j = (long)floor((fixed[0] - lo_end) / ds); j >= 1; j--, nsta++)
            if (sta)
                sta[nsta] = fixed[0] - (double)j * ds;
        for (long q = 0; q < nf; q++) {
            if (sta)
                sta[nsta] = fixed[q];
            nsta++;
            if (q + 1 < nf) {
                double gap = fixed[q + 1] - fixed[q];
                /* the rounding error is carried to the next gap, so the density stays 1/ds */
                long m = lround(gap / ds + carry);
                if (m < 1)
                    m = 1;
                carry = fmin(0.5, fmax(-0.5, carry + gap / ds - (double)m)); /* kept local */
                /* more where their barbs would meet the outline more than OUTLINE_GAP e apart,
                 * but never closer than CORNER_GAP ds */
                for (int k = 0; k < 2; k++)
                    if (ftf[q].valid && ftf[q + 1].valid && ftf[q].has[k] && ftf[q + 1].has[k]) {
                        double arc = fabs(fm_wrap(f, ftf[q + 1].U[k] - ftf[q].U[k]));
                        long mo = (long)ceil(arc / (OUTLINE_GAP * f->e) - 1e-9);
                        if (arc < 0.25 * f->per && mo > m)
                            m = mo;
                    }
                long mmax = (long)floor(gap / (CORNER_GAP * ds) + 1e-9);
                if (m > mmax)
                    m = mmax;
                for (long j = 1; j < m; j++, nsta++)
                    if (sta)
                        sta[nsta] = fixed[q] + gap * (double)j / (double)m;
            }
        }
        for (long j = 1; fixed[nf - 1] + (double)j * ds <= hi_end; j++, nsta++)
            if (sta)
                sta[nsta] = fixed[nf - 1] + (double)j * ds;
        if (pass == 0 && !(sta = malloc((size_t)nsta * sizeof *sta))) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    }
    *r0 = *r1 = -1;
    for (long q = 0; q < nsta; q++)
        if (sta[q] >= s0 && sta[q] <= s1) {
            if (*r0 < 0)
                *r0 = q;
            *r1 = q;
        }
    *out = sta, sta = NULL;
    *n = nsta;
cleanup:
    free(tr);
    free(ss);
    free(ftf);
    free(cs);
    free(fixed);
    free(sta);
    free(found);
    return st;
}

/* ------------------------------------------------------------------ driver */

static int cmp_anchor(const void *a, const void *b)
{
    const anchor *x = a, *y = b;
    if (x->edge != y->edge)
        return x->edge < y->edge ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

typedef struct {
    plume_index a, b; /* a < b */
    int sign;         /* +1 when the barb runs a -> b */
} edge_key;

static int cmp_edge_key(const void *p, const void *q)
{
    const edge_key *x = p, *y = q;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    return (x->b > y->b) - (x->b < y->b);
}

/* bounding box b (x0, y0, x1, y1) grown to hold the polyline's points */
static void fm_grow_box(double b[4], const plume_polyline *pl)
{
    for (plume_index i = 0; i < pl->n; i++) {
        b[0] = fmin(b[0], pl->p[2 * i]), b[2] = fmax(b[2], pl->p[2 * i]);
        b[1] = fmin(b[1], pl->p[2 * i + 1]), b[3] = fmax(b[3], pl->p[2 * i + 1]);
    }
}

/* distance from (x, y) to the box b (x0, y0, x1, y1); 0 inside */
static double fm_box_distance(const double b[4], double x, double y)
{
    return hypot(fmax(fmax(b[0] - x, x - b[2]), 0.0), fmax(fmax(b[1] - y, y - b[3]), 0.0));
}

/* A rachis or barb point far outside the outline (a typo, 5.01 for 0.01) makes the mesher sample
 * and walk the whole curve at the target edge: found by fuzzing, a barb point 5000 m from a 0.2 m
 * feather took minutes. Points may lie outside the outline's bounding box by at most its diagonal. */
static plume_status fm_check_near(const char *name, const plume_polyline *c, const double bb[4], double diag,
                                  plume_err *err)
{
    for (plume_index i = 0; i < c->n; i++) {
        const double x = c->p[2 * i], y = c->p[2 * i + 1], out = fm_box_distance(bb, x, y);
        if (out > diag)
            return plume_err_set(err, PLUME_EINVAL,
                                 "%s: point %ld (%g, %g) lies %g m outside the outline's bounding box, more than "
                                 "its diagonal (%g m): a typo?",
                                 name, (long)i, x, y, out, diag);
    }
    return PLUME_OK;
}

/* The converse: an outline vertex far outside the rachis's and barbs' bounding box (a typo, 0.91 for
 * 0.01) makes a needle the barbs walk along. Found by fuzzing: such a needle, 0.9 m long on a
 * 0.2 m feather, passed the spread test above (the needle adds little to the bounding box's
 * diagonal over the square root of the area: 12), and meshing took 25-36 s in the release build
 * (more than 120 s under the sanitizers) before the CDT refused the crossing barbs it had made.
 * Outline vertices may lie outside that box by at most its diagonal. */
static plume_status fm_check_outline_near_skeleton(const plume_feather_input *in, plume_err *err)
{
    double b[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    fm_grow_box(b, &in->rachis);
    for (int k = 0; k < in->nbarbs_left; k++)
        fm_grow_box(b, in->barbs_left + k);
    for (int k = 0; k < in->nbarbs_right; k++)
        fm_grow_box(b, in->barbs_right + k);
    const double diag = hypot(b[2] - b[0], b[3] - b[1]);
    for (plume_index i = 0; i < in->outline.n; i++) {
        const double x = in->outline.p[2 * i], y = in->outline.p[2 * i + 1], out = fm_box_distance(b, x, y);
        if (out > diag)
            return plume_err_set(err, PLUME_EINVAL,
                                 "outline: point %ld (%g, %g) lies %g m outside the bounding box of the rachis and "
                                 "barb curves, more than its diagonal (%g m): a typo?",
                                 (long)i, x, y, out, diag);
    }
    return PLUME_OK;
}

static plume_status fm_validate(const plume_feather_input *in, int dim, plume_err *err)
{
    plume_status st;
    if (dim != 2 && dim != 3)
        return plume_err_set(err, PLUME_EINVAL, "dim = %d must be 2 or 3", dim);
    if (!(in->edge > 0) || !isfinite(in->edge))
        return plume_err_set(err, PLUME_EINVAL, "edge = %g m must be finite and > 0", in->edge);
    if ((st = plume_feather_check_curve("outline", &in->outline, 1, 3, err)) != PLUME_OK)
        return st;
    double area = fabs(polygon_area(in->outline.p, in->outline.n));
    if (!(area > 0))
        return plume_err_set(err, PLUME_EINVAL, "outline: zero area");
    if (area / (0.43 * in->edge * in->edge) > MAX_TRIANGLES)
        return plume_err_set(err, PLUME_EINVAL,
                             "edge = %g m would give about %.3g triangles on the outline's %g m^2 (limit %.0g)",
                             in->edge, area / (0.43 * in->edge * in->edge), area, MAX_TRIANGLES);
    /* a stray vertex far out (a typo in the OBJ) adds little area but makes every barb walk to the
     * far end of the bounding box: found by fuzzing, a spike 45 outline-sizes long took minutes.
     * A compact outline has diagonal / sqrt(area) of 2-6; 40 still admits an aspect ratio near 1000. */
    double bb[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    fm_grow_box(bb, &in->outline);
    double diag = hypot(bb[2] - bb[0], bb[3] - bb[1]);
    if (diag > MAX_OUTLINE_SPREAD * sqrt(area))
        return plume_err_set(err, PLUME_EINVAL,
                             "outline: its bounding box (diagonal %g m) is %.0f times the square root of its area "
                             "(%g m^2), more than %d: a vertex far from the others?",
                             diag, diag / sqrt(area), area, MAX_OUTLINE_SPREAD);
    if ((st = plume_feather_check_curve("rachis", &in->rachis, 0, 2, err)) != PLUME_OK ||
        (st = fm_check_near("rachis", &in->rachis, bb, diag, err)) != PLUME_OK)
        return st;
    if (!point_in_polygon(in->outline.p, in->outline.n, in->rachis.p))
        return plume_err_set(err, PLUME_EINVAL, "rachis: point 0 (%g, %g), its start, lies outside the outline",
                             in->rachis.p[0], in->rachis.p[1]);
    double wb = in->rachis_width_base, wt = in->rachis_width_tip;
    if (!(wb > 0) || !isfinite(wb) || !(wt > 0) || !isfinite(wt))
        return plume_err_set(err, PLUME_EINVAL,
                             "rachis widths (base %g m, tip %g m) must be finite and > 0", wb, wt);
    for (int side = 0; side < 2; side++) {
        int nb = side == 0 ? in->nbarbs_left : in->nbarbs_right;
        const plume_polyline *bs = side == 0 ? in->barbs_left : in->barbs_right;
        const char *nm = side == 0 ? "left" : "right";
        if (nb < 1 || !bs)
            return plume_err_set(err, PLUME_EINVAL,
                                 "barbs_%s: no barb curve on the %s side of the rachis (each side needs at least one)",
                                 nm, nm);
        for (int k = 0; k < nb; k++) {
            char name[64];
            snprintf(name, sizeof name, "barbs_%s[%d]", nm, k);
            if ((st = plume_feather_check_curve(name, bs + k, 0, 2, err)) != PLUME_OK ||
                (st = fm_check_near(name, bs + k, bb, diag, err)) != PLUME_OK)
                return st;
            if (!point_in_polygon(in->outline.p, in->outline.n, bs[k].p))
                return plume_err_set(err, PLUME_EINVAL, "%s: point 0 (%g, %g), its start, lies outside the outline",
                                     name, bs[k].p[0], bs[k].p[1]);
        }
    }
    return fm_check_outline_near_skeleton(in, err);
}

plume_status plume_feather_mesh(const plume_feather_input *in, int dim, plume_mesh **out, plume_index **barb_edges,
                                plume_index *nbarb, plume_err *err)
{
    return plume_feather_mesh_with_stats(in, dim, out, barb_edges, nbarb, NULL, err);
}

plume_status plume_feather_mesh_with_stats(const plume_feather_input *in, int dim, plume_mesh **out,
                                           plume_index **barb_edges, plume_index *nbarb, plume_feather_stats *stats,
                                           plume_err *err)
{
    if (!in || !out || !barb_edges || !nbarb)
        return plume_err_set(err, PLUME_EINVAL, "feather mesh: NULL argument");
    *out = NULL, *barb_edges = NULL, *nbarb = 0;
    plume_status st = fm_validate(in, dim, err);
    if (st != PLUME_OK)
        return st;

    fm f;
    memset(&f, 0, sizeof f);
    f.in = in, f.err = err, f.e = in->edge;
    plume_cdt_output cdt = {0};
    plume_mesh *m = NULL;
    plume_index *side_ids[2] = {NULL, NULL};
    double *sta[2] = {NULL, NULL}; /* stations (arc length along the centre line) of each side */
    long nsta[2] = {0, 0}, ra[2] = {0, 0}, rb[2] = {0, 0}; /* [ra, rb]: those rooted on the strip */
    edge_key *keys = NULL;
    plume_index *be = NULL;
    unsigned char *ends = NULL; /* [f.g.n] point ends a barb or side, for the outline's points */
    const double e = f.e;

    /* outline, counter-clockwise; its vertices are output vertices 0..no-1 */
    f.no = in->outline.n;
    f.o = malloc((size_t)(2 * f.no) * sizeof *f.o);
    f.outline_used = calloc((size_t)f.no, 1);
    if (!f.o || !f.outline_used) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    int reversed = polygon_area(in->outline.p, f.no) < 0;
    for (plume_index i = 0; i < f.no; i++) {
        plume_index j = reversed ? f.no - 1 - i : i;
        f.o[2 * i] = in->outline.p[2 * j], f.o[2 * i + 1] = in->outline.p[2 * j + 1];
    }
    f.bb[0] = f.bb[2] = f.o[0], f.bb[1] = f.bb[3] = f.o[1];
    for (plume_index i = 0; i < f.no; i++) {
        f.bb[0] = fmin(f.bb[0], f.o[2 * i]), f.bb[2] = fmax(f.bb[2], f.o[2 * i]);
        f.bb[1] = fmin(f.bb[1], f.o[2 * i + 1]), f.bb[3] = fmax(f.bb[3], f.o[2 * i + 1]);
    }
    f.diag = norm2(f.bb[2] - f.bb[0], f.bb[3] - f.bb[1]);
    if (!(f.ocum = malloc((size_t)(f.no + 1) * sizeof *f.ocum))) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    f.ocum[0] = 0;
    for (plume_index i = 0; i < f.no; i++) {
        const double *a = f.o + 2 * i, *b = f.o + 2 * ((i + 1) % f.no);
        f.ocum[i + 1] = f.ocum[i] + norm2(b[0] - a[0], b[1] - a[1]);
    }
    f.per = f.ocum[f.no];
    for (plume_index i = 0; i < f.no; i++)
        if (plume_pslg_point(&f.g, f.o[2 * i], f.o[2 * i + 1]) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    {
        double margin = fmax(in->rachis_width_base, in->rachis_width_tip) + 4 * e;
        double cell = e, w = f.bb[2] - f.bb[0] + 2 * margin, hgt = f.bb[3] - f.bb[1] + 2 * margin;
        if (w * hgt / (cell * cell) > 4e6)
            cell = sqrt(w * hgt / 4e6);
        if (plume_bins_init(&f.pg, f.bb[0] - margin, f.bb[1] - margin, f.bb[2] + margin, f.bb[3] + margin, cell) < 0 ||
            plume_bins_init(&f.sg, f.bb[0] - margin, f.bb[1] - margin, f.bb[2] + margin, f.bb[3] + margin, cell) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
        /* outline edges in pieces no longer than a cell, so the grid stays local */
        for (plume_index i = 0; i < f.no; i++) {
            const double *a = f.o + 2 * i, *b = f.o + 2 * ((i + 1) % f.no);
            long pieces = (long)ceil(norm2(b[0] - a[0], b[1] - a[1]) / cell);
            if (pieces < 1)
                pieces = 1;
            for (long k = 0; k < pieces; k++) {
                double t0 = (double)k / (double)pieces, t1 = (double)(k + 1) / (double)pieces;
                double pa[2] = {a[0] + t0 * (b[0] - a[0]), a[1] + t0 * (b[1] - a[1])};
                double pb[2] = {k + 1 == pieces ? b[0] : a[0] + t1 * (b[0] - a[0]),
                                k + 1 == pieces ? b[1] : a[1] + t1 * (b[1] - a[1])};
                if (k == 0)
                    pa[0] = a[0], pa[1] = a[1];
                if (fm_add_seg(&f, pa, pb, -1, -1, SEG_OUTLINE, 0, i, t0, t1) < 0) {
                    st = PLUME_ENOMEM;
                    goto cleanup;
                }
            }
        }
    }
    if ((st = fm_build_centre(&f)) != PLUME_OK || (st = fm_build_shapes(&f)) != PLUME_OK)
        goto cleanup;

    /* rachis strip: stations, side runs from the middle outward, ends closed on the outline */
    long N = lround(f.L / e);
    if (N < 1)
        N = 1;
    double ds = f.L / (double)N;
    long run[2][2]; /* [side][first, last] station k (of k ds) */
    long kv = (long)ceil((f.diag + f.max_barb_len) / ds) + 1; /* virtual stations beyond the strip */
    {
        long kmid = -1;
        for (long d = 0; d <= N && kmid < 0; d++)
            for (int sg = -1; sg <= 1 && kmid < 0; sg += 2) {
                long k = N / 2 + sg * d;
                if (k < 0 || k > N)
                    continue;
                int ok = 1;
                for (int sigma = -1; sigma <= 1; sigma += 2) {
                    double p[2];
                    fm_offset(&f, (double)k * ds, sigma, p);
                    ok = ok && point_in_polygon(f.o, f.no, p) &&
                         !fm_near_segment(&f, p, GAP_POINT * e, 1u << SEG_OUTLINE, -1);
                }
                if (ok)
                    kmid = k;
            }
        if (kmid < 0) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "rachis: no station where the strip (width %g to %g m) fits %g m inside the outline; "
                               "edge = %g m is too coarse or the rachis runs along the outline",
                               in->rachis_width_base, in->rachis_width_tip, GAP_POINT * e, e);
            goto cleanup;
        }
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            for (int dir = -1; dir <= 1; dir += 2) {
                long k = kmid;
                double p[2], q[2];
                fm_offset(&f, (double)k * ds, sigma, p);
                while (k + dir >= 0 && k + dir <= N) {
                    double t, u;
                    plume_index edge;
                    fm_offset(&f, (double)(k + dir) * ds, sigma, q);
                    if (fm_outline_cross(&f, p, q, &t, &edge, &u) ||
                        fm_near_segment(&f, q, GAP_POINT * e, 1u << SEG_OUTLINE, -1))
                        break;
                    k += dir;
                    p[0] = q[0], p[1] = q[1];
                }
                run[side][dir < 0 ? 0 : 1] = k;
            }
        }
        /* the stations of each side, corner-exact; those of the run root barbs on the strip */
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            double s0 = (double)run[side][0] * ds, s1 = (double)run[side][1] * ds;
            double ext[2] = {fm_run_extent(&f, sigma, s0, ds, -1), fm_run_extent(&f, sigma, s1, ds, 1)};
            if ((st = fm_stations(&f, side, ds, -kv, N + kv, s0, s1, ext, &sta[side], &nsta[side], &ra[side],
                                  &rb[side])) != PLUME_OK)
                goto cleanup;
        }
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            long a = ra[side], b = rb[side];
            side_ids[side] = malloc((size_t)(b - a + 3) * sizeof(plume_index));
            if (!side_ids[side]) {
                st = PLUME_ENOMEM;
                goto cleanup;
            }
            for (long k = a; k <= b; k++) {
                double p[2];
                fm_offset(&f, sta[side][k], sigma, p);
                if ((side_ids[side][k - a + 1] = fm_add_vertex(&f, p)) < 0) {
                    st = PLUME_ENOMEM;
                    goto cleanup;
                }
            }
        }
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            long a = ra[side], b = rb[side];
            plume_index *ids = side_ids[side];
            if ((st = fm_side_end(&f, sigma, sta[side][a], -1, ids[1], &ids[0])) != PLUME_OK ||
                (st = fm_side_end(&f, sigma, sta[side][b], 1, ids[b - a + 1], &ids[b - a + 2])) != PLUME_OK)
                goto cleanup;
            for (long k = 0; k < b - a + 2; k++)
                if (fm_add_constraint(&f, ids[k], ids[k + 1], SEG_SIDE, sigma, side) < 0) {
                    st = PLUME_ENOMEM;
                    goto cleanup;
                }
        }
    }

    /* barbs: rachis-rooted first (base to tip), then the family continued past the strip ends */
    {
        plume_index tag = 0;
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            long a = ra[side], b = rb[side];
            for (int pass = 0; pass < 4; pass++) {
                if (pass == 1) { /* from the strip ends on the outline */
                    plume_index ends[2] = {side_ids[side][0], side_ids[side][b - a + 2]};
                    for (int k = 0; k < 2; k++) {
                        blend bl;
                        double s, d, p[2] = {f.g.p[2 * ends[k]], f.g.p[2 * ends[k] + 1]};
                        fm_project(&f, p, &s, &d);
                        fm_blend(&f, side, s, &bl);
                        if ((st = fm_walk(&f, side, p, ends[k], 1, 0, &bl, tag++)) != PLUME_OK)
                            goto cleanup;
                    }
                    continue;
                }
                long k0 = pass == 0 ? a : pass == 2 ? a - 1 : b + 1;
                long k1 = pass == 0 ? b : pass == 2 ? 0 : nsta[side] - 1;
                long step = pass == 2 ? -1 : 1;
                for (long k = k0; step > 0 ? k <= k1 : k >= k1; k += step) {
                    blend bl;
                    double s = sta[side][k], p[2];
                    fm_blend(&f, side, s, &bl);
                    fm_offset(&f, s, sigma, p);
                    plume_index root = pass == 0 ? side_ids[side][k - a + 1] : -1;
                    if ((st = fm_walk(&f, side, p, root, 0, 0, &bl, tag++)) != PLUME_OK)
                        goto cleanup;
                }
            }
        }
    }

    /* fill barbs from fractional stations where neighbouring barbs diverge (none on most feathers) */
    for (int level = 1; level <= FILL_LEVELS; level++) {
        plume_index before = f.g.n, tag = -level;
        long parts = 1L << level;
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            for (long k = ra[side]; k < rb[side]; k++)
                for (long j = 1; j < parts; j += 2) {
                    blend bl;
                    double s = in->corner_exact
                                   ? sta[side][k] + (sta[side][k + 1] - sta[side][k]) * (double)j / (double)parts
                                   : ((double)(k - kv) + (double)j / (double)parts) * ds; /* as before */
                    double p[2];
                    fm_blend(&f, side, s, &bl);
                    fm_offset(&f, s, sigma, p);
                    if ((st = fm_walk(&f, side, p, -1, 0, 1, &bl, tag)) != PLUME_OK)
                        goto cleanup;
                }
        }
        if (f.g.n == before)
            break;
    }

    /* outline: its vertices, the anchors on its edges, and points so that no gap exceeds e, or
     * OUTLINE_GAP e between two points that each end a barb or a strip side */
    qsort(f.anc, (size_t)f.nanc, sizeof *f.anc, cmp_anchor);
    if (!(ends = calloc((size_t)f.g.n + 1, 1))) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    for (plume_index k = 0; k < 2 * f.g.ns; k++) /* only barb and side segments so far */
        ends[f.g.s[k]] = 1;
    {
        plume_index first = -1, prev = -1, ka = 0;
        for (plume_index i = 0; i < f.no; i++) {
            const double *a = f.o + 2 * i, *b = f.o + 2 * ((i + 1) % f.no);
            double tprev = 0;
            plume_index vprev = i;
            if (first < 0)
                first = i;
            if (prev >= 0 && plume_pslg_segment(&f.g, prev, i) < 0) {
                st = PLUME_ENOMEM;
                goto cleanup;
            }
            prev = i;
            for (;;) {
                int has = ka < f.nanc && f.anc[ka].edge == i;
                double tnext = has ? f.anc[ka].t : 1.0;
                plume_index vnext = has ? f.anc[ka].id : (i + 1) % f.no;
                const double *pp = f.g.p + 2 * vprev, *pn = f.g.p + 2 * vnext;
                double gap = norm2(pn[0] - pp[0], pn[1] - pp[1]);
                double limit = in->corner_exact && ends[vprev] && ends[vnext] ? OUTLINE_GAP * e : e;
                long pieces = gap > limit ? (long)ceil(gap / e - 1e-9) : 1;
                for (long j = 1; j < pieces; j++) {
                    double t = tprev + (tnext - tprev) * (double)j / (double)pieces;
                    plume_index id = plume_pslg_point(&f.g, a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                    if (id < 0 || plume_pslg_segment(&f.g, prev, id) < 0) {
                        st = PLUME_ENOMEM;
                        goto cleanup;
                    }
                    prev = id;
                }
                if (!has)
                    break;
                if (plume_pslg_segment(&f.g, prev, vnext) < 0) {
                    st = PLUME_ENOMEM;
                    goto cleanup;
                }
                prev = vnext, vprev = vnext, tprev = tnext;
                ka++;
            }
        }
        if (plume_pslg_segment(&f.g, prev, first) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    }

    plume_cdt_input ci = {0};
    ci.npoints = f.g.n, ci.points = f.g.p, ci.nsegments = f.g.ns, ci.segments = f.g.s;
    ci.remove_exterior = 1, ci.max_edge = 0;
    if ((st = plume_cdt_triangulate(&ci, &cdt, err)) != PLUME_OK)
        goto cleanup;
    if ((st = plume_mesh_create(cdt.npoints, cdt.ntriangles, dim, &m)) != PLUME_OK)
        goto cleanup;
    memcpy(m->X, cdt.points, (size_t)(2 * cdt.npoints) * sizeof *m->X);
    memcpy(m->tri, cdt.triangles, (size_t)(3 * cdt.ntriangles) * sizeof *m->tri);
    plume_mesh_reset_current(m);
    if ((st = plume_mesh_build_topology(m, err)) != PLUME_OK)
        goto cleanup;

    /* barb edges: directed keys for the triangle lookup, and those present as mesh edges */
    keys = malloc((size_t)(f.nbarb_seg + 1) * sizeof *keys);
    be = malloc((size_t)(2 * f.nbarb_seg + 1) * sizeof *be);
    if (!keys || !be) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    plume_index nbe = 0;
    for (plume_index k = 0; k < f.nbarb_seg; k++) {
        plume_index i = f.g.s[2 * f.barb_seg[k]], j = f.g.s[2 * f.barb_seg[k] + 1];
        keys[k].a = i < j ? i : j, keys[k].b = i < j ? j : i, keys[k].sign = i < j ? 1 : -1;
        plume_index pair[2] = {keys[k].a, keys[k].b};
        plume_index lo = 0, hi = m->ne - 1, found = 0;
        while (lo <= hi && !found) { /* m->edges is sorted (lib/core/mesh.c sorts its half-edges) */
            plume_index mid = (lo + hi) / 2, *ed = m->edges + 2 * mid;
            if (ed[0] == pair[0] && ed[1] == pair[1])
                found = 1;
            else if (ed[0] < pair[0] || (ed[0] == pair[0] && ed[1] < pair[1]))
                lo = mid + 1;
            else
                hi = mid - 1;
        }
        if (found)
            be[2 * nbe] = i, be[2 * nbe + 1] = j, nbe++;
    }
    qsort(keys, (size_t)f.nbarb_seg, sizeof *keys, cmp_edge_key);

    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        double c[2] = {0, 0};
        for (int k = 0; k < 3; k++)
            c[0] += m->X[2 * v[k]] / 3, c[1] += m->X[2 * v[k] + 1] / 3;
        double s, d, cp[2], phi;
        fm_project(&f, c, &s, &d);
        fm_centre(&f, s, cp, &phi);
        double *bd = m->barb_dir + 2 * t;
        if (fabs(d) <= 0.5 * fm_width(&f, s)) {
            m->material[t] = PLUME_FEATHER_RACHIS;
            bd[0] = cos(phi), bd[1] = sin(phi);
            continue;
        }
        m->material[t] = PLUME_FEATHER_VANE;
        double sum[2] = {0, 0};
        for (int k = 0; k < 3; k++) {
            plume_index i = v[k], j = v[(k + 1) % 3];
            edge_key q = {i < j ? i : j, i < j ? j : i, 0};
            const edge_key *hit = bsearch(&q, keys, (size_t)f.nbarb_seg, sizeof *keys, cmp_edge_key);
            if (!hit)
                continue;
            plume_index from = hit->sign > 0 ? hit->a : hit->b, to = hit->sign > 0 ? hit->b : hit->a;
            double dx = m->X[2 * to] - m->X[2 * from], dy = m->X[2 * to + 1] - m->X[2 * from + 1], l = norm2(dx, dy);
            sum[0] += dx / l, sum[1] += dy / l;
        }
        if (sum[0] == 0 && sum[1] == 0) {
            /* no barb edge: inverse-distance average of the barb edges of this side nearby */
            int sigma = d > 0 ? 1 : -1;
            for (double r = IDW_RADIUS * e; sum[0] == 0 && sum[1] == 0 && r < 8 * f.diag; r *= 2) {
                f.qid++;
                FOR_CELLS(&f.sg, c[0] - r, c[1] - r, c[0] + r, c[1] + r, nd)
                {
                    plume_index k = f.sg.item[nd];
                    const fseg *sg = f.s + k;
                    if (sg->kind != SEG_BARB || sg->side != sigma || f.stamp[k] == f.qid)
                        continue;
                    f.stamp[k] = f.qid;
                    double dist = seg_dist(c, sg->a, sg->b, NULL);
                    if (dist > r)
                        continue;
                    double dx = sg->b[0] - sg->a[0], dy = sg->b[1] - sg->a[1], l = norm2(dx, dy);
                    double w = 1.0 / (dist * dist + 0.01 * e * e);
                    sum[0] += w * dx / l, sum[1] += w * dy / l;
                }
            }
            if (sum[0] == 0 && sum[1] == 0) { /* no barb edge on this side at all: the blended shape */
                blend bl;
                fm_blend(&f, sigma > 0 ? 0 : 1, s, &bl);
                double a = blend_angle(&bl, fabs(d));
                sum[0] = cos(a), sum[1] = sin(a);
            }
        }
        double l = norm2(sum[0], sum[1]);
        bd[0] = sum[0] / l, bd[1] = sum[1] / l;
    }

    if (stats) {
        plume_index nu = 0;
        unsigned char *why = NULL;
        memset(stats, 0, sizeof *stats);
        if ((st = plume_vane_barb_coverage(m, be, nbe, PLUME_FEATHER_VANE, &stats->vane_covered,
                                           &stats->vane_triangles, NULL)) != PLUME_OK ||
            (st = plume_feather_uncovered(m, be, nbe, NULL, &why, &nu, err)) != PLUME_OK)
            goto cleanup;
        for (plume_index k = 0; k < nu; k++)
            stats->uncovered[why[k]]++;
        free(why);
        stats->rachis_triangles = m->nt - stats->vane_triangles;
        stats->vane_min_angle = stats->rachis_min_angle = 180;
        for (plume_index t = 0; t < m->nt; t++) {
            double *mn = m->material[t] == PLUME_FEATHER_VANE ? &stats->vane_min_angle : &stats->rachis_min_angle;
            for (int k = 0; k < 3; k++) {
                const double *a = m->X + 2 * m->tri[3 * t + k], *b = m->X + 2 * m->tri[3 * t + (k + 1) % 3],
                             *c = m->X + 2 * m->tri[3 * t + (k + 2) % 3];
                double u[2] = {b[0] - a[0], b[1] - a[1]}, w[2] = {c[0] - a[0], c[1] - a[1]};
                *mn = fmin(*mn, atan2(fabs(u[0] * w[1] - u[1] * w[0]), u[0] * w[0] + u[1] * w[1]) * 180 / FM_PI);
            }
        }
    }
    *out = m, m = NULL;
    *barb_edges = be, be = NULL;
    *nbarb = nbe;
cleanup:
    plume_mesh_destroy(&m);
    plume_cdt_output_free(&cdt);
    free(keys);
    free(be);
    free(ends);
    free(side_ids[0]), free(side_ids[1]);
    free(sta[0]), free(sta[1]);
    free(f.ocum);
    for (int side = 0; side < 2; side++) {
        for (int k = 0; k < f.nsh[side] && f.sh[side]; k++)
            free(f.sh[side][k].tau), free(f.sh[side][k].theta);
        free(f.sh[side]);
    }
    plume_sampled_curve_free(&f.c);
    plume_bins_free(&f.pg);
    plume_bins_free(&f.sg);
    plume_pslg_free(&f.g);
    free(f.o);
    free(f.outline_used);
    free(f.s);
    free(f.stamp);
    free(f.anc);
    free(f.barb_seg);
    return st;
}
