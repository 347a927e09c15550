/* Lagged friction (Li et al. 2020 §5): pair frames at the lagged positions, the smoothed Coulomb
 * potential mu lambda f0(|T^T (x - x_lag)|), and a term over the pairs of the last lagging. */
#include "contact_friction.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vec3.h"

static int finite_n(const double *x, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return 0;
    return 1;
}

/* columns t0, t1 of the 3 x 2 basis P */
static void set_columns(double P[6], const double t0[3], const double t1[3])
{
    for (int k = 0; k < 3; k++)
        P[2 * k] = t0[k], P[2 * k + 1] = t1[k];
}

/* a unit vector orthogonal to the nonzero e: e crossed with the axis e is least aligned with, so
 * the cross product is never small compared with |e| */
static void unit_perp(const double e[3], double t[3])
{
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(e[i]) < fabs(e[k]))
            k = i;
    double axis[3] = {0.0, 0.0, 0.0};
    axis[k] = 1.0;
    cross3(e, axis, t);
    const double l = sqrt(dot3(t, t));
    for (int i = 0; i < 3; i++)
        t[i] /= l;
}

/* point–point: P spans the plane normal to e = a - b. Coincident points (d = 0) have no normal;
 * any orthonormal pair then (the z axis is taken as the normal) */
static void frame_pp(const double a[3], const double b[3], double P[6])
{
    double e[3], t0[3], t1[3];
    sub3(a, b, e);
    if (!(dot3(e, e) > 0.0))
        e[0] = 0.0, e[1] = 0.0, e[2] = 1.0;
    unit_perp(e, t0);
    cross3(e, t0, t1);
    const double l = sqrt(dot3(t1, t1));
    for (int k = 0; k < 3; k++)
        t1[k] /= l;
    set_columns(P, t0, t1);
}

/* point p and the line through e0, e1: P = (edge direction, edge x (p - e0)); *alpha the closest
 * point's parameter along the line. When p is (nearly) on the line the cross product's direction
 * is rounding noise: below the parallel threshold of contact_narrow.h (sin^2 of the angle between
 * the edge and p - e0) any unit vector across the edge is used, the normal being undefined. */
static plume_status frame_pe(const double p[3], const double e0[3], const double e1[3], double P[6], double *alpha)
{
    double e[3], r[3], n[3], t0[3], t1[3];
    sub3(e1, e0, e);
    sub3(p, e0, r);
    const double ee = dot3(e, e);
    if (!(ee > 0.0))
        return PLUME_ESINGULAR;
    *alpha = dot3(r, e) / ee;
    const double l = sqrt(ee);
    for (int k = 0; k < 3; k++)
        t0[k] = e[k] / l;
    cross3(e, r, n);
    const double nn = dot3(n, n);
    if (nn <= PLUME_CONTACT_PARALLEL_SIN2 * ee * dot3(r, r)) {
        unit_perp(t0, t1);
    } else {
        const double ln = sqrt(nn);
        for (int k = 0; k < 3; k++)
            t1[k] = n[k] / ln;
    }
    set_columns(P, t0, t1);
    return PLUME_OK;
}

/* P = (a, (a x b) x a) normalised: the plane normal to c = a x b when c != 0 */
static plume_status frame_plane(const double a[3], const double b[3], double P[6])
{
    double c[3], t0[3], t1[3];
    cross3(a, b, c);
    const double aa = dot3(a, a), cc = dot3(c, c);
    if (!(aa > 0.0) || !(cc > 0.0))
        return PLUME_ESINGULAR;
    cross3(c, a, t1);
    const double la = sqrt(aa), l1 = sqrt(dot3(t1, t1));
    for (int k = 0; k < 3; k++)
        t0[k] = a[k] / la, t1[k] /= l1;
    set_columns(P, t0, t1);
    return PLUME_OK;
}

static void fill_T(plume_friction_basis *b)
{
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < 2; j++)
                b->T[2 * (3 * i + k) + j] = b->w[i] * b->P[2 * k + j];
}

