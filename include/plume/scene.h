/** \file
 * plume: load a scene (a feather, a wing, a bird: docs/scene-format.md), solve it (static scenes)
 * or step it in time with the scene runner (dynamic ones), and read its frames back. */
#ifndef PLUME_PUBLIC_SCENE_H
#define PLUME_PUBLIC_SCENE_H

#include "problem.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A loaded, validated scene (opaque): its mesh, materials, handles, loads and run settings. */
typedef struct plume_scene plume_scene;

/* ---- scenes ---- */
/** Reads, validates and meshes the scene in `path`. Errors (PLUME_EIO unreadable file,
 * PLUME_EFORMAT malformed JSON or a wrong type, PLUME_EINVAL a bad value) name the file, the line
 * and the key ("scene.json:12: materials[0].density must be finite and > 0 (got -1)"). */
PLUME_API plume_status plume_scene_load(const char *path, plume_scene **out, plume_err *err);

/** What a caller may change in a scene before it is meshed (convergence studies). */
typedef struct {
    size_t size;          /**< sizeof the caller's struct, set by plume_scene_load_opts_default */
    double edge;          /**< > 0: replaces mesh.edge (feather and rectangle meshes); default 0 */
    const char *pattern;  /**< non-NULL: replaces a rectangle's "pattern"; default NULL */
} plume_scene_load_opts;

/** Fills o (size bytes) with the defaults (no override) and sets o->size; call it through the macro
 * plume_scene_load_opts_default(o). */
PLUME_API void plume_scene_load_opts_default_sized(plume_scene_load_opts *o, size_t size);
/** Fills *o with the defaults (plume_scene_load_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_scene_load_opts_default(o) plume_scene_load_opts_default_sized((o), sizeof(plume_scene_load_opts))

/** plume_scene_load with overrides (o may be NULL); an override that does not apply to the
 * scene's mesh (an edge for an OBJ) is an error naming the key. */
PLUME_API plume_status plume_scene_load_with(const char *path, const plume_scene_load_opts *o, plume_scene **out,
                                             plume_err *err);

/** plume_scene_load_with on a scene document held in memory (JSON text, e.g., a file's document
 * with some keys changed: apps/sweep) instead of the file: `path` is the file it stands for, whose
 * directory relative file names (OBJ meshes, feather shapes) resolve against; errors name `path`
 * and the key, without a line (the text is not the file). The caller keeps json. */
PLUME_API plume_status plume_scene_load_json(const char *json, const char *path, const plume_scene_load_opts *o,
                                             plume_scene **out, plume_err *err);

/** Frees the scene and everything it owns (mesh, materials, handles, probes, ...); sets *s = NULL;
 * NULL-safe. */
PLUME_API void plume_scene_destroy(plume_scene **s);

/** Changes run settings of a loaded scene, before a run or a problem is built from it. `settings`
 * is a JSON object of scene-file keys (docs/scene-format.md), checked as the loader checks them:
 * "solver", "max_halvings", "max_iter", "steps", "output_every", "bending_model", "predictor",
 * "globalization", "render_field", "camera", and "verbose" (true: the solver's iterations on
 * stderr; not a file key), e.g. `{"solver": "ipopt", "steps": 20}`. Keys that change the mesh,
 * the materials or the loads are not settable (reload the scene, or plume_scene_load_json).
 * All or nothing: a refused key (PLUME_EFORMAT or PLUME_EINVAL, naming it) changes nothing. */
PLUME_API plume_status plume_scene_set(plume_scene *s, const char *settings, plume_err *err);

