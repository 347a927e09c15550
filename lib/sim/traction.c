#include "traction.h"
#include "traction_grips.h"
#include "internal/traction_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/opts.h"
#include "../io/progress.h"
#include "../solve/options.h"

double plume_traction_default_edge(double lx, double ly)
{
    return fmin(lx, ly) / 20.0;
}

double plume_traction_default_barb_spacing(double ly)
{
    return 0.086 * ly;
}

void plume_traction_opts_default_sized(plume_traction_opts *o, size_t size)
{
    static const plume_traction_opts full = {.size = sizeof full,
                                             .strain_max = 0.05,
                                             .steps = 10,
                                             .max_cuts = 8,
                                             .probe_strain = 1e-6,
                                             .solver = PLUME_SOLVER_NEWTON,
                                             .progress = 1,
                                             .max_settles = 100};
    plume_opts_give(o, size, &full, sizeof full);
}

void plume_traction_result_free(plume_traction_result *r)
{
    if (!r)
        return;
    free(r->curve.strain);
    free(r->curve.stress);
    free(r->curve.wbar);
    free(r->curve.iterations);
    free(r->curve.seconds);
    memset(&r->curve, 0, sizeof r->curve);
}

/* Sets the top grip at displacement delta and predicts the free dofs. With no history
 * (da == db) the prediction is the previous state plus the increment of an affine stretch;
 * otherwise it extrapolates linearly through the last two converged states xa (at da) and xb (at
 * db) — from the small-strain probe this is the linear response, a far better start for Newton
 * than an affine stretch that loads the stiff barbs. */
static void predict(const plume_mesh *m, plume_problem *p, const plume_traction_grips *g, double ly, double delta,
                    const double *xa, double da, const double *xb, double db)
{
    int dim = plume_problem_dim(p);
    double *x = plume_problem_x(p);
    plume_index ndof = dim * m->nv;
    if (da == db) {
        for (plume_index i = 0; i < ndof; i++)
            x[i] = xa[i];
        for (plume_index v = 0; v < m->nv; v++)
            x[dim * v + 1] += (delta - da) * plume_traction_grip_shape(g, m->X[2 * v]) * m->X[2 * v + 1] / ly;
    } else {
        double s = (delta - da) / (da - db);
        for (plume_index i = 0; i < ndof; i++)
            x[i] = xa[i] + s * (xa[i] - xb[i]);
    }
    for (plume_index v = 0; v < m->nv; v++)
        if (g->top_flag[v]) {
            x[dim * v] = m->X[2 * v];
            x[dim * v + 1] = m->X[2 * v + 1] + delta * plume_traction_grip_shape(g, m->X[2 * v]);
        } else if (g->bottom_flag[v]) {
            x[dim * v] = m->X[2 * v];
            x[dim * v + 1] = m->X[2 * v + 1];
        }
}

/* The load path's legs (plume_traction_opts.path): how many, and the strains each starts and ends at. */
static int path_legs(const plume_traction_opts *o)
{
    return o->path ? o->npath : 1;
}

static double leg_end(const plume_traction_opts *o, int j)
{
    return o->path ? o->path[j] : o->strain_max;
}

static double leg_start(const plume_traction_opts *o, int j)
{
    return j == 0 ? 0.0 : leg_end(o, j - 1);
}

/* the strain of nominal step k >= 1: step i of its leg's `steps` */
static double step_strain(const plume_traction_opts *o, int k)
{
    const int j = (k - 1) / o->steps, i = (k - 1) % o->steps + 1;
    const double a = leg_start(o, j), b = leg_end(o, j);
    return i == o->steps ? b : a + (b - a) * i / o->steps;
}

/* The probe's relative KKT tolerance (plume_traction_opts.probe_tol_kkt). */
static double probe_tolerance(const plume_traction_opts *o)
{
    if (o->probe_tol_kkt > 0.0)
        return o->probe_tol_kkt;
    return o->solver_opts->tol_kkt * fmin(1.0, o->probe_strain * o->steps / fabs(leg_end(o, 0)));
}

