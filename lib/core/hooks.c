/* plume: barbule hooks (lib/core/hooks.h): zero-length springs per vertex pair, grouped into
 * hooks that slide, let go and catch again between solves. */
#include "hooks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The default law. strength: a single hooklet releases at about 14 uN (Kovalev, Filippov & Gorb,
 * "Unzipping bird feathers", J. R. Soc. Interface 11, 20130988, 2014). No source gives the
 * opening, the slide or the capture distance: the opening and the capture are assumed at the
 * hooklet's scale (a few micrometres) and the slide is off. */
void plume_hook_law_default(plume_hook_law *l)
{
    if (!l)
        return;
    l->strength = 1.4e-5;
    l->opening = 2e-6;
    l->slide = 0.0;
    l->capture = 5e-6;
}

plume_status plume_hook_law_check(const plume_hook_law *l, plume_err *err)
{
    if (!l)
        return plume_err_set(err, PLUME_EINVAL, "hook law: none given");
    if (!(isfinite(l->strength) && l->strength > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "hook law: strength must be finite and > 0 N (got %g)", l->strength);
    if (!(isfinite(l->opening) && l->opening > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "hook law: opening must be finite and > 0 m (got %g)", l->opening);
    if (!(isfinite(l->slide) && l->slide >= 0.0))
        return plume_err_set(err, PLUME_EINVAL, "hook law: slide must be finite and >= 0 m (got %g)", l->slide);
    if (!(isfinite(l->capture) && l->capture >= 0.0))
        return plume_err_set(err, PLUME_EINVAL, "hook law: capture must be finite and >= 0 m (got %g)", l->capture);
    return PLUME_OK;
}

struct plume_hooks {
    plume_hook_law law;
    plume_index nv;
    int nhooks;
    plume_index npairs;
    plume_index *first;   /* [nhooks + 1] */
    plume_index *pairs;   /* [2 npairs]: a, b; the term's stencils */
    int *hook_of;         /* [npairs] */
    double *offset;       /* [3 npairs] rest offsets o_p (the first dim entries used) */
    unsigned char *engaged; /* [nhooks] */
    unsigned char *armed;   /* [nhooks] released and since then opened beyond the capture */
    double *slid;         /* [nhooks] slide so far (m) */
    double *scale;        /* [nhooks] hook k's strength and stiffness are the law's times scale[k] */
    double *dmax;         /* [nhooks] softening: the largest opening committed (m; 0: whole) */
    double soften;        /* > 1: a hook past its opening softens to zero at soften x opening; <= 1 brittle */
    int envelope;         /* softening hooks inside solves: 0 the secant spring of their history (a
                             load step), 1 their law (the solve at fixed load that follows) */
    double overshoot;     /* a commit allowed to cut refuses loads beyond this many strengths */
    double seat;          /* >= 0: a caught hook pressed closer than its catch by more than this (m) seats; < 0: off */
    long released, reengaged;
    double dropped;
    struct {              /* the state kept by keep(save) */
        double *offset, *slid, *dmax;
        unsigned char *engaged, *armed;
        long released, reengaged;
        double dropped;
    } kept;
};

void plume_hooks_destroy(plume_hooks **ph)
{
    if (!ph || !*ph)
        return;
    plume_hooks *h = *ph;
    free(h->first);
    free(h->pairs);
    free(h->hook_of);
    free(h->offset);
    free(h->engaged);
    free(h->armed);
    free(h->slid);
    free(h->scale);
    free(h->dmax);
    free(h->kept.dmax);
    free(h->kept.offset);
    free(h->kept.slid);
    free(h->kept.engaged);
    free(h->kept.armed);
    free(h);
    *ph = NULL;
}

plume_status plume_hooks_create(plume_index nv, int nhooks, const plume_index *first, const plume_index *pairs,
                                const plume_hook_law *law, plume_hooks **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "hooks: no output pointer");
    *out = NULL;
    plume_status st = plume_hook_law_check(law, err);
    if (st != PLUME_OK)
        return st;
    if (nv < 2 || nhooks < 1 || !first || !pairs || first[0] != 0)
        return plume_err_set(err, PLUME_EINVAL, "hooks: %d hooks over %ld vertices: need hooks, pairs and first[0] = 0",
                             nhooks, (long)nv);
    for (int k = 0; k < nhooks; k++)
        if (first[k + 1] <= first[k])
            return plume_err_set(err, PLUME_EINVAL, "hooks: hook %d has no pairs", k);
    const plume_index np = first[nhooks];
    for (plume_index p = 0; p < np; p++) {
        const plume_index a = pairs[2 * p], b = pairs[2 * p + 1];
        if (a < 0 || b < 0 || a >= nv || b >= nv || a == b)
            return plume_err_set(err, PLUME_EINVAL, "hooks: pair %ld joins vertices %ld and %ld (of %ld): two distinct "
                                 "vertices needed", (long)p, (long)a, (long)b, (long)nv);
    }
    plume_hooks *h = calloc(1, sizeof *h);
    if (!h)
        return plume_err_set(err, PLUME_ENOMEM, "hooks: out of memory");
    h->law = *law, h->nv = nv, h->nhooks = nhooks, h->npairs = np;
    h->overshoot = PLUME_HOOKS_OVERSHOOT;
    h->seat = -1.0;
    h->first = malloc((size_t)(nhooks + 1) * sizeof *h->first);
    h->pairs = malloc(2 * (size_t)np * sizeof *h->pairs);
    h->hook_of = malloc((size_t)np * sizeof *h->hook_of);
    h->offset = calloc(3 * (size_t)np, sizeof *h->offset);
    h->engaged = malloc((size_t)nhooks);
    h->armed = calloc((size_t)nhooks, 1);
    h->slid = calloc((size_t)nhooks, sizeof *h->slid);
    h->scale = malloc((size_t)nhooks * sizeof *h->scale);
    h->dmax = calloc((size_t)nhooks, sizeof *h->dmax);
    h->kept.dmax = calloc((size_t)nhooks, sizeof *h->kept.dmax);
    h->kept.offset = calloc(3 * (size_t)np, sizeof *h->kept.offset);
    h->kept.slid = calloc((size_t)nhooks, sizeof *h->kept.slid);
    h->kept.engaged = malloc((size_t)nhooks);
    h->kept.armed = calloc((size_t)nhooks, 1);
    if (!h->first || !h->pairs || !h->hook_of || !h->offset || !h->engaged || !h->armed || !h->slid || !h->scale ||
        !h->dmax || !h->kept.dmax || !h->kept.offset || !h->kept.slid || !h->kept.engaged || !h->kept.armed) {
        plume_hooks_destroy(&h);
        return plume_err_set(err, PLUME_ENOMEM, "hooks: out of memory");
    }
    memcpy(h->first, first, (size_t)(nhooks + 1) * sizeof *first);
    memcpy(h->pairs, pairs, 2 * (size_t)np * sizeof *pairs);
    memset(h->engaged, 1, (size_t)nhooks);
    memset(h->kept.engaged, 1, (size_t)nhooks);
    for (int k = 0; k < nhooks; k++) {
        h->scale[k] = 1.0;
        for (plume_index p = first[k]; p < first[k + 1]; p++)
            h->hook_of[p] = k;
    }
    *out = h;
    return PLUME_OK;
}

/* the stiffness of one pair of hook k (the brittle law; a softening hook's is soft_of's) */
static double pair_stiffness(const plume_hooks *h, int k)
{
    return h->scale[k] * h->law.strength / h->law.opening / (double)(h->first[k + 1] - h->first[k]);
}

static double norm(const double *v, int dim)
{
    double s = 0.0;
    for (int c = 0; c < dim; c++)
        s += v[c] * v[c];
    return sqrt(s);
}

/* d = x_a - x_b - o_p of pair p, as it is */
static void raw_stretch(const plume_hooks *h, int dim, const double *x, plume_index p, double *d)
{
    const plume_index a = h->pairs[2 * p], b = h->pairs[2 * p + 1];
    for (int c = 0; c < dim; c++)
        d[c] = x[dim * a + c] - x[dim * b + c] - h->offset[3 * p + c];
}

/* With seating on, a pair caught at a gap (o_p != 0) holds its lips apart only as far as they were:
 * closing them further along n = o_p / |o_p|, down to where they meet (d . n = -|o_p|), is free,
 * and only opening and sliding stretch it; pressed through each other it resists again, as a pair
 * at creation does about their meeting point. d_n = d . n of the raw stretch d and n; 0 when the
 * pair is two-sided (seating off, or caught with its lips together). */
static int one_sided(const plume_hooks *h, int dim, const double *d, plume_index p, double *dn, double *n)
{
    const double *o = h->offset + 3 * p, len = norm(o, dim);
    if (!(h->seat >= 0.0) || !(len > 0.0))
        return 0;
    *dn = 0.0;
    for (int c = 0; c < dim; c++)
        n[c] = o[c] / len, *dn += d[c] * n[c];
    return 1;
}

/* the stretch d of pair p that its law sees: the raw stretch, less its free closing when the pair
 * is one-sided (all of d_n within the free band, |o_p| of it beyond); *closed (when not NULL) says
 * d_n is inside the band, where d does not depend on it, and n is its direction */
static void pair_stretch_n(const plume_hooks *h, int dim, const double *x, plume_index p, double *d, int *closed,
                           double *n)
{
    double dn = 0.0, nn[3] = {0.0, 0.0, 0.0};
    raw_stretch(h, dim, x, p, d);
    int c1 = 0;
    if (one_sided(h, dim, d, p, &dn, nn) && dn < 0.0) {
        const double band = norm(h->offset + 3 * p, dim), free_part = fmax(dn, -band);
        c1 = dn >= -band;
        for (int c = 0; c < dim; c++)
            d[c] -= free_part * nn[c];
    }
    if (closed)
        *closed = c1;
    if (n)
        for (int c = 0; c < dim; c++)
            n[c] = nn[c];
}

static void pair_stretch(const plume_hooks *h, int dim, const double *x, plume_index p, double *d)
{
    pair_stretch_n(h, dim, x, p, d, NULL, NULL);
}

/* The softening law of hook k (one pair) as a function of its opening t = |d|, with its history
 * dmax (plume_hooks_set_softening): the envelope f rises linearly to the strength at d0, falls
 * linearly to zero at dc = soften d0; below ds = max(dmax, d0) the hook is the secant spring
 * ks = f(ds) / ds. *W energy, *dW = W', *d2W = W'' at t. */
typedef struct {
    double S, d0, dc, ds, ks;
    int frozen; /* the secant spring at every opening (hooks' envelope off) */
} soft_law;

static soft_law soft_of(const plume_hooks *h, int k)
{
    soft_law l;
    l.S = h->scale[k] * h->law.strength, l.d0 = h->law.opening, l.dc = h->soften * l.d0;
    l.ds = fmax(h->dmax[k], l.d0);
    l.frozen = !h->envelope;
    const double fs = l.ds < l.dc ? l.S * (l.dc - l.ds) / (l.dc - l.d0) : 0.0;
    l.ks = fs / l.ds;
    return l;
}

/* the work of the falling branch from a to b (d0 <= a <= b), capped at dc */
static double soft_area(const soft_law *l, double a, double b)
{
    a = fmin(a, l->dc), b = fmin(b, l->dc);
    const double g = l->S / (l->dc - l->d0);
    return g * ((l->dc * b - 0.5 * b * b) - (l->dc * a - 0.5 * a * a));
}

static void soft_eval(const soft_law *l, double t, double *W, double *dW, double *d2W)
{
    if (t <= l->ds || l->frozen) {
        *W = 0.5 * l->ks * t * t, *dW = l->ks * t, *d2W = l->ks;
        return;
    }
    *W = 0.5 * l->ks * l->ds * l->ds + soft_area(l, l->ds, t);
    if (t < l->dc)
        *dW = l->S * (l->dc - t) / (l->dc - l->d0), *d2W = -l->S / (l->dc - l->d0);
    else
        *dW = 0.0, *d2W = 0.0;
}

static double pair_energy(const plume_hooks *h, int dim, const double *x, plume_index p)
{
    const int k = h->hook_of[p];
    if (!h->engaged[k])
        return 0.0;
    double d[3];
    pair_stretch(h, dim, x, p, d);
    if (h->soften > 1.0) {
        const soft_law l = soft_of(h, k);
        double W, dW, d2W;
        soft_eval(&l, norm(d, dim), &W, &dW, &d2W);
        return W;
    }
    double s = 0.0;
    for (int c = 0; c < dim; c++)
        s += d[c] * d[c];
    return 0.5 * pair_stiffness(h, k) * s;
}

/* the pair's force g = dW/dd and its 3x3 stiffness H = d2W/dd2 (softening hooks; H projected to PSD
 * when `project`, the falling branch's negative curvature along d dropped) */
static void soft_pair(const plume_hooks *h, int k, int dim, const double *d, int project, double *W, double *g,
                      double *H)
{
    const soft_law l = soft_of(h, k);
    const double t = norm(d, dim);
    double dW, d2W;
    soft_eval(&l, t, W, &dW, &d2W);
    if (t <= l.ds || l.frozen) { /* the secant spring: ks d, ks I */
        for (int c = 0; c < dim; c++) {
            g[c] = l.ks * d[c];
            for (int e = 0; e < dim; e++)
                H[c * dim + e] = c == e ? l.ks : 0.0;
        }
        return;
    }
    if (project && d2W < 0.0)
        d2W = 0.0;
    const double tang = dW / t;
    for (int c = 0; c < dim; c++) {
        g[c] = dW * d[c] / t;
        for (int e = 0; e < dim; e++)
            H[c * dim + e] = (d2W - tang) * d[c] * d[e] / (t * t) + (c == e ? tang : 0.0);
    }
}

/* H <- P H P, P = I - n n^T (n a unit vector; H symmetric dim x dim) */
static void project_out(double *H, const double *n, int dim)
{
    double Hn[3] = {0.0, 0.0, 0.0}, nHn = 0.0;
    for (int c = 0; c < dim; c++) {
        for (int e = 0; e < dim; e++)
            Hn[c] += H[c * dim + e] * n[e];
        nHn += n[c] * Hn[c];
    }
    for (int c = 0; c < dim; c++)
        for (int e = 0; e < dim; e++)
            H[c * dim + e] += -Hn[c] * n[e] - n[c] * Hn[e] + nHn * n[c] * n[e];
}

static plume_status hooks_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                               int project)
{
    const plume_hooks *h = ctx;
    const int kb = 2 * dim;
    for (plume_index p = 0; p < h->npairs; p++) {
        const int k = h->hook_of[p];
        double d[3], g[3] = {0.0, 0.0, 0.0}, H[9] = {0.0}, W = 0.0, n[3];
        int closed = 0;
        pair_stretch_n(h, dim, x, p, d, &closed, n);
        if (!h->engaged[k]) {
        } else if (h->soften > 1.0) {
            soft_pair(h, k, dim, d, project, &W, g, H);
        } else { /* k [I -I; -I I]: positive semidefinite already */
            const double kp = pair_stiffness(h, k);
            for (int c = 0; c < dim; c++) {
                W += 0.5 * kp * d[c] * d[c], g[c] = kp * d[c];
                H[c * dim + c] = kp;
            }
        }
        if (closed && h->engaged[k]) /* d = P d_raw, P = I - n n^T: the gradient is P g = g, the Hessian P H P */
            project_out(H, n, dim);
        if (energy)
            *energy += W;
        if (grad) {
            const plume_index a = h->pairs[2 * p], b = h->pairs[2 * p + 1];
            for (int c = 0; c < dim; c++)
                grad[dim * a + c] += g[c], grad[dim * b + c] -= g[c];
        }
        if (hblocks) {
            double *B = hblocks + (size_t)p * (size_t)(kb * kb);
            for (int c = 0; c < dim; c++)
                for (int e = 0; e < dim; e++) {
                    const double v = H[c * dim + e];
                    B[c * kb + e] = B[(dim + c) * kb + dim + e] = v;
                    B[c * kb + dim + e] = B[(dim + c) * kb + e] = -v;
                }
        }
    }
    return PLUME_OK;
}

