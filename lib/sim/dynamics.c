#include "dynamics.h"
#include "../core/rigid_motion.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../io/progress.h"

void plume_dynamics_opts_default(plume_dynamics_opts *o)
{
    memset(o, 0, sizeof *o);
    o->dt = 1e-2;
    o->gravity[2] = -9.81;
    o->max_halvings = 6;
    o->solver = PLUME_SOLVER_NEWTON;
    plume_solver_opts_default(&o->solver_opts);
    o->stall_iterations = 6;
    o->easy_iterations = 5;
    o->tangent_predictor = 1;
}

/* 1/(2 dt^2) sum_v m_v |x_v - xt_v|^2 - sum_v m_v g.x_v: inertia of implicit Euler and gravity. */
typedef struct {
    plume_index nv;
    plume_index *stencil; /* 0..nv-1 */
    double *mass;         /* [nv] */
    double *xt;           /* [3 nv] predicted positions x_n + dt v_n */
    double inv_dt2;
    double g[3];
} inertia_ctx;

static void inertia_destroy(void *ctx)
{
    inertia_ctx *c = ctx;
    if (!c)
        return;
    free(c->stencil);
    free(c->mass);
    free(c->xt);
    free(c);
}

static plume_status inertia_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                                 int project)
{
    (void)project; /* blocks are m/dt^2 I: PSD */
    const inertia_ctx *c = ctx;
    if (dim != 3)
        return PLUME_EINVAL;
    for (plume_index v = 0; v < c->nv; v++) {
        double m = c->mass[v], k = m * c->inv_dt2;
        for (int a = 0; a < 3; a++) {
            double d = x[3 * v + a] - c->xt[3 * v + a];
            if (energy)
                *energy += 0.5 * k * d * d - m * c->g[a] * x[3 * v + a];
            if (grad)
                grad[3 * v + a] += k * d - m * c->g[a];
        }
        if (hblocks) {
            double *H = hblocks + 9 * v;
            memset(H, 0, 9 * sizeof *H);
            H[0] = H[4] = H[8] = k;
        }
    }
    return PLUME_OK;
}

typedef struct {
    plume_index nv;
    plume_index *vertices;
    int nkeys;
    double *times, *offsets, *rotations; /* rotations NULL: translation only */
    double pivot[3];
    double *y0;                          /* [3 nv] the vertices' positions at creation */
} handle_copy;

struct plume_dynamics {
    const plume_mesh *mesh;
    plume_problem *p;
    plume_solver *s;
    plume_dynamics_opts o;
    inertia_ctx *inertia; /* owned by the problem */
    handle_copy *handles;
    int nhandles;
    double t;
    double *x, *v, *xsave, *vsave, *u, *lambda, *lsave, *lsave2;
    double *xh, *dx; /* [ndof] a step's start with the handles moved; a motion checked by CCD (0 on
                        the extras) */
    plume_index ne;  /* the problem's unknowns after the vertices (edge angles): no mass, no velocity */
    double *e, *esave; /* [ne] their values at the state (after the step start's re-basing) */
    plume_index n, m;
    int last_iterations; /* the solver iterations of the last step attempted */
    int past_factorizations;    /* those of solvers renewed since (plume_dynamics_stats) */
    double past_factor_seconds;
    plume_energy_ledger ledger; /* the energies since the first step (or the last set_state) */
    double *xtmp;               /* [ndof] the problem's x while the ledger's start is measured */
};

void plume_dynamics_destroy(plume_dynamics **pd)
{
    if (!pd || !*pd)
        return;
    plume_dynamics *d = *pd;
    plume_solver_destroy(&d->s);
    for (int h = 0; h < d->nhandles; h++) {
        free(d->handles[h].vertices);
        free(d->handles[h].times);
        free(d->handles[h].offsets);
        free(d->handles[h].rotations);
        free(d->handles[h].y0);
    }
    free(d->handles);
    free(d->x);
    free(d->v);
    free(d->xsave);
    free(d->xh);
    free(d->dx);
    free(d->vsave);
    free(d->u);
    free(d->lambda);
    free(d->lsave);
    free(d->lsave2);
    free(d->e);
    free(d->esave);
    free(d->xtmp);
    plume_ledger_free(&d->ledger);
    free(d);
    *pd = NULL;
}

/* where handle h puts its vertex i at time t (rigid_motion.h) */
static void handle_position(const handle_copy *h, plume_index i, double t, double out[3])
{
    const plume_rigid_motion m = {h->nkeys, h->times, h->offsets, h->rotations, h->pivot};
    plume_rigid_motion_apply(&m, t, h->y0 + 3 * i, out);
}

