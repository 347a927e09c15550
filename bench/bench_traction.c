/* make bench — tilted 45 deg traction to 5% strain at about 1e3, 1e4 and 4e4 elements: time,
 * Newton iterations, factorisations and peak memory of `newton` against `ipopt`, against the same
 * native solver without chord steps (a factorisation every iteration) and against its previous
 * release (l1-merit line search, unrefined KKT solves), side by side with their ratios, and the
 * time of one Newton iteration against one CHOLMOD factorisation. Each run happens in a child
 * process so that its peak resident memory is its own; the ratios are given for wall time and
 * for the process's CPU time (less sensitive to a busy machine). */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../tests/plume_tree.h"

typedef struct {
    int ok, converged, iterations, factorizations, chord_steps;
    long elements;
    double seconds, cpu_seconds, factor_seconds, stress, violation;
    long maxrss_kb;
} run_result;

typedef enum { NATIVE, NATIVE_NO_CHORD, NATIVE_OLD } native_variant;

/* NATIVE_OLD: the native solver as it was before the filter line search and the refined KKT
 * solves; NATIVE_NO_CHORD: today's without chord steps */
static run_result run_child(double edge, plume_solver_kind solver, native_variant variant, int steps)
{
    run_result r;
    memset(&r, 0, sizeof r);
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_vane vane;
    plume_vane_default(&vane);
    plume_err err = {{0}};
    if (plume_patch_mesh(1.0, 1.3, 45.0, edge, PLUME_PATCH_ALIGNED, 2, &mesh, &err) != PLUME_OK ||
        plume_problem_create(mesh->nv, 2, 1.3, &p, &err) != PLUME_OK ||
        plume_vane_add(p, mesh, &vane, &barbs, &nb, &err) != PLUME_OK) {
        fprintf(stderr, "bench: %s\n", err.msg);
        return r;
    }
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    o.solver_opts = &so;
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.strain_max = 0.05, o.steps = steps, o.solver = solver, o.progress = 0;
    if (variant == NATIVE_OLD) { /* the native solver of the previous release: l1 merit, unrefined KKT solves */
        so.line_search = PLUME_LS_MERIT;
        so.reuse_factorization = 0;
        so.kkt_refine = 0;
    }
    if (variant == NATIVE_NO_CHORD)
        so.reuse_factorization = 0;
    so.verbose = getenv("BENCH_VERBOSE") != NULL; /* --one's iteration log */
    plume_traction_result res;
    double cpu0 = plume_cpu_seconds();
    plume_status st = plume_traction_run(mesh, p, barbs, nb, &o, &res, &err);
    r.cpu_seconds = plume_cpu_seconds() - cpu0;
    if (st == PLUME_OK) {
        r.ok = 1;
        r.converged = res.converged;
        r.iterations = res.newton_iterations;
        r.chord_steps = res.chord_steps;
        r.factorizations = res.factorizations;
        r.seconds = res.seconds;
        r.factor_seconds = res.factor_seconds;
        r.stress = res.curve.stress[res.curve.n - 1];
        r.violation = res.max_violation;
        plume_traction_result_free(&res);
    } else {
        fprintf(stderr, "bench: %s\n", err.msg);
    }
    r.elements = (long)mesh->nt;
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return r;
}

static run_result run_forked(double edge, plume_solver_kind solver, native_variant variant, int steps)
{
    run_result r;
    memset(&r, 0, sizeof r);
    int fd[2];
    if (pipe(fd) != 0)
        return r;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        run_result c = run_child(edge, solver, variant, steps);
        ssize_t w = write(fd[1], &c, sizeof c);
        _exit(w == (ssize_t)sizeof c ? 0 : 1);
    }
    close(fd[1]);
    ssize_t got = read(fd[0], &r, sizeof r);
    close(fd[0]);
    int status;
    struct rusage ru;
    wait4(pid, &status, 0, &ru);
    if (got != (ssize_t)sizeof r)
        memset(&r, 0, sizeof r);
    r.maxrss_kb = ru.ru_maxrss;
    return r;
}

/* the first run, or a faster one (a failed run never replaces a finished one) */
static void keep_fastest(run_result *best, run_result r, int rep)
{
    if (rep == 0 || (r.ok && (!best->ok || r.seconds < best->seconds)))
        *best = r;
}

/* the two tables' titles and column lines; `bench_traction --header` prints them alone (the check
 * of docs/benchmarks.md, scripts/bench-tables.py, compares them with the page) */
static void header_times(int steps, int repeats)
{
    printf("plume bench: tilted 45 deg traction, E_xx/E_yy = 1e4, constraint on, aligned mesh, %d steps to 5%% strain\n"
           "(each figure the fastest of %d runs, %d at 4e4 elements, the variants alternating)\n", steps, repeats,
           repeats < 3 ? repeats : 3);
    printf("%9s | %44s | %13s | %13s | %23s | %13s | %8s\n", "", "time to 5% strain (s)", "ip/nt ratio",
           "iterations", "factorisations/step", "peak MiB", "");
    printf("%9s | %7s %7s %7s %7s %6s %6s | %6s %6s | %6s %6s | %7s %7s %7s | %6s %6s | %8s\n", "elements", "newton",
           "nochord", "old", "ipopt", "nc/nt", "old/nt", "wall", "cpu", "newton", "ipopt", "newton", "nochord", "old",
           "newton", "ipopt", "dstress");
}

