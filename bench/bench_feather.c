/* make bench (third part) — the shipped feather (data/feather/scene_anisotropic.json) at two
 * resolutions: seconds per frame and Newton iterations per step for `newton`, `ipopt` and
 * `linearized`, side by side, over the first steps of the scene (the rachis tip being pulled).
 * Then the feather at 44.7k elements: one Newton iteration's parts and the first step's seconds
 * per iteration, bent by the shape operator and by midedge bending in the same run.
 * `bench_feather --models` (not in make bench: 6-7 minutes): the three bending models at the
 * feather's three meshes (feather_models.c). */
#define _DEFAULT_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../tests/plume_tree.h"
#include "feather_models.h"

#define STEPS 20
#define DEFAULT_SCENE "data/feather/scene_anisotropic.json"
#define LARGE_SCENE "data/feather/scene_anisotropic_0.625mm.json"
#define MODELS_STEPS 10 /* --models: the pull's first 10 steps (0.11 s, the tip a fifth of its way) */

/* the feather's meshes, coarse to fine, for the bending models' part (feather_models.c) */
static const char *const model_scenes[3] = {DEFAULT_SCENE, "data/feather/scene_anisotropic_1.25mm.json", LARGE_SCENE};

/* A copy of the scene with another mesh edge and solver, paths made absolute, in /tmp. */
static int variant(const char *scene, double edge, const char *solver, char *out, size_t n)
{
    char dir[PATH_MAX];
    if (!realpath(scene, dir))
        return -1;
    *strrchr(dir, '/') = '\0';
    json_error_t je;
    json_t *j = json_load_file(scene, 0, &je);
    if (!j)
        return -1;
    json_t *mesh = json_object_get(j, "mesh");
    const char *keys[2] = {"feather", "outline"};
    for (int k = 0; k < 2; k++) {
        char p[PATH_MAX + 256];
        snprintf(p, sizeof p, "%s/%s", dir, json_string_value(json_object_get(mesh, keys[k])));
        json_object_set_new(mesh, keys[k], json_string(p));
    }
    json_object_set_new(mesh, "edge", json_real(edge));
    json_object_set_new(j, "solver", json_string(solver));
    snprintf(out, n, "/tmp/plume-bench-feather-%d.json", (int)getpid());
    int rc = json_dump_file(j, out, JSON_INDENT(1));
    json_decref(j);
    return rc;
}

/* The tables' titles and column lines (the large feather's apart: a line of sizes sits between
 * them); `bench_feather --header` prints them alone, for the default scenes (the check of
 * docs/benchmarks.md, scripts/bench-tables.py, compares them with the page). */
static void header_steps(const char *scene)
{
    printf("\nplume bench (feather): %s, first %d steps, seconds per frame (= step) and Newton iterations per step\n",
           scene, STEPS);
    printf("%8s %9s | %-10s | %9s %8s %8s %9s | %s\n", "edge", "elements", "solver", "s/frame", "it/step", "halved",
           "violation", "vs newton");
}

static void header_large_title(const char *scene)
{
    printf("\nplume bench (feather, one iteration): %s\n", scene);
}

static void header_large_columns(void)
{
    printf("%12s %12s %12s %12s %12s %12s | %12s\n", "energy+grad", "constraints", "Hessian blk", "scatter",
           "factorise", "solve", "analysis");
}

/* The work arrays of one Newton iteration on a problem of n unknowns and m constraints. */
typedef struct {
    double *u, *grad, *sol, *values, *g, *jv, *lambda;
} iteration_arrays;

/* best[] = the CPU seconds (best of 3) of an iteration's parts at u: energy and gradient, the
 * constraints and their Jacobian, the Hessian blocks, their scatter, a factorisation (shifted
 * until it succeeds), a solve. */
static void time_iteration_parts(plume_problem *p, plume_chol *chol, const plume_sparsity *hp, iteration_arrays *a,
                                 double best[6])
{
    const plume_index n = plume_problem_nfree(p);
    double f, t0;
    for (int k = 0; k < 6; k++)
        best[k] = INFINITY;
    for (int r = 0; r < 3; r++) {
        plume_problem_timing ta, tb;
        t0 = plume_cpu_seconds();
        plume_problem_objective(p, a->u, &f, a->grad);
        best[0] = fmin(best[0], plume_cpu_seconds() - t0);
        t0 = plume_cpu_seconds();
        plume_problem_constraints(p, a->u, a->g, NULL);
        plume_problem_jacobian(p, a->u, a->jv);
        best[1] = fmin(best[1], plume_cpu_seconds() - t0);
        plume_problem_timing_get(p, &ta);
        plume_problem_hessian(p, a->u, 1.0, a->lambda, PLUME_HESSIAN_EXACT, a->values);
        plume_problem_timing_get(p, &tb);
        best[2] = fmin(best[2], tb.hessian_eval_seconds - ta.hessian_eval_seconds);
        best[3] = fmin(best[3], tb.hessian_scatter_seconds - ta.hessian_scatter_seconds);
        double shift = 0.0, hmax = 0.0;
        for (plume_index c = 0; c < n; c++)
            hmax = fmax(hmax, fabs(a->values[hp->colptr[c + 1] - 1]));
        t0 = plume_cpu_seconds();
        while (plume_chol_factor(chol, a->values, shift) == PLUME_ESINGULAR && shift < hmax)
            shift = shift > 0.0 ? 10.0 * shift : 1e-8 * hmax;
        best[4] = fmin(best[4], plume_cpu_seconds() - t0);
        t0 = plume_cpu_seconds();
        plume_chol_solve(chol, a->grad, a->sol);
        best[5] = fmin(best[5], plume_cpu_seconds() - t0);
    }
}

