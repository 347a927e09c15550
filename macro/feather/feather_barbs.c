/* plume: the feather mesher's barbs (macro/feather/internal/feather_mesher.h): the input barbs as angle
 * shapes relative to the rachis, their blend at a station, the walk that meshes one barb from its
 * root to the outline or a collision, and the walk along a strip side that closes it on the outline
 * (steps 2, 3 and 4 of the design comment at the top of macro/feather/feather_mesh.c). */
#include <math.h>
#include <stdlib.h>

#include "internal/feather_mesher.h"

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

plume_status plume_fm_build_shapes(fm *f)
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
            plume_fm_project(f, p0, &sh->s_root, &d);
            plume_fm_centre(f, sh->s_root, cp, &phi);
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


void plume_fm_blend(const fm *f, int side, double s, blend *bl)
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
    plume_fm_centre(f, s, p, &bl->phi);
}

double plume_fm_blend_angle(const blend *bl, double tau)
{
    return bl->phi + (1 - bl->w) * shape_theta(bl->a, tau) + bl->w * shape_theta(bl->b, tau);
}

/* ------------------------------------------------------------------ barb walk */

/* Past every input barb's end a barb curve is straight (direction a): jump from p to a sub-step h
 * before the outline, advancing tau by the jump and q to the next sub-step. 0 when the ray misses
 * the outline (the barb never enters the vane). */
int plume_fm_jump_to_outline(const fm *f, double a, double h, double p[2], double q[2], double *tau)
{
    double hit[2];
    if (!plume_fm_ray_hit(f, p, a, hit))
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

/* Where a barb walk is: the start p of its next sub-step, whether it is inside the vane, the last
 * vertex it placed (-1 none) and where, the sub-steps since that vertex (or the entry); done when
 * the walk has ended. */
typedef struct {
    double p[2];
    int inside;
    plume_index last;
    double lastp[2];
    long since;
    int done;
} barb_walk;

/* Outside the vane, the sub-step p -> q crossing the outline: the barb enters, with a vertex on the
 * outline where there is room for one; entering through the strip end or the other side ends the
 * walk. */
static plume_status enter_vane(fm *f, int sigma, barb_walk *w, const double q[2])
{
    const double e = f->e;
    const double *p = w->p;
    double t, u;
    plume_index edge;
    if (!plume_fm_outline_cross(f, p, q, &t, &edge, &u))
        return PLUME_OK;
    w->inside = 1;
    double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])}, s, d;
    plume_fm_project(f, x, &s, &d);
    plume_index snap = plume_fm_snap_target(f, edge, u, SNAP_OUTLINE * e);
    const double *xp = snap >= 0 ? f->o + 2 * snap : x;
    w->last = -1;
    if (sigma * d >= 0.5 * plume_fm_width(f, s) && !(snap >= 0 && f->outline_used[snap]) &&
        !plume_fm_near_vertex(f, xp, xp, GAP_POINT * e, -1) &&
        !plume_fm_near_segment(f, xp, GAP_SEGMENT * e, 1u << SEG_SIDE | 1u << SEG_BARB, -1)) {
        if ((w->last = plume_fm_outline_vertex(f, edge, u, SNAP_OUTLINE * e)) < 0)
            return PLUME_ENOMEM;
        w->lastp[0] = f->g.p[2 * w->last], w->lastp[1] = f->g.p[2 * w->last + 1];
    } else if (sigma * d < 0.5 * plume_fm_width(f, s)) {
        w->done = 1; /* entering through the strip end or the other side */
        return PLUME_OK;
    }
    w->since = 0;
    return PLUME_OK;
}

/* The barb leaves the feather at the fraction t of the sub-step p -> q, across outline edge `edge`
 * at u: its last edge ends on the outline, when that edge is short enough and has room. Ends the
 * walk. */
