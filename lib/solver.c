#include "solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "newton.h"

struct plume_solver {
    plume_solver_kind kind;
    plume_newton *newton; /* newton and linearized */
    plume_ipopt *ipopt;
};

const char *plume_reason_name(plume_reason r)
{
    switch (r) {
    case PLUME_REASON_CONVERGED: return "converged";
    case PLUME_REASON_ITERATION_CAP: return "iteration cap";
    case PLUME_REASON_LINE_SEARCH: return "line-search failure";
    case PLUME_REASON_INFEASIBLE: return "infeasible";
    case PLUME_REASON_NUMERICAL: return "numerical failure";
    case PLUME_REASON_SINGLE_STEP: return "single linearised step";
    case PLUME_REASON_CONTACT_SET: return "steps blocked outside the contact set";
    case PLUME_REASON_STALLED: return "stalled";
    }
    return "unknown";
}

static const char *const kind_names[] = {"newton", "ipopt", "linearized"};

plume_status plume_solver_kind_parse(const char *s, plume_solver_kind *out)
{
    for (int k = 0; k < 3 && s; k++)
        if (strcmp(s, kind_names[k]) == 0) {
            *out = (plume_solver_kind)k;
            return PLUME_OK;
        }
    return PLUME_EINVAL;
}

const char *plume_solver_kind_name(plume_solver_kind k)
{
    return (unsigned)k < 3 ? kind_names[k] : "unknown";
}

void plume_solver_opts_default(plume_solver_opts *o)
{
    memset(o, 0, sizeof *o); /* a field added later is never left undefined */
    o->max_iter = 100;
    o->tol_kkt = 1e-9;
    o->tol_violation = 1e-10;
    o->tol_step = 1e-13;
    o->max_step = 100.0;
    o->kkt = PLUME_KKT_ELIMINATE;
    o->inertia_corrections = 1;
    o->inertia_max_shift = 1.0;
    o->line_search = PLUME_LS_FILTER;
    o->reuse_factorization = 1;
    o->reuse_rate = 0.25;
    o->kkt_refine = 1;
    o->verbose = 0;
    o->exact_hessian_first = 1;
    o->partial_projection = 1;
    o->trust_region = 0;
    o->curved_search = 1;
    o->stall_iterations = 0;
}

static const char *const globalization_names[] = {"curved_line_search", "line_search", "trust_region"};

plume_status plume_globalization_parse(const char *s, plume_globalization *out)
{
    for (int k = 0; s && k < 3; k++)
        if (strcmp(s, globalization_names[k]) == 0) {
            *out = (plume_globalization)k;
            return PLUME_OK;
        }
    return PLUME_EINVAL;
}

const char *plume_globalization_name(plume_globalization g)
{
    return (unsigned)g < 3 ? globalization_names[g] : "unknown";
}

void plume_solver_opts_set_globalization(plume_solver_opts *o, plume_globalization g)
{
    o->curved_search = g == PLUME_GLOBAL_CURVED_LINE_SEARCH;
    o->trust_region = g == PLUME_GLOBAL_TRUST_REGION;
}

plume_status plume_solver_create(plume_solver_kind kind, plume_problem *p, const plume_solver_opts *o,
                                 plume_solver **out, plume_err *err)
{
    if (out)
        *out = NULL;
    if (!p || !o || !out)
        return plume_err_set(err, PLUME_EINVAL, "solver: invalid arguments (problem, options and out are required)");
    if ((unsigned)kind > 2)
        return plume_err_set(err, PLUME_EINVAL, "solver: unknown solver kind %d", (int)kind);
    if (!plume_problem_hessian_pattern(p).colptr)
        return plume_err_set(err, PLUME_EINVAL, "solver: the problem is not finalised (plume_problem_finalize)");
    plume_solver *s = calloc(1, sizeof *s);
    if (!s)
        return plume_err_set(err, PLUME_ENOMEM, "solver: out of memory");
    s->kind = kind;
    plume_status st = kind == PLUME_SOLVER_IPOPT
                          ? plume_ipopt_create(p, o, &s->ipopt)
                          : plume_newton_create(p, o, kind == PLUME_SOLVER_LINEARIZED, &s->newton, err);
    if (st != PLUME_OK && kind == PLUME_SOLVER_IPOPT) /* Ipopt's creation keeps no message */
        plume_err_set(err, st, "ipopt: the solver could not be created (%s)", plume_strerror(st));
    if (st != PLUME_OK) {
        free(s);
        return st;
    }
    *out = s;
    return PLUME_OK;
}

void plume_solver_destroy(plume_solver **ps)
{
    if (!ps || !*ps)
        return;
    plume_newton_destroy(&(*ps)->newton);
    plume_ipopt_destroy(&(*ps)->ipopt);
    free(*ps);
    *ps = NULL;
}

plume_status plume_solver_solve(plume_solver *s, double *u, double *lambda, plume_solve_report *rep)
{
    if (!s)
        return PLUME_EINVAL;
    return s->ipopt ? plume_ipopt_solve(s->ipopt, u, lambda, rep) : plume_newton_solve(s->newton, u, lambda, rep);
}

plume_status plume_solver_set_tol_kkt(plume_solver *s, double tol_kkt)
{
    if (!s || !(tol_kkt > 0.0) || !isfinite(tol_kkt))
        return PLUME_EINVAL;
    if (s->ipopt)
        plume_ipopt_set_tol_kkt(s->ipopt, tol_kkt);
    else
        plume_newton_set_tol_kkt(s->newton, tol_kkt);
    return PLUME_OK;
}

void plume_solver_stats(const plume_solver *s, int *analyses, int *factorizations, double *factor_seconds)
{
    plume_newton_stats(s ? s->newton : NULL, analyses, factorizations, factor_seconds);
}