/* What one Newton iteration costs at the start state, its parts measured one by one (best of 3),
 * printed with the sizes and the symbolic analysis; 0 when the arrays or the analysis fail. */
static int measure_iteration(const plume_scene *s, plume_problem *p, double *factorise)
{
    plume_err err = {{0}};
    plume_chol *chol = NULL;
    iteration_arrays a = {0};
    int ok = 0;
    const plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p);
    plume_sparsity hp = plume_problem_hessian_pattern(p);
    plume_index jnnz;
    const plume_index *jr, *jc;
    plume_problem_jacobian_pattern(p, &jnnz, &jr, &jc);
    a.u = malloc((size_t)n * sizeof *a.u);
    a.grad = malloc((size_t)n * sizeof *a.grad);
    a.sol = malloc((size_t)n * sizeof *a.sol);
    a.values = malloc((size_t)hp.nnz * sizeof *a.values);
    a.g = malloc((size_t)(m + 1) * sizeof *a.g);
    a.jv = malloc((size_t)(jnnz + 1) * sizeof *a.jv);
    a.lambda = calloc((size_t)m + 1, sizeof *a.lambda);
    if (!a.u || !a.grad || !a.sol || !a.values || !a.g || !a.jv || !a.lambda)
        goto done;
    plume_problem_gather(p, a.u);
    double best[6];
    double analyse = plume_cpu_seconds();
    if (plume_chol_create(n, hp.colptr, hp.rowind, 0, &chol, &err) != PLUME_OK) {
        printf("analysis failed: %s\n", err.msg);
        goto done;
    }
    analyse = plume_cpu_seconds() - analyse;
    time_iteration_parts(p, chol, &hp, &a, best);
    printf("%s bending: %ld elements, %ld unknowns, %ld constraints, %ld Hessian entries (upper); CPU ms, best of 3:\n",
           plume_scene_bending_name(s->bending_model), (long)s->mesh->nt, (long)n, (long)m, (long)hp.nnz);
    *factorise = best[4];
    header_large_columns();
    printf("%12.1f %12.1f %12.1f %12.1f %12.1f %12.1f | %12.1f\n", 1e3 * best[0], 1e3 * best[1], 1e3 * best[2],
           1e3 * best[3], 1e3 * best[4], 1e3 * best[5], 1e3 * analyse);
    printf("evaluation + assembly against one factorisation: %.2f\n",
           (best[0] + best[1] + best[2] + best[3]) / best[4]);
    ok = 1;
done:
    plume_chol_destroy(&chol);
    free(a.u);
    free(a.grad);
    free(a.sol);
    free(a.values);
    free(a.g);
    free(a.jv);
    free(a.lambda);
    return ok;
}

/* The first steps' time per Newton iteration, split by the problem's counters (the rest is the
 * factorisations, the solves and the line search). */
static double time_first_steps(plume_problem *p, plume_dynamics *d, int steps)
{
    plume_err err = {{0}};
    plume_problem_timing t0s, t1s;
    plume_problem_timing_get(p, &t0s);
    int iterations = 0, k = 0;
    double seconds = 0.0, cpu = plume_cpu_seconds();
    for (; k < steps; k++) {
        plume_step_report rep;
        if (plume_dynamics_advance(d, 0.0, &rep, &err) != PLUME_OK || !rep.converged) {
            printf("step %d failed: %s\n", k, err.msg);
            break;
        }
        iterations += rep.iterations, seconds += rep.seconds;
    }
    cpu = plume_cpu_seconds() - cpu;
    plume_problem_timing_get(p, &t1s);
    if (iterations > 0) {
        double ev = (t1s.objective_seconds - t0s.objective_seconds + t1s.constraint_seconds - t0s.constraint_seconds);
        double he = t1s.hessian_eval_seconds - t0s.hessian_eval_seconds;
        double sc = t1s.hessian_scatter_seconds - t0s.hessian_scatter_seconds;
        printf("first %d steps, %d Newton iterations: s/iteration wall %.3f (CPU %.3f) = energy+gradient+constraints "
               "%.3f + Hessian blocks %.3f + scatter %.3f + rest (factorisations, solves) %.3f; Hessians per "
               "iteration %.2f\n",
               k, iterations, seconds / iterations, cpu / iterations, ev / iterations, he / iterations, sc / iterations,
               (seconds - ev - he - sc) / iterations, (double)(t1s.hessian_calls - t0s.hessian_calls) / iterations);
    }
    return iterations > 0 ? seconds / iterations : NAN;
}