/* The probe solved with the relative KKT tolerance tol, tighter than the steps' (the solver's
 * own tolerance is restored after it). Why: with the steps' tolerance a newton probe stops early.
 * Its KKT residual is measured against the force scale of the stiff barbs (~1e-6 E_xx h L), whose
 * round-off floor (~1e-10 of it) the probe reaches while its displacement is still ~1e-4 off at
 * 3e4 triangles (newton converges linearly there, by ~1/50 per iteration). Below the floor the
 * solve ends on the step test (tol_step) instead, i.e. at round-off. */
static plume_status solve_probe_tight(const plume_mesh *mesh, plume_problem *p, const plume_traction_grips *g,
                                      const plume_traction_opts *o, plume_solver *s, double tol, const double *xrest,
                                      double delta, double *u, double *lambda, plume_solve_report *rep,
                                      plume_err *err)
{
    predict(mesh, p, g, o->ly, delta, xrest, 0.0, xrest, 0.0);
    plume_problem_gather(p, u);
    plume_status st = plume_solver_set_tol_kkt(s, tol, err);
    if (st == PLUME_OK)
        st = plume_solver_solve(s, u, lambda, rep);
    plume_solver_set_tol_kkt(s, o->solver_opts->tol_kkt, err);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "traction: step 0 (probe): solver error (%s)", plume_strerror(st));
    return PLUME_OK;
}

/* the converged state (x, lambda) at grip displacement delta becomes the latest */
static void history_push(history *h, const double *x, const double *lambda, double delta, size_t nx, plume_index m)
{
    double *t = h->xb;
    h->xb = h->xa, h->db = h->da;
    h->xa = t, h->da = delta;
    memcpy(h->xa, x, nx * sizeof *x);
    t = h->lb, h->lb = h->la, h->la = t;
    if (m > 0)
        memcpy(h->la, lambda, (size_t)m * sizeof *lambda);
}


static plume_status check_opts(const plume_mesh *mesh, plume_problem *p, const plume_traction_opts *o, plume_err *err)
{
    if (!(o->lx > 0) || !(o->ly > 0) || !(o->h > 0) || !isfinite(o->lx * o->ly * o->h))
        return plume_err_set(err, PLUME_EINVAL,
                             "traction: lx, ly and thickness must be finite and > 0 (got %g, %g, %g)",
                             o->lx, o->ly, o->h);
    if (o->path) {
        if (o->npath < 1 || o->npath > 1000)
            return plume_err_set(err, PLUME_EINVAL, "traction: npath must be in [1, 1000] with a path (got %d)",
                                 o->npath);
        for (int j = 0; j < o->npath; j++) {
            if (!(o->path[j] > -1.0) || !isfinite(o->path[j]))
                return plume_err_set(err, PLUME_EINVAL, "traction: path[%d] must be a finite strain > -1 (got %g)", j,
                                     o->path[j]);
            if (o->path[j] == leg_start(o, j))
                return plume_err_set(err, PLUME_EINVAL,
                                     "traction: path[%d] = %g is the strain the leg starts from: a leg must move the "
                                     "grip", j, o->path[j]);
        }
    } else if (!(o->strain_max > 0) || !isfinite(o->strain_max))
        return plume_err_set(err, PLUME_EINVAL, "traction: strain-max must be > 0 (got %g)", o->strain_max);
    if (o->steps < 1 || !(o->probe_strain > 0))
        return plume_err_set(err, PLUME_EINVAL, "traction: steps must be >= 1 and probe_strain > 0 (got %d, %g)",
                             o->steps, o->probe_strain);
    if (o->max_cuts < 0 || o->max_cuts > 30)
        return plume_err_set(err, PLUME_EINVAL, "traction: max_cuts must be in [0, 30] (got %d)", o->max_cuts);
    if (!(o->peel >= 0.0 && o->peel <= 1.0))
        return plume_err_set(err, PLUME_EINVAL, "traction: peel must be in [0, 1] (got %g)", o->peel);
    if (!(o->top_grip_free >= 0.0 && o->top_grip_free < 1.0))
        return plume_err_set(err, PLUME_EINVAL, "traction: top_grip_free must be in [0, 1) (got %g)",
                             o->top_grip_free);
    if (o->max_settles < 0)
        return plume_err_set(err, PLUME_EINVAL, "traction: max_settles must be >= 0 (got %d)", o->max_settles);
    if (o->stop_after < 0)
        return plume_err_set(err, PLUME_EINVAL, "traction: stop_after must be >= 0 (got %d)", o->stop_after);
    if (!(o->probe_tol_kkt >= 0) || !isfinite(o->probe_tol_kkt))
        return plume_err_set(err, PLUME_EINVAL, "traction: probe_tol_kkt must be finite and >= 0 (got %g)",
                             o->probe_tol_kkt);
    if (plume_problem_nvert(p) != mesh->nv)
        return plume_err_set(err, PLUME_EINVAL, "traction: problem and mesh sizes differ");
    return PLUME_OK;
}