static plume_status hooks_energies(void *ctx, int dim, const double *x, double *e)
{
    const plume_hooks *h = ctx;
    for (plume_index p = 0; p < h->npairs; p++)
        e[p] = pair_energy(h, dim, x, p);
    return PLUME_OK;
}

/* the term's commit: the hooks' commit at the equilibrium x, unless may_cut and a hook is loaded
 * beyond the overshoot */
/* Softening hooks between a load step and the solve at fixed load that follows: the largest excess
 * of a hook's secant force over its law, in strengths, over the engaged hooks opened beyond their
 * history (*beyond: how many). */
static double soft_excess(const plume_hooks *h, int dim, const double *x, int *beyond)
{
    double worst = 0.0;
    *beyond = 0;
    for (int k = 0; k < h->nhooks; k++) {
        if (!h->engaged[k])
            continue;
        double d[3];
        pair_stretch(h, dim, x, h->first[k], d);
        const double t = norm(d, dim);
        soft_law l = soft_of(h, k);
        if (!(t > l.ds))
            continue;
        double W, law, d2W;
        l.frozen = 0; /* the law's force at t */
        soft_eval(&l, t, &W, &law, &d2W);
        worst = fmax(worst, (l.ks * t - law) / l.S);
        (*beyond)++;
    }
    return worst;
}