static plume_status copy_handles(plume_dynamics *d, const plume_mesh *mesh, const double *x0, const plume_handle *hs,
                                 int nh, plume_err *err)
{
    d->handles = calloc((size_t)(nh + 1), sizeof *d->handles);
    if (!d->handles)
        return PLUME_ENOMEM;
    d->nhandles = nh;
    for (int h = 0; h < nh; h++) {
        const plume_handle *in = hs + h;
        if (in->nvertices < 1 || !in->vertices || in->nkeys < 1 || !in->times || !in->offsets)
            return plume_err_set(err, PLUME_EINVAL, "handle %d: needs at least one vertex and one keyframe", h);
        for (int k = 0; k < in->nkeys; k++) {
            if (!isfinite(in->times[k]) || (k > 0 && !(in->times[k] > in->times[k - 1])))
                return plume_err_set(err, PLUME_EINVAL, "handle %d: keyframe times must be finite and increasing (key %d)",
                                     h, k);
            for (int a = 0; a < 3; a++)
                if (!isfinite(in->offsets[3 * k + a]) || (in->rotations && !isfinite(in->rotations[3 * k + a])))
                    return plume_err_set(err, PLUME_EINVAL, "handle %d: keyframe %d has a non-finite offset or rotation",
                                         h, k);
        }
        for (int a = 0; a < 3; a++)
            if (!isfinite(in->pivot[a]))
                return plume_err_set(err, PLUME_EINVAL, "handle %d: the pivot must be finite", h);
        handle_copy *c = d->handles + h;
        c->nv = in->nvertices;
        c->nkeys = in->nkeys;
        c->vertices = malloc((size_t)in->nvertices * sizeof *c->vertices);
        c->times = malloc((size_t)in->nkeys * sizeof *c->times);
        c->offsets = malloc((size_t)(3 * in->nkeys) * sizeof *c->offsets);
        c->rotations = in->rotations ? malloc((size_t)(3 * in->nkeys) * sizeof *c->rotations) : NULL;
        c->y0 = malloc((size_t)(3 * in->nvertices) * sizeof *c->y0);
        if (!c->vertices || !c->times || !c->offsets || !c->y0 || (in->rotations && !c->rotations))
            return PLUME_ENOMEM;
        for (plume_index i = 0; i < in->nvertices; i++) {
            if (in->vertices[i] < 0 || in->vertices[i] >= mesh->nv)
                return plume_err_set(err, PLUME_EINVAL, "handle %d: vertex %ld out of range [0, %ld)", h,
                                     (long)in->vertices[i], (long)mesh->nv);
            c->vertices[i] = in->vertices[i];
            memcpy(c->y0 + 3 * i, x0 + 3 * in->vertices[i], 3 * sizeof *x0);
        }
        if (in->rotations)
            memcpy(c->rotations, in->rotations, (size_t)(3 * in->nkeys) * sizeof *c->rotations);
        memcpy(c->pivot, in->pivot, sizeof c->pivot);
        memcpy(c->times, in->times, (size_t)in->nkeys * sizeof *c->times);
        memcpy(c->offsets, in->offsets, (size_t)(3 * in->nkeys) * sizeof *c->offsets);
    }
    return PLUME_OK;
}

/* What plume_dynamics_create checks beyond its pointers: a shell-mode problem over the mesh, the
 * step options and the surface densities. */
static plume_status check_dynamics_inputs(const plume_mesh *mesh, const plume_problem *p, const double *density,
                                          int ndensity, const plume_dynamics_opts *o, plume_err *err)
{
    if (plume_problem_dim(p) != 3 || plume_problem_nvert(p) != mesh->nv)
        return plume_err_set(err, PLUME_EINVAL, "dynamics: needs a shell-mode (dim 3) problem over the mesh's vertices");
    if (!(o->dt > 0.0) || !isfinite(o->dt) || o->max_halvings < 0)
        return plume_err_set(err, PLUME_EINVAL, "dynamics: dt must be finite and > 0 (got %g)", o->dt);
    if (o->adaptive && (!(o->dt_max >= 0.0) || !isfinite(o->dt_max) || o->stall_iterations < 0 || o->easy_iterations < 1))
        return plume_err_set(err, PLUME_EINVAL,
                             "dynamics: adaptive steps need dt_max >= 0 and finite, stall_iterations >= 0 and "
                             "easy_iterations >= 1 (got %g, %d, %d)", o->dt_max, o->stall_iterations, o->easy_iterations);
    for (int k = 0; k < 3; k++)
        if (!isfinite(o->gravity[k]))
            return plume_err_set(err, PLUME_EINVAL, "dynamics: gravity must be finite");
    for (int k = 0; k < ndensity; k++)
        if (!(density[k] > 0.0) || !isfinite(density[k]))
            return plume_err_set(err, PLUME_EINVAL, "dynamics: surface density %d must be finite and > 0 (got %g)", k,
                                 density[k]);
    return PLUME_OK;
}

/* The inertia term's context: lumped masses (a third of each triangle per vertex), gravity and
 * 1/dt^2; xt is set by each step. Fails on a triangle whose material has no density. */