/* the sample at rest in the problem (the mesh's plane, z = 0), its grips' dofs fixed, the problem
 * finalised */
static plume_status place_sample(traction_run *r, plume_err *err)
{
    const plume_mesh *mesh = r->mesh;
    plume_status st;
    r->dim = plume_problem_dim(r->p);
    r->x = plume_problem_x(r->p);
    for (plume_index v = 0; v < mesh->nv; v++) {
        r->x[r->dim * v] = mesh->X[2 * v];
        r->x[r->dim * v + 1] = mesh->X[2 * v + 1];
        if (r->dim == 3)
            r->x[r->dim * v + 2] = 0.0;
        if (r->g.bottom_flag[v] || r->g.top_flag[v])
            for (int k = 0; k < r->dim; k++)
                if ((st = plume_problem_fix_dof(r->p, r->dim * v + k, err)) != PLUME_OK)
                    return st;
    }
    if ((st = plume_problem_finalize(r->p, err)) != PLUME_OK)
        return st;
    r->n = plume_problem_nfree(r->p), r->m = plume_problem_ncons(r->p);
    return PLUME_OK;
}

/* the run's workspaces and the result's curve (steps + 1 points); the history starts at rest */
static plume_status alloc_run(traction_run *r, plume_traction_result *res)
{
    const plume_index n = r->n, m = r->m;
    const size_t nx = (size_t)(r->dim * r->mesh->nv), np = (size_t)r->o->steps * (size_t)path_legs(r->o) + 1;
    r->u = malloc((size_t)(n + 1) * sizeof *r->u);
    r->lambda = calloc((size_t)(m + 1), sizeof *r->lambda);
    r->lambda_saved = calloc((size_t)(m + 1), sizeof *r->lambda_saved);
    r->h.la = calloc((size_t)(m + 1), sizeof *r->h.la);
    r->h.lb = calloc((size_t)(m + 1), sizeof *r->h.lb);
    r->force = malloc((size_t)plume_problem_ndof(r->p) * sizeof *r->force); /* forces writes every unknown */
    r->h.xa = malloc(nx * sizeof *r->h.xa);
    r->h.xb = malloc(nx * sizeof *r->h.xb);
    res->curve.strain = calloc(np, sizeof(double));
    res->curve.stress = calloc(np, sizeof(double));
    res->curve.wbar = calloc(np, sizeof(double));
    res->curve.iterations = calloc(np, sizeof(double));
    res->curve.seconds = calloc(np, sizeof(double));
    if (!r->u || !r->lambda || !r->lambda_saved || !r->h.la || !r->h.lb || !r->force || !r->h.xa || !r->h.xb ||
        !res->curve.strain || !res->curve.stress || !res->curve.wbar || !res->curve.iterations || !res->curve.seconds)
        return PLUME_ENOMEM;
    memcpy(r->h.xa, r->x, nx * sizeof *r->h.xa);
    memcpy(r->h.xb, r->x, nx * sizeof *r->h.xb);
    return PLUME_OK;
}

static void free_run(traction_run *r)
{
    plume_solver_destroy(&r->solver);
    plume_traction_grips_free(&r->g);
    free(r->u);
    free(r->h.xa);
    free(r->h.xb);
    free(r->lambda);
    free(r->lambda_saved);
    free(r->h.la);
    free(r->h.lb);
    free(r->force);
    free(r->hist);
}

/* A solve's counts added to those of its step. */
static void add_report(plume_solve_report *to, const plume_solve_report *from)
{
    to->iterations += from->iterations;
    to->chord_steps += from->chord_steps;
    to->seconds += from->seconds;
    to->max_violation = fmax(to->max_violation, from->max_violation);
}

