/* plume: the scene runner (macro/scene/run.h): the plan of a run, its steps and their acceptance, the
 * contact audit, the progress line and the run's report. The frames are in run_output.c; a static
 * scene's load steps in run_static.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/opts.h"
#include "internal/run.h"

void plume_run_opts_default_sized(plume_run_opts *o, size_t size)
{
    static const plume_run_opts full = {.size = sizeof full,
                                        .audit = 1,
                                        .render = 1,
                                        .solver = -1};
    plume_opts_give(o, size, &full, sizeof full);
}

int plume_run_accepts(plume_solver_kind solver, const plume_step_report *rep, double t0, double h, double t1, double dt)
{
    if (rep->converged)
        return 1;
    /* linearized takes one unconverged step by design: only a step that did not advance fails */
    int advanced = fabs(t1 - (t0 + h)) <= 1e-9 * fmax(dt, fabs(t1));
    return solver == PLUME_SOLVER_LINEARIZED && advanced;
}

static char *copy_string(const char *s, int *nomem)
{
    if (!s)
        return NULL;
    char *c = malloc(strlen(s) + 1);
    if (!c)
        *nomem = 1;
    else
        strcpy(c, s);
    return c;
}

/* The scene's name without directory and .json, for titles and the progress line. */
static char *scene_stem(const char *path, int *nomem)
{
    const char *b = strrchr(path, '/');
    char *out = copy_string(b ? b + 1 : path, nomem);
    size_t len = out ? strlen(out) : 0;
    if (len > 5 && strcmp(out + len - 5, ".json") == 0)
        out[len - 5] = '\0';
    return out;
}

static plume_status check_opts(const plume_run_opts *o, plume_err *err)
{
    if (o->frames < 0)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_opts.frames must be >= 0 (got %ld)", o->frames);
    if (!isfinite(o->end_time) || o->end_time < 0.0)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_opts.end_time must be a time >= 0 s (got %g)", o->end_time);
    if (o->frames > 0 && o->end_time > 0.0)
        return plume_err_set(err, PLUME_EINVAL,
                             "plume_run_opts.frames and plume_run_opts.end_time are exclusive (got %ld and %g s)",
                             o->frames, o->end_time);
    if (o->open && (o->frames > 0 || o->end_time > 0.0))
        return plume_err_set(err, PLUME_EINVAL,
                             "plume_run_opts.open: an open run has no frames or end_time (got %ld and %g s)", o->frames,
                             o->end_time);
    if (o->solver != -1 && (o->solver < PLUME_SOLVER_NEWTON || o->solver > PLUME_SOLVER_LINEARIZED))
        return plume_err_set(err, PLUME_EINVAL,
                             "plume_run_opts.solver must be -1 (the scene's) or a plume_solver_kind (got %d)", o->solver);
    if (o->output_dir && !*o->output_dir)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_opts.output_dir is empty (NULL: no frames)");
    if (o->restart && !*o->restart)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_opts.restart is empty (NULL: no restart)");
    return PLUME_OK;
}