/* The feather at 44.7k elements bent by the shape operator (the scene's) and by midedge bending, in
 * one run: what one Newton iteration costs (measure_iteration), the first steps' time per
 * iteration (time_first_steps), and midedge's ratios. */
static void large_feather(const char *scene, int steps)
{
    static const int models[2] = {PLUME_BENDING_SHAPE_OPERATOR, PLUME_BENDING_MIDEDGE};
    double factorise[2] = {NAN, NAN}, per_iteration[2] = {NAN, NAN};
    header_large_title(scene);
    for (int k = 0; k < 2; k++) {
        plume_err err = {{0}};
        plume_scene *s = NULL;
        plume_problem *p = NULL;
        plume_dynamics *d = NULL;
        if (plume_scene_load(scene, &s, &err) == PLUME_OK)
            s->bending_model = models[k];
        if (!s || plume_scene_dynamics(s, &p, &d, &err) != PLUME_OK)
            printf("setup failed: %s\n", err.msg);
        else if (measure_iteration(s, p, &factorise[k]))
            per_iteration[k] = time_first_steps(p, d, steps);
        plume_dynamics_destroy(&d);
        plume_problem_destroy(&p);
        plume_scene_destroy(&s);
    }
    printf("shape operator over midedge: factorisation %.2f, seconds per iteration %.2f\n", factorise[0] / factorise[1],
           per_iteration[0] / per_iteration[1]);
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        header_steps(DEFAULT_SCENE);
        header_large_title(LARGE_SCENE);
        header_large_columns();
        return 0;
    }
    if (argc > 1 && !strcmp(argv[1], "--large")) { /* bench_feather --large [SCENE [STEPS]]: that part alone */
        large_feather(argc > 2 ? argv[2] : LARGE_SCENE, argc > 3 ? atoi(argv[3]) : 1);
        return 0;
    }
    if (argc > 1 && !strcmp(argv[1], "--models")) { /* bench_feather --models [MESHES [STEPS]]: that part alone */
        const int n = argc > 2 ? atoi(argv[2]) : 3, steps = argc > 3 ? atoi(argv[3]) : MODELS_STEPS;
        feather_models(model_scenes, n >= 1 && n <= 3 ? n : 3, steps >= 1 ? steps : MODELS_STEPS);
        return 0;
    }
    const char *scene = argc > 1 ? argv[1] : DEFAULT_SCENE;
    const double edges[2] = {5e-3, 3.5e-3};
    const char *solvers[3] = {"newton", "ipopt", "linearized"};
    header_steps(scene);
    for (int e = 0; e < 2; e++) {
        double t_newton = NAN;
        for (int k = 0; k < 3; k++) {
            char path[256];
            plume_err err = {{0}};
            plume_scene *s = NULL;
            plume_problem *p = NULL;
            plume_dynamics *d = NULL;
            if (variant(scene, edges[e], solvers[k], path, sizeof path) != 0 || plume_scene_load(path, &s, &err) != PLUME_OK ||
                plume_scene_dynamics(s, &p, &d, &err) != PLUME_OK) {
                printf("%8.4f           | %-10s | setup failed: %s\n", edges[e], solvers[k], err.msg);
                plume_scene_destroy(&s);
                unlink(path);
                continue;
            }
            int iterations = 0, halvings = 0, steps = 0, ok = 1;
            double seconds = 0.0, viol = 0.0;
            for (; steps < STEPS && ok; steps++) {
                plume_step_report rep;
                if (plume_dynamics_advance(d, 0.0, &rep, NULL) != PLUME_OK)
                    break;
                iterations += rep.iterations, halvings += rep.halvings, seconds += rep.seconds;
                viol = fmax(viol, rep.max_violation);
                ok = rep.converged;
            }
            double per = seconds / steps;
            if (k == 0)
                t_newton = per;
            printf("%8.4f %9ld | %-10s | %9.4f %8.1f %8d %9.1e | %s%.2fx%s\n", edges[e], (long)s->mesh->nt, solvers[k], per,
                   (double)iterations / steps, halvings, viol, "", per / t_newton,
                   ok ? "" : k == 2 ? "  (single steps: not converged by design)" : "  (FAILED to converge)");
            plume_dynamics_destroy(&d);
            plume_problem_destroy(&p);
            plume_scene_destroy(&s);
            unlink(path);
        }
    }
    large_feather(LARGE_SCENE, 1);
    return 0;
}
