/* apps/feather — a dynamic shell scene (a full feather, or any triangle mesh) stepped by implicit
 * Euler as a constrained minimisation: VTK frames for ParaView, an HDF5 frames file that a later
 * run can restart from, PNG renders of chosen frames, a progress line and a JSON summary. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"

#define APP "feather"

static const char usage[] =
    "usage: feather SCENE.json [options]\n"
    "Steps a shell scene (mesh, materials, handles, gravity: the format is in docs/scene-format.md) by implicit Euler,\n"
    "each step a constrained minimisation solved to convergence (halved when it fails).\n"
    "  -o DIR              output directory (default out/<scene name>, or the restart file's directory):\n"
    "                      DIR/frames.pvd with DIR/frame_00000.vtu ... (ParaView series: strain, stress, energy\n"
    "                      densities, J, curvature; DIR/frame_barbs_*.vtu the barb edges' strain), DIR/frames.h5,\n"
    "                      DIR/frame_XXXXX.png\n"
    "  --frames N          compute N output frames (N x output_every steps), instead of the scene's duration\n"
    "  --duration T        simulate until time T (s), instead of the scene's duration: steps of dt, the last one\n"
    "                      shortened to end at T when dt does not divide it; the end state is always a frame\n"
    "  --restart FILE.h5   continue from the last frame of a frames file (time, x, v, multipliers) and append\n"
    "                      to DIR/frames.h5 (FILE.h5 is copied there first if it is another file)\n"
    "  --solver S          newton | ipopt | linearized (overrides the scene's \"solver\")\n"
    "  --render-field F    colour the PNG renders by F with a colour bar (overrides the scene's \"render_field\"):\n"
    "                      material, object, mean_curvature, J, membrane_energy, bending_energy, strain_bb,\n"
    "                      strain_tt, strain_bt, stress_bb, stress_tt, stress_bt, crease_angle, and with midedge\n"
    "                      bending curvature_bb, curvature_tt, curvature_bt\n"
    "  --gltf FILE.glb     also write the frames as a glTF 2.0 binary file for Blender and web viewers (a node per\n"
    "                      scene object, normals, the frames as an animation; docs/graphics.md); overrides the\n"
    "                      scene's \"gltf\" file, which is relative to DIR\n"
    "  --gltf-animation A  morph (default: morph targets of one mesh per object) | frames (a mesh per frame shown\n"
    "                      in turn)\n"
    "  --gltf-field F      also write the render field F per vertex (attribute _F in upper case: mean_curvature,\n"
    "                      J, strain_bb, ...)\n"
    "  --json              print a summary object on stdout\n"
    "  --quiet / --verbose no progress line / solver iterations on stderr\n"
    "  --help\n"
    "Exit status: 0 done, 2 bad input, 3 a step did not converge at the smallest step (frames so far kept),\n"
    "1 other errors.\n";

/* "feather: <message>" on stderr; returns 1, the exit code of errors other than bad input. */
static int run_fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s: ", APP);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return 1;
}

