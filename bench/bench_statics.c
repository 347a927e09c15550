/* make bench (statics part) — the shell benchmarks under load stepping, side by side in one run:
 * each increment's solve started from the last equilibrium (the old way), the secant predictor or
 * the tangent predictor (the default: one linear solve for the increment's response, its
 * factorisation counted in fact/it), with the straight line search, the curved one (the default)
 * or the trust region.
 * Newton iterations per load step, factorisations per iteration, the share of the time in
 * CHOLMOD's numeric factorisation (the floor a solver of this kind cannot go under), seconds per
 * step, the probes' error, and the ratios against the old way.
 * Second table: the same benchmarks (and the elastica at edge 0.125 on a grid and a Delaunay
 * mesh) with each bending model, the shape operator (the default), midedge bending (an angle
 * unknown per edge) and the hinge: the probes' error, Newton iterations, unknowns and Hessian
 * entries, seconds per iteration, and the ratios of the shape operator's error and time to each
 * row's. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../tests/plume_tree.h"
#include "../lib/sim/statics.h"
#include "../macro/scene/scene.h"

typedef struct {
    int iterations, factorizations, steps, ok;
    double seconds, factor_seconds, error;
    long unknowns, hessian_entries;
} run;

/* the largest relative error over the probes' referenced components */
static double probes_error(const plume_scene *s, const double *x)
{
    double e = 0.0;
    for (int q = 0; q < s->nprobes; q++) {
        const plume_scene_probe *pr = s->probes + q;
        double u[3], d = 0.0, n = 0.0;
        plume_scene_probe_displacement(s, q, x, u);
        for (int a = 0; a < 3; a++)
            if (pr->has_reference & (1 << a))
                d += (u[a] - pr->reference[a]) * (u[a] - pr->reference[a]), n += pr->reference[a] * pr->reference[a];
        e = fmax(e, n > 0.0 ? sqrt(d / n) : 0.0);
    }
    return e;
}

/* A shell benchmark's mesh: the shipped one (edge 0), or a rectangle's at that edge and pattern. */
typedef struct {
    const char *file;
    double edge;
    const char *pattern;
} shell_scene;

static run run_scene_model(const shell_scene *sc, plume_predictor k, plume_globalization g, int bending_model)
{
    run r = {0, 0, 0, 0, 0.0, 0.0, NAN, 0, 0};
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_statics *st = NULL;
    plume_err err = {{0}};
    const char *file = sc->file;
    plume_scene_load_opts lo;
    plume_scene_load_opts_default(&lo);
    lo.edge = sc->edge;
    lo.pattern = sc->pattern;
    if (plume_scene_load_with(file, &lo, &s, &err) != PLUME_OK) {
        printf("%s: %s\n", file, err.msg);
        return r;
    }
    s->predictor = k;
    s->globalization = g;
    s->bending_model = bending_model;
    double t0 = plume_wall_seconds();
    if (plume_scene_statics(s, &p, &st, &err) != PLUME_OK) {
        printf("%s: %s\n", file, err.msg);
        goto done;
    }
    r.ok = 1;
    r.unknowns = plume_problem_nfree(p);
    r.hessian_entries = plume_problem_hessian_pattern(p).nnz;
    for (int step = 0; step < s->steps && r.ok; step++) {
        plume_load_step_report rep;
        r.ok = plume_statics_step(st, &rep) == PLUME_OK && rep.converged;
        r.iterations += rep.iterations;
        r.steps++;
    }
    r.seconds = plume_wall_seconds() - t0;
    plume_statics_stats(st, &r.factorizations, &r.factor_seconds);
    if (r.ok)
        r.error = probes_error(s, plume_problem_x(p));
done:
    plume_statics_destroy(&st);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return r;
}

static run run_scene(const char *file, plume_predictor k, plume_globalization g)
{
    const shell_scene sc = {file, 0.0, NULL};
    return run_scene_model(&sc, k, g, PLUME_BENDING_SHAPE_OPERATOR);
}

/* the tables' titles and column lines; `bench_statics --header` prints them alone (the check of
 * docs/benchmarks.md, scripts/bench-tables.py, compares them with the page) */
static void print_models_header(void)
{
    printf("\nplume bench (statics, bending models): the same benchmarks, and the elastica at edge 0.125 on a grid\n"
           "and a Delaunay mesh, with the tangent predictor and the curved line search, bent by the shape operator\n"
           "(the default), midedge bending (an angle unknown per edge) or the hinge; the ratios are the shape\n"
           "operator's error and seconds per iteration over each row's\n");
    printf("%-30s %-14s | %8s %9s %6s %9s %9s | %s\n", "scene", "bending", "unknowns", "H entries", "it", "s/it",
           "error", "ratios (error, time)");
}

