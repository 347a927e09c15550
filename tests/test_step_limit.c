/* Terms that limit steps (plume_term.max_step: continuous collision detection) and terms whose
 * stencils follow the state (plume_term.update): the solvers never step through a wall that an
 * unsigned-distance barrier cannot see from the other side, and the Hessian pattern follows the
 * stencils. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../lib/solve/solver.h"

/* One vertex pulled by a spring towards (0, -1), through a wall y = 0 that it sees only through
 * its unsigned distance |y|: barrier kappa b(|y|), b(d) = -(d - dhat)^2 ln(d / dhat) for d < dhat
 * (docs/design.md "Contact"). From the far side (y < -dhat) the barrier is 0, so a full Newton step to
 * the spring's rest point is a perfectly good minimiser: only the step limit keeps it out. */
typedef struct {
    plume_index v[1];
    double kappa, dhat, k;
    int limit;
} wall_ctx;

static void barrier(double d, double dhat, double *b, double *db, double *ddb)
{
    *b = *db = *ddb = 0.0;
    if (d >= dhat)
        return;
    double l = log(d / dhat), e = d - dhat;
    *b = -e * e * l;
    *db = -2.0 * e * l - e * e / d;
    *ddb = -2.0 * l - 4.0 * e / d + e * e / (d * d);
}

static plume_status wall_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                              int project)
{
    (void)project;
    wall_ctx *c = ctx;
    double y = x[dim * 0 + 1], d = fabs(y), s = y < 0.0 ? -1.0 : 1.0;
    if (!(d > 0.0))
        return PLUME_ESINGULAR;
    double b, db, ddb;
    barrier(d, c->dhat, &b, &db, &ddb);
    double ex = x[0], ey = x[1] + 1.0;
    if (energy)
        *energy += c->kappa * b + 0.5 * c->k * (ex * ex + ey * ey);
    if (grad) {
        grad[0] += c->k * ex;
        grad[1] += c->kappa * db * s + c->k * ey;
    }
    if (hblocks) {
        memset(hblocks, 0, (size_t)(dim * dim) * sizeof *hblocks);
        hblocks[0] = c->k;
        hblocks[dim + 1] = c->kappa * ddb + c->k;
    }
    return PLUME_OK;
}

/* the wall's crossing time along y + s dy, with a margin: stop at 80 % of the way to y = 0 */
static plume_status wall_max_step(void *ctx, int dim, const double *x, const double *dx, double *alpha)
{
    wall_ctx *c = ctx;
    double y = x[dim * 0 + 1], dy = dx[dim * 0 + 1];
    *alpha = 1.0;
    if (c->limit && y * (y + dy) <= 0.0 && dy != 0.0)
        *alpha = fmin(1.0, 0.8 * fabs(y / dy));
    return PLUME_OK;
}

static plume_problem *wall_problem_kappa(int limit, double kappa);

static plume_problem *wall_problem(int limit)
{
    return wall_problem_kappa(limit, 1.0);
}

static plume_problem *wall_problem_kappa(int limit, double kappa)
{
    plume_problem *p = NULL;
    if (plume_problem_create(1, 2, 1.0, &p, NULL) != PLUME_OK)
        return NULL;
    wall_ctx *c = calloc(1, sizeof *c);
    c->kappa = kappa, c->dhat = 0.1, c->k = 10.0, c->limit = limit;
    plume_term t = {.size = sizeof(plume_term), .name = "wall", .arity = 1, .nstencil = 1, .stencil = c->v, .eval = wall_eval,
                    .destroy = free, .ctx = c, .max_step = wall_max_step};
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    double *x = plume_problem_x(p);
    x[0] = 0.3, x[1] = 0.5;
    plume_err err;
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
    CHECK(plume_problem_limits_steps(p) == 1);
    return p;
}

