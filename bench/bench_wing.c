/* make bench (fifth part) — the shipped wing (data/bird/wing.json: a dozen overlapping feathers on
 * a flapping kinematic bone) with the barrier and continuous collision detection against the
 * paper's penalty (stiffness 1e11, Table 3 (b)), side by side: seconds per step, the shares of
 * broad phase (CGAL box intersection), narrow phase (pair energies), CCD and the rest (solver,
 * elastic terms, pattern rebuilds), contact pairs, and the exact audit's intersecting pairs; the
 * barrier also with adaptive time steps ("adaptive_dt", dt_max one frame: the stepper covers each
 * frame's interval in steps it picks, figures per nominal step of dt); then the barrier's time per
 * Newton iteration split into evaluation, assembly, contact and the rest. The barrier's run also with
 * midedge bending ("bending_model": "midedge", docs/theory-bending-midedge.md) in place of the shape
 * operator: its iterations per step against the shape operator's, in the same run.
 * bench_wing [SCENE [--barrier]]: --barrier runs the barrier alone (the penalty takes minutes);
 * bench_wing --header prints the tables' titles and column lines alone. */
#define _DEFAULT_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../tests/plume_tree.h"
#include "../lib/contact/contact_broad.h"

#define STEPS 30

/* A copy of the scene with the given contact model and stiffness (and bending model, NULL: the
 * scene's), paths made absolute. */
static int variant(const char *scene, const char *model, double stiffness, int adaptive, const char *bending, char *out,
                   size_t n)
{
    char dir[PATH_MAX];
    if (!realpath(scene, dir))
        return -1;
    *strrchr(dir, '/') = '\0';
    json_error_t je;
    json_t *j = json_load_file(scene, 0, &je);
    if (!j)
        return -1;
    json_t *objs = json_object_get(j, "objects"), *o;
    size_t i;
    json_array_foreach(objs, i, o) {
        json_t *m = json_object_get(o, "mesh"), *k = json_object_get(o, "kinematic");
        const char *keys[3] = {"feather", "outline", "obj"};
        for (int q = 0; q < 3; q++) {
            json_t *holder = q < 2 ? m : k, *v = holder ? json_object_get(holder, keys[q]) : NULL;
            if (!json_is_string(v))
                continue;
            char p[PATH_MAX + 256];
            snprintf(p, sizeof p, "%s/%s", dir, json_string_value(v));
            json_object_set_new(holder, keys[q], json_string(p));
        }
    }
    json_t *c = json_object_get(j, "contact");
    json_object_set_new(c, "model", json_string(model));
    json_object_set_new(c, "stiffness", json_real(stiffness));
    json_object_set_new(j, "max_halvings", json_integer(3));
    if (bending)
        json_object_set_new(j, "bending_model", json_string(bending));
    if (adaptive) {
        json_object_set_new(j, "adaptive_dt", json_true());
        json_object_set_new(j, "dt_max", json_real(json_real_value(json_object_get(j, "dt")) *
                                                   (double)json_integer_value(json_object_get(j, "output_every"))));
    }
    snprintf(out, n, "/tmp/plume-bench-wing-%d.json", (int)getpid());
    int rc = json_dump_file(j, out, JSON_INDENT(1));
    json_decref(j);
    return rc;
}

/* the two tables' titles and column lines; `bench_wing --header` prints them alone, for the
 * default scene (the check of docs/benchmarks.md, scripts/bench-tables.py, compares them with the
 * page) */
static void header_models(const char *scene)
{
    printf("\nplume bench (wing): %s, first %d steps, barrier + CCD against the paper's penalty, and with midedge bending\n",
           scene, STEPS);
    printf("%-8s %9s | %8s %8s %8s %7s %6s | %6s %6s %6s %6s | %6s %9s %11s | %s\n", "model", "elements", "s/frame", "s/step", "it/step",
           "halved", "limit", "broad", "narrow", "ccd", "rest", "pairs", "intersect", "min gap", "vs barrier");
}

static void header_iteration(void)
{
    printf("\nbarrier, per Newton iteration (CPU ms; broad phase + CCD: wall): total | energy+gradient+constraints | Hessian blocks | "
           "scatter | broad phase+CCD | rest (factorisation, solves, pattern rebuilds) | Hessians assembled per iteration | "
           "broad-phase searches / queries\n");
}

