/* plume: the feather mesher's rachis centre line (macro/feather/internal/feather_mesher.h): the input
 * rachis splined, clipped or extended to the outline and sampled with margins (step 1 of the
 * design comment at the top of macro/feather/feather_mesh.c), and what the other steps ask of it: its width,
 * the point and tangent at an arc length, the strip sides' offset points, the projection of a
 * point, and rays to the outline. */
#include <math.h>

#include "internal/feather_mesher.h"

double plume_fm_width(const fm *f, double s)
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
void plume_fm_centre(const fm *f, double s, double p[2], double *ang)
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
void plume_fm_offset(const fm *f, double s, int sigma, double p[2])
{
    double a;
    plume_fm_centre(f, s, p, &a);
    double h = 0.5 * sigma * plume_fm_width(f, s);
    p[0] -= h * sin(a), p[1] += h * cos(a);
}

/* Arc length s of the nearest centre-line point and the signed distance (> 0 on the left). The
 * centre line is smooth and long: the nearest of ~PROJECT_COARSE evenly strided samples locates
 * the foot to within a stride, then the segments two strides around it are searched exactly. */
void plume_fm_project(const fm *f, const double *p, double *s_out, double *d_out)
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
int plume_fm_ray_hit(const fm *f, const double *p, double ang, double hit[2])
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
plume_status plume_fm_build_centre(fm *f)
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
        if (plume_fm_outline_cross(f, p, q, &t, &edge, &u)) {
            exitp[0] = p[0] + t * (q[0] - p[0]), exitp[1] = p[1] + t * (q[1] - p[1]);
            nkeep = i + 1;
            clipped = 1;
        }
    }
    double start_ang = atan2(raw.y[0] - raw.y[1], raw.x[0] - raw.x[1]);
    double base[2], p0[2] = {raw.x[0], raw.y[0]};
    if (!plume_fm_ray_hit(f, p0, start_ang, base)) {
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
        if (!plume_fm_ray_hit(f, pe, end_ang, tip)) {
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