/* The y-reaction on the moving grip: its vertices' forces (r->force), each weighted by how far
 * the grip moves it (1 for a straight pull): the force at the grip's far end that does its work. */
static double grip_reaction(const traction_run *r)
{
    double F = 0.0;
    for (plume_index t = 0; t < r->g.ntop; t++) {
        const plume_index v = r->g.top[t];
        F += r->force[r->dim * v + 1] * plume_traction_grip_shape(&r->g, r->mesh->X[2 * v]);
    }
    return F;
}

/* The grip's reaction and the problem's energy at the current positions. */
static plume_status measure(traction_run *r, double *F, double *E)
{
    plume_status st = plume_problem_forces(r->p, r->m ? r->lambda : NULL, r->force);
    if (st != PLUME_OK)
        return st;
    *F = grip_reaction(r);
    plume_problem_gather(r->p, r->u);
    return plume_problem_objective(r->p, r->u, E, NULL);
}

/* At an equilibrium (sub converged): the stateful terms commit (plume_term.commit), and while
 * they change their state, a solve again at the same grips (its counts added to *sub). Only the
 * first commit may ask for a cut (*cut: undo the increment): the cascade that follows a release
 * at fixed grips is the structure's, not the increment's. *changed: a commit changed something (a
 * state, or only the energy: a softening link's history, which leaves the equilibrium where it is).
 * Leaves sub->converged 0 when a solve fails or the state keeps changing. */
static plume_status settle(traction_run *r, int k, int may_cut, plume_solve_report *sub, int *cut, int *changed,
                           plume_err *err)
{
    *cut = *changed = 0;
    int cascade = 0;
    for (int n = 0;; n++) {
        plume_commit_report c;
        plume_err why;
        plume_status st = plume_problem_commit_terms(r->p, may_cut && n == 0, &c, &why);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "traction: step %d: %s", k, why.msg);
        if (c.overshoot) {
            *cut = 1;
            return PLUME_OK;
        }
        r->inc_energy.released += c.released, r->inc_energy.reengaged += c.reengaged;
        cascade += (int)c.released;
        r->inc_energy.events += c.released > 0;
        if (cascade > r->inc_energy.cascade)
            r->inc_energy.cascade = cascade;
        if (c.energy_drop != 0.0) /* a softening link's history: the equilibrium stays, its energy does not */
            *changed = 1;
        if (!c.changed)
            return PLUME_OK;
        *changed = 1;
        if (n == r->o->max_settles) { /* still changing: a failed step */
            sub->converged = 0;
            sub->reason = PLUME_REASON_ITERATION_CAP;
            return PLUME_OK;
        }
        plume_solve_report again;
        plume_problem_gather(r->p, r->u);
        if ((st = plume_solver_solve(r->solver, r->u, r->lambda, &again)) != PLUME_OK)
            return plume_err_set(err, st, "traction: step %d: solver error (%s)", k, plume_strerror(st));
        add_report(sub, &again);
        if (!again.converged) {
            sub->converged = 0;
            sub->reason = again.reason;
            return PLUME_OK;
        }
    }
}

/* An increment solved to the grip displacement `next` (sub): its work by the trapezoidal rule from
 * the last accepted equilibrium (at r->h.da), then, at a converged loading step (k > 0), the
 * stateful terms' commits (settle) and the energy they gave up: the energy at the first
 * equilibrium minus that at the last. Kept in r->inc_energy until the increment is accepted. */
static plume_status close_increment(traction_run *r, int k, double next, int may_cut, plume_solve_report *sub,
                                    int *cut, plume_err *err)
{
    *cut = 0;
    memset(&r->inc_energy, 0, sizeof r->inc_energy);
    double F1, E1;
    plume_status st = measure(r, &F1, &E1);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "traction: step %d: the energy could not be evaluated (%s)", k,
                             plume_strerror(st));
    r->inc_energy.work = 0.5 * (r->F_eq + F1) * (next - r->h.da);
    r->inc_energy.F = F1, r->inc_energy.E = E1, r->inc_energy.peak = F1;
    int changed = 0;
    if (k == 0 || !sub->converged || !plume_problem_commits(r->p))
        return PLUME_OK;
    if ((st = settle(r, k, may_cut, sub, cut, &changed, err)) != PLUME_OK || *cut || !sub->converged || !changed)
        return st;
    if ((st = measure(r, &r->inc_energy.F, &r->inc_energy.E)) != PLUME_OK)
        return plume_err_set(err, st, "traction: step %d: the energy could not be evaluated (%s)", k,
                             plume_strerror(st));
    r->inc_energy.dissipated = E1 - r->inc_energy.E;
    return PLUME_OK;
}

