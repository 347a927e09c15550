#include "solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ipopt_solver.h"
#include "newton.h"
#include "predict.h"
#include "internal/newton_state.h"
#include "../core/opts.h"
#include "options.h"

/* the tangent predictor's workspace (native backends): full vectors xref, dx; free ones r, gp, gm,
 * du, ut; constraint ones c, cp, cm, lnew */
typedef struct {
    double *xref, *dx, *r, *gp, *gm, *du, *ut, *c, *cp, *cm, *lnew;
} predict_work;

struct plume_solver {
    plume_solver_kind kind;
    plume_problem *p;
    plume_newton *newton; /* newton and linearized */
    plume_ipopt *ipopt;
    predict_work w;
};

static void predict_work_free(predict_work *w)
{
    double **a[] = {&w->xref, &w->dx, &w->r, &w->gp, &w->gm, &w->du, &w->ut, &w->c, &w->cp, &w->cm, &w->lnew};
    for (size_t k = 0; k < sizeof a / sizeof *a; k++) {
        free(*a[k]);
        *a[k] = NULL;
    }
}

static plume_status predict_work_alloc(predict_work *w, const plume_problem *p)
{
    size_t nd = (size_t)plume_problem_ndof(p) + 1;
    size_t n = (size_t)plume_problem_nfree(p) + 1, m = (size_t)plume_problem_ncons(p) + 1;
    w->xref = malloc(nd * sizeof *w->xref);
    w->dx = malloc(nd * sizeof *w->dx);
    w->r = malloc(n * sizeof *w->r);
    w->gp = malloc(n * sizeof *w->gp);
    w->gm = malloc(n * sizeof *w->gm);
    w->du = malloc(n * sizeof *w->du);
    w->ut = malloc(n * sizeof *w->ut);
    w->c = calloc(m, sizeof *w->c);
    w->cp = calloc(m, sizeof *w->cp);
    w->cm = calloc(m, sizeof *w->cm);
    w->lnew = calloc(m, sizeof *w->lnew);
    if (!w->xref || !w->dx || !w->r || !w->gp || !w->gm || !w->du || !w->ut || !w->c || !w->cp || !w->cm || !w->lnew) {
        predict_work_free(w);
        return PLUME_ENOMEM;
    }
    return PLUME_OK;
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

static plume_status solver_create(plume_solver_kind kind, plume_problem *p, const plume_solver_opts *o,
                                  const plume_solver *like, plume_solver **out, plume_err *err);

plume_status plume_solver_create(plume_solver_kind kind, plume_problem *p, const plume_solver_opts *o,
                                 plume_solver **out, plume_err *err)
{
    return solver_create(kind, p, o, NULL, out, err);
}

plume_status plume_solver_renew(plume_solver **s, const plume_solver_opts *o, plume_err *err)
{
    if (!s || !*s)
        return plume_err_set(err, PLUME_EINVAL, "solver: renew needs a solver");
    plume_solver *fresh = NULL;
    plume_status st = solver_create((*s)->kind, (*s)->p, o, *s, &fresh, err);
    if (st != PLUME_OK)
        return st;
    plume_solver_destroy(s);
    *s = fresh;
    return PLUME_OK;
}

static plume_status solver_create(plume_solver_kind kind, plume_problem *p, const plume_solver_opts *o,
                                  const plume_solver *like, plume_solver **out, plume_err *err)
{
    if (out)
        *out = NULL;
    if (!p || !out)
        return plume_err_set(err, PLUME_EINVAL, "solver: invalid arguments (problem and out are required)");
    plume_solver_opts full; /* the caller's options over this library's defaults */
    if (plume_solver_opts_take(&full, o, err) != PLUME_OK)
        return PLUME_EINVAL;
    o = &full;
    if ((unsigned)kind > 2)
        return plume_err_set(err, PLUME_EINVAL, "solver: unknown solver kind %d", (int)kind);
    if (!plume_problem_hessian_pattern(p).colptr)
        return plume_err_set(err, PLUME_EINVAL, "solver: the problem is not finalised (plume_problem_finalize)");
    plume_solver *s = calloc(1, sizeof *s);
    if (!s)
        return plume_err_set(err, PLUME_ENOMEM, "solver: out of memory");
    s->kind = kind;
    s->p = p;
    plume_status st = kind == PLUME_SOLVER_IPOPT
                          ? plume_ipopt_create(p, o, &s->ipopt)
                          : plume_newton_create_like(p, o, kind == PLUME_SOLVER_LINEARIZED, like ? like->newton : NULL,
                                           &s->newton, err);
    if (st != PLUME_OK && kind == PLUME_SOLVER_IPOPT) /* Ipopt's creation keeps no message */
        plume_err_set(err, st, "ipopt: the solver could not be created (%s)", plume_strerror(st));
    if (st == PLUME_OK && kind != PLUME_SOLVER_IPOPT && predict_work_alloc(&s->w, p) != PLUME_OK) {
        plume_newton_destroy(&s->newton);
        st = plume_err_set(err, PLUME_ENOMEM, "solver: out of memory");
    }
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
    predict_work_free(&(*ps)->w);
    free(*ps);
    *ps = NULL;
}

plume_status plume_solver_solve(plume_solver *s, double *u, double *lambda, plume_solve_report *rep)
{
    if (!s)
        return PLUME_EINVAL;
    return s->ipopt ? plume_ipopt_solve(s->ipopt, u, lambda, rep) : plume_newton_solve(s->newton, u, lambda, rep);
}

/* The prescribed dofs of x <- base + a dx (dx is 0 on the free ones). */
static void move_prescribed(plume_problem *p, const double *base, const double *dx, double a, plume_index nd)
{
    double *x = plume_problem_x(p);
    for (plume_index i = 0; i < nd; i++)
        if (plume_problem_is_fixed(p, i))
            x[i] = base[i] + a * dx[i];
}

/* The linearised residual of the increment at u (r, c): the gradient and constraints at the start
 * plus their central differences along the prescribed move, whose step eps dx is 1e-6 of the
 * length scale at most (small enough that no element near a handle leaves its valid range, large
 * enough that round-off stays near 1e-10 of the forces; exact for a linear problem at any eps). */
static plume_status predict_residual(plume_solver *s, const double *u, double dmax, plume_index nd)
{
    plume_problem *p = s->p;
    predict_work *w = &s->w;
    plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p);
    double f;
    plume_status st = plume_problem_objective(p, u, &f, w->r);
    if (st == PLUME_OK && m > 0)
        st = plume_problem_constraints(p, u, w->c, NULL);
    if (st != PLUME_OK || !(dmax > 0.0))
        return st;
    const double eps = fmin(1.0, 1e-6 * plume_problem_length_scale(p) / dmax);
    move_prescribed(p, w->xref, w->dx, eps, nd);
    st = plume_problem_objective(p, u, &f, w->gp);
    if (st == PLUME_OK && m > 0)
        st = plume_problem_constraints(p, u, w->cp, NULL);
    move_prescribed(p, w->xref, w->dx, -eps, nd);
    if (st == PLUME_OK)
        st = plume_problem_objective(p, u, &f, w->gm);
    if (st == PLUME_OK && m > 0)
        st = plume_problem_constraints(p, u, w->cm, NULL);
    move_prescribed(p, w->xref, w->dx, 0.0, nd);
    if (st != PLUME_OK)
        return st;
    for (plume_index i = 0; i < n; i++)
        w->r[i] += (w->gp[i] - w->gm[i]) / (2.0 * eps);
    for (plume_index q = 0; q < m; q++)
        w->c[q] += (w->cp[q] - w->cm[q]) / (2.0 * eps);
    return PLUME_OK;
}

