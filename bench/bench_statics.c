/* make bench (statics part) — the shell benchmarks under load stepping, side by side in one run:
 * each increment's solve started from the last equilibrium (the old way), the secant predictor or
 * the tangent predictor (the default: one linear solve for the increment's response, its
 * factorisation counted in fact/it), with the straight line search, the curved one (the default)
 * or the trust region.
 * Newton iterations per load step, factorisations per iteration, the share of the time in
 * CHOLMOD's numeric factorisation (the floor a solver of this kind cannot go under), seconds per
 * step, the probes' error, and the ratios against the old way. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../tests/plume_tree.h"
#include "../lib/sim/statics.h"
#include "../macro/scene.h"

typedef struct {
    int iterations, factorizations, steps, ok;
    double seconds, factor_seconds, error;
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

static run run_scene(const char *file, plume_predictor k, plume_globalization g)
{
    run r = {0, 0, 0, 0, 0.0, 0.0, NAN};
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_statics *st = NULL;
    plume_err err = {{0}};
    if (plume_scene_load(file, &s, &err) != PLUME_OK) {
        printf("%s: %s\n", file, err.msg);
        return r;
    }
    s->predictor = k;
    s->globalization = g;
    double t0 = plume_wall_seconds();
    if (plume_scene_statics(s, &p, &st, &err) != PLUME_OK) {
        printf("%s: %s\n", file, err.msg);
        goto done;
    }
    r.ok = 1;
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

/* the table's title and column line; `bench_statics --header` prints them alone (the check of
 * docs/benchmarks.md, scripts/bench-tables.py, compares them with the page) */
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

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        print_header();
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
    return 0;
}
