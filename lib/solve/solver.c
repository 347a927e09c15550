#include "solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ipopt_solver.h"
#include "newton.h"

struct plume_solver {
    plume_solver_kind kind;
    plume_newton *newton; /* newton and linearized */
    plume_ipopt *ipopt;
};

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

plume_status plume_solver_set_tol_kkt(plume_solver *s, double tol_kkt, plume_err *err)
{
    if (!s || !(tol_kkt > 0.0) || !isfinite(tol_kkt))
        return plume_err_set(err, PLUME_EINVAL, "solver: the KKT tolerance must be finite and > 0 (got %g)%s",
                             tol_kkt, s ? "" : "; no solver given");
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
