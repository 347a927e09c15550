/** \file
 * plume: the quasi-static traction test (docs/design.md, Scenarios): a rectangle [0,lx] x [0,ly]
 * clamped at y = 0 and at y = ly, the top grip moved by delta along y in steps. Works for any
 * planar or shell problem whose vertices are those of the mesh. */
#ifndef PLUME_TRACTION_H
#define PLUME_TRACTION_H

#include "../core/export.h"
#include "../io/curves.h"
#include "../core/mesh.h"
#include "../core/problem.h"
#include "../solve/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Options of the traction test (plume_traction_opts_default; lx, ly and h have no default). */
typedef struct {
    double lx;           /**< sample width along x (m), must match the mesh's reference bounding box */
    double ly;           /**< sample length along y, between the grips (m), likewise */
    double h;            /**< thickness (m), for the nominal stress F / (lx h) */
    double strain_max;   /**< final nominal strain delta/ly; default 0.05 */
    int steps;           /**< quasi-static steps; default 10 */
    int max_cuts;        /**< adaptive stepping: a step that does not converge is undone and its
                            increment halved, at most max_cuts times (growing back by doubling
                            after a success); 0 = fixed steps. Default 8 */
    double probe_strain; /**< strain of the extra small-strain solve giving initial_slope; default 1e-6 */
    double probe_tol_kkt; /**< relative KKT tolerance (solver.h) of that probe solve, >= 0. Default 0:
                             tol_kkt scaled by probe_strain / (strain_max / steps), at most tol_kkt,
                             so that the probe is solved as accurately, relative to its own (that
                             much smaller) forces, as the first step: 2e-13 with every default. A
                             tighter tolerance than tol_kkt runs the probe on a solver of its own
                             (`linearized` excepted). Measured on the tilted vane, E_xx/E_yy = 1e4:
                             the slope is then exact to ~1e-8 with newton and ipopt alike, where
                             newton's was 1.3e-5 off at 3e4 triangles; the probe takes 4-7 newton
                             iterations instead of 2, and 5 ipopt ones instead of 2 (ipopt's 2 were
                             already as exact). Set tol_kkt here when the slope is not read. */
    plume_solver_kind solver;      /**< the backend of every solve; default newton */
    plume_solver_opts solver_opts; /**< its options; default plume_solver_opts_default */
    int progress;        /**< progress line on stderr: 0 off, 1 when stderr is a terminal, 2 always */
    /** Optional (NULL: none): called with each state of the curve, the rest state as step 0 and
     * then every nominal step that converged (strain, positions x: dim * nv); a status other than
     * PLUME_OK stops the run with that status (output written by it, e.g., --vtk). */
    plume_status (*on_step)(void *user, int step, double strain, const double *x);
    void *on_step_user;  /**< passed to on_step as `user` */
} plume_traction_opts;

/** Fills o with the defaults each field names (progress 1, on_step NULL); lx, ly, h are left 0. */
PLUME_API void plume_traction_opts_default(plume_traction_opts *o);

/** What a traction run gives: the curve and how the solves went (free with
 * plume_traction_result_free). */
typedef struct {
    plume_curve curve;        /**< steps+1 points (fewer if a step failed); arrays owned, see _free */
    double initial_slope;     /**< Pa: nominal stress / strain at probe_strain, the reaction taken as
                                 the virtual work of the forces over the field Y/ly (see traction.c) */
    double probe_tol_kkt;     /**< the relative KKT tolerance the probe met: the probe's own, or the
                                 steps' tol_kkt when its own was beyond the round-off floor (the probe
                                 is then solved again with tol_kkt); 0 if the probe failed */
    int converged;            /**< every step converged (always 0 for `linearized`) */
    int failed_step;          /**< first step that did not converge, or -1 */
    plume_reason failed_reason; /**< why that step's solve stopped (meaningful when failed_step >= 0) */
    int newton_iterations;    /**< total over all steps and the probe */
    int chord_steps;          /**< newton: iterations of those that reused an earlier factorisation */
    int cuts;                 /**< adaptive stepping: increments halved after a failed solve */
    int substeps;             /**< adaptive stepping: intermediate equilibria solved between the nominal
                                 steps (the curve holds the nominal strains only) */
    double max_violation;     /**< max relative constraint violation over the converged steps */
    double seconds;           /**< wall time of the whole run */
    int factorizations;       /**< native solvers: numeric factorisations */
    double factor_seconds;    /**< native solvers: time in numeric factorisations */
} plume_traction_result;

/** Frees the curve's arrays and zeroes the curve (the rest of r is left); NULL-safe. */
PLUME_API void plume_traction_result_free(plume_traction_result *r);

/** Clamps the grips of `p` (created over mesh->nv vertices, terms and constraints added, not
 * finalised), finalises it and runs the test. `rigid_edges` (n pairs; may be 0) are the
 * inextensible edges: if a chain of them links the two grips the sample cannot stretch and the
 * call fails with PLUME_EINFEASIBLE and a message, before any solve. Non-convergence of a step
 * is not an error: the run stops there (except for `linearized`, which never converges by
 * design and runs every step) and the result says which step and why. */
PLUME_API plume_status plume_traction_run(const plume_mesh *mesh, plume_problem *p, const plume_index *rigid_edges,
                                          plume_index nrigid, const plume_traction_opts *o,
                                          plume_traction_result *res, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
