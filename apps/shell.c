/* apps/shell — a static shell scene (macro/scene.h, "solve": "static"): clamps, point and line
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
#include "../lib/sim/statics.h"
#include "../macro/scene.h"
#include "cli.h"

#define APP "shell"

static const char usage[] =
    "usage: shell SCENE.json [options]\n"
    "Brings a static shell scene (\"solve\": \"static\"; clamps, loads, moments, probes: the format is in\n"
    "macro/scene.h) to equilibrium under load stepping, and reports its probes against their references.\n"
    "  --edge E            mesh edge length (m), replacing the scene's mesh.edge (rectangle and feather meshes)\n"
    "  --pattern P         grid | delaunay | aligned: replaces a rectangle mesh's pattern\n"
    "  --steps N           load steps (overrides the scene's \"steps\")\n"
    "  --solver S          newton | ipopt (overrides the scene's \"solver\")\n"
    "  --bending B         shape_operator | hinge (overrides the scene's \"bending_model\")\n"
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
            if (strcmp(v, "shape_operator") && strcmp(v, "hinge"))
                r = cli_fail(APP, "--bending must be shape_operator or hinge (got '%s')", v);
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

/* The command line's overrides of the scene's settings; the solver must reach an equilibrium.
 * Exit code. */
static int apply_overrides(const options *o, plume_scene *scene)
{
    if (o->solver && plume_solver_kind_parse(o->solver, &scene->solver) != PLUME_OK)
        return cli_fail(APP, "--solver must be newton or ipopt (got '%s')", o->solver);
    if (scene->solver == PLUME_SOLVER_LINEARIZED)
        return cli_fail(APP, "the linearized solver takes one step and cannot reach an equilibrium: use newton or ipopt");
    if (o->steps > 0)
        scene->steps = o->steps;
    if (o->bending)
        scene->hinge_bending = o->bending[0] == 'h';
    if (o->predictor)
        plume_predictor_parse(o->predictor, &scene->predictor);
    if (o->globalization)
        plume_globalization_parse(o->globalization, &scene->globalization);
    scene->verbose = o->verbose;
    return 0;
}

/* What the load steps did. */
typedef struct {
    int converged, iterations, cuts, factorizations;
    double seconds, max_violation;
    plume_reason reason;
} statics_tally;

/* A load step's object (its figures and the probes' displacements at x), and its line on stderr
 * unless quiet. */
static json_t *step_json(const plume_load_step_report *r, const plume_scene *scene, const double *x, int quiet)
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
    for (int q = 0; q < scene->nprobes; q++) {
        double u[3];
        plume_scene_probe_displacement(scene, q, x, u);
        json_object_set_new(jp, scene->probes[q].name, json_pack("[f, f, f]", u[0], u[1], u[2]));
        if (!quiet)
            fprintf(stderr, "  %s (%.5g, %.5g, %.5g)", scene->probes[q].name, u[0], u[1], u[2]);
    }
    if (!quiet)
        fputc('\n', stderr);
    json_object_set_new(js, "probes", jp);
    return js;
}

/* The load steps, each recorded in jsteps and (with -o) written as a frame of the series, until
 * one does not converge at the smallest increment. Exit code. */
static int load_steps(const options *o, const plume_scene *scene, plume_problem *p, plume_statics *st,
                      plume_fields *fields, json_t *jsteps, statics_tally *t)
{
    plume_err err = {{0}};
    plume_status s;
    for (int k = 0; k < scene->steps; k++) {
        plume_load_step_report r;
        if ((s = plume_statics_step(st, &r)) != PLUME_OK)
            return cli_fail(APP, "load step %d: %s", k + 1, plume_strerror(s));
        t->iterations += r.iterations;
        t->cuts += r.cuts;
        t->factorizations += r.factorizations;
        t->seconds += r.seconds;
        t->max_violation = fmax(t->max_violation, r.max_violation);
        const double *x = plume_problem_x(p);
        json_array_append_new(jsteps, step_json(&r, scene, x, o->quiet));
        if (o->outdir && plume_fields_series_frame(fields, r.step, r.factor, x, &err) != PLUME_OK) {
            fprintf(stderr, "%s: %s\n", APP, err.msg);
            return 1; /* an output failure, not bad input */
        }
        if (!r.converged) {
            t->converged = 0;
            t->reason = r.reason;
            break;
        }
    }
    return 0;
}

