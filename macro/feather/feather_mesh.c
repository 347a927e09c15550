/* plume: the feather mesher of supplementary §6 (contract in macro/feather/feather_mesh.h): its design (this
 * comment) and its driver, a phase function per step (at the end of this file). Its jobs live
 * beside it and share the state and tolerances of macro/feather/internal/feather_mesher.h: vertices,
 * segments and proximity queries (feather_segments.c), the centre line (feather_centre.c), barb
 * shapes, the barb walk and the strip side ends (feather_barbs.c), corner-exact stations
 * (feather_stations.c), input validation (feather_check.c); small 2D geometry
 * (internal/feather_geom.h), the spatial grid (bins.c), sampled curves and splines
 * (sampled_curve.c). The OBJ outline reader is obj_outline.c.
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
 *    side stops being GAP_POINT e inside the outline (plume_fm_run_extent). Corners closer than
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
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/cdt.h"
#include "../shell/vane.h"
#include "internal/feather_mesher.h"

/* ------------------------------------------------------------------ driver */

/* The rachis strip (step 2): the stations of each side and its vertices, which the barb phases
 * root their barbs on. Only the driver's phases use it, so it lives here, not in feather_mesher.h. */
typedef struct {
    long N, kv;                 /* N + 1 stations k ds span the centre line inside the outline; kv
                                   virtual ones continue it past each end (step 4a) */
    double ds;
    double *sta[2];             /* [nsta] stations (arc length along the centre line) of each side */
    long nsta[2], ra[2], rb[2]; /* [ra, rb]: those rooted on the strip */
    plume_index *side_ids[2];   /* [rb - ra + 3] vertices of each side: its end on the outline at
                                   the base, those of stations ra..rb, its end at the tip */
} fm_strip;

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

/* The outline, counter-clockwise; its vertices become output vertices 0..no-1. Its bounding box,
 * diagonal and arc lengths. */
static plume_status fm_setup_outline(fm *f)
{
    const plume_feather_input *in = f->in;
    f->no = in->outline.n;
    f->o = malloc((size_t)(2 * f->no) * sizeof *f->o);
    f->outline_used = calloc((size_t)f->no, 1);
    if (!f->o || !f->outline_used)
        return PLUME_ENOMEM;
    int reversed = polygon_area(in->outline.p, f->no) < 0;
    for (plume_index i = 0; i < f->no; i++) {
        plume_index j = reversed ? f->no - 1 - i : i;
        f->o[2 * i] = in->outline.p[2 * j], f->o[2 * i + 1] = in->outline.p[2 * j + 1];
    }
    f->bb[0] = f->bb[2] = f->o[0], f->bb[1] = f->bb[3] = f->o[1];
    for (plume_index i = 0; i < f->no; i++) {
        f->bb[0] = fmin(f->bb[0], f->o[2 * i]), f->bb[2] = fmax(f->bb[2], f->o[2 * i]);
        f->bb[1] = fmin(f->bb[1], f->o[2 * i + 1]), f->bb[3] = fmax(f->bb[3], f->o[2 * i + 1]);
    }
    f->diag = norm2(f->bb[2] - f->bb[0], f->bb[3] - f->bb[1]);
    if (!(f->ocum = malloc((size_t)(f->no + 1) * sizeof *f->ocum)))
        return PLUME_ENOMEM;
    f->ocum[0] = 0;
    for (plume_index i = 0; i < f->no; i++) {
        const double *a = f->o + 2 * i, *b = f->o + 2 * ((i + 1) % f->no);
        f->ocum[i + 1] = f->ocum[i] + norm2(b[0] - a[0], b[1] - a[1]);
    }
    f->per = f->ocum[f->no];
    for (plume_index i = 0; i < f->no; i++)
        if (plume_pslg_point(&f->g, f->o[2 * i], f->o[2 * i + 1]) < 0)
            return PLUME_ENOMEM;
    return PLUME_OK;
}

/* The point and segment grids over the outline's box with a margin, and the outline's edges in the
 * segment grid. */