static plume_status inertia_create(const plume_mesh *mesh, const double *density, int ndensity,
                                   const plume_dynamics_opts *o, inertia_ctx **out, plume_err *err)
{
    plume_index nv = mesh->nv;
    inertia_ctx *in = calloc(1, sizeof *in);
    if (!in)
        return PLUME_ENOMEM;
    in->nv = nv;
    in->stencil = malloc((size_t)nv * sizeof *in->stencil);
    in->mass = calloc((size_t)nv, sizeof *in->mass);
    in->xt = calloc((size_t)(3 * nv), sizeof *in->xt);
    if (!in->stencil || !in->mass || !in->xt) {
        inertia_destroy(in);
        return PLUME_ENOMEM;
    }
    memcpy(in->g, o->gravity, sizeof in->g);
    in->inv_dt2 = 1.0 / (o->dt * o->dt);
    for (plume_index v = 0; v < nv; v++)
        in->stencil[v] = v;
    for (plume_index t = 0; t < mesh->nt; t++) {
        int id = mesh->material[t];
        if (id < 0 || id >= ndensity) {
            inertia_destroy(in);
            return plume_err_set(err, PLUME_EINVAL, "dynamics: triangle %ld has material %d without a density", (long)t,
                                 id);
        }
        double m3 = density[id] * fabs(plume_mesh_ref_area(mesh, t)) / 3.0;
        for (int k = 0; k < 3; k++)
            in->mass[mesh->tri[3 * t + k]] += m3;
    }
    *out = in;
    return PLUME_OK;
}

/* The handles' vertices are fixed dofs of the problem: their motion is prescribed. */
static void fix_handle_dofs(const plume_dynamics *d, plume_err *err)
{
    for (int h = 0; h < d->nhandles; h++)
        for (plume_index i = 0; i < d->handles[h].nv; i++)
            for (int a = 0; a < 3; a++)
                plume_problem_fix_dof(d->p, 3 * d->handles[h].vertices[i] + a, err);
}

/* The state and the step's workspaces, sized by the finalized problem (n free dofs, m
 * constraints); x starts at the problem's x, v at rest. */
static plume_status alloc_state(plume_dynamics *d)
{
    d->n = plume_problem_nfree(d->p);
    d->m = plume_problem_ncons(d->p);
    size_t nd = (size_t)(3 * d->mesh->nv), nfull = (size_t)plume_problem_ndof(d->p);
    d->ne = (plume_index)(nfull - nd);
    d->x = malloc(nd * sizeof *d->x);
    d->v = calloc(nd, sizeof *d->v);
    d->xsave = malloc(nd * sizeof *d->xsave);
    d->xh = calloc(nfull, sizeof *d->xh);
    d->dx = calloc(nfull, sizeof *d->dx);
    d->e = malloc((size_t)(d->ne + 1) * sizeof *d->e);
    d->esave = malloc((size_t)(d->ne + 1) * sizeof *d->esave);
    d->vsave = malloc(nd * sizeof *d->vsave);
    d->u = malloc((size_t)(d->n + 1) * sizeof *d->u);
    d->lambda = calloc((size_t)(d->m + 1), sizeof *d->lambda);
    d->lsave = calloc((size_t)(d->m + 1), sizeof *d->lsave);
    d->lsave2 = calloc((size_t)(d->m + 1), sizeof *d->lsave2);
    d->xtmp = malloc(nfull * sizeof *d->xtmp);
    if (!d->x || !d->v || !d->xsave || !d->xh || !d->dx || !d->vsave || !d->u || !d->lambda || !d->lsave || !d->lsave2 ||
        !d->e || !d->esave || !d->xtmp || plume_ledger_alloc(&d->ledger, d->mesh->nv, (plume_index)nfull) != PLUME_OK)
        return PLUME_ENOMEM;
    memcpy(d->x, plume_problem_x(d->p), nd * sizeof *d->x);
    memcpy(d->e, plume_problem_x(d->p) + nd, (size_t)d->ne * sizeof *d->e);
    return PLUME_OK;
}

plume_status plume_dynamics_create(const plume_mesh *mesh, plume_problem *p, const double *density, int ndensity,
                                   const plume_handle *handles, int nhandles, const plume_dynamics_opts *o,
                                   plume_dynamics **out, plume_err *err)
{
    if (!mesh || !p || !density || ndensity < 1 || (nhandles > 0 && !handles) || !o || !out)
        return plume_err_set(err, PLUME_EINVAL, "dynamics: invalid arguments");
    *out = NULL;
    plume_status st = check_dynamics_inputs(mesh, p, density, ndensity, o, err);
    if (st != PLUME_OK)
        return st;
    plume_dynamics *d = calloc(1, sizeof *d);
    if (!d)
        return PLUME_ENOMEM;
    d->mesh = mesh;
    d->p = p;
    d->o = *o;
    if (o->adaptive && o->solver == PLUME_SOLVER_NEWTON && d->o.solver_opts.stall_iterations == 0)
        d->o.solver_opts.stall_iterations = o->stall_iterations;
    inertia_ctx *in = NULL;
    if ((st = inertia_create(mesh, density, ndensity, o, &in, err)) != PLUME_OK) {
        free(d);
        return st;
    }
    plume_term term = {.size = sizeof(plume_term), .name = "inertia", .arity = 1, .nstencil = mesh->nv, .stencil = in->stencil,
                       .eval = inertia_eval, .destroy = inertia_destroy, .ctx = in};
    d->inertia = in;
    if ((st = plume_problem_add_term(p, &term, err)) != PLUME_OK) {
        free(d);
        return st;
    }
    if ((st = copy_handles(d, mesh, plume_problem_x(p), handles, nhandles, err)) != PLUME_OK)
        goto fail;
    fix_handle_dofs(d, err);
    if ((st = plume_problem_finalize(p, err)) != PLUME_OK)
        goto fail;
    plume_err why;
    if ((st = plume_solver_create(o->solver, p, &d->o.solver_opts, &d->s, &why)) != PLUME_OK) {
        plume_err_set(err, st, "dynamics: cannot create the %s solver: %s", plume_solver_kind_name(o->solver), why.msg);
        goto fail;
    }
    if ((st = alloc_state(d)) != PLUME_OK)
        goto fail;
    *out = d;
    return PLUME_OK;
fail:
    plume_dynamics_destroy(&d);
    return st;
}

