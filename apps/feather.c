/* apps/feather — a dynamic shell scene (a full feather, or any triangle mesh) stepped by implicit
 * Euler as a constrained minimisation: VTK frames for ParaView, an HDF5 frames file that a later
 * run can restart from, PNG renders of chosen frames, a progress line and a JSON summary. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../lib/sim/dynamics.h"
#include "../lib/io/frames.h"
#include "../include/plume/plume.h"
#include "../lib/io/render.h"
#include "../lib/io/progress.h"
#include "../macro/scene.h"
#include "cli.h"

#define APP "feather"

static const char usage[] =
    "usage: feather SCENE.json [options]\n"
    "Steps a shell scene (mesh, materials, handles, gravity: the format is in macro/scene.h) by implicit Euler,\n"
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

/* Removes DIR/frame_<digits>.{vtu,vtk,png} and DIR/frame_barbs_<digits>.vtu left by an earlier
 * run, so a ParaView series or a folder of pictures never mixes two runs. Only names this app
 * writes (or wrote before .vtu) are touched. */
static void remove_stale_frames(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *n = e->d_name;
        if (strncmp(n, "frame_", 6) != 0)
            continue;
        const char *p = n + 6;
        if (strncmp(p, "barbs_", 6) == 0)
            p += 6;
        size_t digits = strspn(p, "0123456789");
        const char *ext = p + digits;
        if (digits < 5 || (strcmp(ext, ".vtk") != 0 && strcmp(ext, ".vtu") != 0 && strcmp(ext, ".png") != 0))
            continue;
        char path[4096 + 300];
        snprintf(path, sizeof path, "%s/%s", dir, n);
        unlink(path);
    }
    closedir(d);
}

