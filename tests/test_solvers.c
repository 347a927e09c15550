/* Tests of the solver backends through the plume_solver API on small problems with closed-form
 * solutions, built from terms defined here (springs, anchors, constant forces) and the
 * edge-length constraint. Every case runs under both `newton` (projected Newton / SQP with
 * CHOLMOD) and `ipopt` with the same expectations; `linearized` has its own test. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/edge_length.h"
#include "harness.h"
#include "../lib/core/problem.h"
#include "../lib/solve/solver.h"

/* ---- test terms (any dim, exact gradient and Hessian) ---- */

/* Springs over edges: 1/2 k_e (|x_i - x_j| - L_e)^2; L_e = 0 is the quadratic 1/2 k |x_i - x_j|^2. */
typedef struct {
    plume_index n;
    plume_index *edges;
    double *k, *L;
} spring_ctx;

static void spring_destroy(void *ctx)
{
    spring_ctx *c = ctx;
    if (!c)
        return;
    free(c->edges);
    free(c->k);
    free(c->L);
    free(c);
}

static plume_status spring_eval(void *ctx, int dim, const double *x, double *energy, double *grad,
                                double *hblocks, int project)
{
    const spring_ctx *c = ctx;
    int kd = 2 * dim;
    for (plume_index e = 0; e < c->n; e++) {
        plume_index i = c->edges[2 * e], j = c->edges[2 * e + 1];
        double d[3] = {0, 0, 0}, l2 = 0.0;
        for (int a = 0; a < dim; a++) {
            d[a] = x[dim * i + a] - x[dim * j + a];
            l2 += d[a] * d[a];
        }
        double l = sqrt(l2), k = c->k[e], L = c->L[e];
        if (L > 0.0 && !(l > 0.0))
            return PLUME_EINVAL; /* direction undefined: the solver cuts the step back */
        double r = L > 0.0 ? L / l : 0.0;
        if (energy)
            *energy += 0.5 * k * (l - L) * (l - L);
        if (grad)
            for (int a = 0; a < dim; a++) {
                grad[dim * i + a] += k * (1.0 - r) * d[a];
                grad[dim * j + a] -= k * (1.0 - r) * d[a];
            }
        if (hblocks) {
            /* B = k [(1 - r) (I - n n^T) + n n^T]: eigenvalues k along n, k (1 - r) across, so the
             * PSD projection clamps 1 - r at 0. The stencil block is [B -B; -B B]. */
            double cperp = 1.0 - r;
            if (project && cperp < 0.0)
                cperp = 0.0;
            double *h = hblocks + (size_t)e * kd * kd;
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++) {
                    double nn = l2 > 0.0 ? d[a] * d[b] / l2 : 0.0;
                    double B = k * (cperp * ((a == b) - nn) + nn);
                    h[a * kd + b] = h[(dim + a) * kd + dim + b] = B;
                    h[a * kd + dim + b] = h[(dim + a) * kd + b] = -B;
                }
        }
    }
    return PLUME_OK;
}

/* Springs over `n` edges with stiffness k[] and rest lengths L[] (copied). */
static plume_status spring_term(const plume_index *edges, plume_index n, const double *k, const double *L,
                                plume_term *t)
{
    spring_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->n = n;
    c->edges = malloc((size_t)(2 * n) * sizeof *c->edges);
    c->k = malloc((size_t)n * sizeof *c->k);
    c->L = malloc((size_t)n * sizeof *c->L);
    if (!c->edges || !c->k || !c->L) {
        spring_destroy(c);
        return PLUME_ENOMEM;
    }
    memcpy(c->edges, edges, (size_t)(2 * n) * sizeof *edges);
    memcpy(c->k, k, (size_t)n * sizeof *k);
    memcpy(c->L, L, (size_t)n * sizeof *L);
    memset(t, 0, sizeof *t);
    t->size = sizeof *t;
    t->name = "test springs";
    t->arity = 2;
    t->nstencil = n;
    t->stencil = c->edges;
    t->eval = spring_eval;
    t->destroy = spring_destroy;
    t->ctx = c;
    return PLUME_OK;
}

/* Per-vertex potential 1/2 k |x_v - a_v|^2 - f_v . x_v (anchor to a target and a constant force). */
typedef struct {
    plume_index n;
    plume_index *verts;
    double k;
    double *a, *f; /* [n*3] */
} anchor_ctx;

static void anchor_destroy(void *ctx)
{
    anchor_ctx *c = ctx;
    if (!c)
        return;
    free(c->verts);
    free(c->a);
    free(c->f);
    free(c);
}

static plume_status anchor_eval(void *ctx, int dim, const double *x, double *energy, double *grad,
                                double *hblocks, int project)
{
    (void)project; /* the Hessian k I is PSD already */
    const anchor_ctx *c = ctx;
    for (plume_index s = 0; s < c->n; s++) {
        const double *xv = x + dim * c->verts[s], *a = c->a + 3 * s, *f = c->f + 3 * s;
        for (int q = 0; q < dim; q++) {
            if (energy)
                *energy += 0.5 * c->k * (xv[q] - a[q]) * (xv[q] - a[q]) - f[q] * xv[q];
            if (grad)
                grad[dim * c->verts[s] + q] += c->k * (xv[q] - a[q]) - f[q];
        }
        if (hblocks)
            for (int q = 0; q < dim * dim; q++)
                hblocks[(size_t)s * dim * dim + q] = q % (dim + 1) == 0 ? c->k : 0.0;
    }
    return PLUME_OK;
}