static double term_energy(const plume_hooks *h, int dim, const double *x)
{
    double e = 0.0;
    for (plume_index p = 0; p < h->npairs; p++)
        e += pair_energy(h, dim, x, p);
    return e;
}

/* The term's commit: the hooks' commit at the equilibrium x, unless may_cut and a hook is loaded
 * beyond the overshoot. Softening hooks take two: a load step is solved with each hook the secant
 * spring of its history (convex); where hooks opened beyond it, the first commit puts them on
 * their law (refusing, when it may cut, a secant force above the law by more than the overshoot
 * allows) and asks for a solve at the same load, whose Newton follows the falling branches (and
 * any snap they cause) at fixed load; the second commit moves their histories there and puts them
 * back on their secants, which leaves the equilibrium where it is. */
static plume_status hooks_term_commit(void *ctx, int dim, const double *x, int may_cut, plume_commit_report *r)
{
    plume_hooks *h = ctx;
    if (h->soften > 1.0 && !h->envelope) {
        int beyond = 0;
        const double excess = soft_excess(h, dim, x, &beyond);
        if (beyond) {
            if (may_cut && 1.0 + excess > h->overshoot) {
                r->overshoot = 1;
                return PLUME_OK;
            }
            const double before = term_energy(h, dim, x);
            h->envelope = 1;
            r->changed = 1;
            r->energy_drop = before - term_energy(h, dim, x);
            return PLUME_OK;
        }
    }
    if (may_cut && plume_hooks_max_load(h, dim, x, NULL) > h->overshoot) {
        r->overshoot = 1;
        return PLUME_OK;
    }
    plume_hooks_events ev;
    plume_status st = plume_hooks_commit(h, dim, x, PLUME_HOOKS_ALL, &ev, NULL);
    h->envelope = 0; /* each softened hook now on its new secant: the same force */
    /* a softening hook's history and its release at zero force leave the equilibrium where it is */
    r->changed = ev.released - ev.soft_released + ev.slid + ev.reengaged > 0; /* a seat moves no force */
    r->released = ev.released, r->reengaged = ev.reengaged, r->energy_drop = ev.energy_drop;
    return st;
}