/* Terms whose stencils follow the state (contact) at the problem's x: a new pattern needs a new
 * solver (its symbolic analysis, in the fixed pattern's order while that fits); *changed says
 * whether it happened. */
static plume_status refresh_stencils(plume_dynamics *d, int *changed, plume_err *err)
{
    plume_status st = plume_problem_update_terms(d->p, changed, err);
    if (st != PLUME_OK || !*changed)
        return st;
    if (d->s) {
        int nf = 0;
        double fs = 0.0;
        plume_solver_stats(d->s, NULL, &nf, &fs); /* the renewed solver counts from zero */
        d->past_factorizations += nf, d->past_factor_seconds += fs;
        return plume_solver_renew(&d->s, &d->o.solver_opts, err);
    }
    return plume_solver_create(d->o.solver, d->p, &d->o.solver_opts, &d->s, err);
}

/* Where a step with terms that limit steps (contact with CCD) starts: at the handles' targets and
 * the inertial prediction x_n + dt v_n together when that motion crosses nothing; otherwise the
 * handles move first, and that motion must cross nothing (else the step fails and is halved:
 * *safe = 0), then the free dofs start at the safe fraction of the prediction, whose full value
 * stays the inertia's target (*limited = 1 when it was cut). x holds x_n on entry, with the
 * handles at x_n too. */
static plume_status safe_start(plume_dynamics *d, const double *xh, int *safe, int *limited)
{
    plume_index nd = 3 * d->mesh->nv;
    double *x = plume_problem_x(d->p), *dx = d->dx;
    double a = 1.0;
    /* everything at once first: attached shells move with their handles (a flapping wing), and
     * checking the handles alone against shells standing still would refuse such steps */
    for (plume_index i = 0; i < nd; i++)
        dx[i] = xh[i] - x[i];
    plume_status st = plume_problem_max_motion(d->p, dx, &a);
    if (st != PLUME_OK)
        return st;
    if (a >= 1.0) {
        memcpy(x, xh, (size_t)nd * sizeof *x);
        *safe = 1;
        return PLUME_OK;
    }
    for (plume_index i = 0; i < nd; i++) /* the handles' move (0 on the free dofs) */
        dx[i] = plume_problem_is_fixed(d->p, i) ? xh[i] - x[i] : 0.0;
    a = 1.0;
    st = plume_problem_max_motion(d->p, dx, &a);
    if (st != PLUME_OK)
        return st;
    *safe = a >= 1.0;
    if (!*safe)
        return PLUME_OK;
    for (plume_index i = 0; i < nd; i++)
        if (plume_problem_is_fixed(d->p, i))
            x[i] = xh[i];
    for (plume_index i = 0; i < nd; i++)
        dx[i] = plume_problem_is_fixed(d->p, i) ? 0.0 : d->inertia->xt[i] - x[i];
    if ((st = plume_problem_max_motion(d->p, dx, &a)) != PLUME_OK)
        return st;
    for (plume_index i = 0; i < nd; i++)
        x[i] += a * dx[i];
    *limited = a < 1.0;
    return PLUME_OK;
}

/* Whether a step starts from the tangent predictor: the option is on, the solver is native (Ipopt
 * has no tangent solve) and the handles' targets xh leave the inertial prediction xt. Handles at
 * rest or moving at a constant velocity are already where x + dt v puts them; the predictor would
 * then only answer the residual, one more Newton step counted as none. */
static int step_predicted(const plume_dynamics *d, const double *xt, const double *xh)
{
    if (!d->o.tangent_predictor || d->o.solver == PLUME_SOLVER_IPOPT)
        return 0;
    const double tol = 1e-12 * plume_problem_length_scale(d->p);
    for (int h = 0; h < d->nhandles; h++)
        for (plume_index i = 0; i < d->handles[h].nv; i++) {
            plume_index v = d->handles[h].vertices[i];
            for (int c = 0; c < 3; c++)
                if (fabs(xh[3 * v + c] - xt[3 * v + c]) > tol)
                    return 1;
        }
    return 0;
}

/* The tangent predictor from the positions in the problem (handles at their x~) to the handles'
 * targets xh; where it fails, the plain start (every vertex at xh, the multipliers as they were). */