/* Anchors on `n` vertices, targets a[n*3] and forces f[n*3] (3 slots per vertex; NULL = zeros). */
static plume_status anchor_term(const plume_index *verts, plume_index n, double k, const double *a,
                                const double *f, plume_term *t)
{
    anchor_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->n = n;
    c->k = k;
    c->verts = malloc((size_t)n * sizeof *c->verts);
    c->a = calloc((size_t)(3 * n), sizeof *c->a);
    c->f = calloc((size_t)(3 * n), sizeof *c->f);
    if (!c->verts || !c->a || !c->f) {
        anchor_destroy(c);
        return PLUME_ENOMEM;
    }
    memcpy(c->verts, verts, (size_t)n * sizeof *verts);
    if (a)
        memcpy(c->a, a, (size_t)(3 * n) * sizeof *a);
    if (f)
        memcpy(c->f, f, (size_t)(3 * n) * sizeof *f);
    memset(t, 0, sizeof *t);
    t->size = sizeof *t;
    t->name = "test anchors";
    t->arity = 1;
    t->nstencil = n;
    t->stencil = c->verts;
    t->eval = anchor_eval;
    t->destroy = anchor_destroy;
    t->ctx = c;
    return PLUME_OK;
}

static void opts(plume_solver_opts *o)
{
    plume_solver_opts_default(o);
    o->verbose = getenv("PLUME_VERBOSE") != NULL;
}

/* A finalised problem needs no error message here: a failure is a test failure. */
static int finalize(plume_problem *p)
{
    plume_err err;
    plume_status st = plume_problem_finalize(p, &err);
    CHECK(st == PLUME_OK);
    if (st != PLUME_OK)
        fprintf(stderr, "    finalize: %s\n", err.msg);
    return st == PLUME_OK;
}


/* ---- running a case under each backend ---- */

/* The backends that must meet the same expectations (`linearized` seeks no convergence). */
static const plume_solver_kind solver_kinds[] = {PLUME_SOLVER_NEWTON, PLUME_SOLVER_IPOPT};

/* Runs `run` once per backend; the harness prints file:line only, so a line after the failures
 * names the backend they came from. */
static void for_each_solver(void (*run)(plume_solver_kind))
{
    for (size_t i = 0; i < sizeof solver_kinds / sizeof solver_kinds[0]; i++) {
        int before = plume_test_failures;
        run(solver_kinds[i]);
        if (plume_test_failures > before)
            fprintf(stderr, "    ^ %d failure(s) above with solver '%s'\n", plume_test_failures - before,
                    plume_solver_kind_name(solver_kinds[i]));
    }
}

/* ---- (1) unconstrained quadratic with prescribed dofs ---- */

/* Zero-length springs k_e in series 0-1-2-3-4 (2D); vertices 0 and 4 clamped, vertex 2's y
 * prescribed. In a series chain the force is uniform: x_{i+1} - x_i = D / (k_i sum_j 1/k_j).
 * Free dofs, in order: x1 y1 x2 x3 y3; exact[] holds their values at the minimum. */
static const double QF_X0[2] = {0.0, 0.0}, QF_X4[2] = {3.0, 1.0}, QF_Y2 = -2.0;

static plume_problem *quadratic_problem(double exact[5])
{
    const plume_index edges[] = {0, 1, 1, 2, 2, 3, 3, 4};
    const double k[] = {1.0, 2.0, 4.0, 0.5}, L[] = {0, 0, 0, 0};
    plume_problem *p = NULL;
    plume_term t;
    CHECK(plume_problem_create(5, 2, 3.0, &p, NULL) == PLUME_OK);
    if (!p)
        return NULL;
    CHECK(spring_term(edges, 4, k, L, &t) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    double *x = plume_problem_x(p);
    x[0] = QF_X0[0], x[1] = QF_X0[1], x[8] = QF_X4[0], x[9] = QF_X4[1], x[5] = QF_Y2;
    const plume_index fixed[] = {0, 1, 8, 9, 5};
    for (int i = 0; i < 5; i++)
        CHECK(plume_problem_fix_dof(p, fixed[i], NULL) == PLUME_OK);
    if (!finalize(p)) {
        plume_problem_destroy(&p);
        return NULL;
    }
    CHECK(plume_problem_nfree(p) == 5 && plume_problem_ncons(p) == 0);

    /* x along the whole chain; y on 0-1-2 and on 2-3-4 separately */
    double ex[5];
    double cx = 1.0 / k[0] + 1.0 / k[1] + 1.0 / k[2] + 1.0 / k[3];
    ex[0] = QF_X0[0];
    for (int i = 0; i < 4; i++)
        ex[i + 1] = ex[i] + (QF_X4[0] - QF_X0[0]) / (k[i] * cx);
    double ca = 1.0 / k[0] + 1.0 / k[1], cb = 1.0 / k[2] + 1.0 / k[3];
    exact[0] = ex[1];
    exact[1] = QF_X0[1] + (QF_Y2 - QF_X0[1]) / (k[0] * ca);
    exact[2] = ex[2];
    exact[3] = ex[3];
    exact[4] = QF_Y2 + (QF_X4[1] - QF_Y2) / (k[2] * cb);
    return p;
}

static void case_quadratic_fixed(plume_solver_kind kind)
{
    double exact[5];
    plume_problem *p = quadratic_problem(exact);
    plume_solver *s = NULL;
    if (!p)
        return;
    plume_solver_opts o;
    opts(&o);
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double u[5] = {0.3, -1.0, 7.0, 2.0, 0.0};
    plume_solve_report rep;
    CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK); /* m = 0: lambda may be NULL */
    CHECK(rep.reason == PLUME_REASON_CONVERGED && rep.converged);
    for (int i = 0; i < 5; i++)
        CHECK_REL(u[i], exact[i], 1e-10, 1.0);
    /* the problem's x holds the result, prescribed values untouched */
    const double *x = plume_problem_x(p);
    CHECK(x[2] == u[0] && x[7] == u[4] && x[5] == QF_Y2 && x[8] == QF_X4[0]);
    CHECK(rep.kkt_residual <= o.tol_kkt && rep.max_violation == 0.0);
    /* renewed (same pattern: the old order kept), the same solution from the same start */
    plume_solver *old = s;
    CHECK(plume_solver_renew(&s, &o, NULL) == PLUME_OK && s != NULL && s != old);
    double v[5] = {0.3, -1.0, 7.0, 2.0, 0.0};
    CHECK(plume_solver_solve(s, v, NULL, &rep) == PLUME_OK && rep.converged);
    for (int i = 0; i < 5; i++)
        CHECK_REL(v[i], exact[i], 1e-10, 1.0);
    CHECK(plume_solver_renew(NULL, &o, NULL) == PLUME_EINVAL);
    plume_solver *none = NULL;
    CHECK(plume_solver_renew(&none, &o, NULL) == PLUME_EINVAL && none == NULL);
done:
    plume_solver_destroy(&s);
    CHECK(s == NULL);
    plume_problem_destroy(&p);
}

