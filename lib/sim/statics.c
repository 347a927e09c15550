/* Load stepping with increment cutting (lib/sim/statics.h). The state is the problem's x; the free
 * part u and the multipliers are saved before each attempt and restored when it fails. */
#include "statics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/opts.h"

struct plume_statics {
    plume_problem *p;
    plume_solver *solver;
    plume_statics_opts o;
    plume_load_scaler scale;
    void *user;
    void (*free_user)(void *);
    plume_index n, m;
    double *u, *u_saved, *lambda, *lambda_saved;
    double *xref, *xtarget; /* [ndof] the tangent predictor's: x at the last equilibrium, at the target */
    double *u_prev;  /* the equilibrium before the last one (the secant predictor's), if have_prev */
    double factor_prev;
    int have_prev;
    double factor;   /* last equilibrium */
    double inc;      /* current increment (<= 1/steps) */
    int done;        /* nominal steps completed */
};

void plume_statics_opts_default_sized(plume_statics_opts *o, size_t size)
{
    static const plume_statics_opts full = {.size = sizeof full,
                                            .steps = 10,
                                            .max_cuts = 10,
                                            .solver = PLUME_SOLVER_NEWTON,
                                            .predictor = PLUME_PREDICT_TANGENT};
    plume_opts_give(o, size, &full, sizeof full);
}

static const char *const predictor_names[] = {"none", "secant", "tangent", "secant_tangent"};

const char *plume_predictor_name(plume_predictor k)
{
    return (unsigned)k < 4 ? predictor_names[k] : "unknown";
}

plume_status plume_predictor_parse(const char *name, plume_predictor *k)
{
    for (int i = 0; i < 4 && name; i++)
        if (strcmp(name, predictor_names[i]) == 0) {
            *k = (plume_predictor)i;
            return PLUME_OK;
        }
    return PLUME_EINVAL;
}

void plume_statics_destroy(plume_statics **ps)
{
    if (!ps || !*ps)
        return;
    plume_statics *s = *ps;
    plume_solver_destroy(&s->solver);
    if (s->free_user)
        s->free_user(s->user);
    free(s->u);
    free(s->u_saved);
    free(s->lambda);
    free(s->lambda_saved);
    free(s->u_prev);
    free(s->xref);
    free(s->xtarget);
    free(s);
    *ps = NULL;
}

plume_status plume_statics_create(plume_problem *p, const plume_statics_opts *given, plume_load_scaler scale,
                                  void *user, void (*free_user)(void *), plume_statics **out, plume_err *err)
{
    plume_status st = PLUME_EINVAL;
    plume_statics_opts full; /* the caller's options over this library's defaults */
    const plume_statics_opts *o = &full;
    plume_statics_opts_default(&full);
    if (!p || !given || !scale || !out) {
        st = plume_err_set(err, PLUME_EINVAL, "statics: invalid arguments");
    } else if (plume_opts_take(&full, sizeof full, given, "plume_statics_opts", err) != PLUME_OK) {
        st = PLUME_EINVAL;
    } else if (o->steps < 1 || o->max_cuts < 0 || o->max_cuts > 50) {
        st = plume_err_set(err, PLUME_EINVAL, "statics: steps must be >= 1 and max_cuts in [0, 50] (got %d, %d)",
                           o->steps, o->max_cuts);
    } else if ((unsigned)o->predictor > PLUME_PREDICT_SECANT_TANGENT) {
        st = plume_err_set(err, PLUME_EINVAL, "statics: predictor must be PLUME_PREDICT_NONE, _SECANT, _TANGENT or "
                           "_SECANT_TANGENT (got %d)", (int)o->predictor);
    } else {
        *out = NULL;
        st = PLUME_OK;
    }
    plume_statics *s = st == PLUME_OK ? calloc(1, sizeof *s) : NULL;
    if (!s) {
        if (free_user)
            free_user(user);
        return st == PLUME_OK ? plume_err_set(err, PLUME_ENOMEM, "statics: out of memory") : st;
    }
    s->p = p;
    s->o = *o;
    s->o.solver_opts = NULL; /* read once, below: the caller's struct need not outlive the call */
    if (s->o.predictor >= PLUME_PREDICT_TANGENT && s->o.solver == PLUME_SOLVER_IPOPT)
        s->o.predictor = PLUME_PREDICT_SECANT; /* Ipopt has no tangent solve to lend */
    s->scale = scale;
    s->user = user;
    s->free_user = free_user;
    s->n = plume_problem_nfree(p);
    s->m = plume_problem_ncons(p);
    s->inc = 1.0 / (double)o->steps;
    s->u = malloc((size_t)(s->n + 1) * sizeof *s->u);
    s->u_saved = malloc((size_t)(s->n + 1) * sizeof *s->u_saved);
    s->u_prev = malloc((size_t)(s->n + 1) * sizeof *s->u_prev);
    s->lambda = calloc((size_t)(s->m + 1), sizeof *s->lambda);
    s->lambda_saved = calloc((size_t)(s->m + 1), sizeof *s->lambda_saved);
    size_t nd = (size_t)plume_problem_ndof(p) + 1;
    s->xref = malloc(nd * sizeof *s->xref);
    s->xtarget = malloc(nd * sizeof *s->xtarget);
    if (!s->u || !s->u_saved || !s->u_prev || !s->lambda || !s->lambda_saved || !s->xref || !s->xtarget) {
        plume_statics_destroy(&s);
        return plume_err_set(err, PLUME_ENOMEM, "statics: out of memory");
    }
    plume_err why;
    st = plume_solver_create(o->solver, p, o->solver_opts, &s->solver, &why);
    if (st != PLUME_OK) {
        plume_statics_destroy(&s);
        return plume_err_set(err, st, "statics: the %s solver could not be created: %s",
                             plume_solver_kind_name(o->solver), why.msg);
    }
    *out = s;
    return PLUME_OK;
}