static plume_status leave_vane(fm *f, int sigma, plume_index tag, barb_walk *w, const double q[2], double t,
                               plume_index edge, double u)
{
    const double e = f->e, h = e / SUBSTEPS;
    const double *p = w->p;
    w->done = 1;
    if (w->last < 0 || ((double)w->since + t) * h > LAST_ARC * e)
        return PLUME_OK;
    double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
    plume_index snap = plume_fm_snap_target(f, edge, u, SNAP_OUTLINE * e);
    const double *xp = snap >= 0 ? f->o + 2 * snap : x;
    if (norm2(xp[0] - w->lastp[0], xp[1] - w->lastp[1]) < GAP_POINT * e ||
        (snap >= 0 && f->outline_used[snap]) || plume_fm_near_vertex(f, xp, xp, GAP_POINT * e, w->last) ||
        plume_fm_near_vertex(f, w->lastp, xp, GAP_SEGMENT * e, w->last) ||
        plume_fm_blocked(f, w->lastp, xp, 0, w->last))
        return PLUME_OK;
    plume_index id = plume_fm_outline_vertex(f, edge, u, SNAP_OUTLINE * e);
    if (id < 0 || plume_fm_add_constraint(f, w->last, id, SEG_BARB, sigma, tag) < 0)
        return PLUME_ENOMEM;
    return PLUME_OK;
}

/* A fill barb starts (its first vertex at p) where the gap between its neighbours opens to
 * 2 FILL_CLEAR e. */
static plume_status start_fill_barb(fm *f, barb_walk *w)
{
    const double e = f->e;
    const double *p = w->p;
    if (!plume_fm_near_segment(f, p, GAP_POINT * e, 1u << SEG_OUTLINE, -1) &&
        !plume_fm_near_vertex(f, p, p, FILL_CLEAR * e, -1) &&
        !plume_fm_near_segment(f, p, FILL_CLEAR * e, 1u << SEG_SIDE | 1u << SEG_BARB, -1)) {
        if ((w->last = plume_fm_add_vertex(f, p)) < 0)
            return PLUME_ENOMEM;
        w->lastp[0] = p[0], w->lastp[1] = p[1];
        w->since = 0;
    }
    return PLUME_OK;
}

/* A barb vertex at p, SUBSTEPS or more sub-steps after the last one, with its edge from it; dropped
 * near the outline (the walk goes on to the outline, or ends when the arc since the last vertex is
 * too long), and the walk ends where the barb would come too close to another. */
static plume_status place_barb_vertex(fm *f, int sigma, plume_index tag, barb_walk *w)
{
    const double e = f->e, h = e / SUBSTEPS;
    const double *p = w->p;
    if (plume_fm_near_segment(f, p, GAP_POINT * e, 1u << SEG_OUTLINE, -1)) {
        if ((double)w->since * h > LAST_ARC * e)
            w->done = 1; /* grazing the outline: end here */
        return PLUME_OK; /* else dropped: go on to the outline */
    }
    if (((double)w->since * h > LAST_ARC * e && w->last >= 0) ||
        plume_fm_near_vertex(f, p, p, GAP_POINT * e, w->last) ||
        plume_fm_near_segment(f, p, GAP_SEGMENT * e, 1u << SEG_SIDE | 1u << SEG_BARB, w->last) ||
        (w->last >= 0 && (plume_fm_near_vertex(f, w->lastp, p, GAP_SEGMENT * e, w->last) ||
                          plume_fm_blocked(f, w->lastp, p, 0, w->last)))) {
        w->done = 1; /* too long an arc since the last vertex, or converging on another barb: cut */
        return PLUME_OK;
    }
    plume_index id = plume_fm_add_vertex(f, p);
    if (id < 0 || (w->last >= 0 && plume_fm_add_constraint(f, w->last, id, SEG_BARB, sigma, tag) < 0))
        return PLUME_ENOMEM;
    w->last = id;
    w->lastp[0] = p[0], w->lastp[1] = p[1];
    w->since = 0;
    return PLUME_OK;
}