plume_status plume_friction_pt_basis(const double x[12], plume_contact_pt_type type, plume_friction_basis *b)
{
    if (!x || !b || !finite_n(x, 12) || (int)type < 0 || type >= PLUME_CONTACT_PT_NTYPES)
        return PLUME_EINVAL;
    memset(b, 0, sizeof *b);
    b->is_edge_edge = 0;
    b->type = (int)type;
    const double *p = x, *t = x + 3;
    plume_status st = PLUME_OK;
    b->w[0] = 1.0;
    if (type <= PLUME_CONTACT_PT_T2) {
        frame_pp(p, t + 3 * type, b->P);
        b->w[1 + type] = -1.0;
    } else if (type <= PLUME_CONTACT_PT_E20) {
        const int i = (int)type - PLUME_CONTACT_PT_E01, j = (i + 1) % 3;
        double alpha = 0.0;
        st = frame_pe(p, t + 3 * i, t + 3 * j, b->P, &alpha);
        b->coef[0] = alpha;
        b->w[1 + i] = -(1.0 - alpha);
        b->w[1 + j] = -alpha;
    } else {
        /* the foot of p on the plane, t0 + b1 e1 + b2 e2, by Cramer's rule on r = b1 e1 + b2 e2 + c n
         * with cross products: unlike the normal equations' a11 a22 - a12^2 it does not cancel
         * on thin triangles */
        double e1[3], e2[3], r[3], n[3], c1[3], c2[3];
        sub3(t + 3, t, e1);
        sub3(t + 6, t, e2);
        sub3(p, t, r);
        if ((st = frame_plane(e1, e2, b->P)) == PLUME_OK) {
            cross3(e1, e2, n);
            cross3(r, e2, c1);
            cross3(e1, r, c2);
            const double nn = dot3(n, n), b1 = dot3(c1, n) / nn, b2 = dot3(c2, n) / nn;
            b->coef[0] = b1, b->coef[1] = b2;
            b->w[1] = -(1.0 - b1 - b2), b->w[2] = -b1, b->w[3] = -b2;
        }
    }
    if (st != PLUME_OK)
        return st;
    fill_T(b);
    return PLUME_OK;
}

plume_status plume_friction_ee_basis(const double x[12], plume_contact_ee_type type, plume_friction_basis *b)
{
    if (!x || !b || !finite_n(x, 12) || (int)type < 0 || type >= PLUME_CONTACT_EE_NTYPES)
        return PLUME_EINVAL;
    memset(b, 0, sizeof *b);
    b->is_edge_edge = 1;
    b->type = (int)type;
    plume_status st = PLUME_OK;
    double alpha = 0.0;
    switch (type) {
    case PLUME_CONTACT_EE_A0B0:
    case PLUME_CONTACT_EE_A0B1:
    case PLUME_CONTACT_EE_A1B0:
    case PLUME_CONTACT_EE_A1B1: {
        const int ia = (int)type / 2, ib = 2 + (int)type % 2; /* enum order: A0B0, A0B1, A1B0, A1B1 */
        frame_pp(x + 3 * ia, x + 3 * ib, b->P);
        b->w[ia] = 1.0, b->w[ib] = -1.0;
        break;
    }
    case PLUME_CONTACT_EE_A0_EB:
    case PLUME_CONTACT_EE_A1_EB: {
        const int ia = type == PLUME_CONTACT_EE_A1_EB;
        st = frame_pe(x + 3 * ia, x + 6, x + 9, b->P, &alpha);
        b->w[ia] = 1.0, b->w[2] = -(1.0 - alpha), b->w[3] = -alpha;
        b->coef[0] = alpha;
        break;
    }
    case PLUME_CONTACT_EE_B0_EA:
    case PLUME_CONTACT_EE_B1_EA: {
        const int ib = 2 + (type == PLUME_CONTACT_EE_B1_EA);
        st = frame_pe(x + 3 * ib, x, x + 3, b->P, &alpha);
        b->w[0] = 1.0 - alpha, b->w[1] = alpha, b->w[ib] = -1.0; /* side a minus side b */
        b->coef[0] = alpha;
        break;
    }
    default: { /* LINES: closest points ea0 + alpha ea and eb0 + beta eb of the two lines */
        double ea[3], eb[3], r[3];
        sub3(x + 3, x, ea);
        sub3(x + 9, x + 6, eb);
        sub3(x + 6, x, r);
        if ((st = frame_plane(ea, eb, b->P)) != PLUME_OK)
            break;
        /* Cramer's rule on ea al - eb be - n c = r, n = ea x eb, with cross products (as above) */
        double n[3], c1[3], c2[3];
        cross3(ea, eb, n);
        cross3(r, eb, c1);
        cross3(r, ea, c2);
        const double nn = dot3(n, n), al = dot3(c1, n) / nn, be = dot3(c2, n) / nn;
        b->coef[0] = al, b->coef[1] = be;
        b->w[0] = 1.0 - al, b->w[1] = al, b->w[2] = -(1.0 - be), b->w[3] = -be;
        break;
    }
    }
    if (st != PLUME_OK)
        return st;
    fill_T(b);
    return PLUME_OK;
}