void test_step_limit_wall(void)
{
    for (int kind = 0; kind < 2; kind++) {
        plume_solver_kind sk = kind ? PLUME_SOLVER_IPOPT : PLUME_SOLVER_NEWTON;
        for (int limit = 1; limit >= 0; limit--) {
            plume_problem *p = wall_problem(limit);
            CHECK(p != NULL);
            if (!p)
                return;
            plume_solver_opts o;
            plume_solver_opts_default(&o);
            plume_solver *s = NULL;
            CHECK(plume_solver_create(sk, p, &o, &s, NULL) == PLUME_OK);
            double u[2] = {0.3, 0.5};
            plume_solve_report rep;
            CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK);
            fprintf(stderr, "    %s, step limit %s: y = %.6g, converged %d, %d iterations, %d limited\n",
                    plume_solver_kind_name(sk), limit ? "on" : "off", u[1], rep.converged, rep.iterations,
                    rep.step_limited);
            if (limit) {
                /* on the near side, at the equilibrium of spring and barrier */
                CHECK(rep.converged && u[1] > 0.0 && u[1] < 0.1);
                CHECK(rep.step_limited > 0);
                CHECK(fabs(u[0]) < 1e-8);
            } else {
                /* what the limit prevents: the unsigned barrier lets the vertex tunnel */
                CHECK(u[1] < 0.0);
                CHECK(rep.step_limited == 0);
            }
            plume_solver_destroy(&s);
            plume_problem_destroy(&p);
        }
    }
    /* max_step of a problem without such terms is 1, and its arguments are checked */
    plume_problem *p = wall_problem(1);
    double u[2] = {0.3, 0.5}, du[2] = {0.0, -1.0}, a = -1.0;
    CHECK(plume_problem_max_step(p, u, du, &a) == PLUME_OK && fabs(a - 0.4) < 1e-15);
    CHECK(plume_problem_max_step(p, u, NULL, &a) == PLUME_EINVAL);
    /* a whole-vector motion from the current x (the handles' move at a step's start) */
    const double dx[2] = {0.0, -1.0}, bad[2] = {0.0, NAN};
    CHECK(plume_problem_max_motion(p, dx, &a) == PLUME_OK && fabs(a - 0.4) < 1e-15);
    CHECK(plume_problem_max_motion(p, bad, &a) == PLUME_EINVAL);
    CHECK(plume_problem_max_motion(p, NULL, &a) == PLUME_EINVAL);
    plume_problem_destroy(&p);
}

/* The wall without its barrier (kappa 0: a pair outside the contact set) but with the step limit:
 * every Newton step runs into the wall and is cut to 80 % of the way. newton stops after four
 * steps cut below 1 % in a row and says why (PLUME_REASON_CONTACT_SET), on the near side, instead
 * of creeping toward the wall until round-off stops it. */
void test_step_limit_blocked(void)
{
    plume_problem *p = wall_problem_kappa(1, 0.0);
    if (!p)
        return;
    plume_solver_opts o;
    plume_solver_opts_default(&o);
    plume_solver *s = NULL;
    CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &s, NULL) == PLUME_OK);
    double u[2] = {0.3, 0.5};
    plume_solve_report rep;
    memset(&rep, 0, sizeof rep);
    if (s)
        CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK);
    fprintf(stderr, "    no barrier, step limit on: %s after %d iterations, y = %.3g\n", plume_reason_name(rep.reason),
            rep.iterations, u[1]);
    CHECK(rep.reason == PLUME_REASON_CONTACT_SET && !rep.converged);
    CHECK(rep.iterations <= 10 && u[1] > 0.0);
    CHECK(strcmp(plume_reason_name(PLUME_REASON_CONTACT_SET), "steps blocked outside the contact set") == 0);
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

/* A pair term whose single stencil (0, 2) exists only while the two vertices are closer than r:
 * update adds or drops it, and the Hessian pattern follows. */
typedef struct {
    plume_index pair[2];
    double r;
    int active;
} near_ctx;

