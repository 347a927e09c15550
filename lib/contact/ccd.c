/* plume: Additive CCD (see ccd.h). */
#include "ccd.h"

#include <math.h>
#include <string.h>

#include "contact_narrow.h"

void plume_ccd_opts_default(plume_ccd_opts *o)
{
    if (!o)
        return;
    o->s = 0.1;
    o->min_distance = 0.0;
    o->eta = 0.9;
    o->max_iter = 1000000;
}

static int opts_ok(const plume_ccd_opts *o)
{
    return isfinite(o->s) && o->s > 0.0 && o->s < 1.0 && isfinite(o->min_distance) &&
           o->min_distance >= 0.0 && isfinite(o->eta) && o->eta > 0.0 && o->eta < 1.0 && o->max_iter >= 1;
}

typedef plume_status (*dist2_fn)(const double x[12], double *d2);

static double norm3(const double *a)
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/* gap = d - xi, written as (d^2 - xi^2) / (d + xi) as in the paper (exact for xi = 0); d = xi = 0
 * is a zero gap */
static plume_status gap_at(dist2_fn dist2, const double *x0, const double *dx, double t, double xi,
                           double *gap)
{
    double x[12], d2;
    for (int i = 0; i < 12; i++)
        x[i] = x0[i] + t * dx[i];
    plume_status st = dist2(x, &d2);
    if (st)
        return st;
    const double den = sqrt(d2) + xi;
    *gap = den > 0.0 ? (d2 - xi * xi) / den : 0.0;
    return PLUME_OK;
}

/* Li et al. 2021, Algorithm 1, with the vertex positions evaluated afresh at each t (no drift
 * from accumulating x += t_l p), the last step clamped to end exactly at t_max, and a cap. */
static plume_status accd(dist2_fn dist2, int point_triangle, const double *x0, const double *x1,
                         double t_max, const plume_ccd_opts *oin, double *toi, plume_ccd_report *rep)
{
    plume_ccd_opts o;
    plume_ccd_opts_default(&o);
    if (oin)
        o = *oin;
    if (!x0 || !x1 || !toi || !opts_ok(&o) || !(t_max > 0.0) || !(t_max <= 1.0))
        return PLUME_EINVAL;
    double dx[12], p[12];
    for (int i = 0; i < 12; i++) {
        if (!isfinite(x0[i]) || !isfinite(x1[i]))
            return PLUME_EINVAL;
        dx[i] = x1[i] - x0[i];
    }
    plume_ccd_report r = {0, 0, 0, 0.0, 0.0};
    plume_status st;
    if ((st = gap_at(dist2, x0, dx, 0.0, o.min_distance, &r.gap_start)))
        return st;
    r.gap_toi = r.gap_start;
    if (!(r.gap_start > 0.0)) {
        *toi = 0.0;
        if (rep)
            *rep = r;
        return PLUME_EINFEASIBLE;
    }

    /* l_p bounds |d/dt (y_a - y_b)| for any points y_a, y_b of the two primitives (convex
     * combinations of their vertices); a common translation moves neither, so it is removed
     * first (the mean displacement) to make the bound tighter. */
    for (int a = 0; a < 3; a++) {
        const double mean = 0.25 * (dx[a] + dx[3 + a] + dx[6 + a] + dx[9 + a]);
        for (int v = 0; v < 4; v++)
            p[3 * v + a] = dx[3 * v + a] - mean;
    }
    const double n0 = norm3(p), n1 = norm3(p + 3), n2 = norm3(p + 6), n3 = norm3(p + 9);
    const double lp = point_triangle ? n0 + fmax(n1, fmax(n2, n3)) : fmax(n0, n1) + fmax(n2, n3);

    double t = 0.0, gap = r.gap_start;
    const double target = o.s * r.gap_start;
    if (!(lp > 0.0)) { /* rigid translation or no motion: the distance never changes */
        *toi = t_max;
        if (rep)
            *rep = r;
        return PLUME_OK;
    }
    for (;;) {
        if (r.iterations >= o.max_iter) {
            r.capped = 1;
            r.hit = 1;
            break;
        }
        /* The first step keeps gap >= gap0 - (1 - s) gap0 = s gap0 = target by the Lipschitz
         * bound alone, so it is accepted without looking (toi > 0 always); later steps keep
         * gap >= (1 - eta) gap and are accepted when the end point is still >= target. */
        const int first = r.iterations == 0;
        double tn = t + (first ? 1.0 - o.s : o.eta) * gap / lp;
        const int last = tn >= t_max;
        if (last)
            tn = t_max;
        double gn;
        if ((st = gap_at(dist2, x0, dx, tn, o.min_distance, &gn)))
            return st;
        r.iterations++;
        if (!first && !(gn >= target)) {
            r.hit = 1;
            break;
        }
        t = tn;
        gap = gn;
        if (last)
            break;
    }
    *toi = t;
    r.gap_toi = gap;
    if (rep)
        *rep = r;
    return PLUME_OK;
}

plume_status plume_ccd_point_triangle(const double x0[12], const double x1[12], double t_max,
                                      const plume_ccd_opts *o, double *toi, plume_ccd_report *rep)
{
    return accd(plume_contact_pt_dist2, 1, x0, x1, t_max, o, toi, rep);
}

plume_status plume_ccd_edge_edge(const double x0[12], const double x1[12], double t_max,
                                 const plume_ccd_opts *o, double *toi, plume_ccd_report *rep)
{
    return accd(plume_contact_ee_dist2, 0, x0, x1, t_max, o, toi, rep);
}
