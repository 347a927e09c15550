/* The native solver's three globalisations (plume_globalization: the curved line search, the
 * straight one, the trust region) on small nonconvex problems with known minima, and the curved
 * search against the straight one on a shell benchmark: same minimiser, the iterations each takes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../macro/scene/scene.h"
#include "harness.h"
#include "../lib/core/problem.h"
#include "../lib/solve/solver.h"
#include "../lib/sim/statics.h"

/* Rosenbrock's valley on one 2-D vertex: (1 - x)^2 + 100 (y - x^2)^2, minimum 0 at (1, 1). The
 * Hessian is indefinite where y > x^2 + 1/200; the "projection" (partial_projection) is the
 * Gauss-Newton block of the two squares. */
static plume_status rosenbrock_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *h,
                                    int project)
{
    (void)ctx;
    const double a = x[0], b = x[1], r = b - a * a;
    if (energy)
        *energy += (1.0 - a) * (1.0 - a) + 100.0 * r * r;
    if (grad) {
        grad[0] += -2.0 * (1.0 - a) - 400.0 * a * r;
        grad[1] += 200.0 * r;
    }
    if (h) {
        memset(h, 0, sizeof(double) * (size_t)(dim * dim));
        h[0] = 2.0 + 800.0 * a * a - (project ? 0.0 : 400.0 * r);
        h[1] = h[dim] = -400.0 * a;
        h[dim + 1] = 200.0;
    }
    return PLUME_OK;
}

static const plume_index ONE_VERTEX[1] = {0};

/* the problem's single vertex's x after a newton solve from (x0, y0) with globalisation g */
static plume_solve_report solve_rosenbrock(plume_globalization g, int partial, double x0, double y0, double out[2])
{
    plume_solve_report rep;
    memset(&rep, 0, sizeof rep);
    plume_problem *p = NULL;
    CHECK(plume_problem_create(1, 2, 1.0, &p, NULL) == PLUME_OK);
    if (!p)
        return rep;
    plume_term t = {.size = sizeof(plume_term), .name = "rosenbrock", .arity = 1, .nstencil = 1, .stencil = ONE_VERTEX, .eval = rosenbrock_eval,
                    .partial_projection = partial};
    plume_err err;
    CHECK(plume_problem_add_term(p, &t, &err) == PLUME_OK && plume_problem_finalize(p, &err) == PLUME_OK);
    plume_solver_opts o;
    plume_solver_opts_default(&o);
    plume_solver_opts_set_globalization(&o, g);
    o.verbose = getenv("PLUME_VERBOSE") != NULL;
    plume_solver *s = NULL;
    CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &s, NULL) == PLUME_OK);
    out[0] = x0, out[1] = y0;
    if (s)
        CHECK(plume_solver_solve(s, out, NULL, &rep) == PLUME_OK);
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
    return rep;
}

/* From the textbook start (-1.2, 1) and from (-1.5, 2.5) (where the Hessian is indefinite), each
 * globalisation reaches (1, 1) to 1e-8; the refused trust-region steps are counted. */
void test_solver_paths_rosenbrock(void)
{
    static const double starts[2][2] = {{-1.2, 1.0}, {-1.5, 2.5}};
    for (int k = 0; k < 2; k++) {
        int it[3];
        for (int g = 0; g < 3; g++) {
            double x[2];
            plume_solve_report r = solve_rosenbrock((plume_globalization)g, 1, starts[k][0], starts[k][1], x);
            CHECK(r.converged);
            CHECK(fabs(x[0] - 1.0) < 1e-8 && fabs(x[1] - 1.0) < 1e-8);
            it[g] = r.iterations;
            if (g == PLUME_GLOBAL_TRUST_REGION)
                CHECK(r.backtracks == 0); /* no line search ran */
            if (g == PLUME_GLOBAL_CURVED_LINE_SEARCH)
                CHECK(r.curved_searches > 0);
            if (g == PLUME_GLOBAL_LINE_SEARCH)
                CHECK(r.curved_searches == 0 && r.rejected_steps == 0);
        }
        fprintf(stderr, "    rosenbrock from (%g, %g): curved %d, straight %d, trust region %d iterations\n", starts[k][0],
                starts[k][1], it[0], it[1], it[2]);
    }
}

/* A point on the unit circle, g = |x|^2 - 1 = 0, minimising f = 4 (x^2 - 1/4)^2 + 3/2 |x - (0, -2)|^2
 * (a double well across x, a pull toward (0, -2)): on the circle the minimum is at (0, -1), with
 * lambda = 3/2. f's Hessian is indefinite where x^2 < 5/48 (near the minimum itself); the start is
 * on the circle at 89 degrees from it. Each globalisation gets there. */
typedef struct {
    double g_scale[1];
} circle_ctx;

