/* The contact term: candidates from the broad phase become arity-4 stencils (point–triangle
 * first, then edge–edge), evaluated with the pair potentials of contact_narrow.c; the barrier's
 * steps are limited by Additive CCD over the candidates of the swept boxes. */
#include "contact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact_broad.h"
#include "../core/vec3.h"
#include "../io/progress.h"

/* A pair acting at a step's last state: kind (0 point-triangle, 1 edge-edge) and its 4 vertices, the
 * key; its mollifier threshold and activation distance */
struct acting_pair {
    plume_index key[5];
    double eps, dhat;
};

struct plume_contact {
    plume_contact_term_opts o;
    plume_index nv;
    const plume_index *tri;       /* [3 ntri], owned by broad */
    double *elen2;                /* [ne] rest squared lengths of the broad phase's edges */
    plume_contact_broad *broad;
    plume_index ne;
    const plume_index *edges;     /* [2 ne], owned by broad */
    /* the stencils of the last update: npt point–triangle then nee edge–edge, 4 vertices each */
    plume_index npt, nee, cap;
    plume_index *stencil;         /* [4 cap] */
    double *eps;                  /* [cap] edge–edge mollifier thresholds (0 for point–triangle) */
    plume_index *scratch;         /* [4 cap] the next update's stencils, compared with the last */
    double *x1;                   /* [3 nv] the end of a step (max_step) */
    double *xstart;               /* [3 nv] the last state a step starts from (rebase), when has_start */
    int has_start;
    double *xupd;                 /* [3 nv] the positions of the last update, when has_upd */
    int has_upd;
    struct acting_pair *acting;   /* [nacting] the pairs acting at xstart (sorted by key), found at the
                                     step's first update */
    plume_index nacting;
    int acting_valid;             /* acting is xstart's (0 after a rebase) */
    /* self contact: pairs of one body already within reach at rest (a fine mesh next to a coarse
     * dhat) would be pushed apart from the first step; they get their own activation distance, half
     * their rest distance (sorted for bsearch) */
    plume_index nexcl;
    plume_index *excl;            /* [5 nexcl]: kind (0 point-triangle, 1 edge-edge), 4 vertices */
    double *excl_dhat;            /* [nexcl] */
    double *pdhat;                /* [cap] the activation distance of each stencil */
    plume_contact_stats st;
    /* the pair that limited the last max_step (limit_toi < 1), for reports */
    plume_index limit_v[4];
    int limit_ee;
    double limit_toi;
};

void plume_contact_term_opts_default(plume_contact_term_opts *o)
{
    memset(o, 0, sizeof *o);
    plume_contact_opts_default(&o->pair);
    o->self_contact = 0;
    o->margin = 0.0;
    plume_ccd_opts_default(&o->ccd);
}

const char *plume_contact_model_name(plume_contact_model m)
{
    return m == PLUME_CONTACT_BARRIER ? "barrier" : m == PLUME_CONTACT_PENALTY ? "penalty" : "unknown";
}

static void contact_destroy(void *ctx)
{
    plume_contact *c = ctx;
    if (!c)
        return;
    plume_contact_broad_destroy(&c->broad);
    free(c->elen2);
    free(c->stencil);
    free(c->eps);
    free(c->scratch);
    free(c->x1);
    free(c->xstart);
    free(c->xupd);
    free(c->acting);
    free(c->excl);
    free(c->excl_dhat);
    free(c->pdhat);
    free(c);
}