plume_status plume_friction_pair_basis(int is_edge_edge, const double x[12], plume_friction_basis *b)
{
    plume_status st;
    if (is_edge_edge) {
        plume_contact_ee_type t;
        if ((st = plume_contact_ee_classify(x, &t)) != PLUME_OK)
            return st;
        return plume_friction_ee_basis(x, t, b);
    }
    plume_contact_pt_type t;
    if ((st = plume_contact_pt_classify(x, &t)) != PLUME_OK)
        return st;
    return plume_friction_pt_basis(x, t, b);
}

plume_status plume_friction_mollifier(double y, double eps_u, double *f0, double *f1, double *f1y, double *f2y)
{
    if (!isfinite(y) || y < 0.0 || !isfinite(eps_u) || !(eps_u > 0.0))
        return PLUME_EINVAL;
    double v0, v1, v1y, v2y;
    if (y >= eps_u) {
        v0 = y, v1 = 1.0, v1y = 1.0 / y, v2y = -1.0 / y;
    } else {
        const double s = y / eps_u;
        v0 = eps_u * (s * s - s * s * s / 3.0 + 1.0 / 3.0);
        v1 = s * (2.0 - s);
        v1y = (2.0 - s) / eps_u; /* f1 / y without dividing by y: finite at y = 0 */
        v2y = -s / eps_u;
    }
    if (f0)
        *f0 = v0;
    if (f1)
        *f1 = v1;
    if (f1y)
        *f1y = v1y;
    if (f2y)
        *f2y = v2y;
    return PLUME_OK;
}

plume_status plume_friction_pair_energy(double mu, double lambda, double eps_u, const double T[24], const double x[12],
                                        const double xlag[12], double *D, double *g, double *H)
{
    if (!T || !x || !xlag || !D || !isfinite(mu) || mu < 0.0 || !isfinite(lambda) || lambda < 0.0 ||
        !isfinite(eps_u) || !(eps_u > 0.0) || !finite_n(T, 24) || !finite_n(x, 12) || !finite_n(xlag, 12))
        return PLUME_EINVAL;
    const double ml = mu * lambda;
    *D = 0.0;
    if (g)
        memset(g, 0, 12 * sizeof *g);
    if (H)
        memset(H, 0, 144 * sizeof *H);
    if (!(ml > 0.0))
        return PLUME_OK; /* no friction: skip the frame (and the mollifier's constant eps_u/3) */
    double u[2] = {0.0, 0.0};
    for (int i = 0; i < 12; i++) {
        const double dx = x[i] - xlag[i];
        u[0] += T[2 * i] * dx, u[1] += T[2 * i + 1] * dx;
    }
    const double y = hypot(u[0], u[1]);
    double f0, f1y, f2y;
    plume_status st = plume_friction_mollifier(y, eps_u, &f0, NULL, &f1y, &f2y);
    if (st != PLUME_OK)
        return st;
    *D = ml * f0;
    if (g)
        for (int i = 0; i < 12; i++)
            g[i] = ml * f1y * (T[2 * i] * u[0] + T[2 * i + 1] * u[1]);
    if (H) {
        /* C = f1y I + f2y uh uh^T: eigenvalue f1y across u, f1y + f2y = f1' along it, both >= 0
         * exactly (sliding: 1/y and 0, sticking: (2 - s)/eps_u and 2 (1 - s)/eps_u); clamping
         * removes the round-off of a near-zero f1' at the threshold. At y = 0, f2y = 0: C = f1y I */
        const double across = fmax(f1y, 0.0), along = fmax(f1y + f2y, 0.0);
        double C[4] = {across, 0.0, 0.0, across};
        if (y > 0.0) {
            const double uh[2] = {u[0] / y, u[1] / y}, dl = along - across;
            C[0] += dl * uh[0] * uh[0], C[1] += dl * uh[0] * uh[1];
            C[2] = C[1], C[3] += dl * uh[1] * uh[1];
        }
        double TC[24];
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 2; j++)
                TC[2 * i + j] = ml * (T[2 * i] * C[j] + T[2 * i + 1] * C[2 + j]);
        /* upper triangle mirrored: exactly symmetric blocks */
        for (int i = 0; i < 12; i++)
            for (int j = i; j < 12; j++)
                H[12 * i + j] = H[12 * j + i] = TC[2 * i] * T[2 * j] + TC[2 * i + 1] * T[2 * j + 1];
    }
    return PLUME_OK;
}