/* The increment closed last becomes the run's: its energies into the sums, its equilibrium the
 * start of the next trapezoid, the terms' state kept. */
static plume_status accept_increment(traction_run *r, plume_err *err)
{
    r->work += r->inc_energy.work;
    r->gross_work += fabs(r->inc_energy.work);
    r->dissipated += r->inc_energy.dissipated;
    r->released += r->inc_energy.released, r->reengaged += r->inc_energy.reengaged;
    r->events += r->inc_energy.events;
    r->peak = fmax(r->peak, r->inc_energy.peak);
    if (r->inc_energy.cascade > r->cascade)
        r->cascade = r->inc_energy.cascade;
    r->F_eq = r->inc_energy.F, r->E_eq = r->inc_energy.E;
    memset(&r->inc_energy, 0, sizeof r->inc_energy);
    return plume_problem_keep_terms(r->p, 1, err);
}

/* Adaptive load stepping to the grip displacement delta, up or down: an increment that does not
 * converge, or whose commits overshoot, is undone (back to the last equilibrium h.xa, its
 * multipliers and the terms' kept state) and halved, up to max_cuts times; after a success it
 * grows back by doubling, never past the leg's nominal step. Only the nominal strains enter the
 * curve. The increments' reports summed into *rep. */
static plume_status adaptive_step(traction_run *r, int k, double delta, plume_solve_report *rep,
                                  plume_traction_result *res, plume_err *err)
{
    const plume_traction_opts *o = r->o;
    const plume_index m = r->m;
    const size_t nx = (size_t)(r->dim * r->mesh->nv);
    history *h = &r->h;
    plume_solve_report sub;
    memset(rep, 0, sizeof *rep);
    rep->reason = PLUME_REASON_CONVERGED;
    const double nominal = r->nominal, smallest = ldexp(nominal, -o->max_cuts), dir = delta > h->da ? 1.0 : -1.0;
    int failed = 0;
    while (fabs(delta - h->da) > 1e-12 * nominal) {
        double next = h->da + dir * fmin(r->inc, fabs(delta - h->da));
        if (fabs(delta - next) < 1e-9 * nominal)
            next = delta;
        memcpy(r->lambda_saved, r->lambda, (size_t)(m + 1) * sizeof *r->lambda);
        predict(r->mesh, r->p, &r->g, o->ly, next, h->xa, h->da, h->xb, h->db);
        if (h->da != h->db) /* the multipliers extrapolated with the positions: the barbs'
                             tension grows with the load */
            for (plume_index q = 0; q < m; q++)
                r->lambda[q] = h->la[q] + (next - h->da) / (h->da - h->db) * (h->la[q] - h->lb[q]);
        plume_problem_gather(r->p, r->u);
        plume_status st = plume_solver_solve(r->solver, r->u, r->lambda, &sub);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "traction: step %d: solver error (%s)", k, plume_strerror(st));
        int cut = 0;
        const int may_cut = r->inc * 0.5 >= smallest * (1.0 - 1e-12);
        if (sub.converged && (st = close_increment(r, k, next, may_cut, &sub, &cut, err)) != PLUME_OK)
            return st;
        if (cut) /* a commit overshot: undone and halved like a failed solve */
            sub.converged = 0, sub.reason = PLUME_REASON_ITERATION_CAP;
        add_report(rep, &sub);
        if (sub.converged) {
            if ((st = accept_increment(r, err)) != PLUME_OK)
                return st;
            history_push(h, r->x, r->lambda, next, nx, m);
            r->inc = fmin(nominal, 2.0 * r->inc);
            if (next != delta)
                res->substeps++;
            continue;
        }
        if (!failed)
            rep->reason = sub.reason;
        failed = 1;
        memcpy(r->x, h->xa, nx * sizeof *r->x); /* back to the last equilibrium */
        memcpy(r->lambda, r->lambda_saved, (size_t)(m + 1) * sizeof *r->lambda);
        if ((st = plume_problem_keep_terms(r->p, 0, err)) != PLUME_OK)
            return st;
        if (r->inc * 0.5 < smallest * (1.0 - 1e-12)) {
            rep->converged = 0;
            break;
        }
        r->inc *= 0.5;
        if (cut)
            res->overshoot_cuts++;
        res->cuts++;
    }
    if (fabs(delta - h->da) <= 1e-12 * nominal) {
        rep->converged = 1;
        rep->reason = PLUME_REASON_CONVERGED;
        memcpy(r->x, h->xa, nx * sizeof *r->x);
    }
    return PLUME_OK;
}