static plume_status fm_setup_grids(fm *f)
{
    const plume_feather_input *in = f->in;
    const double e = f->e;
    double margin = fmax(in->rachis_width_base, in->rachis_width_tip) + 4 * e;
    double cell = e, w = f->bb[2] - f->bb[0] + 2 * margin, hgt = f->bb[3] - f->bb[1] + 2 * margin;
    if (w * hgt / (cell * cell) > 4e6)
        cell = sqrt(w * hgt / 4e6);
    if (plume_bins_init(&f->pg, f->bb[0] - margin, f->bb[1] - margin, f->bb[2] + margin, f->bb[3] + margin, cell) < 0 ||
        plume_bins_init(&f->sg, f->bb[0] - margin, f->bb[1] - margin, f->bb[2] + margin, f->bb[3] + margin, cell) < 0)
        return PLUME_ENOMEM;
    /* outline edges in pieces no longer than a cell, so the grid stays local */
    for (plume_index i = 0; i < f->no; i++) {
        const double *a = f->o + 2 * i, *b = f->o + 2 * ((i + 1) % f->no);
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
            if (plume_fm_add_seg(f, pa, pb, -1, -1, SEG_OUTLINE, 0, i, t0, t1) < 0)
                return PLUME_ENOMEM;
        }
    }
    return PLUME_OK;
}

/* The station k ds nearest the middle whose side points both lie GAP_POINT e inside the outline. */
static plume_status fm_strip_middle(const fm *f, const fm_strip *r, long *kmid_out)
{
    const plume_feather_input *in = f->in;
    const double e = f->e;
    long kmid = -1;
    for (long d = 0; d <= r->N && kmid < 0; d++)
        for (int sg = -1; sg <= 1 && kmid < 0; sg += 2) {
            long k = r->N / 2 + sg * d;
            if (k < 0 || k > r->N)
                continue;
            int ok = 1;
            for (int sigma = -1; sigma <= 1; sigma += 2) {
                double p[2];
                plume_fm_offset(f, (double)k * r->ds, sigma, p);
                ok = ok && point_in_polygon(f->o, f->no, p) &&
                     !plume_fm_near_segment(f, p, GAP_POINT * e, 1u << SEG_OUTLINE, -1);
            }
            if (ok)
                kmid = k;
        }
    if (kmid < 0)
        return plume_err_set(f->err, PLUME_EINVAL,
                             "rachis: no station where the strip (width %g to %g m) fits %g m inside the outline; "
                             "edge = %g m is too coarse or the rachis runs along the outline",
                             in->rachis_width_base, in->rachis_width_tip, GAP_POINT * e, e);
    *kmid_out = kmid;
    return PLUME_OK;
}

/* Each side's run of stations k ds from kmid outward while its side points stay GAP_POINT e inside
 * the outline: run[side] = {first, last} k. */
static void fm_strip_runs(const fm *f, const fm_strip *r, long kmid, long run[2][2])
{
    for (int side = 0; side < 2; side++) {
        int sigma = side == 0 ? 1 : -1;
        for (int dir = -1; dir <= 1; dir += 2) {
            long k = kmid;
            double p[2], q[2];
            plume_fm_offset(f, (double)k * r->ds, sigma, p);
            while (k + dir >= 0 && k + dir <= r->N) {
                double t, u;
                plume_index edge;
                plume_fm_offset(f, (double)(k + dir) * r->ds, sigma, q);
                if (plume_fm_outline_cross(f, p, q, &t, &edge, &u) ||
                    plume_fm_near_segment(f, q, GAP_POINT * f->e, 1u << SEG_OUTLINE, -1))
                    break;
                k += dir;
                p[0] = q[0], p[1] = q[1];
            }
            run[side][dir < 0 ? 0 : 1] = k;
        }
    }
}

/* The strip's sides: a vertex at each rooted station (left side first), then each side closed on
 * the outline at both ends and its edges constrained. */
static plume_status fm_strip_sides(fm *f, fm_strip *r)
{
    plume_status st;
    for (int side = 0; side < 2; side++) {
        int sigma = side == 0 ? 1 : -1;
        long a = r->ra[side], b = r->rb[side];
        if (!(r->side_ids[side] = malloc((size_t)(b - a + 3) * sizeof(plume_index))))
            return PLUME_ENOMEM;
        for (long k = a; k <= b; k++) {
            double p[2];
            plume_fm_offset(f, r->sta[side][k], sigma, p);
            if ((r->side_ids[side][k - a + 1] = plume_fm_add_vertex(f, p)) < 0)
                return PLUME_ENOMEM;
        }
    }
    for (int side = 0; side < 2; side++) {
        int sigma = side == 0 ? 1 : -1;
        long a = r->ra[side], b = r->rb[side];
        plume_index *ids = r->side_ids[side];
        if ((st = plume_fm_side_end(f, sigma, r->sta[side][a], -1, ids[1], &ids[0])) != PLUME_OK ||
            (st = plume_fm_side_end(f, sigma, r->sta[side][b], 1, ids[b - a + 1], &ids[b - a + 2])) != PLUME_OK)
            return st;
        for (long k = 0; k < b - a + 2; k++)
            if (plume_fm_add_constraint(f, ids[k], ids[k + 1], SEG_SIDE, sigma, side) < 0)
                return PLUME_ENOMEM;
    }
    return PLUME_OK;
}

