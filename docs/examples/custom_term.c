/* plume example: an energy term of your own in a problem of your own (include/plume/problem.h).
 *
 * A chain of n springs along x, its first vertex held, its last pulled by a force F. Two terms of
 * our own: the springs (two vertices a stencil, E = k/2 (|x_j - x_i| - L)^2) and the pull (one
 * vertex, E = -F . x). Every spring then carries F, so the chain stretches by n F / k: the solver's
 * answer is checked against that. Build against the installed library:
 *   cc -std=c11 custom_term.c $(pkg-config --cflags --libs plume) -lm -o custom_term */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <plume/plume.h>

enum { N_SPRINGS = 8 };

typedef struct {
    double k, L;                          /* stiffness (N/m) and rest length (m) */
    plume_index stencil[2 * N_SPRINGS];   /* vertex pairs */
} springs;

/* E = k/2 (r - L)^2, r = |d|, d = x_j - x_i: the gradient is +-k (r - L) d / r, and the 6x6 Hessian
 * block [[K, -K], [-K, K]] with K = k (d d^T / r^2 + (r - L) / r (I - d d^T / r^2)). Projected
 * (a compressed spring's negative curvature dropped) when the solver asks. */
static plume_status springs_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                                 int project)
{
    const springs *s = ctx;
    for (int e = 0; e < N_SPRINGS; e++) {
        const plume_index i = s->stencil[2 * e], j = s->stencil[2 * e + 1];
        double d[3] = {0, 0, 0}, r = 0;
        for (int a = 0; a < dim; a++) {
            d[a] = x[dim * j + a] - x[dim * i + a];
            r += d[a] * d[a];
        }
        r = sqrt(r);
        if (!(r > 0))
            return PLUME_EINVAL;
        if (energy)
            *energy += 0.5 * s->k * (r - s->L) * (r - s->L);
        if (grad)
            for (int a = 0; a < dim; a++) {
                grad[dim * i + a] -= s->k * (r - s->L) * d[a] / r;
                grad[dim * j + a] += s->k * (r - s->L) * d[a] / r;
            }
        if (hblocks) {
            const int kk = 2 * dim;
            double *h = hblocks + (size_t)e * kk * kk, t = (r - s->L) / r;
            if (project && t < 0)
                t = 0;
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++) {
                    const double K = s->k * (d[a] * d[b] / (r * r) + t * ((a == b) - d[a] * d[b] / (r * r)));
                    h[a * kk + b] = K;
                    h[(a + dim) * kk + b + dim] = K;
                    h[a * kk + b + dim] = -K;
                    h[(a + dim) * kk + b] = -K;
                }
        }
    }
    return PLUME_OK;
}

typedef struct {
    double F[3];
    plume_index stencil[1];
} pull;

/* E = -F . x_tip: linear, so its Hessian block is zero */
static plume_status pull_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                              int project)
{
    (void)project;
    const pull *p = ctx;
    const plume_index v = p->stencil[0];
    for (int a = 0; a < dim; a++) {
        if (energy)
            *energy -= p->F[a] * x[dim * v + a];
        if (grad)
            grad[dim * v + a] -= p->F[a];
        if (hblocks)
            for (int b = 0; b < dim; b++)
                hblocks[a * dim + b] = 0;
    }
    return PLUME_OK;
}

int main(void)
{
    plume_openmp_serial();
    const double k = 50.0, L = 0.1, F = 2.0;
    const plume_index nv = N_SPRINGS + 1;
    plume_err err = {{0}};
    plume_problem *p = NULL;
    plume_solver *solver = NULL;
    int ok = 0;
    springs *s = malloc(sizeof *s);
    pull *f = malloc(sizeof *f);
    double *u = NULL;
    if (!s || !f || plume_problem_create(nv, 3, N_SPRINGS * L, &p, &err))
        goto done;
    *s = (springs){.k = k, .L = L};
    for (int e = 0; e < N_SPRINGS; e++)
        s->stencil[2 * e] = e, s->stencil[2 * e + 1] = e + 1;
    *f = (pull){.F = {F, 0, 0}, .stencil = {nv - 1}};
    double *x = plume_problem_x(p);
    for (plume_index v = 0; v < nv; v++) /* at rest, along x, slightly off the line */
        x[3 * v] = L * (double)v, x[3 * v + 1] = 1e-3 * (double)(v % 2), x[3 * v + 2] = 0;
    /* the problem owns each ctx from here on, whether adding succeeds or not */
    plume_term t_springs = {.size = sizeof(plume_term), .name = "springs", .arity = 2, .nstencil = N_SPRINGS, .stencil = s->stencil,
                            .eval = springs_eval, .destroy = free, .ctx = s};
    plume_term t_pull = {.size = sizeof(plume_term), .name = "pull", .arity = 1, .nstencil = 1, .stencil = f->stencil, .eval = pull_eval,
                         .destroy = free, .ctx = f};
    plume_status st = plume_problem_add_term(p, &t_springs, &err);
    s = NULL;
    if (!st)
        st = plume_problem_add_term(p, &t_pull, &err);
    f = NULL;
    for (int a = 0; a < 3 && !st; a++) /* the first vertex held */
        st = plume_problem_fix_dof(p, a, &err);
    if (st || plume_problem_finalize(p, &err))
        goto done;
    plume_solver_opts o;
    plume_solver_opts_default(&o);
    if (plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &solver, &err))
        goto done;
    u = malloc((size_t)plume_problem_nfree(p) * sizeof *u);
    if (!u)
        goto done;
    plume_problem_gather(p, u);
    plume_solve_report rep;
    if (plume_solver_solve(solver, u, NULL, &rep))
        goto done;
    const double tip = plume_problem_x(p)[3 * (nv - 1)], want = N_SPRINGS * (L + F / k);
    printf("stop: %s after %d iterations; tip at %.12f m, exact %.12f m\n", plume_reason_name(rep.reason),
           rep.iterations, tip, want);
    ok = rep.converged && fabs(tip - want) < 1e-9 * want;
done:
    if (!ok && err.msg[0])
        fprintf(stderr, "custom_term: %s\n", err.msg);
    free(s);
    free(f);
    free(u);
    plume_solver_destroy(&solver);
    plume_problem_destroy(&p);
    printf("custom term example: %s\n", ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}