plume_status plume_friction_normal_force(const plume_contact_opts *o, double d, double *lambda)
{
    if (!o || !lambda || !isfinite(d) || d < 0.0 || !isfinite(o->dhat) || !(o->dhat > 0.0) ||
        !isfinite(o->stiffness) || o->stiffness < 0.0 ||
        (o->model != PLUME_CONTACT_BARRIER && o->model != PLUME_CONTACT_PENALTY))
        return PLUME_EINVAL;
    *lambda = 0.0;
    double phi, dphi;
    plume_status st = o->model == PLUME_CONTACT_BARRIER ? plume_contact_barrier(d, o->dhat, &phi, &dphi, NULL)
                                                        : plume_contact_penalty(d, o->dhat, &phi, &dphi, NULL);
    if (st != PLUME_OK)
        return st;
    *lambda = -o->stiffness * dphi; /* both potentials decrease with d on (0, dhat): dphi <= 0 */
    return PLUME_OK;
}

plume_status plume_friction_pair_normal_force(const plume_contact_opts *o, int is_edge_edge, const double x[12],
                                              double *lambda)
{
    if (!lambda || !x)
        return PLUME_EINVAL;
    double d2 = 0.0;
    plume_status st = is_edge_edge ? plume_contact_ee_dist2(x, &d2) : plume_contact_pt_dist2(x, &d2);
    if (st != PLUME_OK)
        return st;
    return plume_friction_normal_force(o, sqrt(d2), lambda);
}

/* ---- the term ------------------------------------------------------------------------------ */

/* Pairs with what was lagged: vertices, normal force, lagged positions and frame T per pair. */
typedef struct {
    plume_index n, cap;
    plume_index *v;  /* [4 cap] */
    double *lambda;  /* [cap] */
    double *xlag;    /* [12 cap] */
    double *T;       /* [24 cap] */
} pair_set;

struct plume_friction {
    plume_friction_opts o;
    double eps_u;
    plume_index nv;
    /* cur: the pairs eval uses and update last reported (the problem's pattern is built from
     * them); next: those of the last set_pairs, copied into cur by the next update */
    pair_set cur, next;
    int pending;
    const plume_contact *contact;  /* lag from it (plume_friction_follow_contact), or NULL */
    plume_friction_pair *lagged;   /* [nlagged_cap] workspace of friction_lag */
    plume_index nlagged_cap;
};

void plume_friction_opts_default(plume_friction_opts *o)
{
    if (!o)
        return;
    o->mu = 0.3;
    o->eps_v = 1e-3;
    o->dt = 1e-2;
}

double plume_friction_eps_u(const plume_friction *f)
{
    return f ? f->eps_u : 0.0;
}

static void set_free(pair_set *s)
{
    free(s->v);
    free(s->lambda);
    free(s->xlag);
    free(s->T);
    memset(s, 0, sizeof *s);
}

/* room for n pairs; on failure the set keeps its contents and capacity */
static plume_status set_reserve(pair_set *s, plume_index n)
{
    if (n <= s->cap)
        return PLUME_OK;
    const plume_index cap = n + n / 2 + 16;
    plume_index *v = realloc(s->v, (size_t)(4 * cap) * sizeof *v);
    if (v)
        s->v = v;
    double *l = realloc(s->lambda, (size_t)cap * sizeof *l);
    if (l)
        s->lambda = l;
    double *xl = realloc(s->xlag, (size_t)(12 * cap) * sizeof *xl);
    if (xl)
        s->xlag = xl;
    double *T = realloc(s->T, (size_t)(24 * cap) * sizeof *T);
    if (T)
        s->T = T;
    if (!v || !l || !xl || !T)
        return PLUME_ENOMEM;
    s->cap = cap;
    return PLUME_OK;
}

static void friction_destroy(void *ctx)
{
    plume_friction *f = ctx;
    if (!f)
        return;
    set_free(&f->cur);
    set_free(&f->next);
    free(f->lagged);
    free(f);
}