static plume_status near_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                              int project)
{
    (void)project;
    near_ctx *c = ctx;
    if (!c->active)
        return PLUME_OK;
    /* 1/2 |x0 - x2|^2 */
    int k = 2 * dim;
    for (int a = 0; a < dim; a++) {
        double d = x[dim * 0 + a] - x[dim * 2 + a];
        if (energy)
            *energy += 0.5 * d * d;
        if (grad)
            grad[dim * 0 + a] += d, grad[dim * 2 + a] -= d;
    }
    if (hblocks) {
        memset(hblocks, 0, (size_t)(k * k) * sizeof *hblocks);
        for (int a = 0; a < dim; a++) {
            hblocks[a * k + a] = hblocks[(dim + a) * k + dim + a] = 1.0;
            hblocks[a * k + dim + a] = hblocks[(dim + a) * k + a] = -1.0;
        }
    }
    return PLUME_OK;
}

static plume_status near_update(void *ctx, int dim, const double *x, const plume_index **stencil,
                                plume_index *nstencil, int *changed)
{
    near_ctx *c = ctx;
    double d2 = 0.0;
    for (int a = 0; a < dim; a++)
        d2 += (x[a] - x[2 * dim + a]) * (x[a] - x[2 * dim + a]);
    int active = d2 < c->r * c->r;
    *changed = active != c->active;
    c->active = active;
    *stencil = c->pair;
    *nstencil = active;
    return PLUME_OK;
}

static plume_problem *near_problem(int fix_01)
{
    plume_problem *p = NULL;
    CHECK(plume_problem_create(3, 2, 1.0, &p, NULL) == PLUME_OK);
    if (!p)
        return NULL;
    near_ctx *c = calloc(1, sizeof *c);
    c->pair[0] = 0, c->pair[1] = 2, c->r = 1.0;
    plume_term t = {.size = sizeof(plume_term), .name = "near", .arity = 2, .nstencil = 0, .stencil = c->pair, .eval = near_eval,
                    .destroy = free, .ctx = c, .update = near_update};
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    double *x = plume_problem_x(p);
    x[0] = 0.0, x[2] = 1.0, x[4] = 3.0; /* far apart: no stencil */
    for (int d = 0; fix_01 && d < 4; d++)
        CHECK(plume_problem_fix_dof(p, d, NULL) == PLUME_OK);
    plume_err err;
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
    return p;
}

void test_step_limit_update_pattern(void)
{
    plume_problem *p = near_problem(0);
    if (!p)
        return;
    plume_err err;
    double *x = plume_problem_x(p);
    CHECK(plume_problem_limits_steps(p) == 0);
    CHECK(plume_problem_hessian_pattern(p).nnz == 6); /* the diagonal alone */
    int changed = -1;
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 0);
    x[4] = 0.5; /* vertex 2 comes near vertex 0 */
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 1);
    plume_sparsity sp = plume_problem_hessian_pattern(p);
    CHECK(sp.nnz == 12); /* + the 6 off-diagonal pairs of the stencil's 4 dofs (x0, y0, x2, y2) */
    double *h = calloc((size_t)sp.nnz, sizeof *h);
    CHECK(plume_problem_hessian(p, NULL, 1.0, NULL, 0, h) == PLUME_OK);
    double off = 0.0;
    for (plume_index col = 0; col < sp.n; col++)
        for (plume_index k = sp.colptr[col]; k < sp.colptr[col + 1]; k++)
            if (sp.rowind[k] != col)
                off += h[k];
    CHECK(off == -2.0);
    free(h);
    x[4] = 5.0;
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 1);
    CHECK(plume_problem_hessian_pattern(p).nnz == 6);
    CHECK(plume_problem_update_terms(NULL, &changed, &err) == PLUME_EINVAL);
    plume_problem_destroy(&p);

    /* a solver created on the new pattern solves: the pair's spring pulls vertex 2 onto 0 */
    p = near_problem(1);
    if (!p)
        return;
    x = plume_problem_x(p);
    x[4] = 0.5, x[5] = 0.25;
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 1);
    CHECK(plume_problem_hessian_pattern(p).nnz == 3);
    plume_solver *s = NULL;
    plume_solver_opts o;
    plume_solver_opts_default(&o);
    CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &s, NULL) == PLUME_OK);
    double u[2];
    plume_problem_gather(p, u);
    plume_solve_report rep;
    CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK && rep.converged);
    CHECK(fabs(u[0]) < 1e-12 && fabs(u[1]) < 1e-12);
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}