/** What the scene holds, as a JSON object in *json (free it with plume_free): "file", "solve"
 * ("static" or "dynamic"), "elements", "vertices", "constrained_edges", "objects",
 * "bending_model", "solver", "predictor", "globalization", "max_halvings", "max_iter",
 * "verbose"; a static scene's "steps" and "probes" (each {"name", "vertices", "reference": [x,
 * y, z] with null where a component has none, or null, "source"}); a dynamic scene's "dt",
 * "duration", "adaptive_dt", "output_every", "render_field"; "contact" {"model", "dhat",
 * "friction_mu"} when it has contact; "materials" (each {"membrane": {E_xx, E_yy, nu_xy, G_xy,
 * thickness, kappa, from_moduli when read from a file}, "bending": {D_long, D_trans, D_coupling,
 * D_twist, from_moduli}, "density", "constraint"}). Keys may be added, never removed. */
PLUME_API plume_status plume_scene_describe(const plume_scene *s, char **json, plume_err *err);

/** The scene's mesh (borrowed: it lives as long as the scene): shell mode, reference positions X
 * (2 nv) and the placed positions x (3 nv) of the rest state, triangles, materials and barb
 * directions; a scene of several objects has them all, in the order of its "objects". */
PLUME_API const plume_mesh *plume_scene_mesh(const plume_scene *s);

/** The mean displacement u (m) of the vertices of probe k (the order of plume_scene_describe's
 * "probes") at positions x (3 nv, m; plume_run_positions) from the rest state; NaN for a k out of
 * range. */
PLUME_API void plume_scene_probe_displacement(const plume_scene *s, int k, const double *x, double u[3]);



/* ---- frames files ---- */
/** What /frames holds. scene is a NUL-terminated copy (truncated to fit). */
typedef struct {
    long count;       /**< committed frames */
    plume_index nv;   /**< vertices (x and v have 3 nv values) */
    plume_index ncons;/**< multipliers per frame */
    double dt;        /**< the run's time step (s) */
    char scene[1024]; /**< the scene file the run was made from */
} plume_frames_info;

/** One frame. Read by plume_frames_read, which allocates x, v (3 nv) and lambda (ncons, or NULL
 * when ncons = 0); free with plume_frame_free. */
typedef struct {
    long index;       /**< k */
    long step;        /**< time steps taken since t = 0 */
    double t;         /**< time (s) */
    plume_index nv;   /**< vertices */
    plume_index ncons;/**< constraint multipliers */
    double *x;        /**< [3 nv] positions (m), vertex-major */
    double *v;        /**< [3 nv] velocities (m/s) */
    double *lambda;   /**< [ncons] multipliers, NULL when ncons = 0 */
} plume_frame;

/** Reads the /frames attributes. */
PLUME_API plume_status plume_frames_info_read(const char *path, plume_frames_info *info, plume_err *err);

/** Reads frame k (k < 0: the last committed frame). PLUME_EINVAL when k >= count or the file has
 * no frame; PLUME_EFORMAT when a dataset has the wrong size. */
PLUME_API plume_status plume_frames_read(const char *path, long k, plume_frame *frame, plume_err *err);

/** Frees x, v and lambda of a frame read by plume_frames_read and sets them to NULL; NULL-safe. */
PLUME_API void plume_frame_free(plume_frame *frame);


/* ---- the scene runner ---- */
/** Opaque scene runner (plume_run_create, freed by plume_run_destroy): the one loop that runs a
 * scene, stepping a dynamic scene in time or a static one through its load steps. A run holds the
 * scene's problem and stepper and does what every user of a scene needs: the acceptance rule of a
 * step (a step is accepted when its solve converged, or with the `linearized` solver when it
 * advanced), the plan (a number of frames, an end time, or open-ended; a static scene's "steps"),
 * the frame output (a ParaView series, frames.h5 and the scene's PNG renders; a static scene's
 * series steps.pvd, one step_NNNNN.vtu a load step with the load factor as its time, and no
 * frames.h5), a restart from the last frame of a frames file, the contact audit after every step
 * (intersecting triangle pairs by exact predicates, the smallest distance between the bodies) and
 * the progress line. apps/feather, apps/shell, the scene sweep and the flat interface (so Python)
 * all run scenes through it. The runner prints nothing on stdout; what a caller reports is in
 * plume_run_report and plume_run_step_info. A run
 * borrows its scene: the scene must outlive the run. Typical use:
 *
 *     plume_run_opts o;
 *     plume_run_opts_default(&o);
 *     o.output_dir = "out/strip";
 *     o.frames = 10;
 *     plume_run *r = NULL;
 *     if (plume_run_create(scene, &o, &r, &err) == PLUME_OK && plume_run_to_end(r, &err) == PLUME_OK) {
 *         plume_run_report rep;
 *         plume_run_get_report(r, &rep);  // rep.stopped: a step was refused
 *     }
 *     plume_run_destroy(&r);
 */
