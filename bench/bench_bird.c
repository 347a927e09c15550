/* make bench (sixth part) — the whole bird (data/bird/bird.json, written by data/bird/make_bird.py:
 * a hundred-odd feathers on a body and two beating, folding wings, barrier contact with CCD).
 * 1. Speed: the bird with its automatic detail (each feather's mesh edge from the scene
 *    tolerance) against the same bird with every feather at the finest of those edges, and the
 *    shipped wing, over the first SPEED_STEPS steps: seconds per frame and per step, Newton
 *    iterations per step, contact pairs, the exact audit's intersecting steps, and where a step's
 *    time goes (broad phase, CCD, narrow phase, element blocks and their assembly, CHOLMOD's
 *    factorisations, the rest). Then the automatic bird over one whole wingbeat (the issue's
 *    target: at most 10 s a frame on this 2-core machine).
 * 2. What the tolerance buys: the tip trajectories of the outermost feather of each kind (primary,
 *    secondary, the coverts, a rectrix) over the first DETAIL_STEPS steps, for the bird at four
 *    times the default tolerance, the default, the uniform bird, against a reference at a quarter
 *    of the default tolerance (finer meshes); the largest tip distance to the reference against
 *    the CPU time per step, as a table and a chart (out/bench/bird_detail.png).
 * bench_bird [--quick]: --quick skips the wingbeat and the detail study (speed table only);
 * bench_bird --header prints the tables' titles and column lines alone. */
#define _DEFAULT_SOURCE
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../tests/plume_tree.h"
#include "../lib/contact/contact_broad.h"

#define SPEED_STEPS 30
#define DETAIL_STEPS SPEED_STEPS /* the speed runs' window: their tips serve the study too */
#define MAX_TIPS 8
#define GENERATOR "data/bird/make_bird.py"
#define DEFAULT_TOLERANCE 8e-4 /* make_bird.py's default */

/* what one run measured */
typedef struct {
    int ok, steps, iterations, halvings, feathers;
    long elements, max_pairs, intersecting;
    double seconds, cpu, dmin;
    double cpu_detail; /* CPU seconds of the first DETAIL_STEPS steps */
    double broad, narrow, ccd, blocks, factor; /* seconds */
    int ntips;
    char tip_name[MAX_TIPS][64];
    double *tip_u[MAX_TIPS]; /* [3 (steps + 1)] the tip vertex's displacement after each step */
} run_result;

/* Writes a bird into dir with the generator's extra flags; the scene's path into out. */
static int generate(const char *dir, const char *flags, const char *file, char *out, size_t n)
{
    char cmd[PATH_MAX + 512];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s' && python3 %s --out '%s' %s >/dev/null", dir, GENERATOR, dir, flags);
    if (system(cmd) != 0) {
        printf("generator failed: %s\n", cmd);
        return -1;
    }
    snprintf(out, n, "%s/%s", dir, file);
    return 0;
}

/* The kind of a feather from its name: the name without its digits ("l_gcp05" -> "l_gcp"). */
static void kind_of(const char *name, char *kind, size_t n)
{
    size_t k = 0;
    for (const char *c = name; *c && k + 1 < n; c++)
        if (!isdigit((unsigned char)*c))
            kind[k++] = *c;
    kind[k] = 0;
}

/* The tracked feathers: on the left wing and the tail, the last of each kind in name order (the
 * tip-most primary "l_p10", ..., the outer rectrix "t_r06"): the same feathers whatever the
 * meshes; its tip is the vertex farthest up its own reference (+y, along the rachis). */