plume_status plume_run_create(plume_scene *scene, const plume_run_opts *opts, plume_run **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_create: out is NULL");
    *out = NULL;
    plume_run_opts full; /* the caller's options (as many bytes as it has) over the defaults */
    plume_run_opts_default(&full);
    if (opts && plume_opts_take(&full, sizeof full, opts, "plume_run_opts", err) != PLUME_OK)
        return PLUME_EINVAL;
    opts = &full;
    if (!scene)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_create: scene is NULL");
    plume_status st = check_opts(opts, err);
    if (st != PLUME_OK)
        return st;
    plume_run *r = calloc(1, sizeof *r);
    if (!r)
        return plume_err_set(err, PLUME_ENOMEM, "run: out of memory");
    int nomem = 0;
    r->scene = scene;
    r->output_dir = copy_string(opts->output_dir, &nomem);
    r->restart = copy_string(opts->restart, &nomem);
    r->stem = scene_stem(scene->path ? scene->path : "", &nomem);
    r->label = copy_string(opts->label ? opts->label : r->stem, &nomem);
    if (r->output_dir && !nomem) {
        size_t n = strlen(r->output_dir) + sizeof "/frames.h5";
        if ((r->frames_path = malloc(n)) != NULL)
            snprintf(r->frames_path, n, "%s/frames.h5", r->output_dir);
        nomem = !r->frames_path;
    }
    if (nomem) {
        plume_run_destroy(&r);
        return plume_err_set(err, PLUME_ENOMEM, "run: out of memory");
    }
    r->frames_opt = opts->frames;
    r->end_time = opts->end_time;
    r->open = opts->open;
    r->audit = opts->audit;
    r->progress = opts->progress;
    r->render = opts->render;
    const plume_solver_kind solver = scene->solver;
    if (opts->solver != -1)
        scene->solver = (plume_solver_kind)opts->solver;
    if (scene->is_static && scene->gltf) {
        st = plume_err_set(err, PLUME_EINVAL, "%s: \"gltf\" is for dynamic scenes: a static scene's load steps are a "
                           "ParaView series (steps.pvd)", scene->path ? scene->path : "scene");
        plume_run_destroy(&r);
        return st;
    }
    st = scene->is_static ? plume_run_static_create(r, opts, err)
                          : plume_scene_dynamics_contact(scene, &r->p, &r->d, &r->contact, err);
    if (st != PLUME_OK) {
        scene->solver = solver; /* a failed creation leaves the scene as it was */
        plume_run_destroy(&r);
        return st;
    }
    if (r->d)
        plume_dynamics_multipliers(r->d, &r->ncons);
    r->rep.converged = 1;
    r->rep.stop_reason = PLUME_REASON_CONVERGED;
    r->rep.planned_steps = -1;
    r->rep.min_distance = r->rep.distance_cap = scene->has_contact ? 10.0 * scene->contact.pair.dhat : 0.0;
    plume_run_measures_reset(r);
    *out = r;
    return PLUME_OK;
}

plume_status plume_run_open(const char *path, const plume_run_opts *opts, plume_run **out, plume_err *err)
{
    if (out)
        *out = NULL;
    if (!path || !out)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_open: path and out are required");
    plume_scene *scene = NULL;
    plume_status st = plume_scene_load(path, &scene, err);
    if (st == PLUME_OK && (st = plume_run_create(scene, opts, out, err)) == PLUME_OK)
        (*out)->owns_scene = 1;
    else
        plume_scene_destroy(&scene);
    return st;
}

void plume_run_destroy(plume_run **pr)
{
    if (!pr || !*pr)
        return;
    plume_run *r = *pr;
    plume_fields_destroy(&r->fields);
    plume_contact_broad_destroy(&r->broad);
    plume_contact_pairs_free(&r->pairs);
    plume_dynamics_destroy(&r->d);
    plume_statics_destroy(&r->st);
    plume_problem_destroy(&r->p);
    if (r->owns_scene)
        plume_scene_destroy(&r->scene);
    free(r->output_dir);
    free(r->frames_path);
    free(r->restart);
    free(r->label);
    free(r->stem);
    free(r->split_state);
    free(r);
    *pr = NULL;
}

/* How many steps: N frames, or up to the end time: whole steps of dt, then one shorter step that
 * lands on the end time when dt does not divide what is left (1e-9 of a step is round-off, not a
 * step); the run's last state is always a frame. */
static void plan_steps(plume_run *r)
{
    const plume_scene *scene = r->scene;
    const double dt = scene->dt;
    r->end = -1.0;
    r->last_short = 0;
    if (r->open) {
        r->nsteps = -1;
    } else if (r->frames_opt > 0) {
        r->nsteps = r->frames_opt * scene->output_every;
    } else {
        r->end = r->end_time > 0.0 ? r->end_time : scene->duration;
        double left = (r->end - plume_dynamics_time(r->d)) / dt;
        r->nsteps = left > 1e-9 ? (long)floor(left + 1e-9) : 0;
        if (left > 1e-9 && left - (double)r->nsteps > 1e-9)
            r->nsteps++, r->last_short = 1;
    }
    r->rep.planned_steps = r->nsteps;
}