plume_status plume_solver_predict(plume_solver *s, double *u, double *lambda, const double *x_target,
                                  int *factorizations, plume_err *err)
{
    if (factorizations)
        *factorizations = 0;
    if (!s || !u)
        return plume_err_set(err, PLUME_EINVAL, "solver: predict needs the solver and u");
    if (!s->newton)
        return plume_err_set(err, PLUME_EINVAL, "solver: the tangent predictor needs a native backend (newton or "
                             "linearized), not %s", plume_solver_kind_name(s->kind));
    plume_problem *p = s->p;
    predict_work *w = &s->w;
    plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p);
    plume_index nd = plume_problem_ndof(p);
    if (m > 0 && !lambda)
        return plume_err_set(err, PLUME_EINVAL, "solver: predict needs the multipliers of a constrained problem");
    double *x = plume_problem_x(p), dmax = 0.0;
    memcpy(w->xref, x, (size_t)nd * sizeof *x);
    for (plume_index i = 0; i < nd; i++) {
        w->dx[i] = x_target && plume_problem_is_fixed(p, i) ? x_target[i] - x[i] : 0.0;
        dmax = fmax(dmax, fabs(w->dx[i]));
    }
    plume_status st = predict_residual(s, u, dmax, nd);
    int f0 = 0, f1 = 0;
    plume_newton_stats(s->newton, NULL, &f0, NULL);
    if (st == PLUME_OK)
        st = plume_newton_linear_step(s->newton, u, lambda, w->r, w->c, w->du, w->lnew);
    plume_newton_stats(s->newton, NULL, &f1, NULL);
    if (factorizations)
        *factorizations = f1 - f0;
    move_prescribed(p, w->xref, w->dx, 1.0, nd); /* the target, whatever happened */
    if (st != PLUME_OK) {
        plume_problem_scatter(p, u);
        return st == PLUME_ESINGULAR ? st : plume_err_set(err, st, "solver: the tangent predictor failed (%s)",
                                                          plume_strerror(st));
    }
    /* the predicted state must be one the energy is defined at (and, with terms that limit steps,
     * reachable from u at the target without crossing) */
    double a = 1.0;
    if (plume_problem_limits_steps(p) && (st = plume_problem_max_step(p, u, w->du, &a)) == PLUME_OK && a < 1.0)
        a *= 0.9;
    double f = 0.0;
    int ok = 0;
    for (int k = 0; st == PLUME_OK && k < 5 && !ok; k++) {
        if (k > 0)
            a *= 0.5;
        for (plume_index i = 0; i < n; i++)
            w->ut[i] = u[i] + a * w->du[i];
        ok = plume_problem_objective(p, w->ut, &f, NULL) == PLUME_OK && isfinite(f);
    }
    if (ok) {
        for (plume_index i = 0; i < n; i++)
            u[i] += a * w->du[i];
        for (plume_index q = 0; q < m; q++)
            lambda[q] += a * (w->lnew[q] - lambda[q]);
        plume_problem_scatter(p, u);
        return PLUME_OK;
    }
    plume_problem_scatter(p, u);
    return st == PLUME_OK ? PLUME_ESINGULAR : st;
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

double plume_solver_memory(const plume_solver *s)
{
    return s && s->newton ? plume_newton_memory(s->newton) : 0.0;
}

void plume_solver_set_memory(plume_solver *s, double memory)
{
    if (s && s->newton)
        plume_newton_set_memory(s->newton, memory);
}