/* Copies src to dst through "<dst>.tmp.<pid>" and a rename. */
static int copy_file(const char *src, const char *dst)
{
    char tmp[4300];
    if (snprintf(tmp, sizeof tmp, "%s.tmp.%ld", dst, (long)getpid()) >= (int)sizeof tmp)
        return errno = ENAMETOOLONG, -1;
    FILE *in = fopen(src, "rb"), *out = in ? fopen(tmp, "wb") : NULL;
    int ok = in && out;
    char buf[65536];
    size_t n;
    while (ok && (n = fread(buf, 1, sizeof buf, in)) > 0)
        ok = fwrite(buf, 1, n, out) == n;
    ok = ok && !ferror(in);
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        ok = 0;
    if (ok && rename(tmp, dst) != 0)
        ok = 0;
    if (!ok && out)
        unlink(tmp);
    return ok ? 0 : -1;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* Measures of a contact scene that do not trust the model, after every step: triangle pairs that
 * intersect (CGAL's exact predicates, no common vertex) and the smallest distance between
 * non-adjacent primitives of the bodies in contact (up to 10 dhat), with the steps CCD cut short. */
typedef struct {
    plume_contact_broad *broad; /* for the distances (the scene's bodies and self setting) */
    plume_contact_pairs pairs;  /* the audit's list, reused */
    long steps_intersecting, step_limited;
    plume_index max_intersecting, last_intersecting; /* over the run; after the last step */
    plume_index max_pairs;                           /* most contact stencils of an update */
    double min_distance, last_distance, cap, seconds;
} contact_monitor;

static int contact_monitor_start(contact_monitor *cm, const plume_scene *s, plume_err *err)
{
    memset(cm, 0, sizeof *cm);
    plume_status st = plume_scene_contact_broad(s, &cm->broad, err);
    cm->cap = 10.0 * s->contact.pair.dhat;
    cm->min_distance = cm->cap;
    return st == PLUME_OK;
}

static int contact_monitor_step(contact_monitor *cm, const plume_mesh *m, const double *x, plume_err *err)
{
    double t0 = plume_wall_seconds(), dmin;
    plume_contact_audit a;
    if (plume_contact_count_intersections(m->nv, x, m->nt, m->tri, &cm->pairs, &a, err) != PLUME_OK ||
        plume_contact_min_distance(cm->broad, x, cm->cap, &dmin, err) != PLUME_OK)
        return 0;
    cm->steps_intersecting += a.intersecting > 0;
    cm->last_intersecting = a.intersecting;
    cm->last_distance = dmin;
    if (a.intersecting > cm->max_intersecting)
        cm->max_intersecting = a.intersecting;
    cm->min_distance = fmin(cm->min_distance, dmin);
    cm->seconds += plume_wall_seconds() - t0;
    return 1;
}

static void contact_monitor_end(contact_monitor *cm)
{
    plume_contact_broad_destroy(&cm->broad);
    plume_contact_pairs_free(&cm->pairs);
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

typedef struct {
    const plume_scene *scene;
    const char *outdir, *frames_path, *stem;
    plume_fields *fields; /* the ParaView series */
} output_ctx;

static int wants_render(const plume_scene *s, long k)
{
    for (int i = 0; i < s->nrender; i++)
        if (s->render[i] == k)
            return 1;
    return 0;
}

/* No step yet: zeros, and the contact measures -1 without contact (the distance at its cap). */
static void frame_measures_reset(plume_frame_measures *fm, const plume_scene *s)
{
    memset(fm, 0, sizeof *fm);
    fm->contact_pairs = fm->intersecting_pairs = s->has_contact ? 0.0 : -1.0;
    fm->min_distance = s->has_contact ? 10.0 * s->contact.pair.dhat : -1.0;
}

/* The scene's render_field per triangle into v[nt]: a field of macro/fields.h, its values at x.
 * Returns the colour-bar label (NULL: no field, colour by material or by object). */
static const char *render_values(const output_ctx *oc, const double *x, double *v, plume_err *err)
{
    const plume_scene *s = oc->scene;
    if (strcmp(s->render_field, "material") == 0)
        return NULL;
    if (strcmp(s->render_field, "object") == 0)
        return NULL; /* coloured by category (render_frame) */
    plume_field_values fv;
    if (plume_fields_compute(oc->fields, x, &fv, err) != PLUME_OK ||
        plume_field_values_select(&fv, s->render_field, v, err) != PLUME_OK)
        return "";
    return plume_field_label(s->render_field);
}

/* Each triangle's scene object (the whole mesh's triangles; NULL when out of memory) */
static int *object_categories(const plume_scene *s)
{
    int *c = malloc((size_t)(s->mesh->nt + 1) * sizeof *c);
    if (!c)
        return NULL;
    for (plume_index t = 0; t < s->mesh->nt; t++)
        c[t] = 0;
    for (int i = 0; i < s->nobjects; i++)
        for (plume_index t = s->objects[i].t0; t < s->objects[i].t0 + s->objects[i].nt; t++)
            c[t] = i;
    return c;
}

/* The PNG of frame k (DIR/frame_NNNNN.png), coloured as the scene asks. Exit code. */
static int render_frame(const output_ctx *oc, const double *x, double t, long k)
{
    plume_err err = {{0}};
    const plume_mesh *m = oc->scene->mesh;
    plume_render_opts ro;
    plume_render_opts_default(&ro);
    ro.rot_x = oc->scene->camera[0];
    ro.rot_z = oc->scene->camera[1];
    char title[512], path[4400];
    snprintf(title, sizeof title, "%s   t = %.4f s   frame %ld", oc->stem, t, k);
    ro.title = title;
    double *values = malloc((size_t)m->nt * sizeof *values);
    if (!values)
        return run_fail("render: out of memory");
    const char *label = render_values(oc, x, values, &err);
    if (label && !*label) {
        free(values);
        return run_fail("render: %s", err.msg);
    }
    int *object = NULL;
    if (label)
        ro.field = values, ro.field_label = label;
    else if (strcmp(oc->scene->render_field, "object") == 0 && (object = object_categories(oc->scene)) != NULL)
        ro.category = object; /* one of 12 colours per scene object, cycled: neighbours told apart */
    snprintf(path, sizeof path, "%s/frame_%05ld.png", oc->outdir, k);
    plume_status st = plume_render_png(path, m, x, &ro, &err);
    free(values);
    free(object);
    return st == PLUME_OK ? 0 : run_fail("%s", err.msg);
}

/* Writes frame k of the current state: VTU in the series, HDF5 frame, PNG when requested. Exit code. */
static int write_frame(const output_ctx *oc, const plume_dynamics *d, long k, long step, int append,
                       const plume_frame_measures *fm)
{
    plume_err err = {{0}};
    const plume_mesh *m = oc->scene->mesh;
    const double *x = plume_dynamics_positions(d);
    double t = plume_dynamics_time(d);
    if (plume_fields_series_frame(oc->fields, k, t, x, &err) != PLUME_OK)
        return run_fail("%s", err.msg);
    if (append) {
        plume_index ncons;
        const double *lambda = plume_dynamics_multipliers(d, &ncons);
        if (plume_frames_append_measured(oc->frames_path, m->nv, ncons, t, step, x, plume_dynamics_velocities(d), lambda,
                                         fm, &err) != PLUME_OK)
            return run_fail("%s", err.msg);
    }
    if (wants_render(oc->scene, k) && render_frame(oc, x, t, k) != 0)
        return 1;
    return 0;
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

/* What the run did, over its steps. */
typedef struct {
    long step, next_frame; /* the scene's steps so far; the index of the next frame */
    long frames, done_steps, substeps, halvings, iterations, backtracks, shifts, predictions;
    double max_violation, solve_seconds, loop_seconds;
    int converged, failed;
    plume_reason failed_reason;
} run_tally;

/* --restart: the state of the frames file's last frame (into *last), the file copied to
 * frames_path if it is another, the series continued. Exit code. */
static int restart_run(const options *o, const output_ctx *oc, plume_dynamics *d, plume_index ncons, plume_frame *last,
                       run_tally *r)
{
    plume_err err = {{0}};
    const plume_mesh *mesh = oc->scene->mesh;
    const double dt = oc->scene->dt;
    plume_frames_info info;
    if (plume_frames_info_read(o->restart, &info, &err) != PLUME_OK ||
        plume_frames_read(o->restart, -1, last, &err) != PLUME_OK)
        return cli_fail(APP, "--restart: %s", err.msg);
    if (info.nv != mesh->nv || info.ncons != ncons)
        return cli_fail(APP, "--restart: '%s' holds frames of %ld vertices and %ld constraints, but the scene '%s' "
                             "has %ld and %ld (another scene or mesh?)",
                        o->restart, (long)info.nv, (long)info.ncons, o->scene, (long)mesh->nv, (long)ncons);
    if (fabs(info.dt - dt) > 1e-12 * dt)
        fprintf(stderr, "%s: warning: '%s' was written with dt = %g s, the scene now has %g s\n", APP, o->restart,
                info.dt, dt);
    if (plume_dynamics_set_state(d, last->t, last->x, last->v, last->lambda, &err) != PLUME_OK)
        return cli_fail(APP, "--restart: the last frame of '%s': %s", o->restart, err.msg);
    if (!same_file(o->restart, oc->frames_path) && copy_file(o->restart, oc->frames_path) != 0)
        return run_fail("cannot copy '%s' to '%s': %s", o->restart, oc->frames_path, strerror(errno));
    r->step = last->step;
    r->next_frame = last->index + 1;
    if (plume_fields_series_start(oc->fields, oc->outdir, "frames.pvd", "frame", last->t, &err) != PLUME_OK)
        return run_fail("%s", err.msg);
    return 0;
}

/* A new run: stale frames removed, a new series and frames file, the initial state as frame 0.
 * Exit code. */
static int start_run(const options *o, const output_ctx *oc, const plume_dynamics *d, plume_index ncons,
                     const plume_frame_measures *fm, run_tally *r)
{
    plume_err err = {{0}};
    int rc;
    remove_stale_frames(oc->outdir);
    if (plume_fields_series_start(oc->fields, oc->outdir, "frames.pvd", "frame", -1.0, &err) != PLUME_OK)
        return run_fail("%s", err.msg);
    if (plume_frames_create(oc->frames_path, oc->scene->mesh->nv, ncons, oc->scene->dt, o->scene, &err) != PLUME_OK)
        return run_fail("%s", err.msg);
    if ((rc = write_frame(oc, d, 0, 0, 1, fm)) != 0)
        return rc;
    r->next_frame = 1;
    return 0;
}

/* How many steps: N frames, or up to the end time: whole steps of dt, then one shorter step that
 * lands on the end time (*end) when dt does not divide what is left (1e-9 of a step is round-off,
 * not a step; *last_short); the run's last state is always a frame. */
static long planned_steps(const options *o, const plume_scene *scene, const plume_dynamics *d, double *end,
                          int *last_short)
{
    const double dt = scene->dt;
    long nsteps;
    *end = -1.0;
    *last_short = 0;
    if (o->frames > 0)
        nsteps = (long)o->frames * scene->output_every;
    else {
        *end = o->duration > 0.0 ? o->duration : scene->duration;
        double left = (*end - plume_dynamics_time(d)) / dt;
        nsteps = left > 1e-9 ? (long)floor(left + 1e-9) : 0;
        if (left > 1e-9 && left - (double)nsteps > 1e-9)
            nsteps++, *last_short = 1;
    }
    return nsteps;
}

/* A step's report added to the run's tally, the frame's measures and the steps CCD cut short. */
static void tally_step(const plume_step_report *rep, run_tally *r, contact_monitor *cm, plume_frame_measures *fm)
{
    r->halvings += rep->halvings;
    r->substeps += rep->substeps;
    r->iterations += rep->iterations;
    r->backtracks += rep->backtracks;
    r->shifts += rep->shifts;
    r->predictions += rep->predictions;
    cm->step_limited += rep->step_limited;
    r->solve_seconds += rep->seconds;
    fm->newton_iterations += rep->iterations;
    fm->steps_halved += rep->halvings;
    fm->seconds += rep->seconds;
    r->max_violation = fmax(r->max_violation, rep->max_violation);
}

/* The contact measures of a step into the frame's measures (fm) and the run's (cm). */
static void measure_contact_step(const plume_contact *contact, contact_monitor *cm, plume_frame_measures *fm)
{
    plume_contact_stats cs;
    plume_contact_term_stats(contact, &cs);
    fm->contact_pairs = fmax(fm->contact_pairs, (double)cs.candidates);
    if (cs.candidates > cm->max_pairs)
        cm->max_pairs = cs.candidates;
    fm->min_distance = fmin(fm->min_distance, cm->last_distance);
    fm->intersecting_pairs = fmax(fm->intersecting_pairs, (double)cm->last_intersecting);
}

/* The scene object that holds vertex v ("vertex N" when none does) */
static void vertex_owner(const plume_scene *s, plume_index v, char *out, size_t n)
{
    for (int k = 0; k < s->nobjects; k++)
        if (v >= s->objects[k].v0 && v < s->objects[k].v0 + s->objects[k].nv) {
            snprintf(out, n, "'%s'", s->objects[k].name);
            return;
        }
    snprintf(out, n, "vertex %ld", (long)v);
}

/* Why a step's prescribed motion could not start, when contact says which pair stopped it:
 * the two bodies, into why[n] (empty otherwise) */
static void prescribed_crossing(const plume_scene *s, const plume_contact *contact, plume_reason reason, char *why,
                                size_t n)
{
    plume_index v[4];
    int ee = 0;
    double toi = 1.0;
    why[0] = 0;
    if (reason != PLUME_REASON_PRESCRIBED_CROSSING || !plume_contact_last_limit(contact, v, &ee, &toi))
        return;
    char a[160], b[160];
    vertex_owner(s, v[0], a, sizeof a);
    vertex_owner(s, v[2], b, sizeof b);
    snprintf(why, n,
             ": the keyframed motion alone (kinematic bodies and attached vertices moving, the rest still) brings %s "
             "and %s together (%s, vertices %ld and %ld) within %.0f %% of the smallest step, faster than contact can move "
             "them apart; slow the keyframes down there or start the bodies farther apart",
             a, b, ee ? "edge against edge" : "point against triangle", (long)v[0], (long)v[2], 100.0 * toi);
}

/* Steps the scene nsteps times (see planned_steps for end and last_short), writing a frame every
 * output_every steps and at the end, until a step fails to converge (r->failed). Exit code. */
static int step_run(const options *o, const output_ctx *oc, plume_dynamics *d, const plume_contact *contact,
                    contact_monitor *cm, plume_frame_measures *fm, long nsteps, double end, int last_short,
                    run_tally *r)
{
    const plume_scene *scene = oc->scene;
    const plume_mesh *mesh = scene->mesh;
    const double dt = scene->dt;
    plume_err err = {{0}};
    int rc;
    plume_progress prog;
    plume_progress_start(&prog, APP, (int)(nsteps < 2000000000L ? nsteps : 2000000000L), 0);
    if (o->quiet)
        prog.enabled = 0;
    r->frames = o->restart ? 0 : 1;
    r->converged = 1;
    double loop_start = plume_wall_seconds();
    if (scene->has_contact && !contact_monitor_start(cm, scene, &err))
        return run_fail("contact measures: %s", err.msg);
    for (long i = 1; i <= nsteps; i++) {
        plume_step_report rep;
        double t0 = plume_dynamics_time(d);
        /* adaptive steps: one call per output frame (the stepper picks its steps inside and
         * lands on the frame's time); otherwise one call per step of dt */
        long k = 1;
        if (scene->adaptive_dt) {
            k = scene->output_every - r->step % scene->output_every;
            if (k > nsteps - i + 1)
                k = nsteps - i + 1;
        }
        double h = i + k - 1 == nsteps && last_short ? end - t0 : (double)k * dt;
        if (plume_dynamics_advance(d, h, &rep, &err) != PLUME_OK)
            return run_fail("step %ld: %s", r->step + 1, err.msg);
        tally_step(&rep, r, cm, fm);
        if (scene->has_contact && !contact_monitor_step(cm, mesh, plume_dynamics_positions(d), &err))
            return run_fail("contact measures: %s", err.msg);
        if (scene->has_contact)
            measure_contact_step(contact, cm, fm);
        double t1 = plume_dynamics_time(d);
        int advanced = fabs(t1 - (t0 + h)) <= 1e-9 * fmax(dt, fabs(t1));
        if (!rep.converged) {
            r->converged = 0;
            /* linearized takes one unconverged step by design: only a step that did not advance fails */
            if (scene->solver != PLUME_SOLVER_LINEARIZED || !advanced) {
                r->failed = 1;
                r->failed_reason = rep.reason;
                plume_progress_finish(&prog);
                char why[768];
                prescribed_crossing(scene, contact, rep.reason, why, sizeof why);
                fprintf(stderr,
                        "%s: step %ld (t = %.6g s) did not converge even at dt / 2^%d (%s, after %d halvings)%s; "
                        "stopping with %ld frame%s kept in %s (the last at step %ld)\n",
                        APP, r->step + 1, t0, scene->max_halvings, plume_reason_name(rep.reason), rep.halvings, why,
                        r->next_frame, r->next_frame == 1 ? "" : "s", oc->frames_path,
                        r->step - r->step % scene->output_every);
                break;
            }
        }
        r->step += k;
        r->done_steps += k;
        i += k - 1;
        if (r->step % scene->output_every == 0 || i == nsteps) {
            if ((rc = write_frame(oc, d, r->next_frame, r->step, 1, fm)) != 0)
                return rc;
            frame_measures_reset(fm, scene);
            r->next_frame++;
            r->frames++;
        }
        char info[128];
        snprintf(info, sizeof info, "t %.4f s, frame %ld, %d it%s", t1, r->next_frame - 1, rep.iterations,
                 rep.halvings ? ", halved" : "");
        plume_progress_update(&prog, (int)i, info);
    }
    if (!r->failed)
        plume_progress_finish(&prog);
    r->loop_seconds = plume_wall_seconds() - loop_start;
    return 0;
}

/* --json: the run's summary object (total: the app's wall time). */
static json_t *summary_json(const options *o, const output_ctx *oc, const plume_dynamics *d, plume_index ncons,
                            const contact_monitor *cm, const run_tally *r, double total)
{
    const plume_scene *scene = oc->scene;
    const plume_mesh *mesh = scene->mesh;
    long new_frames = r->frames - (o->restart ? 0 : 1);
    json_t *j = json_object();
    json_object_set_new(j, "frames", json_integer(r->frames));
    json_object_set_new(j, "steps", json_integer(r->done_steps));
    json_object_set_new(j, "substeps", json_integer(r->substeps));
    json_object_set_new(j, "steps_halved", json_integer(r->halvings));
    json_object_set_new(j, "newton_iterations", json_integer(r->iterations));
    json_object_set_new(j, "line_search_backtracks", json_integer(r->backtracks));
    json_object_set_new(j, "inertia_shifts", json_integer(r->shifts));
    json_object_set_new(j, "predictions", json_integer(r->predictions));
    json_object_set_new(j, "max_constraint_violation", json_real(r->max_violation));
    json_object_set_new(j, "converged", json_boolean(r->converged));
    json_object_set_new(j, "stop_reason", json_string(r->failed ? plume_reason_name(r->failed_reason)
                                                                : r->converged ? "converged" : "single_step"));
    json_object_set_new(j, "seconds", json_real(total));
    json_object_set_new(j, "solve_seconds", json_real(r->solve_seconds));
    json_object_set_new(j, "seconds_per_frame", new_frames > 0 ? json_real(r->loop_seconds / (double)new_frames)
                                                               : json_null());
    json_object_set_new(j, "elements", json_integer(mesh->nt));
    json_object_set_new(j, "vertices", json_integer(mesh->nv));
    json_object_set_new(j, "constraints", json_integer(ncons));
    json_object_set_new(j, "time", json_real(plume_dynamics_time(d)));
    json_object_set_new(j, "step", json_integer(r->step));
    json_object_set_new(j, "last_frame", json_integer(r->next_frame - 1));
    json_object_set_new(j, "dt", json_real(scene->dt));
    json_object_set_new(j, "solver", json_string(plume_solver_kind_name(scene->solver)));
    json_object_set_new(j, "output_dir", json_string(oc->outdir));
    json_object_set_new(j, "frames_file", json_string(oc->frames_path));
    if (o->restart)
        json_object_set_new(j, "restarted_from", json_string(o->restart));
    if (scene->has_contact) {
        json_t *jc = json_object();
        json_object_set_new(jc, "model", json_string(plume_contact_model_name(scene->contact.pair.model)));
        json_object_set_new(jc, "dhat", json_real(scene->contact.pair.dhat));
        json_object_set_new(jc, "steps_intersecting", json_integer(cm->steps_intersecting));
        json_object_set_new(jc, "max_intersecting_pairs", json_integer(cm->max_intersecting));
        json_object_set_new(jc, "min_distance", json_real(cm->min_distance));
        json_object_set_new(jc, "min_distance_cap", json_real(cm->cap));
        json_object_set_new(jc, "step_limited", json_integer(cm->step_limited));
        json_object_set_new(jc, "max_contact_pairs", json_integer(cm->max_pairs));
        json_object_set_new(jc, "measure_seconds", json_real(cm->seconds));
        json_object_set_new(j, "contact", jc);
    }
    return j;
}

/* The run's summary on stdout: the JSON object (--json) or a line, and one on contact. */
static void report(const options *o, const output_ctx *oc, const plume_dynamics *d, plume_index ncons,
                   const contact_monitor *cm, const run_tally *r, double total)
{
    if (o->json) {
        json_t *j = summary_json(o, oc, d, ncons, cm, r, total);
        cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        return;
    }
    const plume_scene *scene = oc->scene;
    long new_frames = r->frames - (o->restart ? 0 : 1);
    printf("%s: %ld steps to t = %.6g s, %ld frames (last %ld) in %s; %ld elements, %ld constraints; %ld "
           "iterations (%ld backtracks, %ld inertia shifts) and %ld predictions, %ld halvings, max violation %.2g; %.2f s (%.3g s per "
           "frame)%s\n",
           oc->stem, r->done_steps, plume_dynamics_time(d), r->frames, r->next_frame - 1, oc->outdir,
           (long)scene->mesh->nt, (long)ncons, r->iterations, r->backtracks, r->shifts, r->predictions, r->halvings,
           r->max_violation,
           total, new_frames > 0 ? r->loop_seconds / (double)new_frames : 0.0,
           r->failed ? ", stopped: a step did not converge" : !r->converged ? ", single linearised steps, not converged" : "");
    if (scene->has_contact)
        printf("%s: contact (%s, dhat %g m): intersecting triangle pairs in %ld of %ld steps (at most %ld), "
               "smallest distance %.3g m%s, %ld steps cut short by CCD\n",
               oc->stem, plume_contact_model_name(scene->contact.pair.model),
               scene->contact.pair.dhat, cm->steps_intersecting, r->done_steps, (long)cm->max_intersecting,
               cm->min_distance, cm->min_distance >= cm->cap ? " (or more)" : "", cm->step_limited);
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
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_contact *contact = NULL; /* the contact term's handle (its stats), owned by the problem */
    plume_frame_measures fm;       /* the steps since the last frame (frames.h5) */
    contact_monitor cm; /* contact scenes only; freed at done: */
    memset(&cm, 0, sizeof cm);
    plume_frame last = {0};
    run_tally r;
    memset(&r, 0, sizeof r);
    r.failed_reason = PLUME_REASON_CONVERGED;
    if ((st = plume_scene_load(o.scene, &scene, &err)) != PLUME_OK)
        return cli_fail(APP, "%s", err.msg);
    frame_measures_reset(&fm, scene);
    if (o.solver && plume_solver_kind_parse(o.solver, &scene->solver) != PLUME_OK) {
        plume_scene_destroy(&scene);
        return cli_fail(APP, "--solver expects newton|ipopt|linearized (got '%s')", o.solver);
    }
    if (o.render_field)
        snprintf(scene->render_field, sizeof scene->render_field, "%s", o.render_field);

    char stem[256], outdir[4096], frames_path[4200];
    scene_stem(o.scene, stem, sizeof stem);
    output_dir(&o, stem, outdir, sizeof outdir);
    snprintf(frames_path, sizeof frames_path, "%s/frames.h5", outdir);
    output_ctx oc = {scene, outdir, frames_path, stem, NULL};

    scene->verbose = o.verbose;
    if ((rc = cli_output_dir(APP, "-o", outdir)) != 0)
        goto done;
    if ((st = plume_scene_dynamics_contact(scene, &p, &d, &contact, &err)) != PLUME_OK) {
        rc = st == PLUME_EINVAL || st == PLUME_EFORMAT ? cli_fail(APP, "%s: %s", o.scene, err.msg)
                                                       : run_fail("%s", err.msg);
        goto done;
    }
    plume_index ncons;
    plume_dynamics_multipliers(d, &ncons);
    if ((st = plume_scene_fields(scene, &oc.fields, &err)) != PLUME_OK) {
        rc = run_fail("%s", err.msg);
        goto done;
    }
    if ((rc = o.restart ? restart_run(&o, &oc, d, ncons, &last, &r) : start_run(&o, &oc, d, ncons, &fm, &r)) != 0)
        goto done;
    double end;
    int last_short;
    long nsteps = planned_steps(&o, scene, d, &end, &last_short);
    if ((rc = step_run(&o, &oc, d, contact, &cm, &fm, nsteps, end, last_short, &r)) != 0)
        goto done;
    report(&o, &oc, d, ncons, &cm, &r, plume_wall_seconds() - t_start);
    rc = r.failed ? 3 : 0;
done:
    plume_fields_destroy(&oc.fields);
    contact_monitor_end(&cm);
    plume_frame_free(&last);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&scene);
    return rc;
}