static void header_iteration(void)
{
    printf("\nnewton's time per iteration (chord steps, which factorise nothing, included) against one\n"
           "CHOLMOD numeric factorisation (the SPD matrix H + J^T J / dc of the eliminated KKT system;\n"
           "symbolic analysis done once per run, not counted):\n");
    printf("%9s | %12s %14s %7s | %11s | %s\n", "elements", "iteration ms", "factorisation ms", "ratio", "chord steps",
           "max violation");
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    /* edge lengths giving about 1e3, 1e4 and 4e4 triangles on the 1 x 1.3 sample */
    double edges[] = {0.055, 0.0173, 0.0087};
    int nsizes = 3, steps = 5;
    int repeats = 5; /* 3 at 4e4 elements, where one round of the four variants takes 20 s */
    if (argc > 1 && strcmp(argv[1], "--quick") == 0)
        nsizes = 1, repeats = 1;
    if (argc > 1 && strcmp(argv[1], "--header") == 0) {
        header_times(steps, repeats);
        header_iteration();
        return 0;
    }
    if (argc > 1 && strcmp(argv[1], "--one") == 0) {
        /* one run in this process, for perf: --one newton|nochord|old|ipopt EDGE (BENCH_VERBOSE=1: its
         * iterations on stderr) */
        const char *v = argc > 2 ? argv[2] : "";
        const double edge = argc > 3 ? atof(argv[3]) : 0.0;
        const int known = !strcmp(v, "newton") || !strcmp(v, "nochord") || !strcmp(v, "old") || !strcmp(v, "ipopt");
        if (!known || !(edge > 0.0)) {
            fprintf(stderr, "bench_traction: usage: --one newton|nochord|old|ipopt EDGE (e.g. 0.0173), got '%s' '%s'\n",
                    v, argc > 3 ? argv[3] : "");
            return 2;
        }
        const run_result r = run_child(edge, strcmp(v, "ipopt") ? PLUME_SOLVER_NEWTON : PLUME_SOLVER_IPOPT,
                                       !strcmp(v, "nochord") ? NATIVE_NO_CHORD : !strcmp(v, "old") ? NATIVE_OLD : NATIVE, steps);
        printf("%s: %ld elements, %.3f s (cpu %.3f), %d iterations, %d factorisations (%.3f s), %d chord steps, "
               "stress %.10g%s\n", v, r.elements, r.seconds, r.cpu_seconds, r.iterations, r.factorizations,
               r.factor_seconds, r.chord_steps, r.stress, r.converged ? "" : " NOT CONVERGED");
        return r.ok && r.converged ? 0 : 1;
    }
    header_times(steps, repeats);
    run_result rn[3], rc[3], ro[3], ri[3];
    for (int k = 0; k < nsizes; k++) {
        /* each variant `repeats` times, alternating, keeping each one's fastest run: on a shared
         * 2-core machine a run's speed drifts by tens of percent within a minute */
        const int reps = k == 2 && repeats > 3 ? 3 : repeats;
        for (int rep = 0; rep < reps; rep++) {
            keep_fastest(&rn[k], run_forked(edges[k], PLUME_SOLVER_NEWTON, NATIVE, steps), rep);
            keep_fastest(&rc[k], run_forked(edges[k], PLUME_SOLVER_NEWTON, NATIVE_NO_CHORD, steps), rep);
            keep_fastest(&ro[k], run_forked(edges[k], PLUME_SOLVER_NEWTON, NATIVE_OLD, steps), rep);
            keep_fastest(&ri[k], run_forked(edges[k], PLUME_SOLVER_IPOPT, NATIVE, steps), rep);
        }
        /* per load step: the quasi-static steps and the small-strain probe, steps + 1 solves */
        double ds = fmax(fabs(ri[k].stress - rn[k].stress), fmax(fabs(ro[k].stress - rn[k].stress), fabs(rc[k].stress - rn[k].stress)));
        int conv = rn[k].converged && rc[k].converged && ri[k].converged && ro[k].converged;
        printf("%9ld | %7.3f %7.3f %7.3f %7.3f %6.2f %6.2f | %6.2f %6.2f | %6d %6d | %7.2f %7.2f %7.2f | %6.1f %6.1f | %8.1e%s\n",
               rn[k].elements, rn[k].seconds, rc[k].seconds, ro[k].seconds, ri[k].seconds, rc[k].seconds / rn[k].seconds,
               ro[k].seconds / rn[k].seconds, ri[k].seconds / rn[k].seconds, ri[k].cpu_seconds / rn[k].cpu_seconds,
               rn[k].iterations, ri[k].iterations, (double)rn[k].factorizations / (steps + 1),
               (double)rc[k].factorizations / (steps + 1), (double)ro[k].factorizations / (steps + 1),
               rn[k].maxrss_kb / 1024.0, ri[k].maxrss_kb / 1024.0, ds / fabs(rn[k].stress), conv ? "" : "  (NOT CONVERGED)");
    }
    printf("(nochord: newton without chord steps; old: the previous release's native solver; newton's\n"
           " iterations count its chord steps too (listed below); factorisations per load step over the %d\n"
           " steps and the small-strain probe; dstress: largest relative difference of the final stress)\n", steps);
    header_iteration();
    for (int k = 0; k < nsizes; k++) {
        double it = 1e3 * rn[k].seconds / rn[k].iterations, fa = 1e3 * rn[k].factor_seconds / rn[k].factorizations;
        printf("%9ld | %12.2f %14.2f %7.2f | %11d | %.1e\n", rn[k].elements, it, fa, it / fa, rn[k].chord_steps,
               rn[k].violation);
    }
    return 0;
}