plume_status plume_run_start(plume_run *r, plume_err *err)
{
    if (!r)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_start: the run is NULL");
    if (r->started > 0)
        return PLUME_OK;
    if (r->started < 0)
        return plume_err_set(err, PLUME_EINVAL, "run: its start failed; destroy it");
    r->started = -1;
    plume_status st = r->st ? plume_run_static_start(r, err) : plume_run_output_start(r, err);
    if (st != PLUME_OK)
        return st;
    plume_err why = {{0}};
    if (r->scene->has_contact && r->audit && (st = plume_scene_contact_broad(r->scene, &r->broad, &why)) != PLUME_OK)
        return plume_err_set(err, st, "contact measures: %s", why.msg);
    plume_run_splits_tally(r);
    if (!r->st)
        plan_steps(r);
    long total = r->nsteps < 2000000000L ? r->nsteps : 2000000000L;
    plume_progress_start(&r->prog, r->label, (int)(total > 0 ? total : 0), 0);
    if (!r->progress)
        r->prog.enabled = 0;
    r->started = 1;
    return PLUME_OK;
}

/* The audit after a step: intersecting triangle pairs (CGAL's exact predicates, no common vertex)
 * and the smallest distance between non-adjacent primitives of the bodies in contact (up to 10
 * dhat), into the report and the frame's measures. */