static plume_status predict_start(plume_dynamics *d, const double *xh, plume_step_report *rep, plume_err *err)
{
    double *x = plume_problem_x(d->p);
    plume_problem_gather(d->p, d->u);
    memcpy(d->lsave2, d->lambda, (size_t)d->m * sizeof *d->lambda);
    int nf = 0;
    plume_status st = plume_solver_predict(d->s, d->u, d->lambda, xh, &nf, NULL);
    rep->predictions++;
    if (st == PLUME_ENOMEM)
        return plume_err_set(err, st, "dynamics: out of memory");
    if (st != PLUME_OK) {
        memcpy(x, xh, (size_t)plume_problem_ndof(d->p) * sizeof *x);
        memcpy(d->lambda, d->lsave2, (size_t)d->m * sizeof *d->lambda);
    }
    return PLUME_OK;
}

/* A step's start, before the state is saved: the problem's x at the state (x_n and the extras),
 * where the terms re-base their frames (plume_term.rebase: midedge bending's angles become 0, the
 * directors kept; again after a failed attempt, where it changes nothing); the extras' state
 * follows, and a step's extras start where they are. */
static plume_status rebase_at_start(plume_dynamics *d, plume_err *err)
{
    const plume_index nd = 3 * d->mesh->nv;
    double *x = plume_problem_x(d->p);
    memcpy(x, d->x, (size_t)nd * sizeof *x);
    memcpy(x + nd, d->e, (size_t)d->ne * sizeof *x);
    plume_status st = plume_problem_rebase_terms(d->p);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "dynamics: the terms could not re-base their frames at t = %g (%s)", d->t,
                             plume_strerror(st));
    memcpy(d->e, x + nd, (size_t)d->ne * sizeof *d->e);
    memcpy(d->xh + nd, d->e, (size_t)d->ne * sizeof *d->e);
    return PLUME_OK;
}

/* The stateful terms (plume_term.commit: split lines' links) at a converged step's solution: they
 * commit, and while they change their state the step is solved again at the same time, from where
 * it stands. Only the first commit may refuse a link loaded too far past its threshold (may_cut:
 * the step can still be halved); then *ok = 0 and the step is halved. A solve that fails, or a
 * state still changing after PLUME_DYNAMICS_MAX_SETTLES solves, fails the step the same way. */
#define PLUME_DYNAMICS_MAX_SETTLES 100
static plume_status settle_terms(plume_dynamics *d, int may_cut, plume_step_report *rep, int *ok, double *drop,
                                 plume_err *err)
{
    *ok = 1;
    for (int n = 0;; n++) {
        plume_commit_report c;
        plume_err why = {{0}};
        const plume_ledger_inertia li = {d->mesh->nv, d->inertia->mass, d->inertia->xt, d->inertia->inv_dt2};
        plume_status st = plume_ledger_before_commit(&d->ledger, d->p, &li);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "dynamics: the energies at t = %g could not be evaluated (%s)", d->t,
                                 plume_strerror(st));
        st = plume_problem_commit_terms(d->p, may_cut && n == 0, &c, &why);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "dynamics: at t = %g: %s", d->t, why.msg);
        if (c.overshoot || (c.changed && n == PLUME_DYNAMICS_MAX_SETTLES)) {
            *ok = 0;
            if (rep->converged && !c.overshoot)
                rep->reason = PLUME_REASON_ITERATION_CAP;
            return PLUME_OK;
        }
        *drop += c.energy_drop;
        if ((c.changed || c.energy_drop != 0.0) && (st = plume_ledger_after_commit(&d->ledger, d->p, &li)) != PLUME_OK)
            return plume_err_set(err, st, "dynamics: the energies at t = %g could not be evaluated (%s)", d->t,
                                 plume_strerror(st));
        if (!c.changed)
            return PLUME_OK;
        int changed = 0;
        if ((st = refresh_stencils(d, &changed, err)) != PLUME_OK)
            return st;
        plume_solve_report sr;
        plume_problem_gather(d->p, d->u);
        if ((st = plume_solver_solve(d->s, d->u, d->lambda, &sr)) != PLUME_OK)
            return plume_err_set(err, st, "dynamics: the %s solver failed at t = %g (%s)",
                                 plume_solver_kind_name(d->o.solver), d->t, plume_strerror(st));
        rep->iterations += sr.iterations;
        rep->backtracks += sr.backtracks;
        rep->shifts += sr.shifts;
        rep->step_limited += sr.step_limited;
        if (!sr.converged) {
            *ok = 0;
            if (rep->converged)
                rep->reason = sr.reason;
            return PLUME_OK;
        }
        rep->max_violation = fmax(rep->max_violation, sr.max_violation);
    }
}

/* The energy ledger's start: the state's potential and kinetic energy, measured with the stencils
 * of the first step (the problem's x set to the state meanwhile, then back to the step's start). */