int main(int argc, char **argv)
{
    const char *scene = argc > 1 ? argv[1] : "data/bird/wing.json";
    if (!strcmp(scene, "--header")) {
        header_models("data/bird/wing.json");
        header_iteration();
        return 0;
    }
    plume_openmp_serial();
    const char *models[4] = {"barrier", "adaptive", "penalty", "midedge"};
    const double stiffness[4] = {1.0, 1.0, 1e11, 1.0};
    header_models(scene);
    double t_barrier = NAN, split[6] = {NAN, NAN, NAN, NAN, NAN, NAN}, split_hessians = NAN;
    long broad_queries = 0, broad_searches = 0;
    const int nmodels = argc > 2 && !strcmp(argv[2], "--barrier") ? 1 : 4; /* profiling: the barrier alone */
    for (int k = 0; k < nmodels; k++) {
        char path[256];
        plume_err err = {{0}};
        plume_scene *s = NULL;
        plume_problem *p = NULL;
        plume_dynamics *d = NULL;
        plume_contact *c = NULL;
        plume_contact_broad *measure = NULL;
        int *body = NULL;
        if (variant(scene, k == 2 ? "penalty" : "barrier", stiffness[k], k == 1, k == 3 ? "midedge" : NULL, path, sizeof path) != 0 ||
            plume_scene_load(path, &s, &err) != PLUME_OK ||
            plume_scene_dynamics_contact(s, &p, &d, &c, &err) != PLUME_OK) {
            printf("%-8s | setup failed: %s\n", models[k], err.msg);
            goto next;
        }
        body = malloc((size_t)s->mesh->nv * sizeof *body);
        plume_contact_broad_opts bo;
        plume_contact_broad_opts_default(&bo);
        bo.self_contact = 0; /* the gap between bodies: self pairs sit 50 um apart at rest */
        if (!body || plume_scene_bodies(s, body) < 0 ||
            plume_contact_broad_create(s->mesh->nv, s->mesh->nt, s->mesh->tri, body, &bo, &measure, &err) != PLUME_OK) {
            printf("%-8s | audit setup failed: %s\n", models[k], err.msg);
            goto next;
        }
        int iterations = 0, halvings = 0, limited = 0, steps = 0, ok = 1;
        long intersecting = 0, max_pairs = 0;
        double seconds = 0.0, dmin = INFINITY, cpu = 0.0;
        plume_contact_pairs pairs = {0};
        const int per_call = k == 1 ? s->output_every : 1; /* adaptive: a frame per call */
        for (; steps < STEPS && ok; steps += per_call) {
            plume_step_report rep;
            const double c0 = plume_cpu_seconds();
            if (plume_dynamics_advance(d, per_call * s->dt, &rep, NULL) != PLUME_OK)
                break;
            cpu += plume_cpu_seconds() - c0;
            iterations += rep.iterations, halvings += rep.halvings, seconds += rep.seconds, limited += rep.step_limited;
            ok = rep.converged;
            plume_contact_stats cs;
            plume_contact_term_stats(c, &cs);
            if (cs.candidates > max_pairs)
                max_pairs = cs.candidates;
            plume_contact_audit audit;
            double dm = INFINITY;
            const double *x = plume_dynamics_positions(d);
            if (plume_contact_count_intersections(s->mesh->nv, x, s->mesh->nt, s->mesh->tri, &pairs, &audit, &err) == PLUME_OK)
                intersecting += audit.intersecting > 0;
            if (plume_contact_min_distance(measure, x, 0.01, &dm, &err) == PLUME_OK)
                dmin = fmin(dmin, dm);
        }
        plume_contact_pairs_free(&pairs);
        plume_contact_stats cs;
        plume_contact_term_stats(c, &cs);
        double per = seconds / steps, rest = seconds - cs.broad_seconds - cs.narrow_seconds - cs.ccd_seconds;
        if (k == 0) {
            t_barrier = per;
            plume_problem_timing pt;
            plume_problem_timing_get(p, &pt);
            split[0] = cpu / iterations;
            split[1] = (pt.objective_seconds + pt.constraint_seconds) / iterations;
            split[2] = pt.hessian_eval_seconds / iterations;
            split[3] = pt.hessian_scatter_seconds / iterations;
            split[4] = (cs.broad_seconds + cs.ccd_seconds) / iterations;
            split[5] = split[0] - split[1] - split[2] - split[3] - split[4];
            split_hessians = (double)pt.hessian_calls / iterations;
            broad_queries = cs.broad_updates, broad_searches = cs.broad_searches;
        }
        printf("%-8s %9ld | %8.3f %8.3f %8.1f %7d %6d | %5.1f%% %5.1f%% %5.1f%% %5.1f%% | %6ld %4ld/%-4d %9.2e m | %.2fx%s\n",
               models[k], (long)s->mesh->nt, per * s->output_every, per, (double)iterations / steps, halvings, limited,
               100 * cs.broad_seconds / seconds, 100 * cs.narrow_seconds / seconds, 100 * cs.ccd_seconds / seconds,
               100 * rest / seconds, max_pairs, intersecting, steps, dmin, per / t_barrier,
               ok ? "" : "  (FAILED to converge at the last step)");
    next:
        plume_contact_broad_destroy(&measure);
        free(body);
        plume_dynamics_destroy(&d);
        plume_problem_destroy(&p);
        plume_scene_destroy(&s);
        unlink(path);
    }
    printf("(midedge: the barrier's run with \"bending_model\": \"midedge\"; s/frame: s/step times the scene's output_every; pairs: most contact stencils of an update; intersect: steps with an intersecting triangle pair, CGAL exact "
           "audit, self-intersections included; min gap: smallest distance between primitives of different bodies)\n");
    header_iteration();
    printf("%8.2f | %8.2f | %8.2f | %8.2f | %8.2f | %8.2f | %.2f | %ld / %ld\n", 1e3 * split[0], 1e3 * split[1],
           1e3 * split[2], 1e3 * split[3], 1e3 * split[4], 1e3 * split[5], split_hessians, broad_searches, broad_queries);
    return 0;
}