typedef struct plume_run plume_run;

/** Options of a run (plume_run_opts_default). The plan is the first of: frames > 0, end_time > 0,
 * open; else the scene's duration. Strings are borrowed for plume_run_create's call and copied. */
typedef struct {
    size_t size;      /**< sizeof the caller's struct, set by plume_run_opts_default */
    /** Directory of the frames (NULL, the default: no frames are written). Created with its parents.
     * A new run removes the frame files an earlier run left there (frame_NNNNN.{vtu,vtk,png},
     * frame_barbs_NNNNN.vtu), then writes frames.pvd with frame_NNNNN.vtu (and frame_barbs_NNNNN.vtu
     * with constrained barbs), frames.h5 and the PNG renders, frame 0 being the initial state. */
    const char *output_dir;
    long frames;      /**< > 0: run this many frames (frames x the scene's output_every steps); default 0 */
    /** > 0: run until this time (s): steps of dt, the last one shortened to end on it when dt does not
     * divide what is left (1e-9 of a step is round-off, not a step); default 0 */
    double end_time;
    /** 1: no planned end: the caller steps (plume_run_step) as long as it likes, one step of dt a
     * call (adaptive scenes too); default 0 */
    int open;
    /** A frames file (docs/hdf5-layout.md) to continue from: its last frame's time, positions, velocities
     * and multipliers; the step and frame numbering go on from it, and with output_dir the file is
     * copied to output_dir/frames.h5 (when it is another file) and appended to, and the series goes
     * on. NULL (default): start from the scene's initial state. */
    const char *restart;
    int audit;        /**< 1 (default): the contact audit after every step (contact scenes only) */
    int progress;     /**< 1: a progress line on stderr when it is a terminal; default 0 */
    /** The progress line's label; NULL (default): the scene file's name without directory and
     * .json (which also titles the renders) */
    const char *label;
    int render;       /**< 1 (default): the PNG renders the scene's "render" lists (with output_dir) */
    /** -1 (default): the scene's solver; else a plume_solver_kind that replaces it (the scene is changed) */
    int solver;
} plume_run_opts;

/** Fills o (size bytes) with the defaults each field names and sets o->size; call it through the
 * macro plume_run_opts_default(o). */
PLUME_API void plume_run_opts_default_sized(plume_run_opts *o, size_t size);
/** Fills *o with the defaults (plume_run_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_run_opts_default(o) plume_run_opts_default_sized((o), sizeof(plume_run_opts))

/** Creates a run of the scene `scene` (borrowed; it must outlive the run; opts NULL: the
 * defaults): checks the options (errors name the option: "plume_run_opts.frames must be >= 0"),
 * applies the solver override to the scene and builds its problem and stepper (a static scene: its
 * load stepping; frames, end_time, open and restart are refused there, and so is the linearized
 * solver, which cannot reach an equilibrium). Nothing is read or
 * written yet (plume_run_start). Succeeds whole (*out set) or frees what it made (*out NULL). */
PLUME_API plume_status plume_run_create(plume_scene *scene, const plume_run_opts *opts, plume_run **out, plume_err *err);

/** The same from a scene file, which the run loads and owns (errors name the file, line and key). */
PLUME_API plume_status plume_run_open(const char *path, const plume_run_opts *opts, plume_run **out, plume_err *err);

/** Frees the run, its stepper and problem (and its scene when plume_run_open loaded it); sets *r =
 * NULL; NULL-safe. Frames already written stay. */