static plume_status ledger_start(plume_dynamics *d, plume_err *err)
{
    double *x = plume_problem_x(d->p);
    const size_t nd = (size_t)(3 * d->mesh->nv), nfull = nd + (size_t)d->ne;
    memcpy(d->xtmp, x, nfull * sizeof *x);
    memcpy(x, d->x, nd * sizeof *x);
    memcpy(x + nd, d->e, (size_t)d->ne * sizeof *x);
    const plume_ledger_inertia li = {d->mesh->nv, d->inertia->mass, d->inertia->xt, d->inertia->inv_dt2};
    plume_status st = plume_ledger_start(&d->ledger, d->p, &li, d->v);
    memcpy(x, d->xtmp, nfull * sizeof *x);
    return st == PLUME_OK ? PLUME_OK
                          : plume_err_set(err, st, "dynamics: the energies at t = %g could not be evaluated (%s)", d->t,
                                          plume_strerror(st));
}

/* One implicit Euler step of size dt from the current state; 1 when it converged. may_cut: the
 * step may still be halved (stateful terms may then refuse it, settle_terms). */
static plume_status try_step(plume_dynamics *d, double dt, int may_cut, plume_step_report *rep, int *ok,
                             plume_err *err)
{
    plume_index nv = d->mesh->nv;
    inertia_ctx *in = d->inertia;
    double *x = plume_problem_x(d->p), *xh = d->xh;
    int limits = plume_problem_limits_steps(d->p);
    plume_status st = plume_problem_lag_terms(d->p, x); /* friction lags at x_n (x holds the state: rebase_at_start) */
    if (st != PLUME_OK)
        return plume_err_set(err, st, "dynamics: the terms could not take the state at t = %g (%s)", d->t,
                             plume_strerror(st));
    for (plume_index i = 0; i < 3 * nv; i++)
        in->xt[i] = xh[i] = d->x[i] + dt * d->v[i];
    in->inv_dt2 = 1.0 / (dt * dt);
    for (int h = 0; h < d->nhandles; h++)
        for (plume_index i = 0; i < d->handles[h].nv; i++)
            handle_position(d->handles + h, i, d->t + dt, xh + 3 * d->handles[h].vertices[i]);
    if (limits) {
        int safe = 1, limited = 0;
        memcpy(x, d->x, (size_t)(3 * nv) * sizeof *x);
        if ((st = safe_start(d, xh, &safe, &limited)) != PLUME_OK)
            return plume_err_set(err, st, "dynamics: collision detection failed at t = %g (%s)", d->t,
                                 plume_strerror(st));
        rep->step_limited += limited;
        if (!safe) {
            *ok = 0;
            if (rep->converged)
                rep->reason = PLUME_REASON_PRESCRIBED_CROSSING; /* the handles would cross: a smaller step */
            return PLUME_OK;
        }
        if (!limited && step_predicted(d, in->xt, xh)) {
            /* every vertex is at xh, reached without a crossing; the predictor starts again from the
             * handles at their own x~, moves them to their targets with the tangent response of the
             * rest, and cuts that response where continuous collision detection says */
            for (plume_index i = 0; i < 3 * nv; i++)
                if (plume_problem_is_fixed(d->p, i))
                    x[i] = in->xt[i];
            if ((st = predict_start(d, xh, rep, err)) != PLUME_OK)
                return st;
        }
    } else if (step_predicted(d, in->xt, xh)) {
        /* x~ everywhere, handles included (their own inertial prediction); the predictor moves the
         * handles to their targets along the tangent and the free dofs with them */
        memcpy(x, in->xt, (size_t)(3 * nv) * sizeof *x);
        if ((st = predict_start(d, xh, rep, err)) != PLUME_OK)
            return st;
    } else {
        memcpy(x, xh, (size_t)(3 * nv) * sizeof *x);
    }
    int changed = 0;
    if ((st = refresh_stencils(d, &changed, err)) != PLUME_OK || (!d->ledger.started && (st = ledger_start(d, err)) != PLUME_OK))
        return st;
    plume_ledger_begin(&d->ledger, d->xsave, d->esave);
    plume_problem_gather(d->p, d->u);
    plume_solve_report sr;
    st = plume_solver_solve(d->s, d->u, d->lambda, &sr);
    /* a pair that came within reach during the solve is not among the stencils: solve again with
     * it (at most twice more after a converged solve; the solution then includes every pair it
     * touches), and from where a solve stopped because such a pair blocked its steps (up to 8 times;
     * when the stencils did not change, that solve's failure stands) */
    for (int again = 0, blocked = 0; st == PLUME_OK && again < 2 && blocked < 8;) {
        const int was_blocked = sr.reason == PLUME_REASON_CONTACT_SET;
        if (!sr.converged && !was_blocked)
            break;
        again += !was_blocked;
        blocked += was_blocked;
        if ((st = refresh_stencils(d, &changed, err)) != PLUME_OK || !changed)
            break;
        rep->iterations += sr.iterations;
        plume_problem_gather(d->p, d->u);
        st = plume_solver_solve(d->s, d->u, d->lambda, &sr);
    }
    if (st != PLUME_OK)
        return plume_err_set(err, st, "dynamics: the %s solver failed at t = %g (%s)", plume_solver_kind_name(d->o.solver),
                             d->t, plume_strerror(st));
    rep->iterations += sr.iterations;
    d->last_iterations = sr.iterations;
    rep->stalls += sr.reason == PLUME_REASON_STALLED;
    rep->backtracks += sr.backtracks;
    rep->shifts += sr.shifts;
    rep->step_limited += sr.step_limited;
    *ok = sr.converged || (d->o.solver == PLUME_SOLVER_LINEARIZED && sr.reason == PLUME_REASON_SINGLE_STEP);
    if (!*ok) {
        if (rep->converged)
            rep->reason = sr.reason;
        return PLUME_OK;
    }
    if (!sr.converged)
        rep->converged = 0, rep->reason = sr.reason;
    rep->max_violation = fmax(rep->max_violation, sr.max_violation);
    double drop = 0.0;
    if (plume_problem_commits(d->p)) {
        if ((st = settle_terms(d, may_cut, rep, ok, &drop, err)) != PLUME_OK || !*ok)
            return st;
    }
    for (plume_index i = 0; i < 3 * nv; i++) {
        d->v[i] = (x[i] - d->x[i]) / dt;
        d->x[i] = x[i];
    }
    /* the step's energies (xsave, vsave: the state it started from) */
    const plume_ledger_inertia li = {nv, in->mass, in->xt, in->inv_dt2};
    if ((st = plume_ledger_step(&d->ledger, d->p, d->lambda, &li, d->xsave, d->esave, d->vsave, d->v, drop)) != PLUME_OK)
        return plume_err_set(err, st, "dynamics: the energies at t = %g could not be evaluated (%s)", d->t + dt,
                             plume_strerror(st));
    memcpy(d->e, x + 3 * nv, (size_t)d->ne * sizeof *d->e);
    d->t += dt;
    rep->substeps++;
    rep->dt_min = rep->substeps == 1 ? dt : fmin(rep->dt_min, dt);
    rep->dt_max = fmax(rep->dt_max, dt);
    return PLUME_OK;
}