static void print_header(void)
{
    printf("\nplume bench (statics): the shell benchmarks of data/benchmarks/ at their shipped meshes and steps.\n"
           "Each load increment solved from the last equilibrium (none), the secant predictor (secant) or the\n"
           "tangent predictor (tangent, the default; its factorisation counted in fact/it), with the line search\n"
           "along the straight Newton step (line), along the geodesic-acceleration curve (curved, the default)\n"
           "or the adaptive-regularisation trust region (trust); the ratios are the first row's iterations and\n"
           "time over each row's\n");
    printf("%-24s %-15s | %6s %7s %7s %8s %8s %9s | %s\n", "scene", "start, search", "it", "it/step", "fact/it",
           "factor%", "s/step", "error", "ratios (iterations, time)");
}

/* The second table: each benchmark with each bending model, in one run. */
static void bending_models(const char *const *files, size_t nfiles)
{
    static const int models[] = {PLUME_BENDING_SHAPE_OPERATOR, PLUME_BENDING_MIDEDGE, PLUME_BENDING_HINGE};
    enum { NMODELS = sizeof models / sizeof models[0] };
    shell_scene scenes[8];
    size_t n = 0;
    for (size_t f = 0; f < nfiles && n < 6; f++)
        scenes[n++] = (shell_scene){files[f], 0.0, NULL};
    scenes[n++] = (shell_scene){"data/benchmarks/elastica_end_load.json", 0.125, "grid"};
    scenes[n++] = (shell_scene){"data/benchmarks/elastica_end_load.json", 0.125, "delaunay"};
    print_models_header();
    for (size_t i = 0; i < n; i++) {
        char name[64];
        snprintf(name, sizeof name, "%s%s%s", strrchr(scenes[i].file, '/') + 1, scenes[i].pattern ? ", " : "",
                 scenes[i].pattern ? scenes[i].pattern : "");
        run r[NMODELS];
        for (int k = 0; k < NMODELS; k++)
            r[k] = run_scene_model(scenes + i, PLUME_PREDICT_TANGENT, PLUME_GLOBAL_CURVED_LINE_SEARCH, models[k]);
        for (int k = 0; k < NMODELS; k++) {
            const run *q = r + k;
            printf("%-30s %-14s | %8ld %9ld %6d %9.4f %8.4f%% |", k == 0 ? name : "",
                   plume_scene_bending_name(models[k]), q->unknowns, q->hessian_entries, q->iterations,
                   q->iterations ? q->seconds / q->iterations : NAN, 100.0 * q->error);
            if (k > 0)
                printf(" %.3g, %.2f", r[0].error / q->error, (r[0].seconds / r[0].iterations) / (q->seconds / q->iterations));
            printf("%s\n", q->ok ? "" : " (did not converge)");
        }
    }
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        print_header();
        print_models_header();
        return 0;
    }
    plume_openmp_serial();
    static const char *const files[] = {"data/benchmarks/cantilever_shear.json", "data/benchmarks/elastica_end_load.json",
                                        "data/benchmarks/buckled_cantilever.json", "data/benchmarks/rollup.json",
                                        "data/benchmarks/slit_annular_plate.json"};
    /* the old way, the secant alone and curved, the trust region, and the default (tangent, curved) */
    static const struct {
        plume_predictor start;
        plume_globalization g;
        const char *name;
    } ways[] = {{PLUME_PREDICT_NONE, PLUME_GLOBAL_LINE_SEARCH, "none, line"},
                {PLUME_PREDICT_NONE, PLUME_GLOBAL_CURVED_LINE_SEARCH, "none, curved"},
                {PLUME_PREDICT_SECANT, PLUME_GLOBAL_LINE_SEARCH, "secant, line"},
                {PLUME_PREDICT_SECANT, PLUME_GLOBAL_CURVED_LINE_SEARCH, "secant, curved"},
                {PLUME_PREDICT_SECANT, PLUME_GLOBAL_TRUST_REGION, "secant, trust"},
                {PLUME_PREDICT_TANGENT, PLUME_GLOBAL_CURVED_LINE_SEARCH, "tangent, curved"}};
    enum { NWAYS = sizeof ways / sizeof ways[0] };
    print_header();
    for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
        run r[NWAYS];
        for (int k = 0; k < NWAYS; k++)
            r[k] = run_scene(files[f], ways[k].start, ways[k].g);
        for (int k = 0; k < NWAYS; k++) {
            const run *q = r + k;
            printf("%-24s %-15s | %6d %7.1f %7.2f %7.0f%% %8.3f %8.3f%% |", k == 0 ? strrchr(files[f], '/') + 1 : "",
                   ways[k].name, q->iterations, q->steps ? (double)q->iterations / q->steps : NAN,
                   q->iterations ? (double)q->factorizations / q->iterations : NAN,
                   q->seconds > 0.0 ? 100.0 * q->factor_seconds / q->seconds : NAN,
                   q->steps ? q->seconds / q->steps : NAN, 100.0 * q->error);
            if (k > 0)
                printf(" %.2f, %.2f", (double)r[0].iterations / q->iterations, r[0].seconds / q->seconds);
            printf("%s\n", q->ok ? "" : " (did not converge)");
        }
    }
    bending_models(files, sizeof files / sizeof files[0]);
    return 0;
}