static plume_status hooks_term_keep(void *ctx, int save)
{
    plume_hooks *h = ctx;
    h->envelope = 0;
    const size_t no = 3 * (size_t)h->npairs * sizeof(double), ns = (size_t)h->nhooks * sizeof(double);
    const size_t nf = (size_t)h->nhooks;
    if (save) {
        memcpy(h->kept.offset, h->offset, no);
        memcpy(h->kept.slid, h->slid, ns);
        memcpy(h->kept.dmax, h->dmax, ns);
        memcpy(h->kept.engaged, h->engaged, nf);
        memcpy(h->kept.armed, h->armed, nf);
        h->kept.released = h->released, h->kept.reengaged = h->reengaged, h->kept.dropped = h->dropped;
    } else {
        memcpy(h->offset, h->kept.offset, no);
        memcpy(h->slid, h->kept.slid, ns);
        memcpy(h->dmax, h->kept.dmax, ns);
        memcpy(h->engaged, h->kept.engaged, nf);
        memcpy(h->armed, h->kept.armed, nf);
        h->released = h->kept.released, h->reengaged = h->kept.reengaged, h->dropped = h->kept.dropped;
    }
    return PLUME_OK;
}

static plume_status hooks_term_states(void *ctx, int *s)
{
    const plume_hooks *h = ctx;
    for (plume_index p = 0; p < h->npairs; p++)
        s[p] = h->engaged[h->hook_of[p]];
    return PLUME_OK;
}