static int choose_tips(const plume_scene *s, int *obj, plume_index *tip)
{
    char kinds[MAX_TIPS][64];
    int n = 0;
    for (int i = 0; i < s->nobjects; i++) {
        const plume_scene_object *o = s->objects + i;
        if (o->kinematic || !(o->name[0] == 'l' || o->name[0] == 't'))
            continue;
        char kind[64];
        kind_of(o->name, kind, sizeof kind);
        int k = 0;
        while (k < n && strcmp(kinds[k], kind))
            k++;
        if (k == n) {
            if (n == MAX_TIPS)
                continue;
            snprintf(kinds[n++], sizeof kinds[0], "%s", kind);
            obj[k] = i;
        } else if (strcmp(o->name, s->objects[obj[k]].name) > 0) {
            obj[k] = i;
        }
    }
    for (int k = 0; k < n; k++) {
        const plume_scene_object *o = s->objects + obj[k];
        tip[k] = o->v0;
        for (plume_index v = o->v0; v < o->v0 + o->nv; v++)
            if (s->mesh->X[2 * v + 1] > s->mesh->X[2 * tip[k] + 1])
                tip[k] = v;
    }
    return n;
}

static void record_tips(run_result *r, const plume_scene *s, const plume_index *tip, const double *x, int step)
{
    for (int k = 0; k < r->ntips; k++)
        for (int a = 0; a < 3; a++)
            r->tip_u[k][3 * step + a] = x[3 * tip[k] + a] - s->mesh->x[3 * tip[k] + a];
}

/* Runs `steps` steps of a scene: the figures of run_result, the tips when track. */
static run_result run_scene(const char *path, int steps, int track)
{
    run_result r;
    memset(&r, 0, sizeof r);
    r.dmin = INFINITY;
    plume_err err = {{0}};
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_contact *c = NULL;
    plume_contact_broad *measure = NULL;
    plume_contact_pairs pairs = {0};
    int *body = NULL, obj[MAX_TIPS];
    plume_index tip[MAX_TIPS];
    if (plume_scene_load(path, &s, &err) != PLUME_OK || plume_scene_dynamics_contact(s, &p, &d, &c, &err) != PLUME_OK) {
        printf("%s: setup failed: %s\n", path, err.msg);
        goto done;
    }
    body = malloc((size_t)s->mesh->nv * sizeof *body);
    plume_contact_broad_opts bo;
    plume_contact_broad_opts_default(&bo);
    bo.self_contact = 0; /* the gap between bodies */
    if (!body || plume_scene_bodies(s, body) < 0 ||
        plume_contact_broad_create(s->mesh->nv, s->mesh->nt, s->mesh->tri, body, &bo, &measure, &err) != PLUME_OK) {
        printf("%s: audit setup failed: %s\n", path, err.msg);
        goto done;
    }
    r.elements = (long)(s->elastic ? s->elastic->nt : s->mesh->nt);
    for (int i = 0; i < s->nobjects; i++)
        r.feathers += !s->objects[i].kinematic;
    if (track) {
        r.ntips = choose_tips(s, obj, tip);
        for (int k = 0; k < r.ntips; k++) {
            snprintf(r.tip_name[k], sizeof r.tip_name[0], "%s", s->objects[obj[k]].name);
            r.tip_u[k] = calloc((size_t)(3 * (steps + 1)), sizeof(double));
        }
        record_tips(&r, s, tip, plume_dynamics_positions(d), 0);
    }
    r.ok = 1;
    for (; r.steps < steps && r.ok; r.steps++) {
        plume_step_report rep;
        const double c0 = plume_cpu_seconds();
        if (plume_dynamics_advance(d, 0.0, &rep, &err) != PLUME_OK) {
            printf("%s: step %d failed: %s\n", path, r.steps + 1, err.msg);
            r.ok = 0;
            break;
        }
        r.cpu += plume_cpu_seconds() - c0;
        if (r.steps < DETAIL_STEPS)
            r.cpu_detail = r.cpu;
        r.iterations += rep.iterations, r.halvings += rep.halvings, r.seconds += rep.seconds;
        r.ok = rep.converged;
        plume_contact_stats cs;
        plume_contact_term_stats(c, &cs);
        if (cs.candidates > r.max_pairs)
            r.max_pairs = cs.candidates;
        const double *x = plume_dynamics_positions(d);
        plume_contact_audit audit;
        double dm = INFINITY;
        if (plume_contact_count_intersections(s->mesh->nv, x, s->mesh->nt, s->mesh->tri, &pairs, &audit, &err) == PLUME_OK)
            r.intersecting += audit.intersecting > 0;
        if (plume_contact_min_distance(measure, x, 0.01, &dm, &err) == PLUME_OK)
            r.dmin = fmin(r.dmin, dm);
        if (track)
            record_tips(&r, s, tip, x, r.steps + 1);
    }
    plume_contact_stats cs;
    plume_contact_term_stats(c, &cs);
    r.broad = cs.broad_seconds, r.narrow = cs.narrow_seconds, r.ccd = cs.ccd_seconds;
    plume_problem_timing pt;
    plume_problem_timing_get(p, &pt);
    r.blocks = pt.objective_seconds + pt.constraint_seconds + pt.hessian_eval_seconds + pt.hessian_scatter_seconds;
    plume_dynamics_stats(d, NULL, &r.factor);
done:
    plume_contact_pairs_free(&pairs);
    plume_contact_broad_destroy(&measure);
    free(body);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return r;
}