/* Step k's solve to the grip displacement delta, report in *rep: the probe (k = 0) first with
 * the tight tolerance (*tight: that solve; not converged, it is solved again from zero
 * multipliers), then one solve from the predictor (the probe, the linearised solver, no cuts
 * allowed) or adaptive_step. The single-solve paths close their increment here (close_increment)
 * and record_step accepts it. */
static plume_status solve_step(traction_run *r, int k, double delta, double probe_tol, plume_solve_report *rep,
                               plume_solve_report *tight, plume_traction_result *res, plume_err *err)
{
    const plume_traction_opts *o = r->o;
    const int probe = k == 0;
    plume_status st;
    int cut = 0;
    memset(tight, 0, sizeof *tight);
    plume_err why;
    if (!r->solver) {
        if ((st = plume_solver_create(o->solver, r->p, o->solver_opts, &r->solver, &why)) != PLUME_OK)
            return plume_err_set(err, st, "traction: could not create the %s solver: %s",
                                 plume_solver_kind_name(o->solver), why.msg);
        if (r->restarted) /* where the first run's solver stood */
            plume_solver_set_memory(r->solver, r->memory);
    }
    if (probe && probe_tol < o->solver_opts->tol_kkt && o->solver != PLUME_SOLVER_LINEARIZED) {
        if ((st = solve_probe_tight(r->mesh, r->p, &r->g, o, r->solver, probe_tol, r->h.xa, delta, r->u, r->lambda,
                                    tight, err)) != PLUME_OK)
            return st;
        if (!tight->converged) /* a round-off floor above sqrt(probe_tol): start again below */
            memset(r->lambda, 0, (size_t)(r->m + 1) * sizeof *r->lambda);
    }
    if (tight->converged) {
        *rep = *tight;
        res->probe_tol_kkt = probe_tol;
        return close_increment(r, k, delta, 0, rep, &cut, err);
    }
    if (!(probe || o->solver == PLUME_SOLVER_LINEARIZED || o->max_cuts == 0))
        return adaptive_step(r, k, delta, rep, res, err);
    predict(r->mesh, r->p, &r->g, o->ly, delta, r->h.xa, r->h.da, r->h.xb, r->h.db);
    plume_problem_gather(r->p, r->u);
    if ((st = plume_solver_solve(r->solver, r->u, r->lambda, rep)) != PLUME_OK)
        return plume_err_set(err, st, "traction: step %d: solver error (%s)", k, plume_strerror(st));
    /* the linearised solver's single step is its answer: its work counts as a converged one's */
    if ((rep->converged || rep->reason == PLUME_REASON_SINGLE_STEP) &&
        (st = close_increment(r, k, delta, 0, rep, &cut, err)) != PLUME_OK)
        return st;
    rep->iterations += tight->iterations; /* a tight probe that failed counts too */
    rep->seconds += tight->seconds;
    if (probe && rep->converged)
        res->probe_tol_kkt = o->solver_opts->tol_kkt;
    return PLUME_OK;
}

/* With a checkpoint or a restart: the columns of the per-stencil states' history, and a problem
 * whose stateful terms can save their state. */
static plume_status start_states(traction_run *r, plume_err *err)
{
    if (!r->o->checkpoint && !r->o->restart)
        return PLUME_OK;
    if (plume_problem_state_size(r->p) < 0)
        return plume_err_set(err, PLUME_EINVAL, "traction: %s: a stateful term of the problem cannot save its state "
                             "(plume_term.state_size)", r->o->restart ? "restart" : "checkpoint");
    for (int t = 0;; t++) {
        const char *name = plume_problem_states_term(r->p, t);
        plume_index nc = 0;
        if (!name)
            return PLUME_OK;
        plume_status st = plume_problem_term_states(r->p, name, NULL, &nc, err);
        if (st != PLUME_OK)
            return st;
        r->hist_cols += nc;
    }
}