PLUME_API void plume_run_destroy(plume_run **r);

/** Prepares the output and the initial state: with restart, reads the frames file (errors begin
 * with "restart: " and name the file) and continues from its last frame; otherwise writes frame 0
 * (with output_dir). Then plans the steps and starts the progress line. The stepping functions
 * call it first when the caller did not; a second call does nothing. A failed start leaves the run
 * unusable but queryable (plume_run_get_report's restart_dt), to be destroyed. */
PLUME_API plume_status plume_run_start(plume_run *r, plume_err *err);

/** What happened in one call of plume_dynamics_advance. */
typedef struct {
    int substeps;          /**< implicit Euler steps taken (1 when nothing was halved) */
    int halvings;          /**< times a step was halved (adaptive: cut after a failed attempt) */
    int stalls;            /**< adaptive: attempts the solver gave up as stalled (each then halved) */
    double dt_min;         /**< the smallest step taken (s) */
    double dt_max;         /**< the largest step taken (s) */
    int iterations;        /**< solver iterations over all substeps */
    int backtracks;        /**< newton's line-search rejections (plume_solve_report) over all solves */
    int shifts;            /**< newton's inertia shifts (plume_solve_report) over all solves */
    int step_limited;      /**< solver steps cut short by continuous collision detection (contact) */
    int predictions;       /**< tangent predictor solves (opts.tangent_predictor; each one factorisation) */
    double max_violation;  /**< max relative constraint violation over the substeps */
    int converged;         /**< every substep converged */
    plume_reason reason;   /**< why the first attempt that failed stopped (CONVERGED if none failed) */
    double seconds;        /**< wall time of the call */
} plume_step_report;

/** What one call of plume_run_step did. */
typedef struct {
    size_t size;             /**< sizeof the struct the caller compiled against (plume_run_step sets it) */
    plume_step_report step;  /**< the stepper's report of the call (dynamic scenes) */
    plume_load_step_report load; /**< the load step's report (static scenes) */
    double t0;               /**< the time before the step (s; static scenes: the load factor) */
    double t1;               /**< the time after it (s; static scenes: the load factor) */
    long steps;              /**< steps of dt the call covered (> 1: an adaptive scene's frame) */
    int accepted;            /**< plume_run_accepts; 0: the run stopped (plume_run_report.stopped) */
    long frame;              /**< the index of the frame written after the step, or -1 */
    double contact_pairs;    /**< audit: contact stencils after the step; -1 without the audit */
    double min_distance;     /**< audit: smallest distance between the bodies (m, capped at 10 dhat); -1 */
    double intersecting;     /**< audit: intersecting triangle pairs; -1 */
} plume_run_step_info;

/** Takes one step of the plan: one step of dt (the last one of an end time shortened), or for an
 * adaptive scene in a planned run, the steps up to the next frame in one call; audits it, applies
 * the acceptance rule and writes the frame that falls due. info may be NULL. A refused step is not
 * an error: the state stays where the stepper left it, the run is stopped (a stopped open run may
 * still be stepped: the call tries again). Errors (a solver or contact failure, a frame that
 * cannot be written) name the step: "step 12: ..."; PLUME_EINVAL when a planned run has no step
 * left. */
PLUME_API plume_status plume_run_step_sized(plume_run *r, plume_run_step_info *info, size_t size, plume_err *err);
/** plume_run_step_sized with sizeof the plume_run_step_info the caller compiled against: the library
 * writes no more of *info than that (a struct that grows, docs/library.md). */
#define plume_run_step(r, info, err) plume_run_step_sized((r), (info), sizeof(plume_run_step_info), (err))

/** Steps until the next frame is written, the plan ends or a step is refused (planned runs). */
PLUME_API plume_status plume_run_frame(plume_run *r, plume_err *err);

/** Steps until the plan ends or a step is refused (planned runs), then ends the progress line. */
PLUME_API plume_status plume_run_to_end(plume_run *r, plume_err *err);