typedef struct {
    const char *scene, *outdir, *restart, *solver, *render_field, *gltf, *gltf_animation, *gltf_field;
    int frames, json, quiet, verbose;
    double duration;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->duration = -1.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int r = 0;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            return CLI_HELP;
        }
        if (strcmp(a, "--json") == 0) {
            o->json = 1;
            continue;
        }
        if (strcmp(a, "--quiet") == 0) {
            o->quiet = 1;
            continue;
        }
        if (strcmp(a, "--verbose") == 0) {
            o->verbose = 1;
            continue;
        }
        if (a[0] != '-') {
            if (o->scene)
                return cli_fail(APP, "one scene file only (got '%s' and '%s')", o->scene, a);
            o->scene = a;
            continue;
        }
        if (strcmp(a, "-o") && strcmp(a, "--frames") && strcmp(a, "--duration") && strcmp(a, "--restart") &&
            strcmp(a, "--solver") && strcmp(a, "--render-field") && strcmp(a, "--gltf") &&
            strcmp(a, "--gltf-animation") && strcmp(a, "--gltf-field"))
            return cli_fail(APP, "unknown option '%s' (see --help)", a);
        if (!v)
            return cli_fail(APP, "%s needs a value (see --help)", a);
        i++;
        if (strcmp(a, "-o") == 0)
            o->outdir = v;
        else if (strcmp(a, "--frames") == 0)
            r = cli_int(APP, a, v, &o->frames);
        else if (strcmp(a, "--duration") == 0) {
            r = cli_double(APP, a, v, &o->duration);
            if (!r && !(o->duration > 0.0))
                r = cli_fail(APP, "--duration must be > 0 (got %g)", o->duration);
        } else if (strcmp(a, "--restart") == 0)
            o->restart = v;
        else if (strcmp(a, "--render-field") == 0) {
            o->render_field = v; /* checked by the scene (apply_overrides) */
        } else if (strcmp(a, "--gltf") == 0)
            o->gltf = v;
        else if (strcmp(a, "--gltf-animation") == 0)
            o->gltf_animation = v;
        else if (strcmp(a, "--gltf-field") == 0)
            o->gltf_field = v;
        else
            o->solver = v;
        if (r)
            return r;
    }
    if (!o->scene)
        return cli_fail(APP, "no scene file given (usage: feather SCENE.json [options]; see --help)");
    if (o->frames > 0 && o->duration > 0.0)
        return cli_fail(APP, "--frames and --duration are exclusive");
    return 0;
}

/* The scene's name without directory and .json, for the default output directory and titles. */
static void scene_stem(const char *path, char *out, size_t n)
{
    const char *b = strrchr(path, '/');
    b = b ? b + 1 : path;
    snprintf(out, n, "%s", b);
    size_t len = strlen(out);
    if (len > 5 && strcmp(out + len - 5, ".json") == 0)
        out[len - 5] = '\0';
}

/* The output directory: -o, else the restart file's directory, else out/<scene name>. */
static void output_dir(const options *o, const char *stem, char *outdir, size_t n)
{
    if (o->outdir)
        snprintf(outdir, n, "%s", o->outdir);
    else if (o->restart && strrchr(o->restart, '/'))
        snprintf(outdir, n, "%.*s", (int)(strrchr(o->restart, '/') - o->restart), o->restart);
    else if (o->restart)
        snprintf(outdir, n, ".");
    else
        snprintf(outdir, n, "out/%s", stem);
    if (!outdir[0])
        snprintf(outdir, n, "/");
}