/* dt, halved recursively on failure */
static plume_status advance_rec(plume_dynamics *d, double dt, int depth, plume_step_report *rep, plume_err *err)
{
    size_t nd = (size_t)(3 * d->mesh->nv);
    plume_status st = rebase_at_start(d, err);
    if (st != PLUME_OK)
        return st;
    memcpy(d->xsave, d->x, nd * sizeof *d->x);
    memcpy(d->vsave, d->v, nd * sizeof *d->v);
    memcpy(d->esave, d->e, (size_t)d->ne * sizeof *d->e);
    memcpy(d->lsave, d->lambda, (size_t)d->m * sizeof *d->lambda);
    int ok = 0;
    if ((st = plume_problem_keep_terms(d->p, 1, err)) != PLUME_OK)
        return st;
    st = try_step(d, dt, depth < d->o.max_halvings, rep, &ok, err);
    if (st != PLUME_OK || ok)
        return st;
    /* failed: restore (the stateful terms too) and halve */
    if ((st = plume_problem_keep_terms(d->p, 0, err)) != PLUME_OK)
        return st;
    memcpy(d->x, d->xsave, nd * sizeof *d->x);
    memcpy(d->v, d->vsave, nd * sizeof *d->v);
    memcpy(d->e, d->esave, (size_t)d->ne * sizeof *d->e);
    memcpy(d->lambda, d->lsave, (size_t)d->m * sizeof *d->lambda);
    if (depth >= d->o.max_halvings) {
        rep->converged = 0;
        return PLUME_OK;
    }
    rep->halvings++;
    if ((st = advance_rec(d, 0.5 * dt, depth + 1, rep, err)) != PLUME_OK || !rep->converged)
        return st;
    return advance_rec(d, 0.5 * dt, depth + 1, rep, err);
}

/* Adaptive steps over [t, t + span]: each step is the interval left divided into whole steps of
 * at most h, so the last one lands on t + span exactly; h starts at dt, doubles (up to dt_max)
 * after a step that converged within easy_iterations and halves after a failed or stalled one. */
