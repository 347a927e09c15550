/* plume: the scene runner on a static scene (macro/scene/run.c dispatches here): the problem and
 * its load stepping (plume_scene_statics), one load step a plume_run_step, each equilibrium a frame
 * of the ParaView series steps.pvd (step_NNNNN.vtu, the load factor as the time; no frame 0 and no
 * frames.h5: a static run has no clock to restart on). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/io/fs.h"
#include "internal/run.h"

plume_status plume_run_static_create(plume_run *r, const plume_run_opts *o, plume_err *err)
{
    const plume_scene *s = r->scene;
    if (o->frames > 0 || o->end_time > 0.0 || o->open)
        return plume_err_set(err, PLUME_EINVAL,
                             "plume_run_opts.frames, end_time and open plan a dynamic run; a static scene runs its "
                             "load steps (the scene's \"steps\": %d)", s->steps);
    if (o->restart)
        return plume_err_set(err, PLUME_EINVAL,
                             "plume_run_opts.restart: a static scene's run writes no frames file to restart from");
    if (s->solver == PLUME_SOLVER_LINEARIZED)
        return plume_err_set(err, PLUME_EINVAL,
                             "solver: the linearized solver takes one step and cannot reach an equilibrium: use newton "
                             "or ipopt");
    free(r->frames_path);
    r->frames_path = NULL;
    plume_status st = plume_scene_statics(s, &r->p, &r->st, err);
    if (st == PLUME_OK)
        r->ncons = plume_problem_ncons(r->p);
    return st;
}

plume_status plume_run_static_start(plume_run *r, plume_err *err)
{
    r->nsteps = r->scene->steps;
    r->rep.planned_steps = r->nsteps;
    r->rep.next_frame = 1; /* frame k is load step k */
    if (!r->output_dir)
        return PLUME_OK;
    if (plume_make_dirs(r->output_dir) != 0)
        return plume_err_set(err, PLUME_EIO, "output_dir '%s': cannot create the directory: %s", r->output_dir,
                             strerror(errno));
    plume_status st = plume_scene_fields_of(r->scene, r->p, &r->fields, err);
    if (st == PLUME_OK)
        st = plume_fields_series_start(r->fields, r->output_dir, "steps.pvd", "step", -1.0, err);
    return st;
}

/* A load step's report added to the run's report. */
static void tally_load_step(plume_run_report *rep, const plume_load_step_report *l)
{
    rep->substeps += l->substeps;
    rep->halvings += l->cuts;
    rep->iterations += l->iterations;
    rep->factorizations += l->factorizations;
    rep->backtracks += l->backtracks;
    rep->shifts += l->shifts;
    rep->solve_seconds += l->seconds;
    rep->max_violation = fmax(rep->max_violation, l->max_violation);
    if (!l->converged)
        rep->converged = 0;
}

plume_status plume_run_static_step(plume_run *r, plume_run_step_info *info, plume_err *err)
{
    plume_run_report *rep = &r->rep;
    const plume_load_step_report *l = &info->load;
    info->contact_pairs = info->min_distance = info->intersecting = -1.0;
    info->t0 = plume_statics_factor(r->st);
    plume_status st = plume_statics_step(r->st, &info->load);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "load step %ld: %s", rep->step + 1, plume_strerror(st));
    tally_load_step(rep, l);
    info->t1 = plume_statics_factor(r->st);
    info->steps = 1;
    /* every load step's state is a frame, the last one too when it did not converge (the state it
     * was left in is the last equilibrium) */
    if (r->output_dir) {
        if ((st = plume_fields_series_frame(r->fields, l->step, l->factor, plume_problem_x(r->p), err)) != PLUME_OK)
            return st;
        info->frame = l->step;
        rep->next_frame = l->step + 1;
        rep->frames++;
    }
    info->accepted = l->converged;
    if (!info->accepted) {
        rep->stopped = 1;
        rep->stop_reason = l->reason;
        rep->stop_step = rep->step + 1;
        rep->stop_time = info->t1;
        rep->stop_halvings = l->cuts;
        plume_progress_finish(&r->prog);
        return PLUME_OK;
    }
    rep->step++;
    rep->steps++;
    r->done_plan++;
    if (r->prog.enabled) {
        char line[128];
        snprintf(line, sizeof line, "load factor %.4f, %d it%s", info->t1, l->iterations, l->cuts ? ", cut" : "");
        plume_progress_update(&r->prog, (int)r->done_plan, line);
    }
    return PLUME_OK;
}
