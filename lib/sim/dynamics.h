/** \file
 * plume: implicit Euler as a constrained minimisation (docs/design.md "Dynamics", supplementary §3):
 *   x_{n+1} = argmin 1/(2 dt^2) (x - x~)^T M (x - x~) + W(x) - f_ext^T x  s.t. g(x) = 0,
 *   x~ = x_n + dt v_n, v_{n+1} = (x_{n+1} - x_n) / dt, M lumped,
 * with gravity, handles that move prescribed vertices along keyframed paths, and a step that
 * does not converge halved and retried (supplementary §7.2.3). With terms whose stencils follow
 * the state (contact), they are updated before each step (a new pattern gets a new solver) and
 * after it (a pair that came within reach is solved again); with terms that limit steps (the
 * contact barrier's CCD), a step starts where nothing crosses: a handle motion that would cross is
 * a failed step (halved), and the free vertices start at the safe part of the prediction. */
#ifndef PLUME_DYNAMICS_H
#define PLUME_DYNAMICS_H

#include "../../include/plume/scene.h"

#include "../core/export.h"
#include "../core/mesh.h"
#include "../core/problem.h"
#include "../solve/solver.h"
#include "dynamics_energy.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A handle: vertices that follow a keyframed rigid motion (lib/core/rigid_motion.h) of their positions
 * y at the stepper's creation: pivot + offset(t) + R(t) (y - pivot), offset piecewise linear and R
 * slerped between keyframes, both constant after the last. Without rotations a handle translates:
 * y + offset(t). Arrays owned by the caller; copied at creation. */
typedef struct {
    plume_index nvertices;       /**< number of vertices the handle moves */
    const plume_index *vertices; /**< [nvertices] their ids (prescribed by the stepper) */
    int nkeys;                   /**< number of keyframes (>= 1) */
    const double *times;     /**< [nkeys], increasing, seconds */
    const double *offsets;   /**< [3 nkeys] translation of the handle at each key (m) */
    const double *rotations; /**< [3 nkeys] rotation vectors (axis times angle, radians) or NULL */
    double pivot[3];         /**< the rotations' centre at the creation positions (m) */
} plume_handle;

/** Options of the stepper (plume_dynamics_opts_default). */
typedef struct {
    double dt;               /**< time step (s); default 1e-2 */
    double gravity[3];       /**< m/s^2; default (0, 0, -9.81) */
    int max_halvings;        /**< a failed step is halved at most this often; default 6 */
    plume_solver_kind solver;      /**< the backend of every step's solve; default newton */
    plume_solver_opts solver_opts; /**< its options; default plume_solver_opts_default */
    /** Adaptive steps (0, the default: every step is dt, halved recursively when it fails). With 1,
     * each plume_dynamics_advance covers its interval exactly (frames stay at their nominal
     * times) in steps that start at dt, grow 2x after a step that converged within
     * easy_iterations, up to dt_max, and are halved when the solver stalls (stall_iterations
     * non-contracting iterations in a row, newton: plume_solver_opts.stall_iterations) or fails,
     * down to dt / 2^max_halvings. Each advance starts again from dt, so a run continued from a
     * saved state repeats the uninterrupted one. */
    int adaptive;
    double dt_max;           /**< adaptive: the largest step (s); 0 (default): dt */
    int stall_iterations;    /**< adaptive, newton: default 6 (0: only the iteration cap) */
    int easy_iterations;     /**< adaptive: default 5 */
    /** 1 (the default): a step whose handles leave their inertial prediction x~ = x_n + dt v_n
     * (they start, stop or turn) starts its solve from the tangent (consistent) predictor
     * (plume_solver_predict): one linear solve with the tangent at x~, inertia included, for the
     * residual there and the free dofs' response to the handles' move from x~ to their keyframed
     * targets. 0: the free dofs start at x~ with the handles already at their targets; a jump of
     * more than an element crushes the membrane next to a handle, and Newton may then settle in
     * another local minimum than the time-converged trajectory (the shipped feather: 1 mm away,
     * for good; docs/solver-nonconvexity.md). One factorisation per predicted step; native
     * solvers only. With terms that limit steps (contact) it follows the safe start (the handles'
     * move checked by continuous collision detection) when that was not cut, and its response is
     * cut where CCD says. */
    int tangent_predictor;
} plume_dynamics_opts;