/* Walks the barb of a station from `root` (a vertex id, or -1 when the start is not a vertex),
 * adding vertices and constrained barb edges until the outline or a collision. */
plume_status plume_fm_walk(fm *f, int side, const double *start, plume_index root, int root_on_outline, int fill,
                           const blend *bl, plume_index tag)
{
    const double e = f->e, h = e / SUBSTEPS;
    const int sigma = side == 0 ? 1 : -1;
    barb_walk w = {.p = {start[0], start[1]}, .last = root, .lastp = {start[0], start[1]}};
    w.inside = root >= 0 || point_in_polygon(f->o, f->no, w.p);
    double tau_max = f->max_barb_len + 3 * f->diag + 2 * e;
    int jumped = 0;
    plume_status st;
    for (double tau = 0; tau < tau_max; tau += h) {
        double a = plume_fm_blend_angle(bl, tau + 0.5 * h);
        double q[2] = {w.p[0] + h * cos(a), w.p[1] + h * sin(a)};
        double t, u;
        plume_index edge;
        if (!w.inside) {
            if (tau > f->max_barb_len && !jumped) {
                jumped = 1;
                if (!plume_fm_jump_to_outline(f, a, h, w.p, q, &tau))
                    return PLUME_OK;
            }
            if ((st = enter_vane(f, sigma, &w, q)) != PLUME_OK || w.done)
                return st;
            w.p[0] = q[0], w.p[1] = q[1];
            continue;
        }
        if (tau == 0 && root >= 0 && root_on_outline) {
            /* from a strip end on the outline: go on only if the barb heads into the feather */
            if (!point_in_polygon(f->o, f->no, q))
                return PLUME_OK;
        } else if (plume_fm_outline_cross(f, w.p, q, &t, &edge, &u)) {
            return leave_vane(f, sigma, tag, &w, q, t, edge, u);
        }
        if (plume_fm_blocked(f, w.p, q, 0, w.last) && !(fill && tau == 0))
            return PLUME_OK; /* it would cross another barb or the strip: cut (a fill barb starts on a side) */
        w.p[0] = q[0], w.p[1] = q[1];
        w.since++;
        if (fill && w.last < 0) {
            if ((st = start_fill_barb(f, &w)) != PLUME_OK)
                return st;
            continue;
        }
        if (w.since < SUBSTEPS)
            continue;
        if ((st = place_barb_vertex(f, sigma, tag, &w)) != PLUME_OK || w.done)
            return st;
    }
    return PLUME_OK;
}

/* ------------------------------------------------------------------ rachis strip side ends */

/* Follows the side offset curve from station s toward ds sign until the outline: the end vertex. */
plume_status plume_fm_side_end(fm *f, int sigma, double s, double dir, plume_index from, plume_index *end)
{
    double h = f->e / SUBSTEPS, p[2], q[2];
    plume_fm_offset(f, s, sigma, p);
    double smax = f->L + f->diag + f->e, smin = -f->diag - f->e;
    for (double ss = s; ss <= smax && ss >= smin; ss += dir * h) {
        plume_fm_offset(f, ss + dir * h, sigma, q);
        double t, u;
        plume_index edge;
        if (plume_fm_outline_cross(f, p, q, &t, &edge, &u)) {
            const double *fp = f->g.p + 2 * from;
            double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
            double tt, uu;
            plume_index e2;
            double xin[2] = {fp[0] + (1 - 1e-9) * (x[0] - fp[0]), fp[1] + (1 - 1e-9) * (x[1] - fp[1])};
            if (plume_fm_outline_cross(f, fp, xin, &tt, &e2, &uu))
                return plume_err_set(f->err, PLUME_EINVAL,
                                     "rachis: the %s side of the strip cannot be closed on the outline near (%g, %g): "
                                     "edge = %g m is too coarse for the outline there",
                                     sigma > 0 ? "left" : "right", x[0], x[1], f->e);
            plume_index id = plume_fm_outline_vertex(f, edge, u, SNAP_SIDE * f->e);
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
