/* apps/shell — a static shell scene (docs/scene-format.md, "solve": "static"): clamps, point and line
 * loads and end moments stepped from zero to their full value, each load step a constrained
 * minimisation solved to convergence (increments cut when one fails). Prints a line per load step,
 * the probes' displacements against their references, and a JSON summary; writes the equilibrium
 * of each step as a ParaView series (.vtu per step, steps.pvd with the load factors as times). The shell benchmarks of data/benchmarks/ run with it. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"

#define APP "shell"

static const char usage[] =
    "usage: shell SCENE.json [options]\n"
    "Brings a static shell scene (\"solve\": \"static\"; clamps, loads, moments, probes: the format is in\n"
    "docs/scene-format.md) to equilibrium under load stepping, and reports its probes against their references.\n"
    "  --edge E            mesh edge length (m), replacing the scene's mesh.edge (rectangle and feather meshes)\n"
    "  --pattern P         grid | delaunay | aligned: replaces a rectangle mesh's pattern\n"
    "  --steps N           load steps (overrides the scene's \"steps\")\n"
    "  --solver S          newton | ipopt (overrides the scene's \"solver\")\n"
    "  --bending B         shape_operator | hinge | midedge (overrides the scene's \"bending_model\")\n"
    "  --predictor P       secant | none | tangent | secant_tangent: where each load increment's\n"
    "                      solve starts (overrides the scene's \"predictor\"; default tangent,\n"
    "                      lib/sim/statics.h)\n"
    "  --globalization G   curved_line_search | line_search | trust_region: how the native solver\n"
    "                      globalises its Newton steps (overrides the scene's \"globalization\";\n"
    "                      default curved_line_search, lib/solve/solver.h)\n"
    "  -o DIR              write DIR/steps.pvd and DIR/step_NNNNN.vtu, the equilibrium of each load step with\n"
    "                      its strain, stress, energy densities, J and curvature (ParaView series; the\n"
    "                      load factor is the time)\n"
    "  --json              print a summary object on stdout\n"
    "  --quiet / --verbose no per-step lines / solver iterations on stderr\n"
    "  --help\n"
    "Exit status: 0 done, 2 bad input, 3 a load step did not converge at the smallest increment, 1 other errors.\n";

typedef struct {
    const char *scene, *outdir, *solver, *pattern, *bending, *predictor, *globalization;
    int steps, json, quiet, verbose;
    double edge;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int r = 0;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            return CLI_HELP;
        }
        if (strcmp(a, "--json") == 0 || strcmp(a, "--quiet") == 0 || strcmp(a, "--verbose") == 0) {
            *(a[2] == 'j' ? &o->json : a[2] == 'q' ? &o->quiet : &o->verbose) = 1;
            continue;
        }
        if (a[0] != '-') {
            if (o->scene)
                return cli_fail(APP, "one scene file only (got '%s' and '%s')", o->scene, a);
            o->scene = a;
            continue;
        }
        if (strcmp(a, "-o") && strcmp(a, "--edge") && strcmp(a, "--pattern") && strcmp(a, "--steps") &&
            strcmp(a, "--solver") && strcmp(a, "--bending") && strcmp(a, "--predictor") && strcmp(a, "--globalization"))
            return cli_fail(APP, "unknown option '%s' (see --help)", a);
        if (!v)
            return cli_fail(APP, "%s needs a value (see --help)", a);
        i++;
        if (strcmp(a, "-o") == 0) {
            o->outdir = v;
        } else if (strcmp(a, "--edge") == 0) {
            r = cli_double(APP, a, v, &o->edge);
            if (!r && !(o->edge > 0.0))
                r = cli_fail(APP, "--edge must be > 0 (got %g)", o->edge);
        } else if (strcmp(a, "--pattern") == 0) {
            if (strcmp(v, "grid") && strcmp(v, "delaunay") && strcmp(v, "aligned"))
                r = cli_fail(APP, "--pattern must be grid, delaunay or aligned (got '%s')", v);
            o->pattern = v;
        } else if (strcmp(a, "--steps") == 0) {
            r = cli_int(APP, a, v, &o->steps);
        } else if (strcmp(a, "--bending") == 0) {
            if (strcmp(v, "shape_operator") && strcmp(v, "hinge") && strcmp(v, "midedge"))
                r = cli_fail(APP, "--bending must be shape_operator, hinge or midedge (got '%s')", v);
            o->bending = v;
        } else if (strcmp(a, "--predictor") == 0) {
            plume_predictor k;
            if (plume_predictor_parse(v, &k) != PLUME_OK)
                r = cli_fail(APP, "--predictor must be secant, none, tangent or secant_tangent (got '%s')", v);
            o->predictor = v;
        } else if (strcmp(a, "--globalization") == 0) {
            plume_globalization g;
            if (plume_globalization_parse(v, &g) != PLUME_OK)
                r = cli_fail(APP, "--globalization must be curved_line_search, line_search or trust_region (got '%s')", v);
            o->globalization = v;
        } else {
            o->solver = v;
        }
        if (r)
            return r;
    }
    if (!o->scene)
        return cli_fail(APP, "no scene file given (usage: shell SCENE.json [options]; see --help)");
    return 0;
}

/* relative error of a probe against its reference over the referenced components (bits of mask):
 * |u - ref| / |ref| (|u - ref| when ref = 0) */
