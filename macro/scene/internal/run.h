/* plume (private, not installed): the scene runner's state (macro/scene/run.c) and its output half
 * (macro/scene/run_output.c: frames, renders, restart). */
#ifndef PLUME_MACRO_INTERNAL_RUN_H
#define PLUME_MACRO_INTERNAL_RUN_H

#include "../../../lib/contact/contact.h"
#include "../../../lib/contact/contact_broad.h"
#include "../../../lib/io/frames.h"
#include "../../../lib/io/progress.h"
#include "../../shell/fields.h"
#include "../run.h"

struct plume_run {
    plume_scene *scene;           /* borrowed, or owned when owns_scene */
    int owns_scene;
    plume_problem *p;
    plume_dynamics *d;            /* a dynamic scene's stepper, or NULL */
    plume_statics *st;            /* a static scene's load stepping, or NULL */
    plume_contact *contact;       /* the contact term's handle (owned by the problem), or NULL */
    plume_index ncons;
    char *output_dir, *frames_path, *restart; /* owned copies; NULL when not given */
    char *stem, *label;           /* the scene file's name (renders' titles); the progress line's label */
    long frames_opt;
    double end_time;
    int open, audit, progress, render;
    int started;                  /* 1 started, -1 its start failed */
    plume_fields *fields;         /* the ParaView series and the renders' fields (output_dir) */
    /* the plan: steps nsteps (planned runs), done_plan of them taken; end time and a shortened last step */
    long nsteps, done_plan;
    double end;
    int last_short;
    plume_progress prog;
    plume_frame_measures fm;      /* the steps since the last frame (frames.h5) */
    plume_contact_broad *broad;   /* the audit's distances */
    plume_contact_pairs pairs;    /* the audit's list, reused */
    plume_run_report rep;
    double *split_state;          /* [plume_hooks_state_size] a frame's copy of the split lines' state, or NULL */
};

/* run_splits.c: the split lines' links (the problem's term "splits"), or NULL; their counts and
 * lengths into the report after a step; their state as a frame's array (a restart sets it back). */
struct plume_hooks *plume_run_split_hooks(const plume_run *r);
void plume_run_splits_tally(plume_run *r);
/* The "split_links" array of a frame (0 without splits; 1 with a[0] filled from the current state) */
int plume_run_splits_array(plume_run *r, plume_frame_array *a);
plume_status plume_run_splits_restore(plume_run *r, const char *file, long frame, plume_err *err);
/* Of the audit's intersecting triangle pairs, those that share no vertex even with every split
 * line welded shut: a line's lips touch along it (coincident while it holds), as neighbours across
 * an edge do, and are not counted, by the audit's own rule for shared vertices */
plume_index plume_run_splits_unwelded(plume_run *r, const plume_contact_pairs *pairs);

/* run_output.c */
/* No step yet: zeros, and the contact measures -1 without contact (the distance at its cap). */
void plume_run_measures_reset(plume_run *r);
/* The output of a new run (stale frames removed, the series and frames file begun, frame 0) or of
 * a restart (the state of the file's last frame, the file copied, the series continued). */
plume_status plume_run_output_start(plume_run *r, plume_err *err);
/* Frame k of the current state at scene step `step`: the series' VTU, frames.h5, the PNG when the
 * scene renders k. */
plume_status plume_run_write_frame(plume_run *r, long k, long step, plume_err *err);

/* run_gltf.c: the scene's "gltf" when a dynamic run with an output directory ends (nothing
 * otherwise); before the run, its file's directory made (an error names the file at once, not
 * after the run). */
plume_status plume_run_gltf_at_end(plume_run *r, plume_err *err);
plume_status plume_run_gltf_prepare(plume_run *r, plume_err *err);

/* run_static.c: a static scene's run. Its problem and load stepping (checking that the options
 * plan no dynamic run); its output (the series steps.pvd); one load step. */
plume_status plume_run_static_create(plume_run *r, const plume_run_opts *o, plume_err *err);
plume_status plume_run_static_start(plume_run *r, plume_err *err);
plume_status plume_run_static_step(plume_run *r, plume_run_step_info *info, plume_err *err);

#endif