/* --json: the run's summary object (total: the app's wall time). */
static json_t *summary_json(const options *o, const plume_run *run, json_t *desc, const char *outdir,
                            const plume_run_report *r, double total)
{
    long new_frames = r->frames - (o->restart ? 0 : 1);
    json_t *j = json_object();
    json_object_set_new(j, "frames", json_integer(r->frames));
    json_object_set_new(j, "steps", json_integer(r->steps));
    json_object_set_new(j, "substeps", json_integer(r->substeps));
    json_object_set_new(j, "steps_halved", json_integer(r->halvings));
    json_object_set_new(j, "newton_iterations", json_integer(r->iterations));
    json_object_set_new(j, "line_search_backtracks", json_integer(r->backtracks));
    json_object_set_new(j, "inertia_shifts", json_integer(r->shifts));
    json_object_set_new(j, "predictions", json_integer(r->predictions));
    json_object_set_new(j, "max_constraint_violation", json_real(r->max_violation));
    json_object_set_new(j, "converged", json_boolean(r->converged));
    json_object_set_new(j, "stop_reason", json_string(r->stopped ? plume_reason_name(r->stop_reason)
                                                                : r->converged ? "converged" : "single_step"));
    json_object_set_new(j, "seconds", json_real(total));
    json_object_set_new(j, "solve_seconds", json_real(r->solve_seconds));
    json_object_set_new(j, "seconds_per_frame", new_frames > 0 ? json_real(r->loop_seconds / (double)new_frames)
                                                               : json_null());
    json_object_set(j, "elements", json_object_get(desc, "elements"));
    json_object_set(j, "vertices", json_object_get(desc, "vertices"));
    json_object_set_new(j, "constraints", json_integer(plume_run_constraints(run)));
    json_object_set_new(j, "time", json_real(r->time));
    json_object_set_new(j, "step", json_integer(r->step));
    json_object_set_new(j, "last_frame", json_integer(r->next_frame - 1));
    json_object_set(j, "dt", json_object_get(desc, "dt"));
    json_object_set(j, "solver", json_object_get(desc, "solver"));
    json_object_set_new(j, "output_dir", json_string(outdir));
    json_object_set_new(j, "frames_file", json_string(plume_run_frames_path(run)));
    json_object_set(j, "materials", json_object_get(desc, "materials"));
    const char *gltf = json_string_value(json_object_get(json_object_get(desc, "gltf"), "file"));
    if (gltf)
        json_object_set_new(j, "gltf_file", gltf[0] == '/' ? json_string(gltf) : json_sprintf("%s/%s", outdir, gltf));
    if (o->restart)
        json_object_set_new(j, "restarted_from", json_string(o->restart));
    json_t *contact = json_object_get(desc, "contact");
    if (contact) {
        json_t *jc = json_object();
        json_object_set(jc, "model", json_object_get(contact, "model"));
        json_object_set(jc, "dhat", json_object_get(contact, "dhat"));
        json_object_set_new(jc, "steps_intersecting", json_integer(r->steps_intersecting));
        json_object_set_new(jc, "max_intersecting_pairs", json_integer(r->max_intersecting));
        json_object_set_new(jc, "min_distance", json_real(r->min_distance));
        json_object_set_new(jc, "min_distance_cap", json_real(r->distance_cap));
        json_object_set_new(jc, "step_limited", json_integer(r->step_limited));
        json_object_set_new(jc, "max_contact_pairs", json_integer(r->max_pairs));
        json_object_set_new(jc, "measure_seconds", json_real(r->audit_seconds));
        json_object_set_new(j, "contact", jc);
    }
    if (r->work != 0.0 || r->kinetic_energy != 0.0 || r->potential_change != 0.0) {
        json_t *je = json_object();
        json_object_set_new(je, "work", json_real(r->work));
        json_object_set_new(je, "kinetic_energy", json_real(r->kinetic_energy));
        json_object_set_new(je, "kinetic_change", json_real(r->kinetic_change));
        json_object_set_new(je, "potential_change", json_real(r->potential_change));
        json_object_set_new(je, "numerical_dissipation", json_real(r->numerical_dissipation));
        json_object_set_new(je, "commit_dissipation", json_real(r->commit_dissipation));
        json_object_set_new(je, "energy_balance_error", json_real(r->energy_balance_error));
        json_object_set_new(j, "energy", je);
    }
    if (r->split_pairs > 0) {
        json_t *js = json_object();
        json_object_set_new(js, "links", json_integer(r->split_pairs));
        json_object_set_new(js, "splits_opened", json_integer(r->splits_opened));
        json_object_set_new(js, "splits_closed", json_integer(r->splits_closed));
        json_object_set_new(js, "open_length", json_real(r->split_open_now));
        json_object_set_new(js, "longest_open_length", json_real(r->split_longest));
        json_object_set_new(js, "dissipated_energy", json_real(r->split_dissipated));
        json_object_set_new(j, "splits", js);
    }
    return j;
}