/* Step 2, the rachis strip: stations ds apart, each side's run from the middle outward, the
 * stations of each side (corner-exact or every ds), the side vertices and their ends. */
static plume_status fm_build_strip(fm *f, fm_strip *r)
{
    plume_status st;
    r->N = lround(f->L / f->e);
    if (r->N < 1)
        r->N = 1;
    r->ds = f->L / (double)r->N;
    r->kv = (long)ceil((f->diag + f->max_barb_len) / r->ds) + 1;
    long kmid = -1, run[2][2]; /* [side][first, last] station k (of k ds) */
    if ((st = fm_strip_middle(f, r, &kmid)) != PLUME_OK)
        return st;
    fm_strip_runs(f, r, kmid, run);
    /* the stations of each side, corner-exact; those of the run root barbs on the strip */
    for (int side = 0; side < 2; side++) {
        int sigma = side == 0 ? 1 : -1;
        double s0 = (double)run[side][0] * r->ds, s1 = (double)run[side][1] * r->ds;
        double ext[2] = {plume_fm_run_extent(f, sigma, s0, r->ds, -1), plume_fm_run_extent(f, sigma, s1, r->ds, 1)};
        if ((st = plume_fm_stations(f, side, r->ds, -r->kv, r->N + r->kv, s0, s1, ext, &r->sta[side], &r->nsta[side],
                                    &r->ra[side], &r->rb[side])) != PLUME_OK)
            return st;
    }
    return fm_strip_sides(f, r);
}

/* Steps 3 and 4a, the barbs: on each side rachis-rooted first (base to tip), then from the strip
 * ends on the outline, then the family continued past the strip's base and tip ends. */
static plume_status fm_walk_barbs(fm *f, const fm_strip *r)
{
    plume_status st;
    plume_index tag = 0;
    for (int side = 0; side < 2; side++) {
        int sigma = side == 0 ? 1 : -1;
        long a = r->ra[side], b = r->rb[side];
        for (int pass = 0; pass < 4; pass++) {
            if (pass == 1) { /* from the strip ends on the outline */
                plume_index ends[2] = {r->side_ids[side][0], r->side_ids[side][b - a + 2]};
                for (int k = 0; k < 2; k++) {
                    blend bl;
                    double s, d, p[2] = {f->g.p[2 * ends[k]], f->g.p[2 * ends[k] + 1]};
                    plume_fm_project(f, p, &s, &d);
                    plume_fm_blend(f, side, s, &bl);
                    if ((st = plume_fm_walk(f, side, p, ends[k], 1, 0, &bl, tag++)) != PLUME_OK)
                        return st;
                }
                continue;
            }
            long k0 = pass == 0 ? a : pass == 2 ? a - 1 : b + 1;
            long k1 = pass == 0 ? b : pass == 2 ? 0 : r->nsta[side] - 1;
            long step = pass == 2 ? -1 : 1;
            for (long k = k0; step > 0 ? k <= k1 : k >= k1; k += step) {
                blend bl;
                double s = r->sta[side][k], p[2];
                plume_fm_blend(f, side, s, &bl);
                plume_fm_offset(f, s, sigma, p);
                plume_index root = pass == 0 ? r->side_ids[side][k - a + 1] : -1;
                if ((st = plume_fm_walk(f, side, p, root, 0, 0, &bl, tag++)) != PLUME_OK)
                    return st;
            }
        }
    }
    return PLUME_OK;
}

/* Step 4b: fill barbs from fractional stations where neighbouring barbs diverge (none on most
 * feathers); a level with none stops the refinement. */