void test_solvers_quadratic_fixed(void)
{
    for_each_solver(case_quadratic_fixed);
}

/* ---- (2) projection onto a circle ---- */

/* Vertex 0 clamped at the origin, vertex 1 pulled by 1/2 k |x - a|^2 and held at distance R:
 * x = R a / |a|; stationarity k (x - a) + 2 lambda x = 0 gives lambda = k (|a| / R - 1) / 2. */
static void case_circle_projection(plume_solver_kind kind)
{
    const double R = 2.0, kk = 3.0, a[3] = {3.0, 4.0, 0.0};
    const double X[4] = {0.0, 0.0, R, 0.0};
    const plume_index edge[2] = {0, 1}, v1 = 1;
    plume_problem *p = NULL;
    plume_solver *s = NULL;
    plume_term t;
    plume_constraint c;
    CHECK(plume_problem_create(2, 2, R, &p, NULL) == PLUME_OK);
    if (!p)
        return;
    CHECK(anchor_term(&v1, 1, kk, a, NULL, &t) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    CHECK(plume_edge_length_create(edge, 1, X, 2, &c, NULL) == PLUME_OK);
    CHECK(plume_problem_add_constraint(p, &c, NULL) == PLUME_OK);
    CHECK(plume_problem_fix_dof(p, 0, NULL) == PLUME_OK && plume_problem_fix_dof(p, 1, NULL) == PLUME_OK);
    if (!finalize(p))
        goto done;
    CHECK(plume_problem_nfree(p) == 2 && plume_problem_ncons(p) == 1);
    plume_solver_opts o;
    opts(&o);
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double na = hypot(a[0], a[1]), lam_exact = kk * (na / R - 1.0) / 2.0;
    /* from a point off the circle, then from the solution itself (warm restart) */
    double u[2] = {0.5, -1.0}, lam = 0.0;
    plume_solve_report rep;
    for (int round = 0; round < 2; round++) {
        CHECK(plume_solver_solve(s, u, &lam, &rep) == PLUME_OK);
        CHECK(rep.reason == PLUME_REASON_CONVERGED && rep.converged);
        CHECK_REL(u[0], R * a[0] / na, 1e-10, 1.0);
        CHECK_REL(u[1], R * a[1] / na, 1e-10, 1.0);
        CHECK_REL(lam, lam_exact, 1e-9, 1.0);
        CHECK(rep.max_violation < 1e-10);
        CHECK(rep.kkt_residual <= o.tol_kkt);
        double e = 0.5 * kk * (R - na) * (R - na);
        CHECK_REL(rep.energy, e, 1e-10, 1.0);
    }
    CHECK(rep.iterations <= 2); /* restarted at the solution: nothing left to do */
done:
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

void test_solvers_circle_projection(void)
{
    for_each_solver(case_circle_projection);
}

/* ---- (3) inextensible chain pulled at its end ---- */

/* N links of length h from a clamped vertex 0, force F on the last vertex, and springs (i, i+2)
 * of rest length 2h resisting folding. The minimum is the straight chain along F (springs at rest,
 * energy -|F| N h), every link in tension |F|: with g = |x_i - x_{i+1}|^2 - h^2 the end vertex
 * gives -F + 2 lambda h t = 0, so lambda = |F| / (2 h) on every link.
 * The force then turns in steps (quasi-static sequence, each solve from the previous one). */
enum { CHAIN_N = 8 };

static plume_problem *chain_problem(double h, double ks, anchor_ctx **force)
{
    plume_problem *p = NULL;
    plume_index nv = CHAIN_N + 1;
    plume_index links[2 * CHAIN_N], skips[2 * (CHAIN_N - 1)];
    double X[2 * (CHAIN_N + 1)], kv[CHAIN_N], Lv[CHAIN_N];
    for (plume_index i = 0; i < nv; i++) {
        X[2 * i] = h * (double)i;
        X[2 * i + 1] = 0.0;
    }
    for (int i = 0; i < CHAIN_N; i++) {
        links[2 * i] = i;
        links[2 * i + 1] = i + 1;
    }
    for (int i = 0; i < CHAIN_N - 1; i++) {
        skips[2 * i] = i;
        skips[2 * i + 1] = i + 2;
        kv[i] = ks;
        Lv[i] = 2.0 * h;
    }
    plume_term t;
    plume_constraint c;
    const plume_index last = CHAIN_N;
    if (plume_problem_create(nv, 2, h * CHAIN_N, &p, NULL) != PLUME_OK)
        return NULL;
    int ok = spring_term(skips, CHAIN_N - 1, kv, Lv, &t) == PLUME_OK && plume_problem_add_term(p, &t, NULL) == PLUME_OK;
    ok = ok && anchor_term(&last, 1, 0.0, NULL, NULL, &t) == PLUME_OK;
    *force = ok ? t.ctx : NULL; /* owned by the problem, stays valid: the test turns the force */
    ok = ok && plume_problem_add_term(p, &t, NULL) == PLUME_OK;
    ok = ok && plume_edge_length_create(links, CHAIN_N, X, nv, &c, NULL) == PLUME_OK &&
         plume_problem_add_constraint(p, &c, NULL) == PLUME_OK;
    ok = ok && plume_problem_fix_dof(p, 0, NULL) == PLUME_OK && plume_problem_fix_dof(p, 1, NULL) == PLUME_OK;
    memcpy(plume_problem_x(p), X, sizeof X);
    if (!ok || plume_problem_finalize(p, NULL) != PLUME_OK)
        plume_problem_destroy(&p);
    return p;
}

static const double CHAIN_H = 0.01, CHAIN_F = 2.0, CHAIN_KS = 50.0; /* cm links: SI scales, not O(1) */

static void case_chain(plume_solver_kind kind)
{
    const double h = CHAIN_H, Fmag = CHAIN_F;
    plume_solver_opts o;
    opts(&o);
    anchor_ctx *force = NULL;
    plume_problem *p = chain_problem(h, CHAIN_KS, &force);
    plume_solver *s = NULL;
    CHECK(p != NULL);
    if (!p)
        return;
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double u[2 * CHAIN_N], lam[CHAIN_N];
    memset(lam, 0, sizeof lam);
    plume_problem_gather(p, u); /* straight along x */
    for (int step = 0; step <= 4; step++) {
        double th = 0.3 + 0.5 * (double)step; /* the force turns by 0.5 rad per step */
        double tx = cos(th), ty = sin(th);
        force->f[0] = Fmag * tx;
        force->f[1] = Fmag * ty;
        plume_solve_report rep;
        int before = plume_test_failures;
        CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK);
        CHECK(rep.reason == PLUME_REASON_CONVERGED);
        double err = 0.0, lerr = 0.0;
        for (int i = 1; i <= CHAIN_N; i++) {
            err = fmax(err, fabs(u[2 * (i - 1)] - i * h * tx) + fabs(u[2 * (i - 1) + 1] - i * h * ty));
            lerr = fmax(lerr, fabs(lam[i - 1] - Fmag / (2.0 * h)));
        }
        CHECK(err <= 1e-9 * h);
        CHECK(lerr <= 1e-8 * Fmag / (2.0 * h));
        CHECK(rep.max_violation <= o.tol_violation);
        CHECK(rep.kkt_residual <= o.tol_kkt);
        CHECK_REL(rep.energy, -Fmag * CHAIN_N * h, 1e-10, 1e-12);
        if (plume_test_failures > before)
            fprintf(stderr, "    (step %d: %s after %d iterations)\n", step, plume_reason_name(rep.reason),
                    rep.iterations);
    }
done:
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

void test_solvers_chain(void)
{
    for_each_solver(case_chain);
}

/* One solver, two tolerances (plume_solver_set_tol_kkt): from a start a little off equilibrium,
 * a tolerance of 1 (relative) is met before any iteration, the default one is not; bad tolerances
 * are refused. */
static void case_set_tol(plume_solver_kind kind)
{
    plume_solver_opts o;
    opts(&o);
    anchor_ctx *force = NULL;
    plume_problem *p = chain_problem(CHAIN_H, CHAIN_KS, &force);
    plume_solver *s = NULL;
    if (!p)
        return;
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double u[2 * CHAIN_N], lam[CHAIN_N];
    memset(lam, 0, sizeof lam);
    plume_problem_gather(p, u);
    force->f[0] = CHAIN_F, force->f[1] = 0.0;
    plume_solve_report rep;
    CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK && rep.converged);
    force->f[0] = CHAIN_F * cos(1e-3), force->f[1] = CHAIN_F * sin(1e-3); /* turned a little */
    CHECK(plume_solver_set_tol_kkt(s, 1.0, NULL) == PLUME_OK);
    CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK && rep.converged && rep.iterations == 0);
    double loose = rep.kkt_residual;
    CHECK(plume_solver_set_tol_kkt(s, o.tol_kkt, NULL) == PLUME_OK);
    CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK && rep.converged && rep.iterations > 0);
    fprintf(stderr, "    %s: kkt %.2e after 0 iterations at tolerance 1, %.2e after %d at %.0e\n",
            plume_solver_kind_name(kind), loose, rep.kkt_residual, rep.iterations, o.tol_kkt);
    CHECK(loose > o.tol_kkt && rep.kkt_residual <= o.tol_kkt);
    CHECK(plume_solver_set_tol_kkt(s, 0.0, NULL) == PLUME_EINVAL);
    CHECK(plume_solver_set_tol_kkt(s, NAN, NULL) == PLUME_EINVAL);
    CHECK(plume_solver_set_tol_kkt(s, INFINITY, NULL) == PLUME_EINVAL);
    CHECK(plume_solver_set_tol_kkt(NULL, 1e-9, NULL) == PLUME_EINVAL);
