/* apps/feather — a dynamic shell scene (a full feather, or any triangle mesh) stepped by implicit
 * Euler as a constrained minimisation: VTK frames for ParaView, an HDF5 frames file that a later
 * run can restart from, PNG renders of chosen frames, a progress line and a JSON summary. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "../macro/scene/scene.h"
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
    "                      strain_tt, strain_bt, stress_bb, stress_tt, stress_bt, crease_angle\n"
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
    const char *scene, *outdir, *restart, *solver, *render_field;
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
            strcmp(a, "--solver") && strcmp(a, "--render-field"))
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
            o->render_field = v;
            if (!plume_render_field_valid(v))
                r = cli_fail(APP, "--render-field expects material, object or one of %s (got '%s')",
                             plume_field_names(), v);
        } else
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

/* --json "materials": each material's moduli and, when read from a file, the file */
static json_t *materials_json(const plume_scene *scene)
{
    json_t *ja = json_array();
    for (int k = 0; k < scene->nmat; k++) {
        const plume_scene_material *m = scene->mats + k;
        json_t *jm = json_object(), *jb = json_object();
        json_t *jmem = json_pack("{s:f, s:f, s:f, s:f, s:f, s:f}", "E_xx", m->membrane.E_xx, "E_yy", m->membrane.E_yy,
                                 "nu_xy", m->membrane.nu_xy, "G_xy", m->membrane.G_xy, "thickness", m->membrane.h,
                                 "kappa", m->membrane.kappa);
        json_object_set_new(jb, "D_long", json_real(m->bending.D_long));
        json_object_set_new(jb, "D_trans", json_real(m->bending.D_trans));
        json_object_set_new(jb, "D_coupling", json_real(m->bending.D_coupling));
        json_object_set_new(jb, "D_twist", json_real(m->bending.D_twist));
        if (m->membrane_from[0])
            json_object_set_new(jmem, "from_moduli", json_string(m->membrane_from));
        if (m->bending_from[0])
            json_object_set_new(jb, "from_moduli", json_string(m->bending_from));
        json_object_set_new(jm, "membrane", jmem);
        json_object_set_new(jm, "bending", jb);
        json_object_set_new(jm, "density", json_real(m->density));
        json_object_set_new(jm, "constraint", json_boolean(m->constraint));
        json_array_append_new(ja, jm);
    }
    return ja;
}

/* --json: the run's summary object (total: the app's wall time). */
static json_t *summary_json(const options *o, const plume_run *run, const char *outdir, const plume_run_report *r,
                            double total)
{
    const plume_scene *scene = plume_run_scene(run);
    const plume_mesh *mesh = scene->mesh;
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
    json_object_set_new(j, "elements", json_integer(mesh->nt));
    json_object_set_new(j, "vertices", json_integer(mesh->nv));
    json_object_set_new(j, "constraints", json_integer(plume_run_constraints(run)));
    json_object_set_new(j, "time", json_real(r->time));
    json_object_set_new(j, "step", json_integer(r->step));
    json_object_set_new(j, "last_frame", json_integer(r->next_frame - 1));
    json_object_set_new(j, "dt", json_real(scene->dt));
    json_object_set_new(j, "solver", json_string(plume_solver_kind_name(scene->solver)));
    json_object_set_new(j, "output_dir", json_string(outdir));
    json_object_set_new(j, "frames_file", json_string(plume_run_frames_path(run)));
    json_object_set_new(j, "materials", materials_json(scene));
    if (o->restart)
        json_object_set_new(j, "restarted_from", json_string(o->restart));
    if (scene->has_contact) {
        json_t *jc = json_object();
        json_object_set_new(jc, "model", json_string(plume_contact_model_name(scene->contact.pair.model)));
        json_object_set_new(jc, "dhat", json_real(scene->contact.pair.dhat));
        json_object_set_new(jc, "steps_intersecting", json_integer(r->steps_intersecting));
        json_object_set_new(jc, "max_intersecting_pairs", json_integer(r->max_intersecting));
        json_object_set_new(jc, "min_distance", json_real(r->min_distance));
        json_object_set_new(jc, "min_distance_cap", json_real(r->distance_cap));
        json_object_set_new(jc, "step_limited", json_integer(r->step_limited));
        json_object_set_new(jc, "max_contact_pairs", json_integer(r->max_pairs));
        json_object_set_new(jc, "measure_seconds", json_real(r->audit_seconds));
        json_object_set_new(j, "contact", jc);
    }
    return j;
}