static plume_status circle_eval(void *ctx, int dim, const double *x, double *g, double *jac)
{
    (void)ctx;
    (void)dim;
    g[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
    if (jac)
        jac[0] = 2.0 * x[0], jac[1] = 2.0 * x[1];
    return PLUME_OK;
}

static plume_status circle_hess(void *ctx, int dim, const double *x, const double *lambda, double *h, int project)
{
    (void)ctx;
    (void)x;
    memset(h, 0, sizeof(double) * (size_t)(dim * dim));
    double l = project ? fmax(lambda[0], 0.0) : lambda[0];
    h[0] = h[dim + 1] = 2.0 * l;
    return PLUME_OK;
}

static plume_status well_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *h,
                              int project)
{
    (void)ctx;
    const double a = x[0], b = x[1], w = a * a - 0.25;
    if (energy)
        *energy += 4.0 * w * w + 1.5 * (a * a + (b + 2.0) * (b + 2.0));
    if (grad) {
        grad[0] += 16.0 * a * w + 3.0 * a;
        grad[1] += 3.0 * (b + 2.0);
    }
    if (h) {
        memset(h, 0, sizeof(double) * (size_t)(dim * dim));
        double c = 16.0 * w + 32.0 * a * a + 3.0;
        h[0] = project ? fmax(c, 0.0) : c;
        h[dim + 1] = 3.0;
    }
    return PLUME_OK;
}

void test_solver_paths_constrained(void)
{
    for (int g = 0; g < 3; g++) {
        plume_problem *p = NULL;
        CHECK(plume_problem_create(1, 2, 1.0, &p, NULL) == PLUME_OK);
        if (!p)
            return;
        static const double one[1] = {1.0};
        plume_term t = {.size = sizeof(plume_term), .name = "well", .arity = 1, .nstencil = 1, .stencil = ONE_VERTEX, .eval = well_eval};
        plume_constraint c = {.size = sizeof(plume_constraint), .name = "circle", .arity = 1, .m = 1, .stencil = ONE_VERTEX, .scale = one,
                              .eval = circle_eval, .hess = circle_hess};
        plume_err err;
        CHECK(plume_problem_add_term(p, &t, &err) == PLUME_OK && plume_problem_add_constraint(p, &c, &err) == PLUME_OK &&
              plume_problem_finalize(p, &err) == PLUME_OK);
        plume_solver_opts o;
        plume_solver_opts_default(&o);
        plume_solver_opts_set_globalization(&o, (plume_globalization)g);
        o.verbose = getenv("PLUME_VERBOSE") != NULL;
        plume_solver *s = NULL;
        CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &s, NULL) == PLUME_OK);
        double u[2] = {sin(0.99 * 1.5707963267948966), -cos(0.99 * 1.5707963267948966)}, lam[1] = {0.0};
        plume_solve_report r;
        memset(&r, 0, sizeof r);
        if (s)
            CHECK(plume_solver_solve(s, u, lam, &r) == PLUME_OK);
        CHECK(r.converged);
        CHECK(fabs(u[0]) < 1e-7 && fabs(u[1] + 1.0) < 1e-9);
        /* at (0, -1): grad f = (0, 3) = -lambda grad g = -lambda (0, -2): lambda = 3/2 */
        CHECK(fabs(lam[0] - 1.5) < 1e-7);
        fprintf(stderr, "    circle, %s: %d iterations, %d refused trust-region steps, %d curved searches\n",
                plume_globalization_name((plume_globalization)g), r.iterations, r.rejected_steps, r.curved_searches);
        plume_solver_destroy(&s);
        plume_problem_destroy(&p);
    }
}

/* the cantilever's load-stepped Newton iterations and its tip displacement */
static int cantilever(plume_globalization g, double tip[3])
{
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_statics *st = NULL;
    plume_err err;
    int iterations = -1;
    CHECK(plume_scene_load("../data/benchmarks/cantilever_shear.json", &s, &err) == PLUME_OK);
    if (!s)
        return -1;
    s->globalization = g;
    CHECK(plume_scene_statics(s, &p, &st, &err) == PLUME_OK);
    if (st) {
        iterations = 0;
        for (int k = 0; k < s->steps; k++) {
            plume_load_step_report rep;
            CHECK(plume_statics_step(st, &rep) == PLUME_OK && rep.converged);
            iterations += rep.iterations;
        }
        plume_scene_probe_displacement(s, 0, plume_problem_x(p), tip);
    }
    plume_statics_destroy(&st);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return iterations;
}

/* The cantilever under end shear (data/benchmarks): the curved line search reaches the same
 * equilibrium as the straight one in fewer Newton iterations (measured 51 against 89: the curve
 * carries the in-plane motion a large rotation needs, which the straight step leaves to later
 * iterations); the trust region reaches it too. */
void test_solver_paths_cantilever(void)
{
    double tip[3][3];
    int it[3];
    for (int g = 0; g < 3; g++)
        it[g] = cantilever((plume_globalization)g, tip[g]);
    fprintf(stderr, "    cantilever: curved %d, straight %d, trust region %d iterations; tip z %.9f %.9f %.9f\n", it[0],
            it[1], it[2], tip[0][2], tip[1][2], tip[2][2]);
    CHECK(it[0] > 0 && it[1] > 0 && it[2] > 0);
    CHECK(it[0] < it[1]);
    for (int g = 1; g < 3; g++)
        for (int a = 0; a < 3; a++)
            CHECK(fabs(tip[g][a] - tip[0][a]) <= 1e-6 * fabs(tip[0][2]));
}