static void run_free(run_result *r)
{
    for (int k = 0; k < r->ntips; k++)
        free(r->tip_u[k]);
}

static void header_speed(void)
{
    printf("\nplume bench (bird): data/bird/bird.json (make_bird.py), first %d steps, barrier + CCD; uniform: every feather at the "
           "automatic bird's finest edge\n",
           SPEED_STEPS);
    printf("%-9s %5s %8s | %8s %8s %8s %6s | %6s %9s %10s | %6s %6s %6s %6s %6s %6s | %s\n", "bird", "fthr", "elements",
           "s/frame", "s/step", "it/step", "halved", "pairs", "intersect", "min gap", "broad", "ccd", "narrow", "blocks",
           "factor", "rest", "vs auto");
}

static void header_wingbeat(void)
{
    printf("\nthe automatic bird over one wingbeat:\n");
    printf("%6s %8s | %8s %8s %8s %6s | %9s %10s | %s\n", "steps", "elements", "s/frame", "s/step", "it/step", "halved",
           "intersect", "min gap", "target");
}

static void header_detail(void)
{
    printf("\nwhat the tolerance buys: tip distance to the reference (a quarter of the default tolerance) over the first %d steps\n",
           DETAIL_STEPS);
    printf("%-22s %8s | %10s %9s | %12s %12s | %s\n", "bird", "elements", "cpu s/step", "vs auto", "tip error", "relative",
           "worst tip");
}

static void print_speed_row(const char *label, const run_result *r, double output_every, double auto_per)
{
    const double per = r->seconds / (r->steps > 0 ? r->steps : 1), total = r->seconds > 0.0 ? r->seconds : 1.0;
    const double rest = r->seconds - r->broad - r->ccd - r->narrow - r->blocks - r->factor;
    printf("%-9s %5d %8ld | %8.3f %8.3f %8.1f %6d | %6ld %4ld/%-4d %8.2e m | %5.1f%% %5.1f%% %5.1f%% %5.1f%% %5.1f%% %5.1f%% | "
           "%.2fx%s\n",
           label, r->feathers, r->elements, per * output_every, per, (double)r->iterations / (r->steps > 0 ? r->steps : 1),
           r->halvings, r->max_pairs, r->intersecting, r->steps, r->dmin, 100 * r->broad / total, 100 * r->ccd / total,
           100 * r->narrow / total, 100 * r->blocks / total, 100 * r->factor / total, 100 * rest / total,
           per / auto_per, r->ok ? "" : "  (FAILED: a step did not converge)");
}

/* The largest distance over the tracked tips and steps between run a and the reference; the
 * largest reference tip displacement into *scale, the worst tip's name into worst. */
