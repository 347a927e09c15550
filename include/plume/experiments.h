/** \file
 * plume: the experiments over both scales: parameter sweeps (one job per rank), the multiscale study, and the stability measures. */
#ifndef PLUME_PUBLIC_EXPERIMENTS_H
#define PLUME_PUBLIC_EXPERIMENTS_H

#include "traction.h"
#include "homogenize.h"
#include "fit.h"


#ifdef __cplusplus
extern "C" {
#endif

/* ---- parameter sweeps ---- */
/** Opaque expanded sweep: the sweep file's base request, its varied axes and run count
 * (plume_sweep_load, freed by plume_sweep_destroy). */
typedef struct plume_sweep plume_sweep;

/** Loads and expands a sweep file; samples come from samples_path (data/samples.json) when the
 * file varies "sample". */
PLUME_API plume_status plume_sweep_load(const char *path, const char *samples_path, plume_sweep **out, plume_err *err);

/** Frees the sweep; sets *s = NULL; NULL-safe. */
PLUME_API void plume_sweep_destroy(plume_sweep **s);

/** The number of runs (the product of the "vary" entries' lengths; 0 for s NULL). */
PLUME_API int plume_sweep_count(const plume_sweep *s);

/** The job: "traction" | "homogenize" | "fit" | "scene" (the sweep's string; NULL for s NULL). */
PLUME_API const char *plume_sweep_job(const plume_sweep *s);

/** Run k's request and its varied values ({"angle": 45, "sample": "T01", ...}) as JSON texts,
 * malloc'ed (free with free()). A scene run's request is {"scene": the file, "steps": n (when
 * given), "document": the scene's document with run k's values set}. */
PLUME_API plume_status plume_sweep_request(const plume_sweep *s, int k, char **request, char **values, plume_err *err);

/** Executes run k and returns its record as a JSON text (malloc'ed): {"run": k, "values": {...},
 * "outcome": "converged" | the solver's stop reason | "error", "message": plume's message (errors),
 * "result": the job's result (drivers/flat.h; a scene's: drivers/internal/sweep_scene.h, and
 * docs/apps/sweep.md)}. A run that fails is a record, not an error: NULL only when memory runs out. A
 * scene run whose step does not converge at the smallest step has that solver's reason as its
 * outcome and keeps the steps done. */
PLUME_API char *plume_sweep_execute(const plume_sweep *s, int k);

/** The results file: /sweep with attributes "job", "runs" and "file" (the sweep file's text); one
 * group `/sweep/runs/<k>` per recorded run with datasets strain, stress, wbar (when the job gives a
 * curve; units 1, Pa, 1) and string attributes "values", "outcome", "record" (the JSON record
 * without the curve arrays and without timings, so that the file's content does not depend on
 * how the runs were spread) and "seconds". A scene run has instead `per_step/<measure>` datasets
 * (time s, newton_iterations, halvings, and for contact scenes contact_pairs, min_distance m,
 * intersecting_pairs), positions (3 nv, m; scenes of at most 20000 vertices) and its numbers as
 * attributes with a "units" string (docs/hdf5-layout.md); /sweep then keeps the scene file's text
 * in "scene". Creates the file when it does not exist (refusing one of another sweep, or, for a
 * scene sweep, one whose scene file has changed since: PLUME_EINVAL). */
PLUME_API plume_status plume_sweep_results_open(const char *h5path, const plume_sweep *s, plume_err *err);

/** Which runs the file holds (done[k] = 1), e.g., after a sweep was killed: those are not redone. */
PLUME_API plume_status plume_sweep_results_done(const char *h5path, const plume_sweep *s, unsigned char *done, plume_err *err);

/** Adds run k's record (from plume_sweep_execute) to the file; a run is written whole or not at
 * all (its group is created last, from a complete temporary name). */
PLUME_API plume_status plume_sweep_results_add(const char *h5path, const plume_sweep *s, int k, const char *record, plume_err *err);

/** A markdown table of every recorded run (run, values, outcome, last strain and stress, seconds;
 * for a scene: steps, final time, max displacement and min contact distance) into md_path, and
 * the same as a JSON array into *json (malloc'ed; may be NULL). */
PLUME_API plume_status plume_sweep_summary(const char *h5path, const plume_sweep *s, const char *md_path, char **json,
                                           plume_err *err);


/* ---- the multiscale study ---- */
/** Input of one run. */
typedef struct {
    size_t size;               /**< sizeof the caller's struct, set by plume_study_config_default */
    double lx;                 /**< sample width (m); default 1 (supplementary Table 4) */
    double ly;                 /**< sample length between the grips (m); default 1.3 */
    double h;                  /**< thickness (m); default 1 (a micro run's layout.h follows it) */
    double angle;              /**< barb angle from the pulling axis y (deg); default 45 (tilted) */
    plume_ortho moduli;        /**< Pa; default E_xx 1e4, E_yy 1, G_xy 1, nu 0 */
    double kappa;              /**< compression-term coefficient; default 0 */
    int constraint;            /**< 1: inextensible barbs; 0: penalty (finite E_xx); default 1 */
    plume_patch_kind mesh;     /**< default PLUME_PATCH_ALIGNED */
    double edge;               /**< target edge length (m); default 0.065 (min(lx, ly)/20 is 0.05) */
    double strain_max;         /**< default 0.05 */
    int steps;                 /**< default 2 */
    plume_solver_kind solver;  /**< default newton */
    int max_iter;              /**< solver iteration cap per step; default 100 */
    int micro;                 /**< 1: the resolved microscale specimen of `layout` (plume_micro_specimen)
                                  in place of the vane: lx, ly, angle, strain_max, steps, solver and
                                  max_iter apply, moduli, kappa, constraint, mesh and edge do not, and h
                                  must equal layout.h. Default 0: the macroscale vane */
    plume_layout layout;       /**< micro only; default plume_layout_default */
} plume_study_config;

/** Fills c (size bytes) with the defaults each field names (layout.h set to h) and sets c->size;
 * call it through the macro plume_study_config_default(c). */
PLUME_API void plume_study_config_default_sized(plume_study_config *c, size_t size);
/** Fills *c with the defaults (plume_study_config_default_sized with sizeof the struct the caller compiled against). */
#define plume_study_config_default(c) plume_study_config_default_sized((c), sizeof(plume_study_config))

/** Output of one run. `curve` is owned by the result (plume_study_result_free). */
typedef struct {
    plume_curve curve;       /**< the points computed (all steps unless a step failed) */
    double strain;           /**< nominal strain at the last computed point */
    double stress;           /**< nominal stress at the last computed point (Pa) */
    double wbar;             /**< w-bar at the last computed point */
    double seconds;          /**< wall time of the traction run (mesh and set-up excluded) */
    int iterations;          /**< solver iterations, all steps and the small-strain probe (solved
                                with the steps' tolerance: the study reads no initial slope) */
    int converged;           /**< every step converged (never for `linearized`) */
    int complete;            /**< the last point is at strain_max (linearized runs count) */
    plume_reason reason;     /**< CONVERGED, or why the first failed step stopped */
    long elements;           /**< elements (micro at order 2: quadratic triangles, not the four
                                triangles each is split into) */
    long vertices;           /**< mesh vertices (nodes) */
} plume_study_result;

/** Meshes, builds and runs the traction test of `c` (the vane, or the micro specimen). A step that does not converge is not an
 * error: the result says so (converged 0, reason) and holds the points before it. Errors
 * (invalid input or layout, barbs spanning both grips with the constraint on: PLUME_EINFEASIBLE,
 * a dependency) leave `r` zeroed with a message in err. */
PLUME_API plume_status plume_study_traction(const plume_study_config *c, plume_study_result *r, plume_err *err);

/** Frees the curve's arrays and zeroes r; NULL-safe. */
PLUME_API void plume_study_result_free(plume_study_result *r);

/** |a - ref| / |ref| (|a - ref| if ref is 0); NaN if either is not finite. */
PLUME_API double plume_study_rel_error(double a, double ref);


/* ---- stability measures ---- */
/** Condition estimate (1 / CHOLMOD rcond of the Hessian's factor at rest) of the tilted 45 deg
 * sample (1 x 1.3, aligned mesh of the given edge, grips clamped) with E_yy = G_xy = 1 and
 * E_xx = ratio. constraint 0: the penalty model, whose Hessian carries the stiff mode;
 * 1: what the constrained model leaves to the Hessian once the constraint has taken the stiff
 * mode out (the same sample with E_xx = E_yy), independent of the ratio. */
PLUME_API plume_status plume_stability_condition(double ratio, double edge, int constraint, double *cond, plume_err *err);

/** A strip one element wide (0.05 x 1 m, E = 1 Pa, nu = 0, planar) clamped at both ends and
 * compressed to a length ratio `lambda_end` in `steps` steps, with compression coefficient kappa
 * (0: plain St Venant–Kirchhoff, whose 1D energy softens below lambda = 1/sqrt 3) and the cubic
 * term, or with log_barrier the log barrier of supplementary §8 in its place. A tiny
 * deterministic imperfection lets the strip leave the unstable uniform state. Returns the
 * smallest and largest element area ratios J at the end, whether every step converged, and the
 * total Newton iterations. Without the term elements collapse and invert (J < 0) so that others
 * can stretch (J > 1); with it they stay open. */
PLUME_API plume_status plume_stability_compression(double kappa, int log_barrier, double lambda_end, int steps, double *min_J,
                                                   double *max_J, int *converged, int *iterations, plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