static plume_status audit_step(plume_run *r, plume_run_step_info *info, plume_err *err)
{
    const plume_mesh *m = r->scene->mesh;
    const double *x = plume_dynamics_positions(r->d);
    plume_run_report *rep = &r->rep;
    plume_status st;
    plume_err why = {{0}};
    double t0 = plume_wall_seconds(), dmin;
    plume_contact_audit a;
    if ((st = plume_contact_count_intersections(m->nv, x, m->nt, m->tri, &r->pairs, &a, &why)) != PLUME_OK ||
        (st = plume_contact_min_distance(r->broad, x, rep->distance_cap, &dmin, &why)) != PLUME_OK)
        return plume_err_set(err, st, "contact measures: %s", why.msg);
    if (r->scene->splits)
        a.intersecting = plume_run_splits_unwelded(r, &r->pairs);
    rep->steps_intersecting += a.intersecting > 0;
    if (a.intersecting > rep->max_intersecting)
        rep->max_intersecting = a.intersecting;
    rep->min_distance = fmin(rep->min_distance, dmin);
    rep->audit_seconds += plume_wall_seconds() - t0;
    plume_contact_stats cs;
    plume_contact_term_stats(r->contact, &cs);
    if (cs.candidates > rep->max_pairs)
        rep->max_pairs = cs.candidates;
    plume_frame_measures *fm = &r->fm;
    fm->contact_pairs = fmax(fm->contact_pairs, (double)cs.candidates);
    fm->min_distance = fmin(fm->min_distance, dmin);
    fm->intersecting_pairs = fmax(fm->intersecting_pairs, (double)a.intersecting);
    info->contact_pairs = (double)cs.candidates;
    info->min_distance = dmin;
    info->intersecting = (double)a.intersecting;
    return PLUME_OK;
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

/* Why a step's prescribed motion could not start, when contact says which pair stopped it: the
 * two bodies, into why[n] (empty otherwise) */
static void prescribed_crossing(const plume_scene *s, const plume_contact *contact, plume_reason reason, char *why,
                                size_t n)
{
    plume_index v[4];
    int ee = 0;
    double toi = 1.0;
    why[0] = 0;
    if (reason != PLUME_REASON_PRESCRIBED_CROSSING || !contact || !plume_contact_last_limit(contact, v, &ee, &toi))
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

/* A step's report added to the run's report and the frame's measures. */
static void tally_step(plume_run *r, const plume_step_report *s)
{
    plume_run_report *rep = &r->rep;
    rep->halvings += s->halvings;
    rep->substeps += s->substeps;
    rep->iterations += s->iterations;
    rep->backtracks += s->backtracks;
    rep->shifts += s->shifts;
    rep->predictions += s->predictions;
    rep->step_limited += s->step_limited;
    rep->solve_seconds += s->seconds;
    rep->max_violation = fmax(rep->max_violation, s->max_violation);
    r->fm.newton_iterations += s->iterations;
    r->fm.steps_halved += s->halvings;
    r->fm.seconds += s->seconds;
}

static plume_status step_once(plume_run *r, plume_run_step_info *info, plume_err *err)
{
    const plume_scene *scene = r->scene;
    const double dt = scene->dt;
    plume_run_report *rep = &r->rep;
    plume_status st;
    plume_err why = {{0}};
    info->frame = -1;
    info->contact_pairs = info->min_distance = info->intersecting = -1.0;
    /* planned runs of adaptive scenes: one call per output frame (the stepper picks its steps
     * inside and lands on the frame's time); otherwise one call per step of dt */
    long k = 1;
    if (!r->open && scene->adaptive_dt) {
        k = scene->output_every - rep->step % scene->output_every;
        if (k > r->nsteps - r->done_plan)
            k = r->nsteps - r->done_plan;
    }
    const double t0 = plume_dynamics_time(r->d);
    const double h = r->open ? dt : r->done_plan + k == r->nsteps && r->last_short ? r->end - t0 : (double)k * dt;
    if ((st = plume_dynamics_advance(r->d, r->open ? 0.0 : h, &info->step, &why)) != PLUME_OK)
        return plume_err_set(err, st, "step %ld: %s", rep->step + 1, why.msg);
    tally_step(r, &info->step);
    if (scene->has_contact && r->audit && (st = audit_step(r, info, err)) != PLUME_OK)
        return st;
    rep->audited = scene->has_contact && r->audit;
    info->t0 = t0;
    info->t1 = plume_dynamics_time(r->d);
    info->steps = k;
    if (!info->step.converged)
        rep->converged = 0;
    info->accepted = plume_run_accepts(scene->solver, &info->step, t0, h, info->t1, dt);
    if (!info->accepted) {
        rep->stopped = 1;
        rep->stop_reason = info->step.reason;
        rep->stop_step = rep->step + 1;
        rep->stop_time = t0;
        rep->stop_halvings = info->step.halvings;
        prescribed_crossing(scene, r->contact, info->step.reason, rep->stop_detail, sizeof rep->stop_detail);
        plume_progress_finish(&r->prog);
        return PLUME_OK;
    }
    rep->step += k;
    rep->steps += k;
    if (!r->open)
        r->done_plan += k;
    plume_run_splits_tally(r);
    if (r->output_dir && (rep->step % scene->output_every == 0 || (!r->open && r->done_plan == r->nsteps))) {
        if ((st = plume_run_write_frame(r, rep->next_frame, rep->step, err)) != PLUME_OK)
            return st;
        plume_run_measures_reset(r);
        info->frame = rep->next_frame++;
        rep->frames++;
    }
    if (r->prog.enabled) {
        char line[128];
        snprintf(line, sizeof line, "t %.4f s, frame %ld, %d it%s", info->t1, rep->next_frame - 1, info->step.iterations,
                 info->step.halvings ? ", halved" : "");
        plume_progress_update(&r->prog, (int)(r->open ? rep->steps : r->done_plan), line);
    }
    return PLUME_OK;
}

int plume_run_done(const plume_run *r)
{
    return !r || r->started < 0 || r->rep.stopped || (r->started > 0 && !r->open && r->done_plan >= r->nsteps);
}

/* One step into the library's whole info struct. */
static plume_status run_step(plume_run *r, plume_run_step_info *info, plume_err *err)
{
    memset(info, 0, sizeof *info);
    info->size = sizeof *info;
    info->frame = -1;
    plume_status st = plume_run_start(r, err);
    if (st != PLUME_OK)
        return st;
    if (!r->open && (r->rep.stopped || r->done_plan >= r->nsteps))
        return plume_err_set(err, PLUME_EINVAL, "run: no step left (%ld of %ld planned steps taken%s)", r->done_plan,
                             r->nsteps, r->rep.stopped ? ", then a step was refused" : "");
    if (r->open)
        r->rep.stopped = 0; /* an open run tries again */
    double t = plume_wall_seconds();
    st = r->st ? plume_run_static_step(r, info, err) : step_once(r, info, err);
    r->rep.loop_seconds += plume_wall_seconds() - t;
    return st;
}

plume_status plume_run_step_sized(plume_run *r, plume_run_step_info *info, size_t size, plume_err *err)
{
    plume_run_step_info full;
    plume_status st = run_step(r, &full, err);
    if (info)
        plume_opts_give(info, size, &full, sizeof full);
    return st;
}

plume_status plume_run_frame(plume_run *r, plume_err *err)
{
    plume_status st = plume_run_start(r, err);
    plume_run_step_info info = {.frame = -1};
    while (st == PLUME_OK && !plume_run_done(r) && info.frame < 0 && !r->open)
        st = run_step(r, &info, err);
    if (st == PLUME_OK && r->open)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_frame: an open run is stepped by plume_run_step");
    if (plume_run_done(r))
        plume_progress_finish(&r->prog);
    return st;
}

plume_status plume_run_to_end(plume_run *r, plume_err *err)
{
    plume_status st = plume_run_start(r, err);
    if (st == PLUME_OK && r->open)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_to_end: an open run has no end (plume_run_step)");
    plume_run_step_info info;
    while (st == PLUME_OK && !plume_run_done(r))
        st = run_step(r, &info, err);
    if (st == PLUME_OK)
        plume_progress_finish(&r->prog);
    if (st == PLUME_OK) /* a run a step stopped too: the frames so far */
        st = plume_run_gltf_at_end(r, err);
    return st;
}

void plume_run_get_report_sized(const plume_run *r, plume_run_report *out, size_t size)
{
    if (!out)
        return;
    plume_run_report full;
    memset(&full, 0, sizeof full);
    if (r) {
        full = r->rep;
        full.time = plume_run_time(r);
        const plume_energy_ledger *l = r->d ? plume_dynamics_energy(r->d) : NULL;
        if (l && l->started) {
            full.work = l->work;
            full.kinetic_energy = l->ke;
            full.kinetic_change = l->ke - l->ke0;
            full.potential_change = l->u - l->u0;
            full.numerical_dissipation = l->numerical;
            full.commit_dissipation = l->commits;
            full.energy_balance_error = plume_ledger_error(l);
        }
    }
    full.size = sizeof full;
    memset(out, 0, size);
    plume_opts_give(out, size, &full, sizeof full);
}

double plume_run_time(const plume_run *r)
{
    return !r ? NAN : r->st ? plume_statics_factor(r->st) : plume_dynamics_time(r->d);
}

const double *plume_run_positions(const plume_run *r)
{
    return !r ? NULL : r->st ? plume_problem_x(r->p) : plume_dynamics_positions(r->d);
}

plume_status plume_run_fields(plume_run *r, plume_fields **out, plume_err *err)
{
    if (!r || !out)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_fields: the run and out are required");
    return plume_scene_fields_of(r->scene, r->p, out, err);
}

const double *plume_run_velocities(const plume_run *r)
{
    return r && r->d ? plume_dynamics_velocities(r->d) : NULL;
}

plume_index plume_run_constraints(const plume_run *r)
{
    return r ? r->ncons : 0;
}

const plume_scene *plume_run_scene(const plume_run *r)
{
    return r ? r->scene : NULL;
}

const plume_dynamics *plume_run_dynamics(const plume_run *r)
{
    return r ? r->d : NULL;
}

const char *plume_run_frames_path(const plume_run *r)
{
    return r ? r->frames_path : NULL;
}