/** Non-zero when a planned run has no step left or a step was refused. */
PLUME_API int plume_run_done(const plume_run *r);

/** What a run did, for its caller to print (plume_run_get_report). Counts are over this run's
 * calls (a restarted run counts from the restart). */
typedef struct {
    size_t size;             /**< sizeof the struct the caller compiled against (plume_run_get_report sets it) */
    double time;             /**< the current time (s); a static scene's load factor */
    long step;               /**< the scene's steps since t = 0 (a restart goes on from the file's) */
    long next_frame;         /**< the index of the next frame (frames 0 .. next_frame - 1 exist) */
    long frames;             /**< frames this run wrote, frame 0 of a new run included */
    long planned_steps;      /**< steps the plan asks for (-1: open) */
    long steps;              /**< steps accepted */
    long substeps;           /**< implicit Euler steps taken (more than steps when some were halved) */
    long halvings;           /**< times a step was halved (static scenes: a load increment cut) */
    long iterations;         /**< solver iterations */
    long factorizations;     /**< numeric factorisations (static scenes; 0 for dynamic ones) */
    long backtracks;         /**< newton's line-search rejections */
    long shifts;             /**< newton's inertia shifts */
    long predictions;        /**< tangent predictor solves */
    double max_violation;    /**< the largest relative constraint violation of a step */
    double solve_seconds;    /**< the steps' wall time (plume_step_report.seconds) */
    double loop_seconds;     /**< wall time spent in the stepping functions */
    int converged;           /**< every step converged (linearized steps do not) */
    int stopped;             /**< a step was refused: */
    plume_reason stop_reason;/**< why it failed (PLUME_REASON_CONVERGED when none was refused) */
    long stop_step;          /**< its number (step + 1 when it was refused) */
    double stop_time;        /**< the time it started from (s) */
    int stop_halvings;       /**< the halvings it tried */
    /** When the refused step's prescribed motion alone ran two bodies into each other, which ones
     * and where, as a sentence starting ": the keyframed motion alone ..."; "" otherwise */
    char stop_detail[768];
    int audited;             /**< the contact audit ran (a contact scene with opts.audit) */
    long steps_intersecting; /**< steps after which triangle pairs intersected */
    long max_intersecting;   /**< most intersecting pairs after a step */
    long max_pairs;          /**< most contact stencils of a step */
    long step_limited;       /**< solver steps cut short by CCD (contact scenes, audit or not) */
    double min_distance;     /**< smallest distance between the bodies (m), at most distance_cap */
    double distance_cap;     /**< 10 dhat: a larger distance is not measured */
    double audit_seconds;    /**< wall time of the audit */
    double restart_dt;       /**< the dt the restart file was written with (s); 0 without restart */
    /* a scene with split lines ("splits"; docs/unzipping.md); since libplume 3.2 */
    long split_pairs;        /**< the lines' links (vertex pairs); 0 without splits */
    long splits_opened;      /**< links that let go, since t = 0 (a restart carries the count on) */
    long splits_closed;      /**< links that caught again */
    double split_open_now;   /**< the length of line open after the last step, all lines (m) */
    double split_longest;    /**< the longest stretch of one line open at once over the run's steps (m) */
    double split_dissipated; /**< the energy the links gave up as they let go, since t = 0 (J) */
    /* the energy balance of a dynamic scene over this run's steps (J; static scenes 0; since
     * libplume 3.4; docs/apps/feather.md, "The energy balance") */
    double work;             /**< the handles' and kinematic bodies' work on the scene */
    double kinetic_energy;   /**< the kinetic energy of the lumped masses at the last state */
    double kinetic_change;   /**< the kinetic energy's change over this run's steps */
    double potential_change; /**< the potential's change (elastic, contact and gravity) */
    double numerical_dissipation; /**< what implicit Euler's steps gave up: 1/2 |v' - v|_M^2 and the
                                 step's forces along its chord less the potential's change there */
    double commit_dissipation; /**< what the split lines' commits gave up over this run's steps */
    double energy_balance_error; /**< (work - kinetic change - potential change - numerical - commit
                                 dissipation) / max(the steps' gross work, the largest energy change):
                                 the error of Simpson's rule on the potential along each step, and
                                 any energy moved unaccounted (lagged friction's work) */
} plume_run_report;