/* The run's summary on stdout: the JSON object (--json) or a line, and one on contact. */
static void report(const options *o, const plume_run *run, json_t *desc, const char *stem, const char *outdir,
                   double total)
{
    plume_run_report r;
    plume_run_get_report(run, &r);
    if (o->json) {
        json_t *j = summary_json(o, run, desc, outdir, &r, total);
        cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        return;
    }
    json_t *contact = json_object_get(desc, "contact");
    long new_frames = r.frames - (o->restart ? 0 : 1);
    printf("%s: %ld steps to t = %.6g s, %ld frames (last %ld) in %s; %ld elements, %ld constraints; %ld "
           "iterations (%ld backtracks, %ld inertia shifts) and %ld predictions, %ld halvings, max violation %.2g; %.2f s (%.3g s per "
           "frame)%s\n",
           stem, r.steps, r.time, r.frames, r.next_frame - 1, outdir,
           (long)json_integer_value(json_object_get(desc, "elements")),
           (long)plume_run_constraints(run), r.iterations, r.backtracks, r.shifts, r.predictions, r.halvings,
           r.max_violation, total, new_frames > 0 ? r.loop_seconds / (double)new_frames : 0.0,
           r.stopped ? ", stopped: a step did not converge" : !r.converged ? ", single linearised steps, not converged" : "");
    if (contact)
        printf("%s: contact (%s, dhat %g m): intersecting triangle pairs in %ld of %ld steps (at most %ld), "
               "smallest distance %.3g m%s, %ld steps cut short by CCD\n",
               stem, json_string_value(json_object_get(contact, "model")),
               json_number_value(json_object_get(contact, "dhat")),
               r.steps_intersecting, r.steps, r.max_intersecting, r.min_distance,
               r.min_distance >= r.distance_cap ? " (or more)" : "", r.step_limited);
    if (r.work != 0.0 || r.kinetic_energy != 0.0 || r.potential_change != 0.0)
        printf("%s: energy: work %.4g J = kinetic %+.4g J + potential %+.4g J + implicit Euler's dissipation %.4g J + "
               "the splits' %.4g J (balance error %.2g)\n",
               stem, r.work, r.kinetic_change, r.potential_change, r.numerical_dissipation, r.commit_dissipation,
               r.energy_balance_error);
    if (r.split_pairs > 0)
        printf("%s: splits: %ld of %ld links opened, %ld closed again; open now %.4g m of line, longest open stretch "
               "%.4g m; dissipated %.4g J\n",
               stem, r.splits_opened, r.split_pairs, r.splits_closed, r.split_open_now, r.split_longest,
               r.split_dissipated);
}

/* A step that did not converge at the smallest step: what stopped the run, on stderr. */
static void report_stop(const plume_run *run, json_t *desc)
{
    plume_run_report r;
    plume_run_get_report(run, &r);
    fprintf(stderr,
            "%s: step %ld (t = %.6g s) did not converge even at dt / 2^%d (%s, after %d halvings)%s; "
            "stopping with %ld frame%s kept in %s (the last at step %ld)\n",
            APP, r.stop_step, r.stop_time, (int)json_integer_value(json_object_get(desc, "max_halvings")),
            plume_reason_name(r.stop_reason), r.stop_halvings, r.stop_detail, r.next_frame, r.next_frame == 1 ? "" : "s",
            plume_run_frames_path(run), r.step - r.step % (long)json_integer_value(json_object_get(desc, "output_every")));
}

/* One override of the scene's settings, plume_scene_set's key = value; its error names the flag. */
static int set_one(plume_scene *scene, const char *flag, const char *key, json_t *value)
{
    json_t *set = json_object();
    json_object_set_new(set, key, value);
    char *text = json_dumps(set, JSON_COMPACT);
    json_decref(set);
    plume_err err = {{0}};
    int rc = 0;
    if (!text)
        rc = cli_fail(APP, "out of memory");
    else if (plume_scene_set(scene, text, &err) != PLUME_OK) {
        const char *why = strstr(err.msg, key); /* "plume_scene_set:1: <key> must be ..." */
        if (why && why[strlen(key)] == '.') /* "gltf.file must ...": the flag names the sub-key */
            why = strchr(why, ' ');
        rc = cli_fail(APP, "%s %s", flag, why ? why + (*why == ' ' ? 1 : strlen(key) + 1) : err.msg);
    }
    free(text);
    return rc;
}