static void hooks_term_destroy(void *ctx)
{
    plume_hooks *h = ctx;
    plume_hooks_destroy(&h);
}

static plume_index hooks_term_state_size(void *ctx)
{
    return plume_hooks_state_size(ctx);
}

static void hooks_term_state_get(void *ctx, double *s)
{
    plume_hooks_state_get(ctx, s);
}

static plume_status hooks_term_state_set(void *ctx, const double *s)
{
    return plume_hooks_state_set(ctx, s, NULL);
}

void plume_hooks_term(plume_hooks *h, int own, plume_term *t)
{
    memset(t, 0, sizeof *t);
    t->size = sizeof *t;
    t->name = "hooks";
    t->arity = 2;
    t->nstencil = h ? h->npairs : 0;
    t->stencil = h ? h->pairs : NULL;
    t->eval = hooks_eval;
    t->energies = hooks_energies;
    t->commit = hooks_term_commit;
    t->keep = hooks_term_keep;
    t->states = hooks_term_states;
    t->state_size = hooks_term_state_size;
    t->state_get = hooks_term_state_get;
    t->state_set = hooks_term_state_set;
    t->destroy = own ? hooks_term_destroy : NULL;
    t->partial_projection = h && h->soften > 1.0; /* set softening before the term */
    t->ctx = h;
}