static double probe_error(const double u[3], const double ref[3], int mask)
{
    double d = 0.0, r = 0.0;
    for (int a = 0; a < 3; a++)
        if (mask & (1 << a))
            d += (u[a] - ref[a]) * (u[a] - ref[a]), r += ref[a] * ref[a];
    return r > 0.0 ? sqrt(d / r) : sqrt(d);
}

/* The command line's overrides of the scene's settings (values checked by parse_args), as the
 * settings object plume_scene_set takes. Exit code. */
static int apply_overrides(const options *o, plume_scene *scene)
{
    json_t *set = json_object();
    if (o->solver) {
        plume_solver_kind k;
        if (plume_solver_kind_parse(o->solver, &k) != PLUME_OK) {
            json_decref(set);
            return cli_fail(APP, "--solver must be newton or ipopt (got '%s')", o->solver);
        }
        if (k == PLUME_SOLVER_LINEARIZED) {
            json_decref(set);
            return cli_fail(APP, "the linearized solver takes one step and cannot reach an equilibrium: use newton or ipopt");
        }
        json_object_set_new(set, "solver", json_string(o->solver));
    }
    if (o->steps > 0)
        json_object_set_new(set, "steps", json_integer(o->steps));
    if (o->bending)
        json_object_set_new(set, "bending_model", json_string(o->bending));
    if (o->predictor)
        json_object_set_new(set, "predictor", json_string(o->predictor));
    if (o->globalization)
        json_object_set_new(set, "globalization", json_string(o->globalization));
    json_object_set_new(set, "verbose", json_boolean(o->verbose));
    char *text = json_dumps(set, JSON_COMPACT);
    json_decref(set);
    plume_err err = {{0}};
    int rc = text && plume_scene_set(scene, text, &err) == PLUME_OK ? 0 : cli_fail(APP, "%s", text ? err.msg : "out of memory");
    free(text);
    return rc;
}

/* The name of probe q of the description. */
static const char *probe_name(json_t *desc, size_t q)
{
    return json_string_value(json_object_get(json_array_get(json_object_get(desc, "probes"), q), "name"));
}

/* A load step's object (its figures and the probes' displacements at x), and its line on stderr
 * unless quiet. */