static plume_status advance_adaptive(plume_dynamics *d, double span, plume_step_report *rep, plume_err *err)
{
    size_t nd = (size_t)(3 * d->mesh->nv);
    const double t_end = d->t + span, h_max = d->o.dt_max > 0.0 ? d->o.dt_max : d->o.dt;
    const double h_min = d->o.dt / ldexp(1.0, d->o.max_halvings);
    double h = fmin(d->o.dt, h_max);
    while (t_end - d->t > 1e-12 * span) {
        double left = t_end - d->t;
        double k = ceil(left / h * (1.0 - 1e-12));
        double step = k <= 1.0 ? left : left / k;
        plume_status st = rebase_at_start(d, err);
        if (st != PLUME_OK)
            return st;
        memcpy(d->xsave, d->x, nd * sizeof *d->x);
        memcpy(d->vsave, d->v, nd * sizeof *d->v);
        memcpy(d->esave, d->e, (size_t)d->ne * sizeof *d->e);
        memcpy(d->lsave, d->lambda, (size_t)d->m * sizeof *d->lambda);
        int ok = 0;
        if ((st = plume_problem_keep_terms(d->p, 1, err)) != PLUME_OK)
            return st;
        st = try_step(d, step, 0.5 * step >= h_min * (1.0 - 1e-9), rep, &ok, err);
        if (st != PLUME_OK)
            return st;
        if (ok) {
            if (d->last_iterations <= d->o.easy_iterations)
                h = fmin(2.0 * step, h_max);
            else
                h = fmax(h, step); /* a step made shorter to land on t_end does not shrink h */
            continue;
        }
        memcpy(d->x, d->xsave, nd * sizeof *d->x);
        memcpy(d->v, d->vsave, nd * sizeof *d->v);
        memcpy(d->e, d->esave, (size_t)d->ne * sizeof *d->e);
        memcpy(d->lambda, d->lsave, (size_t)d->m * sizeof *d->lambda);
        if ((st = plume_problem_keep_terms(d->p, 0, err)) != PLUME_OK)
            return st;
        if (0.5 * step < h_min * (1.0 - 1e-9)) {
            rep->converged = 0;
            return PLUME_OK;
        }
        rep->halvings++;
        h = 0.5 * step;
    }
    d->t = t_end; /* the round-off of the sum of steps */
    return PLUME_OK;
}

plume_status plume_dynamics_advance(plume_dynamics *d, double dt, plume_step_report *rep, plume_err *err)
{
    if (!d || !rep)
        return plume_err_set(err, PLUME_EINVAL, "dynamics: invalid arguments (stepper and report are required)");
    if (!isfinite(dt))
        return plume_err_set(err, PLUME_EINVAL, "dynamics: the step must be finite (got %g)", dt);
    memset(rep, 0, sizeof *rep);
    rep->converged = 1;
    rep->reason = PLUME_REASON_CONVERGED;
    double t0 = plume_wall_seconds();
    plume_status st = d->o.adaptive ? advance_adaptive(d, dt > 0.0 ? dt : d->o.dt, rep, err)
                                     : advance_rec(d, dt > 0.0 ? dt : d->o.dt, 0, rep, err);
    /* leave the problem's x at the state (a failed attempt may have left a trial there) */
    memcpy(plume_problem_x(d->p), d->x, (size_t)(3 * d->mesh->nv) * sizeof *d->x);
    memcpy(plume_problem_x(d->p) + 3 * d->mesh->nv, d->e, (size_t)d->ne * sizeof *d->e);
    rep->seconds = plume_wall_seconds() - t0;
    return st;
}

double plume_dynamics_time(const plume_dynamics *d) { return d->t; }
const double *plume_dynamics_positions(const plume_dynamics *d) { return d->x; }
const double *plume_dynamics_velocities(const plume_dynamics *d) { return d->v; }
const double *plume_dynamics_masses(const plume_dynamics *d) { return d->inertia->mass; }

void plume_dynamics_stats(const plume_dynamics *d, int *factorizations, double *factor_seconds)
{
    int nf = 0;
    double fs = 0.0;
    plume_solver_stats(d ? d->s : NULL, NULL, &nf, &fs);
    if (factorizations)
        *factorizations = d ? d->past_factorizations + nf : 0;
    if (factor_seconds)
        *factor_seconds = d ? d->past_factor_seconds + fs : 0.0;
}

const double *plume_dynamics_multipliers(const plume_dynamics *d, plume_index *m)
{
    if (m)
        *m = d->m;
    return d->lambda;
}

plume_status plume_dynamics_set_state(plume_dynamics *d, double t, const double *x, const double *v,
                                      const double *lambda, plume_err *err)
{
    if (!d || !x || !v)
        return plume_err_set(err, PLUME_EINVAL, "dynamics: set_state needs the stepper, positions and velocities");
    if (!isfinite(t))
        return plume_err_set(err, PLUME_EINVAL, "dynamics: set_state: the time must be finite (got %g)", t);
    size_t nd = (size_t)(3 * d->mesh->nv);
    for (size_t i = 0; i < nd; i++)
        if (!isfinite(x[i]) || !isfinite(v[i]))
            return plume_err_set(err, PLUME_EINVAL, "dynamics: set_state: vertex %zu has a non-finite %s", i / 3,
                                 isfinite(x[i]) ? "velocity" : "position");
    d->t = t;
    memcpy(d->x, x, nd * sizeof *d->x);
    memcpy(d->v, v, nd * sizeof *d->v);
    memcpy(plume_problem_x(d->p), x, nd * sizeof *x);
    memcpy(d->e, plume_problem_x(d->p) + nd, (size_t)d->ne * sizeof *d->e); /* the extras as the problem holds them */
    if (lambda)
        memcpy(d->lambda, lambda, (size_t)d->m * sizeof *d->lambda);
    else
        memset(d->lambda, 0, (size_t)d->m * sizeof *d->lambda);
    d->ledger.started = 0; /* the energies count from this state */
    return PLUME_OK;
}

const plume_energy_ledger *plume_dynamics_energy(const plume_dynamics *d)
{
    return d ? &d->ledger : NULL;
}