plume_status plume_hooks_set_scale(plume_hooks *h, int k, double scale)
{
    if (!h || k < 0 || k >= h->nhooks || !(scale > 0.0) || !isfinite(scale))
        return PLUME_EINVAL;
    h->scale[k] = scale;
    return PLUME_OK;
}

plume_status plume_hooks_set_seating(plume_hooks *h, double distance)
{
    if (!h || !(distance >= 0.0) || !isfinite(distance))
        return PLUME_EINVAL;
    h->seat = distance;
    return PLUME_OK;
}

plume_status plume_hooks_set_softening(plume_hooks *h, double ratio)
{
    if (!h || !(ratio >= 1.0) || !isfinite(ratio))
        return PLUME_EINVAL;
    for (int k = 0; ratio > 1.0 && k < h->nhooks; k++)
        if (h->first[k + 1] - h->first[k] != 1)
            return PLUME_EINVAL;
    h->soften = ratio;
    return PLUME_OK;
}

plume_status plume_hooks_set_overshoot(plume_hooks *h, double factor)
{
    if (!h || !(factor > 1.0) || !isfinite(factor))
        return PLUME_EINVAL;
    h->overshoot = factor;
    return PLUME_OK;
}

int plume_hooks_count(const plume_hooks *h)
{
    return h ? h->nhooks : 0;
}

int plume_hooks_engaged(const plume_hooks *h, int k)
{
    return h && k >= 0 && k < h->nhooks ? h->engaged[k] : 0;
}

void plume_hooks_force(const plume_hooks *h, int dim, const double *x, int k, double *f)
{
    for (int c = 0; c < dim; c++)
        f[c] = 0.0;
    if (!h || k < 0 || k >= h->nhooks || !h->engaged[k])
        return;
    const double kp = pair_stiffness(h, k);
    for (plume_index p = h->first[k]; p < h->first[k + 1]; p++) {
        double d[3];
        pair_stretch(h, dim, x, p, d);
        if (h->soften > 1.0) {
            double W, g[3], H[9];
            soft_pair(h, k, dim, d, 0, &W, g, H);
            for (int c = 0; c < dim; c++)
                f[c] += g[c];
            continue;
        }
        for (int c = 0; c < dim; c++)
            f[c] += kp * d[c];
    }
}

double plume_hooks_max_load(const plume_hooks *h, int dim, const double *x, int *which)
{
    double worst = 0.0;
    int at = -1;
    for (int k = 0; h && k < h->nhooks; k++) {
        if (!h->engaged[k])
            continue;
        double f[3];
        plume_hooks_force(h, dim, x, k, f);
        const double r = norm(f, dim) / (h->scale[k] * h->law.strength);
        if (at < 0 || r > worst)
            worst = r, at = k;
    }
    if (which)
        *which = at;
    return worst;
}

/* hook k's energy at x */
static double hook_energy(const plume_hooks *h, int dim, const double *x, int k)
{
    double e = 0.0;
    for (plume_index p = h->first[k]; p < h->first[k + 1]; p++)
        e += pair_energy(h, dim, x, p);
    return e;
}

/* A softening hook k (one pair) at x: opened beyond its history, its history moves there (the
 * energy above the new secant is dissipated); at the end of its falling branch it lets go. */
static void soften(plume_hooks *h, int dim, const double *x, int k, plume_hooks_events *ev)
{
    double d[3];
    pair_stretch(h, dim, x, h->first[k], d);
    const double t = norm(d, dim);
    const soft_law l = soft_of(h, k);
    if (t <= l.ds)
        return;
    const double before = hook_energy(h, dim, x, k);
    if (t >= l.dc) {
        h->engaged[k] = 0;
        h->armed[k] = 0;
        ev->released++;
        ev->soft_released++;
    } else {
        h->dmax[k] = t;
        ev->softened++;
    }
    ev->energy_drop += before - hook_energy(h, dim, x, k);
}