/* The command line's overrides of the scene's settings. Exit code. */
static int apply_overrides(const options *o, plume_scene *scene)
{
    int rc = set_one(scene, "--verbose", "verbose", json_boolean(o->verbose));
    if (!rc && o->solver)
        rc = set_one(scene, "--solver", "solver", json_string(o->solver));
    if (!rc && o->render_field)
        rc = set_one(scene, "--render-field", "render_field", json_string(o->render_field));
    /* the glTF flags, one at a time so that an error names its flag; --gltf's file is the
     * caller's (relative to the working directory), the scene's relative to DIR */
    char file[4096 + 1024], cwd[4096];
    if (!rc && o->gltf) {
        if (!*o->gltf)
            return cli_fail(APP, "--gltf needs a file name");
        if (o->gltf[0] != '/' && getcwd(cwd, sizeof cwd))
            snprintf(file, sizeof file, "%s/%s", cwd, o->gltf);
        else
            snprintf(file, sizeof file, "%s", o->gltf);
        rc = set_one(scene, "--gltf", "gltf", json_pack("{s:s}", "file", file));
    }
    if (!rc && o->gltf_animation)
        rc = set_one(scene, "--gltf-animation", "gltf", json_pack("{s:s}", "animation", o->gltf_animation));
    if (!rc && o->gltf_field)
        rc = set_one(scene, "--gltf-field", "gltf", json_pack("{s:s}", "field", o->gltf_field));
    return rc;
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc == CLI_HELP ? 0 : rc;
    double t_start = plume_wall_seconds();
    plume_err err = {{0}};
    plume_status st;
    plume_scene *scene = NULL;
    plume_run *run = NULL;
    json_t *desc = NULL;
    if ((st = plume_scene_load(o.scene, &scene, &err)) != PLUME_OK)
        return cli_fail(APP, "%s", err.msg);
    plume_solver_kind kind;
    if (o.solver && plume_solver_kind_parse(o.solver, &kind) != PLUME_OK) {
        plume_scene_destroy(&scene);
        return cli_fail(APP, "--solver expects newton|ipopt|linearized (got '%s')", o.solver);
    }
    if ((rc = apply_overrides(&o, scene)) != 0 || !(desc = cli_describe(APP, scene))) {
        rc = rc ? rc : 1;
        goto done;
    }

    char stem[256], outdir[4096];
    scene_stem(o.scene, stem, sizeof stem);
    output_dir(&o, stem, outdir, sizeof outdir);

    if (strcmp(json_string_value(json_object_get(desc, "solve")), "static") == 0) {
        rc = cli_fail(APP, "%s is a static scene (\"solve\": \"static\"), which has no dynamics: apps/shell solves it",
                      o.scene);
        goto done;
    }
    if ((rc = cli_output_dir(APP, "-o", outdir)) != 0)
        goto done;
    plume_run_opts ro;
    plume_run_opts_default(&ro);
    ro.output_dir = outdir;
    ro.frames = o.frames > 0 ? o.frames : 0;
    ro.end_time = o.frames > 0 ? 0.0 : o.duration > 0.0 ? o.duration : 0.0;
    ro.restart = o.restart;
    ro.progress = !o.quiet;
    ro.label = APP;
    if ((st = plume_run_create(scene, &ro, &run, &err)) != PLUME_OK) {
        /* the library's message names the scene file when the scene is at fault */
        const int named = strncmp(err.msg, o.scene, strlen(o.scene)) == 0;
        rc = st == PLUME_EINVAL || st == PLUME_EFORMAT ? cli_fail(APP, named ? "%.0s%s" : "%s: %s", o.scene, err.msg)
                                                       : run_fail("%s", err.msg);
        goto done;
    }
    st = plume_run_start(run, &err);
    plume_run_report r;
    plume_run_get_report(run, &r);
    const double dt = json_number_value(json_object_get(desc, "dt"));
    if (o.restart && r.restart_dt > 0.0 && fabs(r.restart_dt - dt) > 1e-12 * dt)
        fprintf(stderr, "%s: warning: '%s' was written with dt = %g s, the scene now has %g s\n", APP, o.restart,
                r.restart_dt, dt);
    if (st != PLUME_OK) { /* the restart file's and the glTF file's errors are bad input, named */
        rc = strncmp(err.msg, "restart: ", 9) == 0      ? cli_fail(APP, "--%s", err.msg)
             : strncmp(err.msg, "glTF file ", 10) == 0 ? cli_fail(APP, "%s", err.msg)
                                                       : run_fail("%s", err.msg);
        goto done;
    }
    if ((st = plume_run_to_end(run, &err)) != PLUME_OK) {
        rc = run_fail("%s", err.msg);
        goto done;
    }
    plume_run_get_report(run, &r);
    if (r.stopped)
        report_stop(run, desc);
    report(&o, run, desc, stem, outdir, plume_wall_seconds() - t_start);
    rc = r.stopped ? 3 : 0;
done:
    json_decref(desc);
    plume_run_destroy(&run);
    plume_scene_destroy(&scene);
    return rc;
}