static json_t *step_json(const plume_load_step_report *r, const plume_scene *scene, json_t *desc, const double *x,
                         int quiet)
{
    json_t *js = json_object();
    json_object_set_new(js, "step", json_integer(r->step));
    json_object_set_new(js, "factor", json_real(r->factor));
    json_object_set_new(js, "iterations", json_integer(r->iterations));
    json_object_set_new(js, "backtracks", json_integer(r->backtracks));
    json_object_set_new(js, "inertia_shifts", json_integer(r->shifts));
    json_object_set_new(js, "cuts", json_integer(r->cuts));
    json_object_set_new(js, "converged", json_boolean(r->converged));
    if (!quiet)
        fprintf(stderr, "  step %3d  factor %.4f  iterations %3d (backtracks %d, shifts %d)  cuts %d  %s", r->step,
                r->factor, r->iterations, r->backtracks, r->shifts, r->cuts,
                r->converged ? "converged" : plume_reason_name(r->reason));
    json_t *jp = json_object();
    for (size_t q = 0; q < json_array_size(json_object_get(desc, "probes")); q++) {
        double u[3];
        plume_scene_probe_displacement(scene, (int)q, x, u);
        json_object_set_new(jp, probe_name(desc, q), json_pack("[f, f, f]", u[0], u[1], u[2]));
        if (!quiet)
            fprintf(stderr, "  %s (%.5g, %.5g, %.5g)", probe_name(desc, q), u[0], u[1], u[2]);
    }
    if (!quiet)
        fputc('\n', stderr);
    json_object_set_new(js, "probes", jp);
    return js;
}

/* The load steps, each recorded in jsteps (and with -o written by the run as a frame of the
 * series), until the last or one that does not converge at the smallest increment. Exit code. */
static int load_steps(const options *o, plume_run *run, json_t *desc, json_t *jsteps)
{
    plume_err err = {{0}};
    while (!plume_run_done(run)) {
        plume_run_step_info info;
        if (plume_run_step(run, &info, &err) != PLUME_OK) {
            if (strncmp(err.msg, "load step ", 10) == 0)
                return cli_fail(APP, "%s", err.msg);
            fprintf(stderr, "%s: %s\n", APP, err.msg);
            return 1; /* an output failure, not bad input */
        }
        json_array_append_new(jsteps, step_json(&info.load, plume_run_scene(run), desc, plume_run_positions(run), o->quiet));
    }
    return 0;
}

/* The probes' displacements at x against their references (each error on stderr unless quiet). */
static json_t *probes_json(const plume_scene *scene, json_t *desc, const double *x, int quiet)
{
    json_t *jprobes = json_object();
    json_t *ja = json_object_get(desc, "probes");
    for (size_t q = 0; q < json_array_size(ja); q++) {
        json_t *pr = json_array_get(ja, q), *ref = json_object_get(pr, "reference");
        const char *name = probe_name(desc, q);
        double u[3];
        plume_scene_probe_displacement(scene, (int)q, x, u);
        json_t *j = json_object();
        json_object_set_new(j, "displacement", json_pack("[f, f, f]", u[0], u[1], u[2]));
        if (json_is_array(ref)) {
            double r[3];
            int mask = 0;
            for (int a = 0; a < 3; a++) {
                json_t *c = json_array_get(ref, (size_t)a);
                r[a] = json_is_number(c) ? json_number_value(c) : NAN;
                mask |= json_is_number(c) ? 1 << a : 0;
            }
            double e = probe_error(u, r, mask);
            json_object_set(j, "reference", ref);
            json_object_set_new(j, "relative_error", json_real(e));
            if (json_object_get(pr, "source"))
                json_object_set(j, "source", json_object_get(pr, "source"));
            if (!quiet)
                fprintf(stderr, "%s: %s displacement (%.6g, %.6g, %.6g), reference (%.6g, %.6g, %.6g): error %.3g %%\n",
                        APP, name, u[0], u[1], u[2], r[0], r[1], r[2], 100.0 * e);
        }
        json_object_set_new(jprobes, name, j);
    }
    return jprobes;
}