static int key_cmp(const void *a, const void *b)
{
    const plume_index *x = a, *y = b;
    for (int k = 0; k < 5; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* the activation distance of a pair (kind, vertices): dhat, or the reduced one of a pair within
 * reach at rest */
static double pair_dhat(const plume_contact *c, int kind, const plume_index v[4])
{
    if (c->nexcl == 0)
        return c->o.pair.dhat;
    plume_index key[5] = {kind, v[0], v[1], v[2], v[3]};
    const plume_index *f = bsearch(key, c->excl, (size_t)c->nexcl, 5 * sizeof *key, key_cmp);
    return f ? c->excl_dhat[(f - c->excl) / 5] : c->o.pair.dhat;
}

/* the four vertices of candidate k of a broad-phase answer: (v, t0, t1, t2) for the first nvt
 * (point–triangle), (ea0, ea1, eb0, eb1) after them (edge–edge) */
static void candidate_vertices(const plume_index *tri, const plume_index *edges, const plume_contact_candidates *cand,
                               plume_index k, plume_index v[4])
{
    if (k < cand->nvt) {
        const plume_index *t = tri + 3 * cand->vt[k].b;
        v[0] = cand->vt[k].a, v[1] = t[0], v[2] = t[1], v[3] = t[2];
    } else {
        const plume_index *a = edges + 2 * cand->ee[k - cand->nvt].a, *b = edges + 2 * cand->ee[k - cand->nvt].b;
        v[0] = a[0], v[1] = a[1], v[2] = b[0], v[3] = b[1];
    }
}

static void pair_vertices(const plume_contact *c, const plume_contact_candidates *cand, plume_index k,
                          plume_index v[4])
{
    candidate_vertices(c->tri, c->edges, cand, k, v);
}

static plume_status contact_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                                 int project)
{
    plume_contact *c = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    double t0 = plume_wall_seconds();
    /* With pair.project_psd = PLUME_CONTACT_PROJECT_GAUSS_NEWTON (the default) the exact Hessian
     * has the exact blocks and a projected one the Gauss-Newton blocks (the term's
     * partial_projection): newton tries the exact Hessian first and projects contact before
     * shifting anything. Gauss-Newton blocks on every iteration made Newton converge linearly at
     * every contact (the contact stack: 919 iterations and caps at 100, against 406 and none:
     * docs/solver-nonconvexity.md). EIGEN: the nearest PSD blocks always (IPC's choice). 0: exact
     * blocks, the nearest PSD ones when the solver asks for projection. */
    plume_contact_opts po = c->o.pair;
    if (project && !po.project_psd) /* exact blocks, but the solver wants PSD ones: the nearest */
        po.project_psd = PLUME_CONTACT_PROJECT_EIGEN;
    if (!project && po.project_psd == PLUME_CONTACT_PROJECT_GAUSS_NEWTON)
        po.project_psd = 0;
    plume_index ns = c->npt + c->nee;
    double E = 0.0;
    plume_status st = PLUME_OK;
    for (plume_index s = 0; s < ns && st == PLUME_OK; s++) {
        const plume_index *v = c->stencil + 4 * s;
        double xs[12], g[12], e = 0.0;
        double *H = hblocks ? hblocks + 144 * s : NULL;
        gather12(x, v, xs);
        po.dhat = c->pdhat[s];
        if (s < c->npt)
            st = plume_contact_pt_energy(&po, xs, &e, grad ? g : NULL, H, NULL);
        else
            st = plume_contact_ee_energy(&po, xs, c->eps[s], &e, grad ? g : NULL, H, NULL);
        if (st != PLUME_OK)
            break;
        E += e;
        if (grad)
            for (int a = 0; a < 12; a++)
                grad[3 * v[a / 3] + a % 3] += g[a];
    }
    c->st.narrow_seconds += plume_wall_seconds() - t0;
    if (st != PLUME_OK)
        return st; /* PLUME_ESINGULAR: a barrier pair at d = 0, an infeasible trial point */
    if (energy)
        *energy += E;
    return PLUME_OK;
}

/* room for n stencils */
static plume_status reserve(plume_contact *c, plume_index n)
{
    if (n <= c->cap)
        return PLUME_OK;
    plume_index cap = n + n / 2 + 16;
    plume_index *s = realloc(c->stencil, (size_t)(4 * cap) * sizeof *s);
    if (s)
        c->stencil = s;
    plume_index *w = realloc(c->scratch, (size_t)(4 * cap) * sizeof *w);
    if (w)
        c->scratch = w;
    double *e = realloc(c->eps, (size_t)cap * sizeof *e);
    if (e)
        c->eps = e;
    double *dh = realloc(c->pdhat, (size_t)cap * sizeof *dh);
    if (dh)
        c->pdhat = dh;
    if (!s || !w || !e || !dh)
        return PLUME_ENOMEM;
    c->cap = cap;
    return PLUME_OK;
}

static int acting_cmp(const void *a, const void *b)
{
    return key_cmp(((const struct acting_pair *)a)->key, ((const struct acting_pair *)b)->key);
}

/* The pairs that act at the step's last state x0 (within their dhat there), the potential's terms
 * the step starts from, into c->acting (sorted by key). From the last update's pairs when it was at
 * x0 (then they hold every pair within reach there), else from a query at x0 (a restart's first
 * step): the same pairs in one order either way, so a restart repeats a run bit for bit. */
static plume_status find_acting(plume_contact *c, const double *x0)
{
    const int from_last = c->has_upd && memcmp(c->xupd, x0, (size_t)(3 * c->nv) * sizeof *x0) == 0;
    plume_contact_candidates cand = {0};
    plume_status st = from_last ? PLUME_OK : plume_contact_broad_update(c->broad, x0, NULL, c->o.pair.dhat, &cand, NULL);
    if (st != PLUME_OK)
        return st;
    c->st.broad_seconds += from_last ? 0.0 : cand.seconds;
    const plume_index ncand = from_last ? c->npt + c->nee : cand.nvt + cand.nee;
    free(c->acting);
    c->nacting = 0;
    c->acting = malloc((size_t)(ncand + 1) * sizeof *c->acting);
    if (!c->acting)
        return PLUME_ENOMEM;
    for (plume_index o = 0; o < ncand; o++) {
        struct acting_pair *a = c->acting + c->nacting;
        plume_index *v = a->key + 1;
        if (from_last) {
            memcpy(v, c->stencil + 4 * o, 4 * sizeof *v);
            a->key[0] = o >= c->npt, a->dhat = c->pdhat[o], a->eps = c->eps[o];
        } else {
            pair_vertices(c, &cand, o, v);
            a->key[0] = o >= cand.nvt, a->dhat = pair_dhat(c, (int)a->key[0], v);
            a->eps = a->key[0] ? PLUME_CONTACT_MOLLIFIER_SCALE * c->elen2[cand.ee[o - cand.nvt].a] *
                                     c->elen2[cand.ee[o - cand.nvt].b]
                               : 0.0;
        }
        double xs[12], d2 = 0.0;
        gather12(x0, v, xs);
        st = a->key[0] ? plume_contact_ee_dist2(xs, &d2) : plume_contact_pt_dist2(xs, &d2);
        if (st != PLUME_OK)
            return st;
        c->nacting += a->dhat > 0.0 && d2 < a->dhat * a->dhat;
    }
    qsort(c->acting, (size_t)c->nacting, sizeof *c->acting, acting_cmp);
    c->acting_valid = 1;
    return PLUME_OK;
}

/* Adds to the n stencils of scratch (npt point-triangle first) the acting pairs not among them,
 * each kind after its own; *n and *npt grow */
static plume_status merge_acting(plume_contact *c, plume_index *n, plume_index *npt)
{
    plume_index *keys = malloc((size_t)(5 * *n + 1) * sizeof *keys);
    plume_index *add = malloc((size_t)(c->nacting + 1) * sizeof *add);
    if (!keys || !add) {
        free(keys);
        free(add);
        return PLUME_ENOMEM;
    }
    for (plume_index q = 0; q < *n; q++) {
        keys[5 * q] = q >= *npt;
        memcpy(keys + 5 * q + 1, c->scratch + 4 * q, 4 * sizeof *keys);
    }
    qsort(keys, (size_t)*n, 5 * sizeof *keys, key_cmp);
    plume_index nadd = 0, addpt = 0;
    for (plume_index k = 0; k < c->nacting; k++)
        if (!bsearch(c->acting[k].key, keys, (size_t)*n, 5 * sizeof *keys, key_cmp)) {
            add[nadd++] = k;
            addpt += c->acting[k].key[0] == 0;
        }
    free(keys);
    plume_status st = reserve(c, *n + nadd);
    if (st != PLUME_OK || nadd == 0) {
        free(add);
        return st;
    }
    /* the edge-edge block moves up by the point-triangle pairs added before it */
    plume_index *w = c->scratch;
    const plume_index nee = *n - *npt;
    memmove(w + 4 * (*npt + addpt), w + 4 * *npt, (size_t)(4 * nee) * sizeof *w);
    memmove(c->eps + *npt + addpt, c->eps + *npt, (size_t)nee * sizeof *c->eps);
    memmove(c->pdhat + *npt + addpt, c->pdhat + *npt, (size_t)nee * sizeof *c->pdhat);
    plume_index ipt = *npt, iee = *n + addpt;
    for (plume_index a = 0; a < nadd; a++) {
        const struct acting_pair *p = c->acting + add[a];
        const plume_index at = p->key[0] == 0 ? ipt++ : iee++;
        memcpy(w + 4 * at, p->key + 1, 4 * sizeof *w);
        c->eps[at] = p->eps;
        c->pdhat[at] = p->dhat;
    }
    *npt += addpt;
    *n += nadd;
    free(add);
    return PLUME_OK;
}

static plume_status contact_update(void *ctx, int dim, const double *x, const plume_index **stencil,
                                   plume_index *nstencil, int *changed)
{
    plume_contact *c = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    /* In a time step (after a rebase) the pairs that act at the step's last state stay: the
     * potential the step moves on from is then the one the last step ended with (a pair within its
     * dhat there but out of reach of the step's start would leave with its energy) */
    plume_status st = c->has_start && !c->acting_valid ? find_acting(c, c->xstart) : PLUME_OK;
    plume_contact_candidates cand;
    if (st == PLUME_OK)
        st = plume_contact_broad_update(c->broad, x, NULL, c->o.pair.dhat + c->o.margin, &cand, NULL);
    c->st.updates++;
    if (st == PLUME_OK) {
        c->st.broad_seconds += cand.seconds;
        st = reserve(c, cand.nvt + cand.nee);
    }
    /* the boxes' candidates, kept when truly within reach: fewer stencils to evaluate, and a
     * pattern that changes only when a pair comes within dhat + margin or leaves it */
    plume_index n = 0, npt = 0;
    for (plume_index k = 0; st == PLUME_OK && k < cand.nvt + cand.nee; k++) {
        plume_index *w = c->scratch;
        double xs[12], d2 = 0.0;
        pair_vertices(c, &cand, k, w + 4 * n);
        double dh = pair_dhat(c, k >= cand.nvt, w + 4 * n), r = dh + c->o.margin;
        if (!(dh > 0.0)) /* touching at rest: no barrier can act; CCD alone keeps it */
            continue;
        gather12(x, w + 4 * n, xs);
        st = k < cand.nvt ? plume_contact_pt_dist2(xs, &d2) : plume_contact_ee_dist2(xs, &d2);
        if (st != PLUME_OK || !(d2 < r * r))
            continue;
        c->pdhat[n] = dh;
        /* the edge-edge mollifier's threshold from the rest lengths (0: point-triangle); written in
         * place: when the set is unchanged the values are the same */
        c->eps[n] = k < cand.nvt ? 0.0
                                 : PLUME_CONTACT_MOLLIFIER_SCALE * c->elen2[cand.ee[k - cand.nvt].a] *
                                       c->elen2[cand.ee[k - cand.nvt].b];
        npt += k < cand.nvt;
        n++;
    }
    if (st == PLUME_OK && c->has_start && c->nacting > 0)
        st = merge_acting(c, &n, &npt);
    if (st != PLUME_OK)
        return st;
    memcpy(c->xupd, x, (size_t)(3 * c->nv) * sizeof *x);
    c->has_upd = 1;
    plume_index *w = c->scratch;
    *changed = npt != c->npt || n - npt != c->nee || (n > 0 && memcmp(w, c->stencil, (size_t)(4 * n) * sizeof *w) != 0);
    if (*changed) {
        c->scratch = c->stencil;
        c->stencil = w;
        c->npt = npt;
        c->nee = n - npt;
    }
    c->st.candidates = n;
    *stencil = c->stencil;
    *nstencil = n;
    return PLUME_OK;
}

/* plume_term.rebase: a time step starts from x (kept for the next updates) */
static plume_status contact_rebase(void *ctx, int dim, double *x)
{
    plume_contact *c = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    memcpy(c->xstart, x, (size_t)(3 * c->nv) * sizeof *x);
    c->has_start = 1;
    c->acting_valid = 0; /* found at the step's first update */
    return PLUME_OK;
}

/* Additive CCD over the pairs whose swept boxes meet: the largest fraction of dx that no pair
 * crosses (ccd.h: each pair keeps at least s of its starting gap) */
static plume_status contact_max_step(void *ctx, int dim, const double *x, const double *dx, double *alpha)
{
    plume_contact *c = ctx;
    *alpha = 1.0;
    if (dim != 3)
        return PLUME_EINVAL;
    if (c->o.pair.model != PLUME_CONTACT_BARRIER)
        return PLUME_OK; /* the penalty allows interpenetration: no step limit */
    for (plume_index i = 0; i < 3 * c->nv; i++)
        c->x1[i] = x[i] + dx[i];
    plume_contact_candidates cand;
    plume_status st = plume_contact_broad_update(c->broad, x, c->x1, 0.0, &cand, NULL);
    if (st != PLUME_OK)
        return st;
    c->st.broad_seconds += cand.seconds;
    double t0 = plume_wall_seconds(), a = 1.0;
    for (plume_index k = 0; k < cand.nvt + cand.nee && a > 0.0; k++) {
        plume_index v[4];
        pair_vertices(c, &cand, k, v);
        double x0s[12], x1s[12], toi = 1.0;
        gather12(x, v, x0s);
        gather12(c->x1, v, x1s);
        st = k < cand.nvt ? plume_ccd_point_triangle(x0s, x1s, 1.0, &c->o.ccd, &toi, NULL)
                          : plume_ccd_edge_edge(x0s, x1s, 1.0, &c->o.ccd, &toi, NULL);
        if (st == PLUME_EINFEASIBLE) { /* already touching: no step is safe */
            toi = 0.0;
            st = PLUME_OK;
        }
        if (st != PLUME_OK)
            break;
        if (toi < a) {
            memcpy(c->limit_v, v, sizeof v);
            c->limit_ee = k >= cand.nvt;
        }
        a = fmin(a, toi);
    }
    c->limit_toi = a;
    c->st.ccd_seconds += plume_wall_seconds() - t0;
    c->st.step_limits += a < 1.0;
    *alpha = a;
    return st;
}

int plume_contact_last_limit(const plume_contact *c, plume_index v[4], int *edge_edge, double *toi)
{
    if (!c || !(c->limit_toi < 1.0))
        return 0;
    if (v)
        memcpy(v, c->limit_v, sizeof c->limit_v);
    if (edge_edge)
        *edge_edge = c->limit_ee;
    if (toi)
        *toi = c->limit_toi;
    return 1;
}

/* The smallest distance below cap (cap when none), one broad-phase search inflated by cap */
static plume_status min_distance_within(plume_contact_broad *b, const double *x, double cap, double *dmin, plume_err *err)
{
    *dmin = cap;
    plume_contact_candidates cand;
    plume_status st = plume_contact_broad_update(b, x, NULL, cap, &cand, err);
    if (st != PLUME_OK)
        return st;
    plume_index ne, ntri;
    const plume_index *edges, *tri;
    plume_contact_broad_edges(b, &ne, &edges);
    plume_contact_broad_triangles(b, &ntri, &tri);
    double d2min = cap * cap;
    for (plume_index k = 0; k < cand.nvt + cand.nee; k++) {
        plume_index v[4];
        double xs[12], d2;
        candidate_vertices(tri, edges, &cand, k, v);
        gather12(x, v, xs);
        if ((st = k < cand.nvt ? plume_contact_pt_dist2(xs, &d2) : plume_contact_ee_dist2(xs, &d2)) != PLUME_OK)
            return plume_err_set(err, st, "contact: a candidate pair's distance failed (%s)", plume_strerror(st));
        d2min = fmin(d2min, d2);
    }
    *dmin = sqrt(d2min);
    return PLUME_OK;
}

/* The candidates within cap grow with cap squared (every layer of a bird's overlapping feathers
 * within 10 dhat of each other): bodies in contact are found within cap / 5 first (the bird:
 * 0.10 s a step against 1.0 s), and the search widens to cap only when nothing is that close. */
plume_status plume_contact_min_distance(plume_contact_broad *b, const double *x, double cap, double *dmin,
                                        plume_err *err)
{
    if (!b || !x || !dmin || !(cap > 0.0) || !isfinite(cap))
        return plume_err_set(err, PLUME_EINVAL, "contact: min distance needs a broad phase, positions and a cap > 0");
    plume_status st = min_distance_within(b, x, 0.2 * cap, dmin, err);
    if (st != PLUME_OK || *dmin < 0.2 * cap)
        return st;
    return min_distance_within(b, x, cap, dmin, err);
}

void plume_contact_term_pairs(const plume_contact *c, plume_index *npt, plume_index *nee, const plume_index **stencil,
                              const double **dhat, plume_contact_opts *opts)
{
    if (npt)
        *npt = c ? c->npt : 0;
    if (nee)
        *nee = c ? c->nee : 0;
    if (stencil)
        *stencil = c ? c->stencil : NULL;
    if (dhat)
        *dhat = c ? c->pdhat : NULL;
    if (opts && c)
        *opts = c->o.pair;
}

void plume_contact_term_stats(const plume_contact *c, plume_contact_stats *s)
{
    if (!s)
        return;
    memset(s, 0, sizeof *s);
    if (c) {
        *s = c->st;
        plume_contact_broad_stats(c->broad, &s->broad_updates, NULL);
        s->broad_searches = plume_contact_broad_searches(c->broad);
    }
}

/* The pairs of one body within dhat of each other at rest (self contact only) get the
 * activation distance half their rest distance: nothing pushes at rest, and a pair that closes
 * in is still repelled (and CCD still stops it crossing). */
static plume_status reduce_rest_pairs(plume_contact *c, const int *body, const double *xrest, plume_err *err)
{
    /* within dhat only: a pair farther apart at rest has no barrier energy there, whatever the
     * margin that makes it a candidate */
    const double reach = c->o.pair.dhat;
    plume_contact_candidates cand;
    plume_status st = plume_contact_broad_update(c->broad, xrest, NULL, reach, &cand, err);
    if (st != PLUME_OK)
        return st;
    plume_index n = cand.nvt + cand.nee;
    c->excl = malloc((size_t)(5 * n + 5) * sizeof *c->excl);
    double *d = malloc((size_t)(n + 1) * sizeof *d);
    c->excl_dhat = malloc((size_t)(n + 1) * sizeof *c->excl_dhat);
    if (!c->excl || !d || !c->excl_dhat) {
        free(d);
        return plume_err_set(err, PLUME_ENOMEM, "contact: out of memory");
    }
    for (plume_index k = 0; k < n; k++) {
        plume_index *key = c->excl + 5 * c->nexcl;
        double xs[12], d2 = 0.0;
        pair_vertices(c, &cand, k, key + 1);
        if (body && (body[key[1]] != body[key[2]] || body[key[1]] != body[key[3]] || body[key[1]] != body[key[4]]))
            continue;
        gather12(xrest, key + 1, xs);
        if ((st = k < cand.nvt ? plume_contact_pt_dist2(xs, &d2) : plume_contact_ee_dist2(xs, &d2)) != PLUME_OK) {
            free(d);
            return plume_err_set(err, st, "contact: a rest pair's distance failed (%s)", plume_strerror(st));
        }
        if (!(d2 < reach * reach))
            continue;
        key[0] = k >= cand.nvt;
        d[c->nexcl++] = 0.5 * sqrt(d2);
    }
    /* sort the keys, and their distances with them */
    plume_index *order = malloc((size_t)(6 * c->nexcl + 6) * sizeof *order);
    if (!order) {
        free(d);
        return plume_err_set(err, PLUME_ENOMEM, "contact: out of memory");
    }
    for (plume_index k = 0; k < c->nexcl; k++) {
        memcpy(order + 6 * k, c->excl + 5 * k, 5 * sizeof *order);
        order[6 * k + 5] = k;
    }
    qsort(order, (size_t)c->nexcl, 6 * sizeof *order, key_cmp);
    for (plume_index k = 0; k < c->nexcl; k++) {
        memcpy(c->excl + 5 * k, order + 6 * k, 5 * sizeof *order);
        c->excl_dhat[k] = d[order[6 * k + 5]];
    }
    free(order);
    free(d);
    c->st.excluded = c->nexcl;
    return PLUME_OK;
}

plume_status plume_contact_term_create(plume_index nv, plume_index ntri, const plume_index *tri, const int *body,
                                       const double *xrest, const plume_contact_term_opts *o, plume_term *out,
                                       plume_contact **handle, plume_err *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (handle)
        *handle = NULL;
    if (!out || !o || !xrest || !tri || nv <= 0 || ntri < 0)
        return plume_err_set(err, PLUME_EINVAL, "contact: NULL output, options, rest positions or triangles, or no vertex");
    if (!(o->pair.dhat > 0.0) || !isfinite(o->pair.dhat) || !(o->pair.stiffness > 0.0) ||
        !isfinite(o->pair.stiffness) || !(o->margin >= 0.0) || !isfinite(o->margin) ||
        (o->pair.model != PLUME_CONTACT_BARRIER && o->pair.model != PLUME_CONTACT_PENALTY))
        return plume_err_set(err, PLUME_EINVAL,
                             "contact: needs dhat > 0, stiffness > 0, margin >= 0 (all finite) and model barrier or "
                             "penalty (got dhat %g, stiffness %g, margin %g)",
                             o->pair.dhat, o->pair.stiffness, o->margin);
    if (!o->self_contact && !body)
        return plume_err_set(err, PLUME_EINVAL, "contact: without self_contact, body ids are needed");
    plume_contact *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->o = *o;
    c->o.weld = NULL; /* the broad phase keeps its copy */
    c->nv = nv;
    c->limit_toi = 1.0; /* no step limited yet */
    plume_contact_broad_opts bo;
    plume_contact_broad_opts_default(&bo);
    bo.self_contact = o->self_contact;
    bo.weld = o->weld;
    bo.reuse = 1; /* the stencil updates and every Newton step's CCD ask again as the bodies move a little */
    plume_status st = plume_contact_broad_create(nv, ntri, tri, body, &bo, &c->broad, err);
    if (st != PLUME_OK)
        goto fail;
    plume_contact_broad_edges(c->broad, &c->ne, &c->edges);
    plume_contact_broad_triangles(c->broad, NULL, &c->tri);
    c->elen2 = malloc((size_t)(c->ne + 1) * sizeof *c->elen2);
    c->x1 = malloc((size_t)(3 * nv) * sizeof *c->x1);
    c->xstart = malloc((size_t)(3 * nv) * sizeof *c->xstart);
    c->xupd = malloc((size_t)(3 * nv) * sizeof *c->xupd);
    if (!c->elen2 || !c->x1 || !c->xstart || !c->xupd || reserve(c, 64) != PLUME_OK) {
        st = plume_err_set(err, PLUME_ENOMEM, "contact: out of memory");
        goto fail;
    }
    for (plume_index e = 0; e < c->ne; e++) {
        const double *a = xrest + 3 * c->edges[2 * e], *b = xrest + 3 * c->edges[2 * e + 1];
        c->elen2[e] = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
    }
    if (o->self_contact && (st = reduce_rest_pairs(c, body, xrest, err)) != PLUME_OK)
        goto fail;
    out->name = "contact";
    out->arity = 4;
    out->nstencil = 0;
    out->stencil = c->stencil;
    out->size = sizeof *out;
    out->eval = contact_eval;
    out->destroy = contact_destroy;
    out->ctx = c;
    out->update = contact_update;
    out->rebase = contact_rebase;
    out->partial_projection = o->pair.project_psd == PLUME_CONTACT_PROJECT_GAUSS_NEWTON;
    out->max_step = o->pair.model == PLUME_CONTACT_BARRIER ? contact_max_step : NULL;
    if (handle)
        *handle = c;
    return PLUME_OK;
fail:
    contact_destroy(c);
    return st;
}