/* The run's summary on stdout: the JSON object (--json) or a line, and one on contact. */
static void report(const options *o, const plume_run *run, const char *stem, const char *outdir, double total)
{
    plume_run_report r;
    plume_run_get_report(run, &r);
    if (o->json) {
        json_t *j = summary_json(o, run, outdir, &r, total);
        cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        return;
    }
    const plume_scene *scene = plume_run_scene(run);
    long new_frames = r.frames - (o->restart ? 0 : 1);
    printf("%s: %ld steps to t = %.6g s, %ld frames (last %ld) in %s; %ld elements, %ld constraints; %ld "
           "iterations (%ld backtracks, %ld inertia shifts) and %ld predictions, %ld halvings, max violation %.2g; %.2f s (%.3g s per "
           "frame)%s\n",
           stem, r.steps, r.time, r.frames, r.next_frame - 1, outdir, (long)scene->mesh->nt,
           (long)plume_run_constraints(run), r.iterations, r.backtracks, r.shifts, r.predictions, r.halvings,
           r.max_violation, total, new_frames > 0 ? r.loop_seconds / (double)new_frames : 0.0,
           r.stopped ? ", stopped: a step did not converge" : !r.converged ? ", single linearised steps, not converged" : "");
    if (scene->has_contact)
        printf("%s: contact (%s, dhat %g m): intersecting triangle pairs in %ld of %ld steps (at most %ld), "
               "smallest distance %.3g m%s, %ld steps cut short by CCD\n",
               stem, plume_contact_model_name(scene->contact.pair.model), scene->contact.pair.dhat,
               r.steps_intersecting, r.steps, r.max_intersecting, r.min_distance,
               r.min_distance >= r.distance_cap ? " (or more)" : "", r.step_limited);
}

/* A step that did not converge at the smallest step: what stopped the run, on stderr. */
static void report_stop(const plume_run *run)
{
    const plume_scene *scene = plume_run_scene(run);
    plume_run_report r;
    plume_run_get_report(run, &r);
    fprintf(stderr,
            "%s: step %ld (t = %.6g s) did not converge even at dt / 2^%d (%s, after %d halvings)%s; "
            "stopping with %ld frame%s kept in %s (the last at step %ld)\n",
            APP, r.stop_step, r.stop_time, scene->max_halvings, plume_reason_name(r.stop_reason), r.stop_halvings,
            r.stop_detail, r.next_frame, r.next_frame == 1 ? "" : "s", plume_run_frames_path(run),
            r.step - r.step % scene->output_every);
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
    if ((st = plume_scene_load(o.scene, &scene, &err)) != PLUME_OK)
        return cli_fail(APP, "%s", err.msg);
    if (o.solver && plume_solver_kind_parse(o.solver, &scene->solver) != PLUME_OK) {
        plume_scene_destroy(&scene);
        return cli_fail(APP, "--solver expects newton|ipopt|linearized (got '%s')", o.solver);
    }
    if (o.render_field)
        snprintf(scene->render_field, sizeof scene->render_field, "%s", o.render_field);

    char stem[256], outdir[4096];
    scene_stem(o.scene, stem, sizeof stem);
    output_dir(&o, stem, outdir, sizeof outdir);

    scene->verbose = o.verbose;
    if (scene->is_static) {
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
    if (o.restart && r.restart_dt > 0.0 && fabs(r.restart_dt - scene->dt) > 1e-12 * scene->dt)
        fprintf(stderr, "%s: warning: '%s' was written with dt = %g s, the scene now has %g s\n", APP, o.restart,
                r.restart_dt, scene->dt);
    if (st != PLUME_OK) { /* the restart file's errors are bad input, named by the flag */
        rc = strncmp(err.msg, "restart: ", 9) == 0 ? cli_fail(APP, "--%s", err.msg) : run_fail("%s", err.msg);
        goto done;
    }
    if ((st = plume_run_to_end(run, &err)) != PLUME_OK) {
        rc = run_fail("%s", err.msg);
        goto done;
    }
    plume_run_get_report(run, &r);
    if (r.stopped)
        report_stop(run);
    report(&o, run, stem, outdir, plume_wall_seconds() - t_start);
    rc = r.stopped ? 3 : 0;
done:
    plume_run_destroy(&run);
    plume_scene_destroy(&scene);
    return rc;
}
