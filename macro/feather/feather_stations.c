/* plume: the feather mesher's corner-exact stations (macro/feather/internal/feather_mesher.h): where each
 * side's barbs are rooted, a barb through every outline vertex it can reach and the others spaced
 * evenly between (step 3b of the design comment at the top of macro/feather/feather_mesh.c); without
 * corner_exact the stations every ds. Barbs are traced here without being meshed, with the same
 * steps as the walk. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal/feather_mesher.h"

/* Where a barb meets the outline, followed without meshing it (no collisions): the same steps as
 * plume_fm_walk, so a station found here meets the outline at the same point when it is walked. */
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
    plume_fm_blend(f, side, s, &bl);
    plume_fm_offset(f, s, sigma, p);
    int inside = rooted;
    if (!rooted && point_in_polygon(f->o, f->no, p))
        return;
    double tau_max = f->max_barb_len + 3 * f->diag + 2 * e;
    int jumped = 0;
    for (double tau = 0; tau < tau_max; tau += h) {
        double a = plume_fm_blend_angle(&bl, tau + 0.5 * h);
        double q[2] = {p[0] + h * cos(a), p[1] + h * sin(a)};
        double t, u;
        plume_index edge;
        if (!inside && tau > f->max_barb_len && !jumped) {
            jumped = 1;
            if (!plume_fm_jump_to_outline(f, a, h, p, q, &tau))
                return;
        }
        if (plume_fm_outline_cross(f, p, q, &t, &edge, &u)) {
            double x[2] = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
            int k = inside ? 1 : 0;
            if (!inside) {
                double ss, d;
                plume_fm_project(f, x, &ss, &d);
                if (sigma * d < 0.5 * plume_fm_width(f, ss))
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
    plume_fm_offset(f, from, sigma, p);
    plume_fm_offset(f, s, sigma, q);
    return point_in_polygon(f->o, f->no, q) && !plume_fm_near_segment(f, q, GAP_POINT * f->e, 1u << SEG_OUTLINE, -1) &&
           !plume_fm_outline_cross(f, p, q, &t, &edge, &u);
}

/* How far past the run's end station s (toward dir = -1 or +1, at most one station spacing ds)
 * the side stays rootable: the run stops at whole stations, a corner station may go further. */
double plume_fm_run_extent(const fm *f, int sigma, double s, double ds, int dir)
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

/* The corner stations of one side, sorted (malloc'ed *out, *n of them): for each outline vertex a
 * station whose barb crosses the outline exactly there, bracketed by the family sampled every ds/2
 * (stations kmin ds to kmax ds) and at the ends ext of the strip's extent, then bisected. */
static plume_status fm_corners(const fm *f, int side, double ds, long kmin, long kmax, const double ext[2],
                               double **out, long *n)
{
    plume_status st = PLUME_OK;
    long ns = 2 * (kmax - kmin) + 1 + 2;
    ftrace *tr = malloc((size_t)ns * sizeof *tr);
    double *ss = malloc((size_t)ns * sizeof *ss);
    unsigned char *found = calloc((size_t)f->no, 1);
    long nc = 0, ccap = 64;
    double *cs = malloc((size_t)ccap * sizeof *cs);
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
    *out = cs, cs = NULL;
    *n = nc;
cleanup:
    free(tr);
    free(ss);
    free(found);
    free(cs);
    return st;
}

/* The kept stations (malloc'ed *out, sorted, *n of them): the strip run's ends [*s0, *s1], moved
 * onto the outermost corner of the strip's extent near them, and the corners cs (nc, sorted) at
 * least CORNER_GAP ds from every one kept before. */
static plume_status fm_kept(const double *cs, long nc, double ds, const double ext[2], double *s0, double *s1,
                            double **out, long *n)
{
    const double tol = 1e-9 * ds;
    for (long c = 0; c < nc; c++)
        if (cs[c] >= ext[0] - tol && cs[c] < *s0 + CORNER_GAP * ds) {
            *s0 = cs[c];
            break;
        }
    for (long c = nc - 1; c >= 0; c--)
        if (cs[c] <= ext[1] + tol && cs[c] > *s1 - CORNER_GAP * ds) {
            *s1 = cs[c];
            break;
        }
    double *fixed = malloc((size_t)(nc + 2) * sizeof *fixed);
    if (!fixed)
        return PLUME_ENOMEM;
    long nf = 0;
    fixed[nf++] = *s0;
    if (*s1 > *s0)
        fixed[nf++] = *s1;
    for (long c = 0; c < nc; c++) {
        int ok = 1;
        for (long q = 0; q < nf && ok; q++) /* tens of corners: a scan is enough */
            ok = fabs(cs[c] - fixed[q]) >= CORNER_GAP * ds;
        if (ok)
            fixed[nf++] = cs[c];
    }
    qsort(fixed, (size_t)nf, sizeof *fixed, cmp_double);
    *out = fixed;
    *n = nf;
    return PLUME_OK;
}

/* All stations of one side (malloc'ed *out, *n of them) from the kept ones (nf, sorted, those in
 * [s0, s1] rooted): below the first every ds down to kmin ds, between kept ones evenly, above the
 * last every ds up to kmax ds. */
static plume_status fm_spaced(const fm *f, int side, double ds, long kmin, long kmax, const double *fixed, long nf,
                              double s0, double s1, double **out, long *n)
{
    plume_status st = PLUME_OK;
    const double tol = 1e-9 * ds;
    double *sta = NULL;
    long nsta = 0;
    ftrace *ftf = malloc((size_t)nf * sizeof *ftf);
    if (!ftf)
        return PLUME_ENOMEM;
    for (long q = 0; q < nf; q++)
        fm_trace(f, side, fixed[q], fixed[q] >= s0 && fixed[q] <= s1, ftf + q);
    /* counted in the first pass, stored in the second */
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
            break;
        }
    }
    free(ftf);
    *out = sta;
    *n = nsta;
    return st;
}

