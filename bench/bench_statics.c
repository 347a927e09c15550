/* make bench (statics part) — the shell benchmarks under load stepping, each increment's solve
 * started from the last equilibrium (the old way) and from the secant predictor (the default), side
 * by side in one run: Newton iterations per load step, factorisations per iteration, the share of
 * the time in CHOLMOD's numeric factorisation (the floor a solver of this kind cannot go under),
 * seconds per step, the probes' error, and the ratios. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../lib/plume.h"
#include "../lib/statics.h"
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

static run run_scene(const char *file, plume_predictor k)
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

int main(void)
{
    plume_openmp_serial();
    static const char *const files[] = {"data/benchmarks/cantilever_shear.json", "data/benchmarks/elastica_end_load.json",
                                        "data/benchmarks/buckled_cantilever.json", "data/benchmarks/rollup.json",
                                        "data/benchmarks/slit_annular_plate.json"};
    printf("\nplume bench (statics): the shell benchmarks of data/benchmarks/ at their shipped meshes and steps,\n"
           "each load increment solved from the last equilibrium (none) or from the secant predictor (secant)\n");
    printf("%-24s %-7s | %6s %7s %7s %8s %8s %9s | %s\n", "scene", "start", "it", "it/step", "fact/it", "factor%",
           "s/step", "error", "none / secant (iterations, time)");
    for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
        run r[2];
        for (int k = 0; k < 2; k++)
            r[k] = run_scene(files[f], k == 0 ? PLUME_PREDICT_NONE : PLUME_PREDICT_SECANT);
        for (int k = 0; k < 2; k++) {
            const run *q = r + k;
            printf("%-24s %-7s | %6d %7.1f %7.2f %7.0f%% %8.3f %8.3f%% |", k == 0 ? strrchr(files[f], '/') + 1 : "",
                   k == 0 ? "none" : "secant", q->iterations, q->steps ? (double)q->iterations / q->steps : NAN,
                   q->iterations ? (double)q->factorizations / q->iterations : NAN,
                   q->seconds > 0.0 ? 100.0 * q->factor_seconds / q->seconds : NAN,
                   q->steps ? q->seconds / q->steps : NAN, 100.0 * q->error);
            if (k == 1)
                printf(" %.2f, %.2f%s", (double)r[0].iterations / r[1].iterations, r[0].seconds / r[1].seconds,
                       r[0].ok && r[1].ok ? "" : " (a run did not converge)");
            printf("\n");
        }
    }
    return 0;
}