done:
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

void test_solvers_set_tol_kkt(void)
{
    for_each_solver(case_set_tol);
}

/* ---- (4) infeasible ---- */

/* A - C - B with rest lengths 1/2 each, A and B clamped 2 apart: C cannot reach both. Neither
 * backend may call this converged; which reason it gives is printed. */
static void case_infeasible(plume_solver_kind kind)
{
    const double X[6] = {0.0, 0.0, 0.5, 0.0, 1.0, 0.0};
    const plume_index edges[4] = {0, 1, 1, 2}, vc = 1;
    const double a[3] = {1.0, 0.3, 0.0};
    plume_problem *p = NULL;
    plume_solver *s = NULL;
    plume_term t;
    plume_constraint c;
    CHECK(plume_problem_create(3, 2, 1.0, &p, NULL) == PLUME_OK);
    if (!p)
        return;
    CHECK(anchor_term(&vc, 1, 1.0, a, NULL, &t) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    CHECK(plume_edge_length_create(edges, 2, X, 3, &c, NULL) == PLUME_OK);
    CHECK(plume_problem_add_constraint(p, &c, NULL) == PLUME_OK);
    double *x = plume_problem_x(p);
    x[4] = 2.0; /* B at (2, 0) */
    for (plume_index d = 0; d < 6; d++)
        if (d != 2 && d != 3)
            CHECK(plume_problem_fix_dof(p, d, NULL) == PLUME_OK);
    if (!finalize(p))
        goto done;
    plume_solver_opts o;
    opts(&o);
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double u[2] = {1.0, 0.2}, lam[2] = {0.0, 0.0};
    plume_solve_report rep;
    CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK);
    CHECK(rep.reason != PLUME_REASON_CONVERGED && !rep.converged);
    CHECK(rep.max_violation > o.tol_violation);
    CHECK(rep.iterations <= o.max_iter);
    fprintf(stderr, "    note: infeasible problem, solver '%s' reports '%s' after %d iterations (violation %.3g)\n",
            plume_solver_kind_name(kind), plume_reason_name(rep.reason), rep.iterations, rep.max_violation);
done:
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

void test_solvers_infeasible(void)
{
    for_each_solver(case_infeasible);
}

/* ---- (5) overdetermined ---- */

/* More constraints than unknowns: one free vertex tied to three clamped ones, pulled towards the
 * one point (1, 1) that satisfies all three. From that point both backends report convergence
 * without moving. From elsewhere the system is still consistent: a backend may converge (then to
 * (1, 1)) or give up; Ipopt refuses any problem with fewer unknowns than equalities and reports
 * it infeasible, returning the start as given. */
static void case_overdetermined(plume_solver_kind kind)
{
    const double X[8] = {0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 1.0, 1.0}; /* vertex 3 free at (1, 1) */
    const plume_index edges[6] = {3, 0, 3, 1, 3, 2}, v3 = 3;
    const double a[3] = {1.0, 1.0, 0.0};
    plume_problem *p = NULL;
    plume_solver *s = NULL;
    plume_term t;
    plume_constraint c;
    CHECK(plume_problem_create(4, 2, 2.0, &p, NULL) == PLUME_OK);
    if (!p)
        return;
    CHECK(anchor_term(&v3, 1, 1.0, a, NULL, &t) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    CHECK(plume_edge_length_create(edges, 3, X, 4, &c, NULL) == PLUME_OK);
    CHECK(plume_problem_add_constraint(p, &c, NULL) == PLUME_OK);
    memcpy(plume_problem_x(p), X, sizeof X);
    for (plume_index d = 0; d < 6; d++)
        CHECK(plume_problem_fix_dof(p, d, NULL) == PLUME_OK);
    if (!finalize(p))
        goto done;
    CHECK(plume_problem_nfree(p) == 2 && plume_problem_ncons(p) == 3);
    plume_solver_opts o;
    opts(&o);
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double u[2] = {1.0, 1.0}, lam[3] = {0.0, 0.0, 0.0};
    plume_solve_report rep;
    CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK);
    CHECK(rep.reason == PLUME_REASON_CONVERGED && rep.converged && u[0] == 1.0 && u[1] == 1.0);
    CHECK(rep.max_violation == 0.0);
    u[0] = 1.2;
    CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK);
    CHECK(rep.converged == (rep.reason == PLUME_REASON_CONVERGED));
    if (rep.converged) {
        CHECK_REL(u[0], 1.0, 1e-10, 1.0);
        CHECK_REL(u[1], 1.0, 1e-10, 1.0);
        /* PLUME_REASON_CONVERGED: the tolerances met, or newton at its round-off floor within
         * sqrt(tol_kkt) (here 1.1e-9 against 1e-9: the multipliers wander, LICQ failing) */
        CHECK(rep.max_violation <= o.tol_violation &&
              rep.kkt_residual <= (kind == PLUME_SOLVER_NEWTON ? sqrt(o.tol_kkt) : o.tol_kkt));
    } else {
        CHECK(rep.max_violation > o.tol_violation || rep.kkt_residual > o.tol_kkt);
    }
    if (kind == PLUME_SOLVER_IPOPT) {
        CHECK(rep.reason == PLUME_REASON_INFEASIBLE && !rep.converged);
        CHECK(u[0] == 1.2 && u[1] == 1.0); /* returned as given */
    }
    if (kind == PLUME_SOLVER_NEWTON) {
        /* LICQ fails here (three gradients in 2D), so the multipliers are not unique and the SQP
         * multiplier iteration may wander in the null space of J^T: the primal point must still be
         * found, and the report must not claim more than it measured (checked above) */
        CHECK_REL(u[0], 1.0, 1e-8, 1.0);
        CHECK_REL(u[1], 1.0, 1e-8, 1.0);
        if (!rep.converged)
            fprintf(stderr, "    note: newton on the overdetermined case: '%s' at (%.17g, %.17g), kkt %.3g\n",
                    plume_reason_name(rep.reason), u[0], u[1], rep.kkt_residual);
    }
done:
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

void test_solvers_overdetermined(void)
{
    for_each_solver(case_overdetermined);
}

/* ---- (6) report fields, iteration cap, bad input ---- */

static void case_report(plume_solver_kind kind)
{
    const double X[4] = {0.0, 0.0, 1.0, 0.0};
    const plume_index edge[2] = {0, 1}, v1 = 1;
    const double a[3] = {-1.0, 3.0, 0.0};
    plume_problem *p = NULL;
    plume_solver *s = NULL;
    plume_term t;
    plume_constraint c;
    plume_solve_report rep;
    plume_solver_opts o;
    opts(&o);

    /* argument checks before anything exists */
    CHECK(plume_solver_create(kind, NULL, &o, &s, NULL) == PLUME_EINVAL && s == NULL);

    CHECK(plume_problem_create(2, 2, 1.0, &p, NULL) == PLUME_OK);
    if (!p)
        return;
    CHECK(anchor_term(&v1, 1, 1.0, a, NULL, &t) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
    CHECK(plume_edge_length_create(edge, 1, X, 2, &c, NULL) == PLUME_OK);
    CHECK(plume_problem_add_constraint(p, &c, NULL) == PLUME_OK);
    CHECK(plume_problem_fix_dof(p, 0, NULL) == PLUME_OK && plume_problem_fix_dof(p, 1, NULL) == PLUME_OK);
    CHECK(plume_solver_create(kind, p, &o, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_solver_create(kind, p, NULL, &s, NULL) == PLUME_EINVAL && s == NULL);
    plume_err why = {{0}};
    CHECK(plume_solver_create(kind, p, &o, &s, &why) == PLUME_EINVAL && s == NULL); /* not finalised */
    CHECK(strstr(why.msg, "not finalised") != NULL);
    plume_solver_destroy(&s);
    if (!finalize(p))
        goto done;
    /* tolerances must be positive, the iteration budget not negative; newton's globalisation
     * options within their ranges (ipopt does not read them) */
    const int nbad = kind == PLUME_SOLVER_IPOPT ? 4 : 8;
    for (int which = 0; which < nbad; which++) {
        plume_solver_opts bad = o;
        if (which == 0)
            bad.tol_kkt = 0.0;
        else if (which == 1)
            bad.tol_violation = -1e-10;
        else if (which == 2)
            bad.tol_kkt = NAN;
        else if (which == 3)
            bad.max_iter = -1;
        else if (which == 4)
            bad.line_search = (plume_line_search)7;
        else if (which == 5)
            bad.reuse_rate = 1.0;
        else if (which == 6)
            bad.inertia_max_shift = 0.0;
        else
            bad.inertia_max_shift = INFINITY;
        why.msg[0] = 0;
        plume_status st = plume_solver_create(kind, p, &bad, &s, &why);
        CHECK(st == PLUME_EINVAL && s == NULL);
        /* the message names the options (newton's own, or Ipopt's creation) */
        CHECK(strstr(why.msg, kind == PLUME_SOLVER_IPOPT ? "ipopt" : "options need") != NULL);
        if (st != PLUME_EINVAL)
            fprintf(stderr, "    (bad option %d accepted)\n", which);
        plume_solver_destroy(&s);
    }

    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    double u[2] = {1.0, 0.0}, lam = 0.0;
    CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_EINVAL); /* m = 1 needs lambda */
    CHECK(plume_solver_solve(s, NULL, &lam, &rep) == PLUME_EINVAL);
    CHECK(plume_solver_solve(s, u, &lam, NULL) == PLUME_EINVAL);
    CHECK(plume_solver_solve(s, u, &lam, &rep) == PLUME_OK);
    CHECK(rep.reason == PLUME_REASON_CONVERGED && rep.converged == 1);
    CHECK(rep.iterations > 0 && rep.iterations <= o.max_iter);
    if (kind == PLUME_SOLVER_NEWTON) /* one factorisation per step, except chord steps */
        CHECK(rep.factorizations + rep.chord_steps >= rep.iterations && rep.chord_steps <= rep.iterations);
    CHECK(rep.seconds >= 0.0 && rep.seconds < 60.0);
    CHECK(rep.kkt_residual >= 0.0 && rep.kkt_residual <= o.tol_kkt);
    CHECK(rep.max_violation >= 0.0 && rep.max_violation <= o.tol_violation);
    double na = hypot(a[0], a[1]);
    CHECK_REL(rep.energy, 0.5 * (na - 1.0) * (na - 1.0), 1e-10, 1.0);
    /* the report agrees with plume's own measures at the returned point */
    double kkt, viol, f;
    CHECK(plume_problem_kkt_residual(p, u, &lam, &kkt) == PLUME_OK && kkt == rep.kkt_residual);
    CHECK(plume_problem_constraints(p, u, NULL, &viol) == PLUME_OK && viol == rep.max_violation);
    CHECK(plume_problem_objective(p, u, &f, NULL) == PLUME_OK && f == rep.energy);
    plume_solver_destroy(&s);

    /* one iteration from far away is not enough: ITERATION_CAP, never a silent success */
    o.max_iter = 1;
    CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
    if (!s)
        goto done;
    u[0] = 0.8, u[1] = -0.6, lam = 0.0;
    CHECK(plume_solver_solve(s, u, &lam, &rep) == PLUME_OK);
    CHECK(rep.reason == PLUME_REASON_ITERATION_CAP && !rep.converged);
    CHECK(rep.iterations == 1);
    CHECK(rep.kkt_residual > o.tol_kkt || rep.max_violation > o.tol_violation);
done:
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
}

void test_solvers_report(void)
{
    /* the dispatch layer itself */
    plume_solver_kind k = PLUME_SOLVER_IPOPT;
    for (int i = 0; i < 3; i++) {
        CHECK(plume_solver_kind_parse(plume_solver_kind_name((plume_solver_kind)i), &k) == PLUME_OK);
        CHECK(k == (plume_solver_kind)i);
    }
    CHECK(plume_solver_kind_parse("Newton", &k) == PLUME_EINVAL && k == PLUME_SOLVER_LINEARIZED);
    CHECK(plume_solver_kind_parse(NULL, &k) == PLUME_EINVAL);
    CHECK(strcmp(plume_solver_kind_name((plume_solver_kind)7), "unknown") == 0);
    CHECK(strcmp(plume_reason_name(PLUME_REASON_ITERATION_CAP), "iteration cap") == 0);
    plume_solve_report rep;
    plume_solver_opts o;
    opts(&o);
    plume_solver *s = NULL;
    double u = 0.0;
    CHECK(plume_solver_solve(NULL, &u, NULL, &rep) == PLUME_EINVAL);
    plume_solver_destroy(NULL);
    plume_solver_destroy(&s);
    double exact[5];
    plume_problem *p = quadratic_problem(exact);
    if (p) {
        CHECK(plume_solver_create((plume_solver_kind)3, p, &o, &s, NULL) == PLUME_EINVAL && s == NULL);
        plume_problem_destroy(&p);
    }
    for_each_solver(case_report);
}

/* ---- (7) the single linearised step ---- */

/* On a quadratic energy without constraints one Newton step is the solution; on the chain the
 * step follows the tangent of the constraint manifold and stretches the links (the failure of
 * linearised predictions that the paper shows), while `newton` from the same start does not. */
void test_solvers_linearized(void)
{
    plume_solver_opts o;
    opts(&o);
    plume_solve_report rep;
    plume_solver *s = NULL;
    double exact[5];
    plume_problem *p = quadratic_problem(exact);
    if (!p)
        return;
    CHECK(plume_solver_create(PLUME_SOLVER_LINEARIZED, p, &o, &s, NULL) == PLUME_OK);
    if (s) {
        double u[5] = {0.3, -1.0, 7.0, 2.0, 0.0};
        CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK);
        CHECK(rep.reason == PLUME_REASON_SINGLE_STEP && !rep.converged);
        CHECK(rep.iterations == 1);
        for (int i = 0; i < 5; i++)
            CHECK_REL(u[i], exact[i], 1e-10, 1.0);
        CHECK(rep.kkt_residual <= 1e-10 && rep.max_violation == 0.0);
        CHECK(plume_problem_x(p)[2] == u[0]);
    }
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);

    /* chain at equilibrium under a force along th0 (exact positions and multipliers), then the
     * force turns by 0.5 rad */
    const double h = CHAIN_H, Fmag = CHAIN_F, th0 = 0.3, th1 = 0.8;
    anchor_ctx *force = NULL;
    p = chain_problem(h, CHAIN_KS, &force);
    CHECK(p != NULL);
    if (!p)
        return;
    double u0[2 * CHAIN_N], lam0[CHAIN_N];
    for (int i = 1; i <= CHAIN_N; i++) {
        u0[2 * (i - 1)] = i * h * cos(th0);
        u0[2 * (i - 1) + 1] = i * h * sin(th0);
        lam0[i - 1] = Fmag / (2.0 * h);
    }
    force->f[0] = Fmag * cos(th1);
    force->f[1] = Fmag * sin(th1);
    for (int pass = 0; pass < 2; pass++) {
        plume_solver_kind kind = pass == 0 ? PLUME_SOLVER_LINEARIZED : PLUME_SOLVER_NEWTON;
        double u[2 * CHAIN_N], lam[CHAIN_N];
        memcpy(u, u0, sizeof u);
        memcpy(lam, lam0, sizeof lam);
        CHECK(plume_solver_create(kind, p, &o, &s, NULL) == PLUME_OK);
        if (!s)
            break;
        CHECK(plume_solver_solve(s, u, lam, &rep) == PLUME_OK);
        double viol;
        CHECK(plume_problem_constraints(p, u, NULL, &viol) == PLUME_OK && viol == rep.max_violation);
        if (kind == PLUME_SOLVER_LINEARIZED) {
            CHECK(rep.reason == PLUME_REASON_SINGLE_STEP && !rep.converged && rep.iterations == 1);
            CHECK(rep.max_violation > 1e-6);
            /* the step did move the chain towards the new force */
            CHECK(atan2(u[2 * CHAIN_N - 1], u[2 * CHAIN_N - 2]) > th0 + 0.1);
            fprintf(stderr, "    note: linearised step on the chain: violation %.3g\n", rep.max_violation);
        } else {
            CHECK(rep.converged && rep.max_violation <= o.tol_violation);
            CHECK_REL(atan2(u[2 * CHAIN_N - 1], u[2 * CHAIN_N - 2]), th1, 1e-9, 1.0);
        }
        plume_solver_destroy(&s);
    }
    plume_problem_destroy(&p);
}

