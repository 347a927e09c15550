/* plume: validation of the feather mesher's input (macro/feather/internal/feather_mesher.h): each curve
 * well formed (enough points, finite, no coincident neighbours, not self-intersecting), the edge
 * and widths, and no point or outline vertex so far from the rest that meshing would crawl (found
 * by fuzzing). The mesher's design is the comment at the top of macro/feather/feather_mesh.c. */
#include <stdio.h>
#include <stdlib.h>

#include "internal/feather_mesher.h"

typedef struct {
    double xmin, xmax;
    plume_index i;
} sweep_item;

static int cmp_sweep(const void *a, const void *b)
{
    double x = ((const sweep_item *)a)->xmin, y = ((const sweep_item *)b)->xmin;
    return (x > y) - (x < y);
}

/* One input curve: at least min_points points, finite, no coincident neighbours, not
 * self-intersecting (sweep over x); `closed` for the outline. PLUME_EINVAL with a message naming
 * `name` and the points, or PLUME_ENOMEM. */
static plume_status check_curve(const char *name, const plume_polyline *c, int closed, plume_index min_points,
                                plume_err *err)
{
    if (c->n < min_points || !c->p)
        return plume_err_set(err, PLUME_EINVAL, "%s: %ld point(s): at least %ld are needed", name, (long)c->n,
                             (long)min_points);
    const double *p = c->p;
    plume_index n = c->n;
    for (plume_index i = 0; i < n; i++)
        if (!isfinite(p[2 * i]) || !isfinite(p[2 * i + 1]))
            return plume_err_set(err, PLUME_EINVAL, "%s: point %ld (%g, %g) is not finite", name, (long)i,
                                 p[2 * i], p[2 * i + 1]);
    plume_index ns = closed ? n : n - 1;
    double lo[2] = {p[0], p[1]}, hi[2] = {p[0], p[1]};
    for (plume_index i = 0; i < n; i++)
        for (int k = 0; k < 2; k++)
            lo[k] = fmin(lo[k], p[2 * i + k]), hi[k] = fmax(hi[k], p[2 * i + k]);
    double tiny = 1e-12 * norm2(hi[0] - lo[0], hi[1] - lo[1]); /* keeps spline parameters increasing */
    for (plume_index i = 0; i < ns; i++) {
        plume_index j = (i + 1) % n;
        if (!(norm2(p[2 * j] - p[2 * i], p[2 * j + 1] - p[2 * i + 1]) > tiny))
            return plume_err_set(err, PLUME_EINVAL, "%s: points %ld and %ld coincide at (%g, %g)", name, (long)i,
                                 (long)j, p[2 * i], p[2 * i + 1]);
    }
    /* adjacent segments only meet at their shared point unless the curve turns back on itself */
    for (plume_index i = closed ? 0 : 1; i < (closed ? n : n - 1); i++) {
        const double *a = p + 2 * ((i + n - 1) % n), *b = p + 2 * i, *d = p + 2 * ((i + 1) % n);
        if (orient(a, b, d) == 0 && (a[0] - b[0]) * (d[0] - b[0]) + (a[1] - b[1]) * (d[1] - b[1]) > 0)
            return plume_err_set(err, PLUME_EINVAL,
                                 "%s: self-intersecting: the curve turns back on itself at point %ld", name, (long)i);
    }
    sweep_item *it = malloc((size_t)ns * sizeof *it);
    if (!it)
        return PLUME_ENOMEM;
    for (plume_index i = 0; i < ns; i++) {
        const double *a = p + 2 * i, *b = p + 2 * ((i + 1) % n);
        it[i].xmin = fmin(a[0], b[0]), it[i].xmax = fmax(a[0], b[0]), it[i].i = i;
    }
    qsort(it, (size_t)ns, sizeof *it, cmp_sweep);
    plume_status st = PLUME_OK;
    for (plume_index k = 0; k < ns && st == PLUME_OK; k++)
        for (plume_index l = k + 1; l < ns && it[l].xmin <= it[k].xmax; l++) {
            plume_index i = it[k].i, j = it[l].i;
            plume_index lo = i < j ? i : j, hi = i < j ? j : i;
            if (hi - lo == 1 || (closed && lo == 0 && hi == n - 1))
                continue; /* neighbours: handled above */
            const double *a = p + 2 * i, *b = p + 2 * ((i + 1) % n), *cc = p + 2 * j, *d = p + 2 * ((j + 1) % n);
            if (segs_touch(a, b, cc, d)) {
                st = plume_err_set(err, PLUME_EINVAL,
                                   "%s: self-intersecting: segment %ld (points %ld-%ld) meets segment %ld (points "
                                   "%ld-%ld)",
                                   name, (long)lo, (long)lo, (long)((lo + 1) % n), (long)hi, (long)hi,
                                   (long)((hi + 1) % n));
                break;
            }
        }
    free(it);
    return st;
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

plume_status plume_fm_validate(const plume_feather_input *in, int dim, plume_err *err)
{
    plume_status st;
    if (dim != 2 && dim != 3)
        return plume_err_set(err, PLUME_EINVAL, "dim = %d must be 2 or 3", dim);
    if (!(in->edge > 0) || !isfinite(in->edge))
        return plume_err_set(err, PLUME_EINVAL, "edge = %g m must be finite and > 0", in->edge);
    if ((st = check_curve("outline", &in->outline, 1, 3, err)) != PLUME_OK)
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
    if ((st = check_curve("rachis", &in->rachis, 0, 2, err)) != PLUME_OK ||
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
            if ((st = check_curve(name, bs + k, 0, 2, err)) != PLUME_OK ||
                (st = fm_check_near(name, bs + k, bb, diag, err)) != PLUME_OK)
                return st;
            if (!point_in_polygon(in->outline.p, in->outline.n, bs[k].p))
                return plume_err_set(err, PLUME_EINVAL, "%s: point 0 (%g, %g), its start, lies outside the outline",
                                     name, bs[k].p[0], bs[k].p[1]);
        }
    }
    return fm_check_outline_near_skeleton(in, err);
}