/* At an equilibrium: the terms re-base their frames (plume_term.rebase), and the last equilibrium
 * u_prev, in the old frames, moves as the equilibrium's unknowns did, so the secant through the two
 * is what it was (exact where the edges did not turn between them). s->u is the equilibrium. */
static plume_status rebase(plume_statics *s)
{
    if (!plume_problem_rebases(s->p))
        return PLUME_OK;
    plume_status st = plume_problem_rebase_terms(s->p);
    if (st != PLUME_OK)
        return st;
    plume_problem_gather(s->p, s->u_saved); /* a workspace until the next increment saves into it */
    for (plume_index i = 0; i < s->n; i++) {
        s->u_prev[i] += s->u_saved[i] - s->u[i];
        s->u[i] = s->u_saved[i];
    }
    return PLUME_OK;
}

plume_status plume_statics_step(plume_statics *s, plume_load_step_report *rep)
{
    memset(rep, 0, sizeof *rep);
    rep->reason = PLUME_REASON_CONVERGED;
    if (s->done >= s->o.steps) {
        rep->step = s->done;
        rep->factor = s->factor;
        return PLUME_OK;
    }
    const double nominal = 1.0 / (double)s->o.steps, smallest = ldexp(nominal, -s->o.max_cuts);
    const double target = (s->done + 1 == s->o.steps) ? 1.0 : (double)(s->done + 1) * nominal;
    rep->step = s->done + 1;
    int failed = 0, from_predictor = 0;
    while (s->factor < target) {
        double next = fmin(target, s->factor + s->inc);
        if (target - next < 1e-12 * nominal) /* no sliver of a step at the end */
            next = target;
        if (!from_predictor) { /* a retry from the last equilibrium keeps what was saved */
            plume_problem_gather(s->p, s->u);
            memcpy(s->u_saved, s->u, (size_t)s->n * sizeof *s->u);
            memcpy(s->lambda_saved, s->lambda, (size_t)s->m * sizeof *s->lambda);
        }
        const plume_predictor k = s->o.predictor;
        const int secant = (k == PLUME_PREDICT_SECANT || k == PLUME_PREDICT_SECANT_TANGENT) && s->have_prev;
        const int tangent = !secant && (k == PLUME_PREDICT_TANGENT || k == PLUME_PREDICT_SECANT_TANGENT);
        const size_t nd = (size_t)plume_problem_ndof(s->p);
        double *x = plume_problem_x(s->p);
        if (!from_predictor && tangent) { /* the prescribed values at the last equilibrium (a cut leaves
                                             those of the failed target in x) */
            s->scale(s->user, s->factor);
            memcpy(s->xref, x, nd * sizeof *x);
        }
        s->scale(s->user, next);
        from_predictor = !from_predictor && (secant || tangent);
        if (from_predictor && tangent) {
            /* the load at next, the prescribed dofs back at the last equilibrium: the predictor
             * moves them to next's along the tangent */
            memcpy(s->xtarget, x, nd * sizeof *x);
            memcpy(x, s->xref, nd * sizeof *x);
            memcpy(s->u, s->u_saved, (size_t)s->n * sizeof *s->u);
            int nf = 0;
            plume_status pst = plume_solver_predict(s->solver, s->u, s->m > 0 ? s->lambda : NULL, s->xtarget, &nf, NULL);
            rep->factorizations += nf;
            rep->predictions++;
            if (pst == PLUME_ENOMEM)
                return pst;
            if (pst != PLUME_OK) { /* no prediction: the last equilibrium, as without one */
                from_predictor = 0;
                memcpy(s->u, s->u_saved, (size_t)s->n * sizeof *s->u);
                memcpy(s->lambda, s->lambda_saved, (size_t)s->m * sizeof *s->lambda);
            }
        } else if (from_predictor) {
            double r = (next - s->factor) / (s->factor - s->factor_prev);
            for (plume_index i = 0; i < s->n; i++)
                s->u[i] = s->u_saved[i] + r * (s->u_saved[i] - s->u_prev[i]);
        } else {
            memcpy(s->u, s->u_saved, (size_t)s->n * sizeof *s->u);
        }
        plume_solve_report sr;
        plume_status st = plume_solver_solve(s->solver, s->u, s->m > 0 ? s->lambda : NULL, &sr);
        rep->iterations += sr.iterations;
        rep->factorizations += sr.factorizations;
        rep->backtracks += sr.backtracks;
        rep->shifts += sr.shifts;
        rep->seconds += sr.seconds;
        if (st != PLUME_OK && st != PLUME_ESINGULAR)
            return st;
        if (st == PLUME_OK && sr.converged) {
            plume_problem_scatter(s->p, s->u);
            memcpy(s->u_prev, s->u_saved, (size_t)s->n * sizeof *s->u_prev);
            if ((st = rebase(s)) != PLUME_OK)
                return st;
            s->factor_prev = s->factor;
            s->have_prev = 1;
            s->factor = next;
            rep->substeps++;
            rep->max_violation = fmax(rep->max_violation, sr.max_violation);
            s->inc = fmin(nominal, 2.0 * s->inc); /* grow back after a cut */
            from_predictor = 0;
            continue;
        }
        plume_problem_scatter(s->p, s->u_saved); /* back to the last equilibrium */
        memcpy(s->lambda, s->lambda_saved, (size_t)s->m * sizeof *s->lambda);
        if (from_predictor) { /* the same increment again, from the last equilibrium */
            rep->predictor_retries++;
            continue;
        }
        if (!failed)
            rep->reason = st == PLUME_OK ? sr.reason : PLUME_REASON_NUMERICAL;
        failed = 1;
        if (s->inc * 0.5 < smallest * (1.0 - 1e-12)) {
            s->scale(s->user, s->factor);
            rep->factor = s->factor;
            return PLUME_OK; /* not converged at the smallest increment */
        }
        s->inc *= 0.5;
        rep->cuts++;
    }
    rep->factor = s->factor;
    rep->converged = 1;
    s->done++;
    return PLUME_OK;
}

void plume_statics_stats(const plume_statics *s, int *factorizations, double *factor_seconds)
{
    plume_solver_stats(s ? s->solver : NULL, NULL, factorizations, factor_seconds);
}

double plume_statics_factor(const plume_statics *s)
{
    return s->factor;
}

int plume_statics_steps_done(const plume_statics *s)
{
    return s->done;
}

const double *plume_statics_multipliers(const plume_statics *s, plume_index *m)
{
    if (m)
        *m = s->m;
    return s->lambda;
}