static plume_status fm_fill_barbs(fm *f, const fm_strip *r)
{
    plume_status st;
    for (int level = 1; level <= FILL_LEVELS; level++) {
        plume_index before = f->g.n, tag = -level;
        long parts = 1L << level;
        for (int side = 0; side < 2; side++) {
            int sigma = side == 0 ? 1 : -1;
            const double *sta = r->sta[side];
            for (long k = r->ra[side]; k < r->rb[side]; k++)
                for (long j = 1; j < parts; j += 2) {
                    blend bl;
                    double s = f->in->corner_exact
                                   ? sta[k] + (sta[k + 1] - sta[k]) * (double)j / (double)parts
                                   : ((double)(k - r->kv) + (double)j / (double)parts) * r->ds; /* as before */
                    double p[2];
                    plume_fm_blend(f, side, s, &bl);
                    plume_fm_offset(f, s, sigma, p);
                    if ((st = plume_fm_walk(f, side, p, -1, 0, 1, &bl, tag)) != PLUME_OK)
                        return st;
                }
        }
        if (f->g.n == before)
            break;
    }
    return PLUME_OK;
}

/* Step 5, the outline closed: its vertices, the anchors on its edges, and points so that no gap
 * exceeds e, or OUTLINE_GAP e between two points that each end a barb or a strip side. */