/** Fills *out (size bytes) with what the run did so far; call it through the macro
 * plume_run_get_report(r, out). */
PLUME_API void plume_run_get_report_sized(const plume_run *r, plume_run_report *out, size_t size);
/** plume_run_get_report_sized with sizeof the plume_run_report the caller compiled against. */
#define plume_run_get_report(r, out) plume_run_get_report_sized((r), (out), sizeof(plume_run_report))

/** The time of the current state (s). */
PLUME_API double plume_run_time(const plume_run *r);

/** Positions of the current state (3 nv, m); the stepper's array, valid until the next step. */
PLUME_API const double *plume_run_positions(const plume_run *r);

/** Velocities of the current state (3 nv, m/s); the stepper's array, valid until the next step. */
PLUME_API const double *plume_run_velocities(const plume_run *r);

/** The number of constraint multipliers (inextensible barbs and the like). */
PLUME_API plume_index plume_run_constraints(const plume_run *r);

/** The run's scene (its own for plume_run_open, else the caller's). */
PLUME_API const plume_scene *plume_run_scene(const plume_run *r);

/** The frames file (output_dir/frames.h5), or NULL without output_dir. */
PLUME_API const char *plume_run_frames_path(const plume_run *r);

/** Writes the current state of a dynamic run (time, step, positions, velocities, multipliers) as
 * the next frame of the frames file `path`, the run's own or another (a caller that steps an open
 * run and keeps the states it likes: Python's Scene.write_frames). With create, the file is
 * written anew first (its directory made with its parents), recording the scene by its absolute
 * path, its dt and its materials, as the runner's own file; otherwise the file must hold frames of
 * this scene's mesh. Errors name the file; PLUME_EINVAL for a static run (it has no frames file). */
PLUME_API plume_status plume_run_write_state(plume_run *r, const char *path, int create, plume_err *err);

/* ---- glTF export ---- */
/** How a glTF file animates the frames (docs/graphics.md): morph targets of one mesh per object
 * (the default), or one mesh per object and frame shown in turn. */
enum { PLUME_GLTF_MORPH = 0, PLUME_GLTF_FRAMES = 1 };

/** Options of plume_run_write_gltf (plume_gltf_opts_default). */
typedef struct {
    size_t size;       /**< sizeof the caller's struct, set by plume_gltf_opts_default */
    int animation;     /**< PLUME_GLTF_MORPH (default) or PLUME_GLTF_FRAMES */
    const char *field; /**< NULL (default), or a per-triangle field of the renders (mean_curvature, J,
                          strain_bb, ...; docs/scene-format.md "render_field"), averaged to the vertices
                          (weighted by area) and written as the vertex attribute "_" + its name in
                          upper case (_MEAN_CURVATURE) */
} plume_gltf_opts;

/** Fills *o with the defaults; size is sizeof the caller's struct (use the macro
 * plume_gltf_opts_default(o)). */
PLUME_API void plume_gltf_opts_default_sized(plume_gltf_opts *o, size_t size);
/** Fills *o with the defaults (plume_gltf_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_gltf_opts_default(o) plume_gltf_opts_default_sized((o), sizeof(plume_gltf_opts))

/** Writes the frames of the frames file `frames_path` (NULL: the run's own, DIR/frames.h5) as a
 * glTF 2.0 binary file `path` (.glb): a node per scene object named as in the scene (a "mesh"
 * scene: one, named after the scene file), a primitive per material (named by the material's
 * "name", else material_K; kinematic bodies "kinematic"), vertex normals, metres, glTF's y up
 * (the scene's z), the frames' times as the animation, and the scene's camera and times in the
 * scene's extras (docs/graphics.md). The frames file must hold frames of this scene's mesh. Errors
 * name the file, the option or the field; the file is written whole or not at all. */