/* --json: the run's summary on stdout (takes jprobes and jsteps). */
static void print_json(const options *o, json_t *desc, const plume_run *run, json_t *jprobes, json_t *jsteps)
{
    plume_run_report r;
    plume_run_get_report(run, &r);
    json_t *j = json_object();
    json_object_set_new(j, "scene", json_string(o->scene));
    json_object_set(j, "elements", json_object_get(desc, "elements"));
    json_object_set(j, "vertices", json_object_get(desc, "vertices"));
    json_object_set_new(j, "constraints", json_integer(plume_run_constraints(run)));
    json_object_set(j, "bending_model", json_object_get(desc, "bending_model"));
    json_object_set(j, "solver", json_object_get(desc, "solver"));
    json_object_set(j, "load_steps", json_object_get(desc, "steps"));
    json_object_set(j, "predictor", json_object_get(desc, "predictor"));
    json_object_set(j, "globalization", json_object_get(desc, "globalization"));
    json_object_set_new(j, "load_factor", json_real(r.time));
    json_object_set_new(j, "converged", json_boolean(r.converged));
    json_object_set_new(j, "stop_reason", json_string(plume_reason_name(r.stop_reason)));
    json_object_set_new(j, "newton_iterations", json_integer(r.iterations));
    json_object_set_new(j, "increment_cuts", json_integer(r.halvings));
    json_object_set_new(j, "factorizations", json_integer(r.factorizations));
    json_object_set_new(j, "max_constraint_violation", json_real(r.max_violation));
    json_object_set_new(j, "solve_seconds", json_real(r.solve_seconds));
    json_object_set_new(j, "probes", jprobes);
    json_object_set_new(j, "steps", jsteps);
    cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
}

/* The bending model as the log line names it. */
static const char *bending_label(const char *model)
{
    return strcmp(model, "hinge") == 0 ? "hinge" : strcmp(model, "midedge") == 0 ? "midedge" : "shape-operator";
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc == CLI_HELP ? 0 : rc;
    plume_err err = {{0}};
    plume_scene *scene = NULL;
    plume_run *run = NULL;
    json_t *desc = NULL, *jsteps = json_array();
    plume_scene_load_opts lo;
    plume_scene_load_opts_default(&lo);
    lo.edge = o.edge, lo.pattern = o.pattern;
    plume_status s = plume_scene_load_with(o.scene, &lo, &scene, &err);
    if (s != PLUME_OK) {
        rc = cli_fail(APP, "%s", err.msg);
        goto done;
    }
    if (!(desc = cli_describe(APP, scene))) {
        rc = 1;
        goto done;
    }
    if (strcmp(json_string_value(json_object_get(desc, "solve")), "static") != 0) {
        rc = cli_fail(APP, "%s is a dynamic scene: run it with apps/feather (or add \"solve\": \"static\")", o.scene);
        goto done;
    }
    if ((rc = apply_overrides(&o, scene)) || (o.outdir && (rc = cli_output_dir(APP, "-o", o.outdir))))
        goto done;
    json_decref(desc); /* the settings as overridden */
    if (!(desc = cli_describe(APP, scene))) {
        rc = 1;
        goto done;
    }
    plume_run_opts ro;
    plume_run_opts_default(&ro);
    ro.output_dir = o.outdir;
    if ((s = plume_run_create(scene, &ro, &run, &err)) != PLUME_OK || (s = plume_run_start(run, &err)) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        rc = s == PLUME_EINVAL ? 2 : 1;
        goto done;
    }
    if (!o.quiet)
        fprintf(stderr, "%s: %s, %ld elements, %ld vertices, %ld load steps, %s bending\n", APP, o.scene,
                (long)json_integer_value(json_object_get(desc, "elements")),
                (long)json_integer_value(json_object_get(desc, "vertices")),
                (long)json_integer_value(json_object_get(desc, "steps")),
                bending_label(json_string_value(json_object_get(desc, "bending_model"))));
    if ((rc = load_steps(&o, run, desc, jsteps)))
        goto done;
    json_t *jprobes = probes_json(scene, desc, plume_run_positions(run), o.quiet);
    if (o.json) {
        print_json(&o, desc, run, jprobes, jsteps);
        jprobes = jsteps = NULL;
    }
    json_decref(jprobes);
    plume_run_report r;
    plume_run_get_report(run, &r);
    if (r.stopped) {
        fprintf(stderr, "%s: load step did not converge at the smallest increment (%s); load factor reached %.6g\n", APP,
                plume_reason_name(r.stop_reason), r.time);
        rc = 3;
    }
done:
    json_decref(jsteps);
    json_decref(desc);
    plume_run_destroy(&run);
    plume_scene_destroy(&scene);
    return rc;
}