/* Step k solved (rep, tight: solve_step's): its counts into the result, then, where it is an
 * equilibrium, the reactions, the history, and the probe's initial slope or a point of the curve
 * (on_step, the progress line). *stop: the run ends here (not converged). */
static plume_status record_step(traction_run *r, int k, double strain, const plume_solve_report *rep,
                                const plume_solve_report *tight, plume_traction_result *res, plume_progress *prog,
                                int *stop, plume_err *err)
{
    const plume_traction_opts *o = r->o;
    const plume_mesh *mesh = r->mesh;
    const int dim = r->dim;
    const double delta = strain * o->ly;
    plume_status st;
    res->newton_iterations += rep->iterations;
    res->chord_steps += rep->chord_steps + (tight->converged ? 0 : tight->chord_steps);
    int ok = rep->converged || (o->solver == PLUME_SOLVER_LINEARIZED && rep->reason == PLUME_REASON_SINGLE_STEP);
    if (!rep->converged && res->converged) {
        res->converged = 0;
        res->failed_step = k;
        res->failed_reason = rep->reason;
    }
    *stop = !ok;
    if (!ok)
        return PLUME_OK;
    if (rep->converged)
        res->max_violation = fmax(res->max_violation, rep->max_violation);
    /* r->force: the forces at this equilibrium, which close_increment measured last */
    if (!(r->h.da == delta)) { /* the adaptive path has accepted and pushed it already */
        if ((st = accept_increment(r, err)) != PLUME_OK)
            return st;
        history_push(&r->h, r->x, r->lambda, delta, (size_t)(dim * mesh->nv), r->m);
    }
    if (k == 0) { /* the probe's equilibrium is the first state of the history */
        const double F = plume_traction_reaction_virtual_work(mesh, &r->g, r->force, dim, o->ly);
        res->initial_slope = F / (o->lx * o->h) / strain;
        res->curve.iterations[0] = rep->iterations;
        res->curve.seconds[0] = rep->seconds;
        return PLUME_OK;
    }
    double stress = grip_reaction(r) / (o->lx * o->h);
    double wbar = (plume_traction_side_integral(mesh, r->x, dim, r->g.right, r->g.nright) -
                   plume_traction_side_integral(mesh, r->x, dim, r->g.left, r->g.nleft)) /
                  (o->lx * o->ly);
    size_t i = (size_t)res->curve.n++;
    res->curve.strain[i] = strain;
    res->curve.stress[i] = stress;
    res->curve.wbar[i] = wbar;
    res->curve.iterations[i] = rep->iterations;
    res->curve.seconds[i] = rep->seconds;
    if (o->on_step && (st = o->on_step(o->on_step_user, k, strain, r->x)) != PLUME_OK)
        return plume_err_set(err, st, "traction: writing step %d failed (%s)", k, plume_strerror(st));
    if (o->checkpoint && ((st = plume_traction_states_record(r, err)) != PLUME_OK ||
                          (st = plume_traction_checkpoint_write(r, k, res, err)) != PLUME_OK))
        return st;
    char info[128];
    snprintf(info, sizeof info, "strain %.4f  stress %.4g Pa  %d it", strain, stress, rep->iterations);
    plume_progress_update(prog, k, info);
    return PLUME_OK;
}