PLUME_API plume_status plume_run_write_gltf(plume_run *r, const char *frames_path, const char *path,
                                            const plume_gltf_opts *o, plume_err *err);



/* ---- ParaView series of a mesh and its fields (what the runner writes; apps/traction and
 * apps/homogenize write their specimens and cells the same way) ---- */
/** Opaque field calculator of one mesh: materials, the bending term, the barb edges, the rest
 * geometry, the output arrays and an open ParaView series (plume_fields_create, freed by
 * plume_fields_destroy). */
typedef struct plume_fields plume_fields;

/** What the fields need, copied or taken: the mesh (borrowed, must outlive the object; topology
 * built in shell mode), dim of the positions given later (2: planar, 3: shell), the first nt_elastic triangles
 * with materials mats[mesh->material[t]], an optional bending term whose ownership passes to the
 * object (its `energies` gives the bending energy; NULL: none; its stencils are the triangles,
 * or the mesh's hinges for the hinge model), and the constrained barb edges (copied, may be
 * NULL). PLUME_EINVAL naming what is wrong, PLUME_ENOMEM. */
PLUME_API plume_status plume_fields_create(const plume_mesh *mesh, int dim, plume_index nt_elastic,
                                           const plume_membrane_material *mats, int nmat, plume_term *bending,
                                           const plume_index *barb_edges, plume_index nbarb, plume_fields **out,
                                           plume_err *err);

/** Frees the object, its bending term and its output arrays (not the mesh); sets *f = NULL;
 * NULL-safe. */
PLUME_API void plume_fields_destroy(plume_fields **f);

/** Starts a ParaView series in directory dir: files "<stem>_NNNNN.vtu" (and
 * "<stem>_barbs_NNNNN.vtu") and the collection dir/pvd_name (e.g., "frames.pvd"). With
 * resume_until >= 0 an existing collection keeps its entries of time <= resume_until (a restarted
 * run); otherwise it is replaced at the first frame. */
PLUME_API plume_status plume_fields_series_start(plume_fields *f, const char *dir, const char *pvd_name, const char *stem,
                                                 double resume_until, plume_err *err);

/** Each frame also writes the stencils of p's term named `term` (arity 2: links such as barbule
 * hooks) as lines, "<stem>_<term>_NNNNN.vtu", part 2 of the collection, with cell data "state"
 * (plume_term.states; 1 without it) and "energy" (J; plume_term.energies; 0 without it). p is
 * borrowed: it must outlive the frames, and its x holds the frame's positions when they come from
 * its own solves. PLUME_EINVAL naming the term when p has none of that name or its arity is not 2. */
PLUME_API plume_status plume_fields_add_links(plume_fields *f, plume_problem *p, const char *term, plume_err *err);

/** Writes frame `index` at time t (positions x): its .vtu files and the updated .pvd. Point data:
 * displacement; cell data: material, barb_direction, the fields above, and "object" after
 * plume_fields_set_objects. */
PLUME_API plume_status plume_fields_series_frame(plume_fields *f, long index, double t, const double *x, plume_err *err);

/** The field calculator of a scene's states: its membrane materials, its bending term and its
 * barb edges over the whole mesh (kinematic triangles get NaN), ready for
 * plume_fields_series_start. The caller destroys *out; it borrows the scene's mesh, so the scene
 * must outlive it. A scene with "bending_model": "midedge" is refused: its bending energies need
 * the edge angles of a run (plume_run_fields). */
PLUME_API plume_status plume_scene_fields(const plume_scene *s, plume_fields **out, plume_err *err);

/** The field calculator of a run's states (plume_scene_fields of its scene, for every bending
 * model: midedge bending reads the run's edge angles, so give it the run's positions,
 * plume_run_positions, between steps). The caller destroys *out before the run. */
PLUME_API plume_status plume_run_fields(plume_run *r, plume_fields **out, plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