/* An overloaded engaged hook k (|f| > strength): it slides while its slide allows, else lets go. */
static void overload(plume_hooks *h, int dim, const double *x, int k, const double *f, plume_hooks_events *ev)
{
    const double strength = h->scale[k] * h->law.strength;
    const double F = norm(f, dim), kh = strength / h->law.opening;
    const double move = (F - strength) / kh; /* the return map: |F| back to the strength */
    const double before = hook_energy(h, dim, x, k);
    if (h->law.slide > 0.0 && h->slid[k] + move <= h->law.slide) {
        for (plume_index p = h->first[k]; p < h->first[k + 1]; p++)
            for (int c = 0; c < dim; c++)
                h->offset[3 * p + c] += move * f[c] / F;
        h->slid[k] += move;
        ev->slid++;
    } else {
        h->engaged[k] = 0;
        h->armed[k] = 0;
        ev->released++;
    }
    ev->energy_drop += before - hook_energy(h, dim, x, k);
}

/* The mean distance of hook k's pairs at x, and the mean length of their offsets */
static void hook_gaps(const plume_hooks *h, int dim, const double *x, int k, double *gap, double *offset)
{
    double g = 0.0, o = 0.0;
    for (plume_index p = h->first[k]; p < h->first[k + 1]; p++) {
        const plume_index a = h->pairs[2 * p], b = h->pairs[2 * p + 1];
        double d[3];
        for (int c = 0; c < dim; c++)
            d[c] = x[dim * a + c] - x[dim * b + c];
        g += norm(d, dim);
        o += norm(h->offset + 3 * p, dim);
    }
    const double n = (double)(h->first[k + 1] - h->first[k]);
    *gap = g / n, *offset = o / n;
}

/* Seating (plume_hooks_set_seating): an engaged pair caught at a gap and pressed closer than it
 * by more than the seating distance takes the closer gap as its own: its offset shortens along n
 * by the closing, to zero where the lips met or passed each other. The closing within the band is
 * free and the resistance beyond it is about the meeting point (one_sided), so its force and
 * energy stay as they are; only where the pair holds from moves. 1 when a pair of hook k seated. */
static int seat(plume_hooks *h, int dim, const double *x, int k, plume_hooks_events *ev)
{
    int seated = 0;
    double before = 0.0;
    for (plume_index p = h->first[k]; p < h->first[k + 1]; p++) {
        double d[3], dn = 0.0, n[3];
        raw_stretch(h, dim, x, p, d);
        if (!one_sided(h, dim, d, p, &dn, n) || !(dn < -h->seat))
            continue;
        if (!seated) /* the energy before the hook's first seat, only when it seats */
            before = hook_energy(h, dim, x, k);
        double *o = h->offset + 3 * p;
        const double len = norm(o, dim), to = fmax(len + dn, 0.0);
        for (int c = 0; c < dim; c++)
            o[c] = to > 0.0 ? n[c] * to : 0.0;
        seated = 1;
    }
    if (seated) {
        ev->seated++;
        ev->energy_drop += before - hook_energy(h, dim, x, k);
    }
    return seated;
}

/* A released hook k catches again when the mean distance of its pairs is within the capture,
 * once it has opened clear of the barb since it let go. With seating on (split lines) a hook whose
 * lips come back within the seating distance catches too, whether or not they parted: a link by a
 * held line end lets go with its lips a micrometre apart and never parts further. */
static void catch_again(plume_hooks *h, int dim, const double *x, int k, plume_hooks_events *ev)
{
    double mean, offset;
    hook_gaps(h, dim, x, k, &mean, &offset);
    if (!(h->law.capture > 0.0))
        return;
    if (mean > h->law.capture) { /* opened clear of the barb: it may catch when pressed back */
        h->armed[k] = 1;
        return;
    }
    if (h->seat >= 0.0 && mean <= h->seat)
        h->armed[k] = 1;
    if (!h->armed[k])
        return;
    for (plume_index p = h->first[k]; p < h->first[k + 1]; p++) { /* offsets at the gaps: zero force */
        const plume_index a = h->pairs[2 * p], b = h->pairs[2 * p + 1];
        for (int c = 0; c < dim; c++)
            h->offset[3 * p + c] = x[dim * a + c] - x[dim * b + c];
    }
    h->engaged[k] = 1;
    h->armed[k] = 0;
    h->slid[k] = 0.0;
    h->dmax[k] = 0.0;
    ev->reengaged++;
}