/** Fills o with the defaults each field names. */
void plume_dynamics_opts_default(plume_dynamics_opts *o);

/** Opaque implicit-Euler stepper: the state (t, x, v, multipliers), the copied handles, the
 * inertia term and the solver (plume_dynamics_create, freed by plume_dynamics_destroy). */
typedef struct plume_dynamics plume_dynamics;

/** Takes a shell-mode problem over mesh->nv vertices holding the elastic terms and constraints
 * (not finalised), adds the inertia and gravity terms with the lumped masses of the per-triangle
 * surface densities (kg/m^2, indexed by material id), fixes the handles' vertices, finalises it
 * and creates the solver. The problem stays owned by the caller and must outlive the stepper.
 * Initial state: x = the problem's x (set it first, typically the rest shape), v = 0, t = 0. */
plume_status plume_dynamics_create(const plume_mesh *mesh, plume_problem *p, const double *density, int ndensity,
                                             const plume_handle *handles, int nhandles, const plume_dynamics_opts *o,
                                             plume_dynamics **out, plume_err *err);
/** Frees the stepper, its solver and its copies of the handles (not the problem, which the caller
 * owns); sets *d = NULL; NULL-safe. */
void plume_dynamics_destroy(plume_dynamics **d);



/** Advances the state by dt (opts.dt when dt <= 0): one implicit Euler step, halved recursively
 * on non-convergence up to max_halvings (adaptive: as many steps as the interval needs, see
 * plume_dynamics_opts.adaptive). Not converging at the smallest step is reported (state
 * left at the last converged substep), not an error; errors (a solver or contact failure, memory)
 * carry a message in err (NULL allowed). */
plume_status plume_dynamics_advance(plume_dynamics *d, double dt, plume_step_report *rep, plume_err *err);

/** The time of the current state (s). */
double plume_dynamics_time(const plume_dynamics *d);
/** Positions of the current state (3 nv, m); the stepper's array, valid until it is destroyed. */
const double *plume_dynamics_positions(const plume_dynamics *d);
/** Velocities of the current state (3 nv, m/s); the stepper's array, valid until it is destroyed. */
const double *plume_dynamics_velocities(const plume_dynamics *d);
/** The constraint multipliers of the last step, *m of them (m may be NULL); the stepper's array. */
const double *plume_dynamics_multipliers(const plume_dynamics *d, plume_index *m);
/** Restores a saved state: time t, positions x and velocities v (3 nv each, copied) and the
 * multipliers lambda (NULL: zero). With the multipliers too, a restarted run repeats the
 * uninterrupted one exactly. PLUME_EINVAL for a non-finite time, position or velocity, named in
 * err (NULL allowed); nothing changes then. */
plume_status plume_dynamics_set_state(plume_dynamics *d, double t, const double *x, const double *v,
                                                const double *lambda, plume_err *err);

/** Lumped vertex masses (nv, kg), for tests and energy checks; the stepper's array. */
const double *plume_dynamics_masses(const plume_dynamics *d);

/** The energy ledger (dynamics_energy.h): the handles' work, the kinetic and potential energies,
 * implicit Euler's and the stateful terms' dissipation, since the first step or the last
 * plume_dynamics_set_state; the stepper's struct. */
const plume_energy_ledger *plume_dynamics_energy(const plume_dynamics *d);

/** The native solver's numeric factorisations since the stepper was created and their wall
 * seconds (pointers may be NULL; zeros for Ipopt or d == NULL), to split a step's time. */
void plume_dynamics_stats(const plume_dynamics *d, int *factorizations, double *factor_seconds);

#ifdef __cplusplus
}
#endif
#endif