static plume_status friction_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                                  int project)
{
    (void)project; /* the blocks are PSD already (plume_friction_pair_energy) */
    plume_friction *f = ctx;
    if (dim != 3 || !x)
        return PLUME_EINVAL;
    const pair_set *s = &f->cur;
    double E = 0.0;
    for (plume_index k = 0; k < s->n; k++) {
        const plume_index *v = s->v + 4 * k;
        double xs[12], g[12], e = 0.0;
        gather12(x, v, xs);
        plume_status st = plume_friction_pair_energy(f->o.mu, s->lambda[k], f->eps_u, s->T + 24 * k, xs,
                                                     s->xlag + 12 * k, &e, grad ? g : NULL,
                                                     hblocks ? hblocks + 144 * k : NULL);
        if (st != PLUME_OK)
            return st;
        E += e;
        if (grad)
            for (int a = 0; a < 12; a++)
                grad[3 * v[a / 3] + a % 3] += g[a];
    }
    if (energy)
        *energy += E;
    return PLUME_OK;
}

/* no re-lagging: the pairs are the last set_pairs'; changed when their vertex lists differ */
static plume_status friction_update(void *ctx, int dim, const double *x, const plume_index **stencil,
                                    plume_index *nstencil, int *changed)
{
    (void)x;
    plume_friction *f = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    *changed = 0;
    if (f->pending) {
        const plume_index n = f->next.n;
        plume_status st = set_reserve(&f->cur, n);
        if (st != PLUME_OK)
            return st;
        *changed = n != f->cur.n || (n > 0 && memcmp(f->cur.v, f->next.v, (size_t)(4 * n) * sizeof *f->cur.v) != 0);
        if (n > 0) {
            memcpy(f->cur.v, f->next.v, (size_t)(4 * n) * sizeof *f->cur.v);
            memcpy(f->cur.lambda, f->next.lambda, (size_t)n * sizeof *f->cur.lambda);
            memcpy(f->cur.xlag, f->next.xlag, (size_t)(12 * n) * sizeof *f->cur.xlag);
            memcpy(f->cur.T, f->next.T, (size_t)(24 * n) * sizeof *f->cur.T);
        }
        f->cur.n = n;
        f->pending = 0;
    }
    *stencil = f->cur.v;
    *nstencil = f->cur.n;
    return PLUME_OK;
}

/* the checks of one pair, and its lagged positions and frame (b) when valid */
static plume_status check_pair(const plume_friction *f, plume_index k, const plume_friction_pair *pr,
                               const double *x_lag, double xs[12], plume_friction_basis *b, plume_err *err)
{
    for (int a = 0; a < 4; a++) {
        if (pr->v[a] < 0 || pr->v[a] >= f->nv)
            return plume_err_set(err, PLUME_EINVAL, "friction: pair %ld: vertex %ld out of range [0, %ld)", (long)k,
                                 (long)pr->v[a], (long)f->nv);
        for (int c = 0; c < a; c++)
            if (pr->v[c] == pr->v[a])
                return plume_err_set(err, PLUME_EINVAL, "friction: pair %ld: vertex %ld repeated", (long)k,
                                     (long)pr->v[a]);
    }
    if (!isfinite(pr->lambda) || pr->lambda < 0.0)
        return plume_err_set(err, PLUME_EINVAL, "friction: pair %ld: normal force %g (needs finite >= 0)", (long)k,
                             pr->lambda);
    gather12(x_lag, pr->v, xs);
    if (!finite_n(xs, 12))
        return plume_err_set(err, PLUME_EINVAL, "friction: pair %ld: non-finite lagged position", (long)k);
    plume_status st = plume_friction_pair_basis(pr->is_edge_edge != 0, xs, b);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "friction: pair %ld: no tangent frame (%s)", (long)k, plume_strerror(st));
    return PLUME_OK;
}