/* A wavy term on one vertex: c cos(x0), curvature -c cos(x0) along x0, indefinite where cos > 0.
 * Its "projection" (partial_projection) drops that curvature, as Gauss-Newton bending does. */
typedef struct {
    plume_index v[1];
    double c;
} wave_ctx;

static plume_status wave_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *h,
                              int project)
{
    const wave_ctx *w = ctx;
    if (energy)
        *energy += w->c * cos(x[0]);
    if (grad)
        grad[0] += -w->c * sin(x[0]);
    if (h) {
        memset(h, 0, sizeof(double) * (size_t)(dim * dim));
        h[0] = project ? 0.0 : -w->c * cos(x[0]);
    }
    return PLUME_OK;
}

/* With a term whose exact block is indefinite but whose projection is cheap (plume_term.
 * partial_projection), newton projects that term alone before shifting the whole matrix: no
 * inertia shift, the same minimiser. The three Hessian modes assemble what they say. */
void test_solvers_partial_projection(void)
{
    double x_end[2][2];
    int shifts[2], partial[2];
    for (int run = 0; run < 2; run++) {
        plume_problem *p = NULL;
        CHECK(plume_problem_create(1, 2, 1.0, &p, NULL) == PLUME_OK);
        if (!p)
            return;
        const plume_index v0 = 0;
        const double a[3] = {2.0, 0.5, 0.0};
        plume_term anchor;
        CHECK(anchor_term(&v0, 1, 1.0, a, NULL, &anchor) == PLUME_OK);
        CHECK(plume_problem_add_term(p, &anchor, NULL) == PLUME_OK);
        static wave_ctx w = {{0}, 3.0};
        plume_term t = {.size = sizeof(plume_term), .name = "wave", .arity = 1, .nstencil = 1, .stencil = w.v, .eval = wave_eval, .ctx = &w,
                        .partial_projection = 1};
        CHECK(plume_problem_add_term(p, &t, NULL) == PLUME_OK);
        CHECK(finalize(p));
        double *x = plume_problem_x(p);
        x[0] = 0.1, x[1] = 0.0; /* cos > 1/3: the exact Hessian 1 - 3 cos(x0) is negative */
        if (run == 0) { /* the modes: x0 block exact 1 - 3 cos, partial 1, projected 1 */
            plume_sparsity hp = plume_problem_hessian_pattern(p);
            double *h = calloc((size_t)hp.nnz, sizeof *h);
            double u[2] = {0.1, 0.0};
            CHECK(plume_problem_hessian(p, u, 1.0, NULL, PLUME_HESSIAN_EXACT, h) == PLUME_OK);
            CHECK_REL(h[0], 1.0 - 3.0 * cos(0.1), 1e-12, 0.0);
            CHECK(plume_problem_hessian(p, u, 1.0, NULL, PLUME_HESSIAN_PARTIAL, h) == PLUME_OK);
            CHECK_REL(h[0], 1.0, 1e-12, 0.0);
            CHECK(plume_problem_hessian(p, u, 1.0, NULL, PLUME_HESSIAN_PROJECTED, h) == PLUME_OK);
            CHECK_REL(h[0], 1.0, 1e-12, 0.0);
            CHECK(plume_problem_has_partial_projection(p) == 1);
            free(h);
        }
        plume_solver_opts o;
        opts(&o);
        o.partial_projection = run == 0;
        plume_solver *s = NULL;
        CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &s, NULL) == PLUME_OK);
        double u[2] = {0.1, 0.0};
        plume_solve_report rep;
        CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK && rep.converged);
        shifts[run] = rep.shifts, partial[run] = rep.partial_projections;
        memcpy(x_end[run], u, sizeof u);
        plume_solver_destroy(&s);
        plume_problem_destroy(&p);
    }
    fprintf(stderr, "    partial projection: %d shifts, %d partly projected; off: %d shifts; x0 %.12f vs %.12f\n", shifts[0],
            partial[0], shifts[1], x_end[0][0], x_end[1][0]);
    CHECK(shifts[0] == 0 && partial[0] >= 1);
    CHECK(shifts[1] >= 1 && partial[1] == 0);
    CHECK(fabs(x_end[0][0] - x_end[1][0]) < 1e-9 && fabs(x_end[0][1] - 0.5) < 1e-9);
    /* the minimiser: x0 - 2 - 3 sin(x0) = 0, in (pi/2, pi)... checked through the gradient */
    CHECK(fabs(x_end[0][0] - 2.0 - 3.0 * sin(x_end[0][0])) < 1e-8);
}