static plume_status fm_close_outline(fm *f)
{
    const double e = f->e;
    plume_status st = PLUME_ENOMEM;
    qsort(f->anc, (size_t)f->nanc, sizeof *f->anc, cmp_anchor);
    unsigned char *ends = calloc((size_t)f->g.n + 1, 1); /* [g.n] point ends a barb or side */
    if (!ends)
        return PLUME_ENOMEM;
    for (plume_index k = 0; k < 2 * f->g.ns; k++) /* only barb and side segments so far */
        ends[f->g.s[k]] = 1;
    plume_index first = -1, prev = -1, ka = 0;
    for (plume_index i = 0; i < f->no; i++) {
        const double *a = f->o + 2 * i, *b = f->o + 2 * ((i + 1) % f->no);
        double tprev = 0;
        plume_index vprev = i;
        if (first < 0)
            first = i;
        if (prev >= 0 && plume_pslg_segment(&f->g, prev, i) < 0)
            goto cleanup;
        prev = i;
        for (;;) {
            int has = ka < f->nanc && f->anc[ka].edge == i;
            double tnext = has ? f->anc[ka].t : 1.0;
            plume_index vnext = has ? f->anc[ka].id : (i + 1) % f->no;
            const double *pp = f->g.p + 2 * vprev, *pn = f->g.p + 2 * vnext;
            double gap = norm2(pn[0] - pp[0], pn[1] - pp[1]);
            double limit = f->in->corner_exact && ends[vprev] && ends[vnext] ? OUTLINE_GAP * e : e;
            long pieces = gap > limit ? (long)ceil(gap / e - 1e-9) : 1;
            for (long j = 1; j < pieces; j++) {
                double t = tprev + (tnext - tprev) * (double)j / (double)pieces;
                plume_index id = plume_pslg_point(&f->g, a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
                if (id < 0 || plume_pslg_segment(&f->g, prev, id) < 0)
                    goto cleanup;
                prev = id;
            }
            if (!has)
                break;
            if (plume_pslg_segment(&f->g, prev, vnext) < 0)
                goto cleanup;
            prev = vnext, vprev = vnext, tprev = tnext;
            ka++;
        }
    }
    if (plume_pslg_segment(&f->g, prev, first) < 0)
        goto cleanup;
    st = PLUME_OK;
cleanup:
    free(ends);
    return st;
}

/* Step 5, the constrained Delaunay triangulation of the vertices and segments, without refinement,
 * as a mesh of dimension dim with its topology. */
static plume_status fm_triangulate(const fm *f, int dim, plume_mesh **out)
{
    plume_cdt_input ci = {0};
    plume_cdt_output cdt = {0};
    plume_mesh *m = NULL;
    ci.npoints = f->g.n, ci.points = f->g.p, ci.nsegments = f->g.ns, ci.segments = f->g.s;
    ci.remove_exterior = 1, ci.max_edge = 0;
    plume_status st = plume_cdt_triangulate(&ci, &cdt, f->err);
    if (st == PLUME_OK && (st = plume_mesh_create(cdt.npoints, cdt.ntriangles, dim, &m, f->err)) == PLUME_OK) {
        memcpy(m->X, cdt.points, (size_t)(2 * cdt.npoints) * sizeof *m->X);
        memcpy(m->tri, cdt.triangles, (size_t)(3 * cdt.ntriangles) * sizeof *m->tri);
        plume_mesh_reset_current(m);
        st = plume_mesh_build_topology(m, f->err);
    }
    plume_cdt_output_free(&cdt);
    if (st != PLUME_OK)
        plume_mesh_destroy(&m);
    *out = m;
    return st;
}

/* The barb segments as directed keys sorted for the triangle lookup (*keys, f->nbarb_seg of them),
 * and those present as mesh edges (*be, *nbe of them: all, as there is no refinement). Both arrays
 * are the caller's, also on failure. */
static plume_status fm_barb_edges(const fm *f, const plume_mesh *m, edge_key **keys_out, plume_index **be_out,
                                  plume_index *nbe_out)
{
    edge_key *keys = *keys_out = malloc((size_t)(f->nbarb_seg + 1) * sizeof *keys);
    plume_index *be = *be_out = malloc((size_t)(2 * f->nbarb_seg + 1) * sizeof *be);
    if (!keys || !be)
        return PLUME_ENOMEM;
    plume_index nbe = 0;
    for (plume_index k = 0; k < f->nbarb_seg; k++) {
        plume_index i = f->g.s[2 * f->barb_seg[k]], j = f->g.s[2 * f->barb_seg[k] + 1];
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
    qsort(keys, (size_t)f->nbarb_seg, sizeof *keys, cmp_edge_key);
    *nbe_out = nbe;
    return PLUME_OK;
}

/* The direction of a vane triangle (centroid c, at s and signed distance d from the centre line)
 * that owns no barb edge, added to sum (zero on entry): the inverse-distance average of the barb
 * edges of its side nearby, else the blended shape's. */
static void fm_idw_direction(fm *f, const double c[2], double s, double d, double sum[2])
{
    const double e = f->e;
    int sigma = d > 0 ? 1 : -1;
    for (double r = IDW_RADIUS * e; sum[0] == 0 && sum[1] == 0 && r < 8 * f->diag; r *= 2) {
        f->qid++;
        FOR_CELLS(&f->sg, c[0] - r, c[1] - r, c[0] + r, c[1] + r, nd)
        {
            plume_index k = f->sg.item[nd];
            const fseg *sg = f->s + k;
            if (sg->kind != SEG_BARB || sg->side != sigma || f->stamp[k] == f->qid)
                continue;
            f->stamp[k] = f->qid;
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
        plume_fm_blend(f, sigma > 0 ? 0 : 1, s, &bl);
        double a = plume_fm_blend_angle(&bl, fabs(d));
        sum[0] = cos(a), sum[1] = sin(a);
    }
}

/* Step 6: each triangle's material (rachis within half the width of the centre line, else vane)
 * and barb direction (the rachis tangent; a vane triangle's barb edges, oriented away from the
 * rachis, else fm_idw_direction). */
static void fm_barb_directions(fm *f, plume_mesh *m, const edge_key *keys)
{
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        double c[2] = {0, 0};
        for (int k = 0; k < 3; k++)
            c[0] += m->X[2 * v[k]] / 3, c[1] += m->X[2 * v[k] + 1] / 3;
        double s, d, cp[2], phi;
        plume_fm_project(f, c, &s, &d);
        plume_fm_centre(f, s, cp, &phi);
        double *bd = m->barb_dir + 2 * t;
        if (fabs(d) <= 0.5 * plume_fm_width(f, s)) {
            m->material[t] = PLUME_FEATHER_RACHIS;
            bd[0] = cos(phi), bd[1] = sin(phi);
            continue;
        }
        m->material[t] = PLUME_FEATHER_VANE;
        double sum[2] = {0, 0};
        for (int k = 0; k < 3; k++) {
            plume_index i = v[k], j = v[(k + 1) % 3];
            edge_key q = {i < j ? i : j, i < j ? j : i, 0};
            const edge_key *hit = bsearch(&q, keys, (size_t)f->nbarb_seg, sizeof *keys, cmp_edge_key);
            if (!hit)
                continue;
            plume_index from = hit->sign > 0 ? hit->a : hit->b, to = hit->sign > 0 ? hit->b : hit->a;
            double dx = m->X[2 * to] - m->X[2 * from], dy = m->X[2 * to + 1] - m->X[2 * from + 1], l = norm2(dx, dy);
            sum[0] += dx / l, sum[1] += dy / l;
        }
        if (sum[0] == 0 && sum[1] == 0)
            fm_idw_direction(f, c, s, d, sum);
        double l = norm2(sum[0], sum[1]);
        bd[0] = sum[0] / l, bd[1] = sum[1] / l;
    }
}

/* The stats of plume_feather_mesh_with_stats: barb coverage, why each other vane triangle has no
 * barb edge, the triangles of each material and their smallest angles. */
static plume_status fm_stats(const plume_mesh *m, const plume_index *be, plume_index nbe, plume_feather_stats *stats,
                             plume_err *err)
{
    plume_status st;
    plume_index nu = 0;
    unsigned char *why = NULL;
    memset(stats, 0, sizeof *stats);
    if ((st = plume_vane_barb_coverage(m, be, nbe, PLUME_FEATHER_VANE, &stats->vane_covered, &stats->vane_triangles,
                                       NULL, err)) != PLUME_OK ||
        (st = plume_feather_uncovered(m, be, nbe, NULL, &why, &nu, err)) != PLUME_OK)
        return st;
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
    return PLUME_OK;
}

static void fm_free(fm *f)
{
    free(f->ocum);
    for (int side = 0; side < 2; side++) {
        for (int k = 0; k < f->nsh[side] && f->sh[side]; k++)
            free(f->sh[side][k].tau), free(f->sh[side][k].theta);
        free(f->sh[side]);
    }
    plume_sampled_curve_free(&f->c);
    plume_bins_free(&f->pg);
    plume_bins_free(&f->sg);
    plume_pslg_free(&f->g);
    free(f->o);
    free(f->outline_used);
    free(f->s);
    free(f->stamp);
    free(f->anc);
    free(f->barb_seg);
}

plume_status plume_feather_mesh(const plume_feather_input *in, int dim, plume_mesh **out, plume_index **barb_edges,
                                plume_index *nbarb, plume_err *err)
{
    return plume_feather_mesh_with_stats(in, dim, out, barb_edges, nbarb, NULL, err);
}

/* The steps of the design comment above, one phase each. */
plume_status plume_feather_mesh_with_stats(const plume_feather_input *in, int dim, plume_mesh **out,
                                           plume_index **barb_edges, plume_index *nbarb, plume_feather_stats *stats,
                                           plume_err *err)
{
    if (!in || !out || !barb_edges || !nbarb)
        return plume_err_set(err, PLUME_EINVAL, "feather mesh: NULL argument");
    *out = NULL, *barb_edges = NULL, *nbarb = 0;
    plume_status st = plume_fm_validate(in, dim, err);
    if (st != PLUME_OK)
        return st;

    fm f;
    memset(&f, 0, sizeof f);
    f.in = in, f.err = err, f.e = in->edge;
    fm_strip strip;
    memset(&strip, 0, sizeof strip);
    plume_mesh *m = NULL;
    edge_key *keys = NULL;
    plume_index *be = NULL, nbe = 0;
    if ((st = fm_setup_outline(&f)) != PLUME_OK || (st = fm_setup_grids(&f)) != PLUME_OK ||
        (st = plume_fm_build_centre(&f)) != PLUME_OK || (st = plume_fm_build_shapes(&f)) != PLUME_OK ||
        (st = fm_build_strip(&f, &strip)) != PLUME_OK || (st = fm_walk_barbs(&f, &strip)) != PLUME_OK ||
        (st = fm_fill_barbs(&f, &strip)) != PLUME_OK || (st = fm_close_outline(&f)) != PLUME_OK ||
        (st = fm_triangulate(&f, dim, &m)) != PLUME_OK || (st = fm_barb_edges(&f, m, &keys, &be, &nbe)) != PLUME_OK)
        goto cleanup;
    fm_barb_directions(&f, m, keys);
    if (stats && (st = fm_stats(m, be, nbe, stats, err)) != PLUME_OK)
        goto cleanup;
    *out = m, m = NULL;
    *barb_edges = be, be = NULL;
    *nbarb = nbe;
cleanup:
    plume_mesh_destroy(&m);
    free(keys);
    free(be);
    for (int side = 0; side < 2; side++)
        free(strip.side_ids[side]), free(strip.sta[side]);
    fm_free(&f);
    return st;
}