plume_status plume_friction_set_pairs(plume_friction *f, plume_index npairs, const plume_friction_pair *pairs,
                                      const double *x_lag, plume_err *err)
{
    if (!f || !x_lag || npairs < 0 || (npairs > 0 && !pairs))
        return plume_err_set(err, PLUME_EINVAL, "friction: set_pairs needs the term, lagged positions and "
                                                "npairs >= 0 pairs");
    /* everything is checked before anything is written, so that a failed call changes nothing */
    plume_friction_basis b;
    double xs[12];
    plume_status st;
    for (plume_index k = 0; k < npairs; k++)
        if ((st = check_pair(f, k, pairs + k, x_lag, xs, &b, err)) != PLUME_OK)
            return st;
    if (set_reserve(&f->next, npairs) != PLUME_OK)
        return plume_err_set(err, PLUME_ENOMEM, "friction: out of memory for %ld pairs", (long)npairs);
    pair_set *s = &f->next;
    for (plume_index k = 0; k < npairs; k++) {
        check_pair(f, k, pairs + k, x_lag, xs, &b, NULL); /* succeeded above: same input */
        memcpy(s->v + 4 * k, pairs[k].v, 4 * sizeof *s->v);
        s->lambda[k] = pairs[k].lambda;
        memcpy(s->xlag + 12 * k, xs, sizeof xs);
        memcpy(s->T + 24 * k, b.T, sizeof b.T);
    }
    s->n = npairs;
    f->pending = 1;
    return PLUME_OK;
}

/* plume_term.lag: the contact's pairs at the step's start x, with their normal forces there */
static plume_status friction_lag(void *ctx, int dim, const double *x)
{
    plume_friction *f = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    if (!f->contact)
        return PLUME_OK;
    plume_index npt = 0, nee = 0;
    const plume_index *st = NULL;
    const double *dhat = NULL;
    plume_contact_opts po;
    plume_contact_term_pairs(f->contact, &npt, &nee, &st, &dhat, &po);
    plume_index n = npt + nee, k = 0;
    if (n > f->nlagged_cap) {
        plume_friction_pair *q = realloc(f->lagged, (size_t)(n + n / 2 + 16) * sizeof *q);
        if (!q)
            return PLUME_ENOMEM;
        f->lagged = q;
        f->nlagged_cap = n + n / 2 + 16;
    }
    for (plume_index s = 0; s < n; s++) {
        double xs[12], lambda = 0.0;
        plume_friction_pair *pr = f->lagged + k;
        memcpy(pr->v, st + 4 * s, sizeof pr->v);
        pr->is_edge_edge = s >= npt;
        gather12(x, pr->v, xs);
        po.dhat = dhat[s];
        plume_status e = plume_friction_pair_normal_force(&po, pr->is_edge_edge, xs, &lambda);
        if (e != PLUME_OK || !(lambda > 0.0))
            continue; /* out of reach now, or touching (d = 0 under the penalty): no force to lag */
        pr->lambda = lambda;
        k++;
    }
    return plume_friction_set_pairs(f, k, f->lagged, x, NULL);
}

plume_status plume_friction_follow_contact(plume_friction *f, const plume_contact *c)
{
    if (!f || !c)
        return PLUME_EINVAL;
    f->contact = c;
    return PLUME_OK;
}

plume_status plume_friction_term_create(plume_index nv, const plume_friction_opts *o, plume_term *out,
                                        plume_friction **handle, plume_err *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (handle)
        *handle = NULL;
    if (!out || !o || nv <= 0)
        return plume_err_set(err, PLUME_EINVAL, "friction: NULL output or options, or no vertex (nv %ld)", (long)nv);
    const double eps_u = o->eps_v * o->dt;
    if (!isfinite(o->mu) || o->mu < 0.0 || !isfinite(o->eps_v) || !(o->eps_v > 0.0) || !isfinite(o->dt) ||
        !(o->dt > 0.0) || !isfinite(eps_u) || !(eps_u > 0.0))
        return plume_err_set(err, PLUME_EINVAL,
                             "friction: needs mu >= 0, eps_v > 0 and dt > 0, all finite (got mu %g, eps_v %g, dt %g)",
                             o->mu, o->eps_v, o->dt);
    plume_friction *f = calloc(1, sizeof *f);
    if (!f || set_reserve(&f->cur, 16) != PLUME_OK || set_reserve(&f->next, 16) != PLUME_OK) {
        friction_destroy(f);
        return plume_err_set(err, PLUME_ENOMEM, "friction: out of memory");
    }
    f->o = *o;
    f->eps_u = eps_u;
    f->nv = nv;
    out->name = "friction";
    out->arity = 4;
    out->nstencil = 0;
    out->stencil = f->cur.v;
    out->size = sizeof *out;
    out->eval = friction_eval;
    out->destroy = friction_destroy;
    out->ctx = f;
    out->update = friction_update;
    out->max_step = NULL;
    out->lag = friction_lag;
    if (handle)
        *handle = f;
    return PLUME_OK;
}