static double tip_error(const run_result *a, const run_result *ref, int steps, double *scale, const char **worst)
{
    double e = 0.0;
    int matched = 0;
    *scale = 0.0;
    *worst = "-";
    for (int k = 0; k < a->ntips; k++) {
        int q = 0;
        while (q < ref->ntips && strcmp(ref->tip_name[q], a->tip_name[k]))
            q++;
        if (q == ref->ntips)
            continue;
        matched++;
        for (int j = 0; j <= steps; j++) {
            const double *u = a->tip_u[k] + 3 * j, *v = ref->tip_u[q] + 3 * j;
            double d = sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) + (u[2] - v[2]) * (u[2] - v[2]));
            *scale = fmax(*scale, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
            if (d > e)
                e = d, *worst = a->tip_name[k];
        }
    }
    return matched == a->ntips && matched > 0 ? e : NAN; /* NaN: the runs tracked different feathers */
}

/* the chart of tip error against CPU time per step, one point per bird */
static void chart(const char *labels[], const double *cpu, const double *err, int n)
{
    mkdir("out", 0777);
    mkdir("out/bench", 0777);
    const char *script = "out/bench/bird_detail.gp", *data = "out/bench/bird_detail.dat";
    FILE *f = fopen(data, "w"), *g = f ? fopen(script, "w") : NULL;
    if (!f || !g) {
        if (f)
            fclose(f);
        printf("(chart not written: cannot write out/bench)\n");
        return;
    }
    for (int k = 0; k < n; k++)
        fprintf(f, "%.6g %.6g \"%s\"\n", cpu[k], err[k], labels[k]);
    fclose(f);
    fprintf(g, "set terminal pngcairo size 900,600\nset output 'out/bench/bird_detail.png'\n"
               "set title 'the bird: tip distance to the reference against CPU time per step'\n"
               "set xlabel 'CPU s per step'\nset ylabel 'largest tip distance (m)'\nset logscale y\nset grid\n"
               "set offsets graph 0.1, graph 0.25, graph 0.1, graph 0.1\n"
               "plot '%s' using 1:2 with points pt 7 ps 1.5 notitle, '' using 1:2:3 with labels offset 1,1 left notitle\n",
            data);
    fclose(g);
    plume_err err2 = {{0}};
    if (plume_gnuplot_run(script, "out/bench/bird_detail.log", "bench_bird", &err2) == PLUME_OK)
        printf("chart: out/bench/bird_detail.png\n");
    else
        printf("(chart not drawn: %s)\n", err2.msg);
}