/* Stations of one side, sorted (malloc'ed *out, *n of them; [*r0, *r1] the rooted ones, those of
 * the strip run [s0, s1], which a corner station may extend to ext[0] <= s0 and ext[1] >= s1, the
 * extent of the strip's side inside the outline (plume_fm_run_extent)). A station whose barb meets
 * the outline exactly at an outline vertex is a corner station (docs/design.md, "Meshes that
 * respect the fibres": a barb line through every corner); corners closer than CORNER_GAP ds to a
 * kept station are dropped, and the others are spaced evenly between consecutive kept ones,
 * round(gap / ds) - 1 of them, so that the density stays ~1/ds. Without corners the stations are
 * k ds, kmin <= k <= kmax, as before. */
plume_status plume_fm_stations(fm *f, int side, double ds, long kmin, long kmax, double s0, double s1,
                               const double ext[2], double **out, long *n, long *r0, long *r1)
{
    if (!f->in->corner_exact) { /* every ds, as before corner-exact stations */
        long a = lround(s0 / ds), b = lround(s1 / ds);
        if (!(*out = malloc((size_t)(kmax - kmin + 1) * sizeof **out)))
            return PLUME_ENOMEM;
        for (long k = kmin; k <= kmax; k++)
            (*out)[k - kmin] = (double)k * ds;
        *n = kmax - kmin + 1, *r0 = a - kmin, *r1 = b - kmin;
        return PLUME_OK;
    }
    double *cs = NULL, *fixed = NULL, *sta = NULL;
    long nc = 0, nf = 0, nsta = 0;
    plume_status st;
    if ((st = fm_corners(f, side, ds, kmin, kmax, ext, &cs, &nc)) != PLUME_OK ||
        (st = fm_kept(cs, nc, ds, ext, &s0, &s1, &fixed, &nf)) != PLUME_OK ||
        (st = fm_spaced(f, side, ds, kmin, kmax, fixed, nf, s0, s1, &sta, &nsta)) != PLUME_OK)
        goto cleanup;
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
    free(cs);
    free(fixed);
    free(sta);
    return st;
}