/* The probes' displacements at x against their references (each error on stderr unless quiet). */
static json_t *probes_json(const plume_scene *scene, const double *x, int quiet)
{
    json_t *jprobes = json_object();
    for (int q = 0; q < scene->nprobes; q++) {
        const plume_scene_probe *pr = scene->probes + q;
        double u[3];
        plume_scene_probe_displacement(scene, q, x, u);
        json_t *j = json_object();
        json_object_set_new(j, "displacement", json_pack("[f, f, f]", u[0], u[1], u[2]));
        if (pr->has_reference) {
            double e = probe_error(u, pr->reference, pr->has_reference);
            json_t *jr = json_array();
            for (int a = 0; a < 3; a++)
                json_array_append_new(jr, pr->has_reference & (1 << a) ? json_real(pr->reference[a]) : json_null());
            json_object_set_new(j, "reference", jr);
            json_object_set_new(j, "relative_error", json_real(e));
            if (pr->source)
                json_object_set_new(j, "source", json_string(pr->source));
            if (!quiet)
                fprintf(stderr, "%s: %s displacement (%.6g, %.6g, %.6g), reference (%.6g, %.6g, %.6g): error %.3g %%\n",
                        APP, pr->name, u[0], u[1], u[2], pr->reference[0], pr->reference[1], pr->reference[2], 100.0 * e);
        }
        json_object_set_new(jprobes, pr->name, j);
    }
    return jprobes;
}

/* --json: the run's summary on stdout (takes jprobes and jsteps). */
static void print_json(const options *o, const plume_scene *scene, const plume_problem *p, const plume_statics *st,
                       const statics_tally *t, json_t *jprobes, json_t *jsteps)
{
    const plume_mesh *m = scene->mesh;
    json_t *j = json_object();
    json_object_set_new(j, "scene", json_string(o->scene));
    json_object_set_new(j, "elements", json_integer(m->nt));
    json_object_set_new(j, "vertices", json_integer(m->nv));
    json_object_set_new(j, "constraints", json_integer(plume_problem_ncons(p)));
    json_object_set_new(j, "bending_model", json_string(scene->hinge_bending ? "hinge" : "shape_operator"));
    json_object_set_new(j, "solver", json_string(plume_solver_kind_name(scene->solver)));
    json_object_set_new(j, "load_steps", json_integer(scene->steps));
    json_object_set_new(j, "predictor", json_string(plume_predictor_name(scene->predictor)));
    json_object_set_new(j, "globalization", json_string(plume_globalization_name(scene->globalization)));
    json_object_set_new(j, "load_factor", json_real(plume_statics_factor(st)));
    json_object_set_new(j, "converged", json_boolean(t->converged));
    json_object_set_new(j, "stop_reason", json_string(plume_reason_name(t->reason)));
    json_object_set_new(j, "newton_iterations", json_integer(t->iterations));
    json_object_set_new(j, "increment_cuts", json_integer(t->cuts));
    json_object_set_new(j, "factorizations", json_integer(t->factorizations));
    json_object_set_new(j, "max_constraint_violation", json_real(t->max_violation));
    json_object_set_new(j, "solve_seconds", json_real(t->seconds));
    json_object_set_new(j, "probes", jprobes);
    json_object_set_new(j, "steps", jsteps);
    cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
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
    plume_problem *p = NULL;
    plume_statics *st = NULL;
    plume_fields *fields = NULL; /* with -o: the ParaView series */
    json_t *jsteps = json_array();
    plume_scene_load_opts lo = {o.edge, o.pattern};
    plume_status s = plume_scene_load_with(o.scene, &lo, &scene, &err);
    if (s != PLUME_OK) {
        rc = cli_fail(APP, "%s", err.msg);
        goto done;
    }
    if (!scene->is_static) {
        rc = cli_fail(APP, "%s is a dynamic scene: run it with apps/feather (or add \"solve\": \"static\")", o.scene);
        goto done;
    }
    if ((rc = apply_overrides(&o, scene)) || (o.outdir && (rc = cli_output_dir(APP, "-o", o.outdir))))
        goto done;
    if ((s = plume_scene_statics(scene, &p, &st, &err)) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        rc = s == PLUME_EINVAL ? 2 : 1;
        goto done;
    }
    if (o.outdir && ((s = plume_scene_fields(scene, &fields, &err)) != PLUME_OK ||
                     (s = plume_fields_series_start(fields, o.outdir, "steps.pvd", "step", -1.0, &err)) != PLUME_OK)) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        rc = 1;
        goto done;
    }
    if (!o.quiet)
        fprintf(stderr, "%s: %s, %ld elements, %ld vertices, %d load steps, %s bending\n", APP, o.scene,
                (long)scene->mesh->nt, (long)scene->mesh->nv, scene->steps,
                scene->hinge_bending ? "hinge" : "shape-operator");
    statics_tally t = {1, 0, 0, 0, 0.0, 0.0, PLUME_REASON_CONVERGED};
    if ((rc = load_steps(&o, scene, p, st, fields, jsteps, &t)))
        goto done;
    json_t *jprobes = probes_json(scene, plume_problem_x(p), o.quiet);
    if (o.json) {
        print_json(&o, scene, p, st, &t, jprobes, jsteps);
        jprobes = jsteps = NULL;
    }
    json_decref(jprobes);
    if (!t.converged) {
        fprintf(stderr, "%s: load step did not converge at the smallest increment (%s); load factor reached %.6g\n", APP,
                plume_reason_name(t.reason), plume_statics_factor(st));
        rc = 3;
    }
done:
    plume_fields_destroy(&fields);
    json_decref(jsteps);
    plume_statics_destroy(&st);
    plume_problem_destroy(&p);
    plume_scene_destroy(&scene);
    return rc;
}
