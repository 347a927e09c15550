/* plume: the quasi-static traction test (DESIGN.md, Scenarios): a rectangle [0,lx] x [0,ly]
 * clamped at y = 0 and at y = ly, the top grip moved by delta along y in steps. Works for any
 * planar or shell problem whose vertices are those of the mesh. */
#ifndef PLUME_TRACTION_H
#define PLUME_TRACTION_H

#include "curves.h"
#include "mesh.h"
#include "problem.h"
#include "solver.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double lx, ly;       /* sample size (m), must match the mesh's reference bounding box */
    double h;            /* thickness (m), for the nominal stress F / (lx h) */
    double strain_max;   /* final nominal strain delta/ly; default 0.05 */
    int steps;           /* quasi-static steps; default 10 */
    double probe_strain; /* strain of the extra small-strain solve giving initial_slope; default 1e-6 */
    plume_solver_kind solver;
    plume_solver_opts solver_opts;
    int progress;        /* progress line on stderr: 0 off, 1 when stderr is a terminal, 2 always */
} plume_traction_opts;

void plume_traction_opts_default(plume_traction_opts *o);

typedef struct {
    plume_curve curve;        /* steps+1 points (fewer if a step failed); arrays owned, see _free */
    double initial_slope;     /* Pa: nominal stress / strain at probe_strain */
    int converged;            /* every step converged (always 0 for `linearized`) */
    int failed_step;          /* first step that did not converge, or -1 */
    plume_reason failed_reason;
    int newton_iterations;    /* total over all steps and the probe */
    double max_violation;     /* max relative constraint violation over the converged steps */
    double seconds;           /* wall time of the whole run */
    int factorizations;       /* native solvers: numeric factorisations */
    double factor_seconds;    /* native solvers: time in numeric factorisations */
} plume_traction_result;

void plume_traction_result_free(plume_traction_result *r);

/* Clamps the grips of `p` (created over mesh->nv vertices, terms and constraints added, not
 * finalised), finalises it and runs the test. `rigid_edges` (n pairs; may be 0) are the
 * inextensible edges: if a chain of them links the two grips the sample cannot stretch and the
 * call fails with PLUME_EINFEASIBLE and a message, before any solve. Non-convergence of a step
 * is not an error: the run stops there (except for `linearized`, which never converges by
 * design and runs every step) and the result says which step and why. */
plume_status plume_traction_run(const plume_mesh *mesh, plume_problem *p, const plume_index *rigid_edges,
                                plume_index nrigid, const plume_traction_opts *o,
                                plume_traction_result *res, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