plume_status plume_hooks_commit(plume_hooks *h, int dim, const double *x, plume_hooks_mode mode,
                                plume_hooks_events *ev, plume_err *err)
{
    if (!h || !x || dim < 1 || dim > 3)
        return plume_err_set(err, PLUME_EINVAL, "hooks commit: hooks, positions and a dimension 1-3 are required");
    if (mode != PLUME_HOOKS_ALL && mode != PLUME_HOOKS_ONE)
        return plume_err_set(err, PLUME_EINVAL, "hooks commit: unknown mode %d", (int)mode);
    plume_hooks_events e = {0};
    int most = -1;
    if (mode == PLUME_HOOKS_ONE)
        plume_hooks_max_load(h, dim, x, &most);
    for (int k = 0; k < h->nhooks; k++) { /* each hook once: one let go here does not catch here */
        if (!h->engaged[k]) {
            catch_again(h, dim, x, k, &e);
            continue;
        }
        if (h->seat >= 0.0)
            seat(h, dim, x, k, &e);
        double f[3];
        plume_hooks_force(h, dim, x, k, f);
        if (h->soften > 1.0) {
            if (mode == PLUME_HOOKS_ALL || k == most)
                soften(h, dim, x, k, &e);
            continue;
        }
        if (norm(f, dim) > h->scale[k] * h->law.strength && (mode == PLUME_HOOKS_ALL || k == most))
            overload(h, dim, x, k, f, &e);
    }
    h->released += e.released, h->reengaged += e.reengaged, h->dropped += e.energy_drop;
    if (ev)
        *ev = e;
    return PLUME_OK;
}

void plume_hooks_totals(const plume_hooks *h, long *released, long *reengaged, double *dropped)
{
    if (released)
        *released = h ? h->released : 0;
    if (reengaged)
        *reengaged = h ? h->reengaged : 0;
    if (dropped)
        *dropped = h ? h->dropped : 0.0;
}

plume_index plume_hooks_state_size(const plume_hooks *h)
{
    return h ? 4 * (plume_index)h->nhooks + 3 * h->npairs + 3 : 0;
}

void plume_hooks_state_get(const plume_hooks *h, double *s)
{
    const int n = h->nhooks;
    for (int k = 0; k < n; k++)
        s[k] = h->engaged[k], s[n + k] = h->armed[k], s[2 * n + k] = h->slid[k];
    memcpy(s + 3 * n, h->offset, 3 * (size_t)h->npairs * sizeof *s);
    memcpy(s + 3 * n + 3 * h->npairs, h->dmax, (size_t)n * sizeof *s);
    double *t = s + 4 * n + 3 * h->npairs;
    t[0] = (double)h->released, t[1] = (double)h->reengaged, t[2] = h->dropped;
}

plume_status plume_hooks_state_set(plume_hooks *h, const double *s, plume_err *err)
{
    if (!h || !s)
        return plume_err_set(err, PLUME_EINVAL, "hooks state: hooks and a state are required");
    const int n = h->nhooks;
    const plume_index size = plume_hooks_state_size(h);
    for (plume_index i = 0; i < size; i++)
        if (!isfinite(s[i]))
            return plume_err_set(err, PLUME_EINVAL, "hooks state: entry %ld is not finite", (long)i);
    for (int k = 0; k < n; k++)
        if ((s[k] != 0.0 && s[k] != 1.0) || (s[n + k] != 0.0 && s[n + k] != 1.0) || s[2 * n + k] < 0.0)
            return plume_err_set(err, PLUME_EINVAL, "hooks state: hook %d has engaged %g, armed %g, slid %g (flags are 0 "
                                 "or 1, the slide >= 0)", k, s[k], s[n + k], s[2 * n + k]);
    const double *kk = s + 3 * n + 3 * h->npairs, *t = kk + n;
    for (int k = 0; k < n; k++)
        if (kk[k] < 0.0)
            return plume_err_set(err, PLUME_EINVAL, "hooks state: hook %d has a softening history of %g m (an opening, "
                                 ">= 0)", k, kk[k]);
    if (t[0] < 0.0 || t[1] < 0.0 || t[2] < 0.0)
        return plume_err_set(err, PLUME_EINVAL, "hooks state: negative totals (%g released, %g caught, %g J)", t[0], t[1],
                             t[2]);
    for (int k = 0; k < n; k++)
        h->engaged[k] = (unsigned char)s[k], h->armed[k] = (unsigned char)s[n + k], h->slid[k] = s[2 * n + k];
    memcpy(h->offset, s + 3 * n, 3 * (size_t)h->npairs * sizeof *s);
    memcpy(h->dmax, kk, (size_t)n * sizeof *s);
    h->released = (long)t[0], h->reengaged = (long)t[1], h->dropped = t[2];
    return hooks_term_keep(h, 1);
}