/* the finest mesh edge of a generated bird's feathers, for the uniform bird */
static double finest_edge(const char *path)
{
    json_error_t je;
    json_t *j = json_load_file(path, 0, &je), *o;
    double h = INFINITY;
    size_t i;
    json_array_foreach(json_object_get(j, "objects"), i, o) {
        json_t *e = json_object_get(json_object_get(o, "mesh"), "edge");
        if (json_is_number(e))
            h = fmin(h, json_number_value(e));
    }
    json_decref(j);
    return h;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        header_speed();
        header_wingbeat();
        header_detail();
        return 0;
    }
    const int quick = argc > 1 && !strcmp(argv[1], "--quick");
    plume_openmp_serial();
    char tmp[64], flags[128], uniform[PATH_MAX], coarse[PATH_MAX], reference[PATH_MAX];
    snprintf(tmp, sizeof tmp, "/tmp/plume-bench-bird-%d", (int)getpid());
    const double h = finest_edge("data/bird/bird.json");
    snprintf(flags, sizeof flags, "--uniform-edge %.6g", h);
    if (!(h > 0.0) || !isfinite(h) || generate(tmp, flags, "bird_uniform.json", uniform, sizeof uniform) != 0)
        return 1;
    header_speed();
    run_result a = run_scene("data/bird/bird.json", SPEED_STEPS, 1);
    run_result u = run_scene(uniform, SPEED_STEPS, 1);
    run_result w = run_scene("data/bird/wing.json", SPEED_STEPS, 0);
    const double auto_per = a.seconds / (a.steps > 0 ? a.steps : 1);
    print_speed_row("auto", &a, 5, auto_per);
    print_speed_row("uniform", &u, 5, auto_per);
    print_speed_row("wing", &w, 5, auto_per);
    printf("(s/frame: s/step x 5, both scenes' output_every; pairs: most contact stencils of an update; intersect: steps with an "
           "intersecting triangle pair, CGAL's exact audit; min gap: between different bodies; broad .. factor: shares of the "
           "steps' wall time, blocks = energies, gradients, constraints, element Hessians and their assembly, factor = CHOLMOD's "
           "numeric factorisations)\n");
    if (!quick) {
        header_wingbeat();
        plume_scene *s = NULL;
        plume_err err = {{0}};
        int beat = 0;
        if (plume_scene_load("data/bird/bird.json", &s, &err) == PLUME_OK)
            beat = (int)lround(s->duration / s->dt);
        plume_scene_destroy(&s);
        run_result b = run_scene("data/bird/bird.json", beat, 0);
        const double per = b.seconds / (b.steps > 0 ? b.steps : 1);
        printf("%6d %8ld | %8.3f %8.3f %8.1f %6d | %4ld/%-4d %8.2e m | <= 10 s a frame: %s\n", b.steps, b.elements, 5 * per,
               per, (double)b.iterations / (b.steps > 0 ? b.steps : 1), b.halvings, b.intersecting, b.steps, b.dmin,
               b.ok && 5 * per <= 10.0 ? "met" : "NOT met");
        run_free(&b);

        header_detail();
        snprintf(flags, sizeof flags, "--tolerance %.6g", 4.0 * DEFAULT_TOLERANCE);
        char dir[PATH_MAX];
        snprintf(dir, sizeof dir, "%s/coarse", tmp);
        int okc = generate(dir, flags, "bird.json", coarse, sizeof coarse) == 0;
        snprintf(flags, sizeof flags, "--tolerance %.6g", DEFAULT_TOLERANCE / 4.0);
        snprintf(dir, sizeof dir, "%s/reference", tmp);
        int okr = generate(dir, flags, "bird.json", reference, sizeof reference) == 0;
        run_result c = okc ? run_scene(coarse, DETAIL_STEPS, 1) : (run_result){0};
        run_result r = okr ? run_scene(reference, DETAIL_STEPS, 1) : (run_result){0};
        const char *labels[4] = {"tolerance x4", "auto (default)", "uniform", "reference"};
        const run_result *runs[4] = {&c, &a, &u, &r};
        double cpu[4], errs[4];
        for (int k = 0; k < 4; k++) {
            const run_result *q = runs[k];
            double scale = 0.0;
            const char *worst = "-";
            cpu[k] = q->cpu_detail / DETAIL_STEPS;
            errs[k] = k == 3 ? 0.0 : tip_error(q, &r, DETAIL_STEPS, &scale, &worst);
            printf("%-22s %8ld | %10.3f %8.2fx | %10.3e m %11.2e | %s\n", labels[k], q->elements, cpu[k],
                   cpu[k] / (a.cpu_detail / DETAIL_STEPS), errs[k], scale > 0.0 && k < 3 ? errs[k] / scale : 0.0, k == 3 ? "-" : worst);
        }
        printf("(tip error: the largest distance, over the tracked feathers' tips and the steps, to the reference's; relative: over "
               "the reference's largest tip displacement; tracked: the outermost feather of each kind on the left wing and the tail)\n");
        chart(labels, cpu, errs, 3);
        run_free(&c);
        run_free(&r);
    }
    run_free(&a);
    run_free(&u);
    run_free(&w);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", tmp);
    return 0;
}