plume_status plume_traction_run(const plume_mesh *mesh, plume_problem *p, const plume_index *rigid_edges,
                                plume_index nrigid, const plume_traction_opts *given,
                                plume_traction_result *res, plume_err *err)
{
    if (!mesh || !p || !given || !res || (nrigid > 0 && !rigid_edges))
        return plume_err_set(err, PLUME_EINVAL, "traction: invalid arguments");
    memset(res, 0, sizeof *res);
    res->failed_step = -1;
    /* the caller's options over this library's defaults, their solver options never NULL below */
    plume_traction_opts full;
    plume_solver_opts so;
    const plume_traction_opts *o = &full;
    plume_traction_opts_default(&full);
    if (plume_opts_take(&full, sizeof full, given, "plume_traction_opts", err) != PLUME_OK ||
        plume_solver_opts_take(&so, full.solver_opts, err) != PLUME_OK)
        return PLUME_EINVAL;
    full.solver_opts = &so;
    plume_status st = check_opts(mesh, p, o, err);
    if (st != PLUME_OK)
        return st;
    traction_run r = {.mesh = mesh, .p = p, .o = o};
    double t_start = plume_wall_seconds();
    if ((st = plume_traction_grips_find(mesh, o->lx, o->ly, o->peel, o->top_grip_free, &r.g, err)) != PLUME_OK ||
        (st = plume_traction_barbs_stretch_check(mesh, &r.g, rigid_edges, nrigid, err)) != PLUME_OK ||
        (st = place_sample(&r, err)) != PLUME_OK || (st = alloc_run(&r, res)) != PLUME_OK ||
        (st = plume_problem_keep_terms(p, 1, err)) != PLUME_OK)
        goto cleanup;
    if ((st = measure(&r, &r.F_eq, &r.E_rest)) != PLUME_OK) {
        plume_err_set(err, st, "traction: the energy at rest could not be evaluated (%s)", plume_strerror(st));
        goto cleanup;
    }
    r.E_eq = r.E_rest;
    const int nsteps = o->steps * path_legs(o);
    res->curve.n = 1; /* the rest state */
    res->converged = 1;
    plume_progress prog;
    plume_progress_start(&prog, "traction", nsteps, o->progress == 2);
    if (o->progress == 0)
        prog.enabled = 0;

    double probe_tol = probe_tolerance(o);
    int first = 0; /* the first step to solve: 0 (the probe) from rest, a restart's next */
    if ((st = start_states(&r, err)) != PLUME_OK)
        goto cleanup;
    if (o->restart) {
        if ((st = plume_traction_checkpoint_read(&r, &first, res, err)) != PLUME_OK)
            goto cleanup;
        first++;
    } else {
        if (o->on_step && (st = o->on_step(o->on_step_user, 0, 0.0, r.x)) != PLUME_OK) {
            plume_err_set(err, st, "traction: writing the rest state failed (%s)", plume_strerror(st));
            goto cleanup;
        }
        if ((st = plume_traction_states_record(&r, err)) != PLUME_OK)
            goto cleanup;
    }

    /* step 0 is the small-strain probe (initial slope), then the quasi-static steps, leg by leg */
    for (int k = first; k <= nsteps; k++) {
        double strain = k == 0 ? o->probe_strain : step_strain(o, k);
        if (k >= 1 && (k - 1) % o->steps == 0) { /* a leg starts: its nominal increment */
            const int j = (k - 1) / o->steps;
            r.nominal = r.inc = fabs(leg_end(o, j) - leg_start(o, j)) * o->ly / o->steps;
        }
        plume_solve_report rep, tight;
        int stop;
        if ((st = solve_step(&r, k, strain * o->ly, probe_tol, &rep, &tight, res, err)) != PLUME_OK ||
            (st = record_step(&r, k, strain, &rep, &tight, res, &prog, &stop, err)) != PLUME_OK)
            goto cleanup;
        if (stop || (o->stop_after > 0 && k == o->stop_after))
            break;
    }
    plume_progress_finish(&prog);
    plume_solver_stats(r.solver, NULL, &res->factorizations, &res->factor_seconds);
    res->factorizations += r.factorizations0, res->factor_seconds += r.factor_seconds0;
    res->work = r.work;
    res->stored_energy = r.E_eq - r.E_rest;
    res->dissipated_energy = r.dissipated;
    res->energy_balance_error = r.gross_work > 0.0 ? (r.work - res->stored_energy - r.dissipated) / r.gross_work : 0.0;
    res->released = r.released, res->reengaged = r.reengaged, res->largest_cascade = r.cascade;
    res->release_events = r.events;
    res->peak_stress = r.peak / (o->lx * o->h);
    st = PLUME_OK;
cleanup:
    res->seconds = plume_wall_seconds() - t_start;
    if (st != PLUME_OK)
        plume_traction_result_free(res);
    free_run(&r);
    return st;
}
