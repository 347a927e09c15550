/** \file
 * plume: a minimisation problem  min_u f(u)  s.t.  g(u) = 0  built from energy terms and
 * constraint sets over the vertices of a mesh. Prescribed (Dirichlet) coordinates are eliminated
 * from the unknowns u: u holds only the free coordinates, in increasing dof order. */
#ifndef PLUME_PROBLEM_H
#define PLUME_PROBLEM_H

#include "../../include/plume/problem.h"

#include "export.h"
#include "status.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Upper triangle of a symmetric n x n matrix in compressed sparse columns (row indices sorted). */
typedef struct {
    plume_index n;   /**< matrix size (the free dofs) */
    plume_index nnz; /**< stored entries of the upper triangle */
    const plume_index *colptr; /**< [n+1] */
    const plume_index *rowind; /**< [nnz] */
} plume_sparsity;

/** Coordinates per vertex (2 or 3), as created. */
int plume_problem_dim(const plume_problem *p);

/** The length scale given to plume_problem_create (m). */
double plume_problem_length_scale(const plume_problem *p);
/** 1 if unknown `dof` (in [0, plume_problem_ndof), unchecked) is prescribed, else 0. */
int plume_problem_is_fixed(const plume_problem *p, plume_index dof);

/** The free part of x <- u (nfree values); u NULL leaves x unchanged. */
void plume_problem_scatter(plume_problem *p, const double *u);

/** Sparsity of the Hessian of the Lagrangian on the free dofs (upper triangle, fixed). */
plume_sparsity plume_problem_hessian_pattern(const plume_problem *p);
/** The part of the Hessian pattern that does not follow the state: the entries of the terms
 * without update, of the constraints and the diagonal (upper triangle, free dofs, rows sorted;
 * owned by the problem, the same arrays from finalize to destroy). Equal to the Hessian pattern
 * without contact terms. A solver orders the factorisation of every contact pattern by it. */
plume_sparsity plume_problem_fixed_pattern(const plume_problem *p);

/** 1 if some term or constraint set has partial_projection (PLUME_HESSIAN_PARTIAL differs from
 * EXACT). */
int plume_problem_has_partial_projection(const plume_problem *p);

/** What plume_problem_hessian assembles. */
enum {
    PLUME_HESSIAN_EXACT = 0,     /**< every block exact */
    PLUME_HESSIAN_PROJECTED = 1, /**< every element block projected to PSD (constraints included) */
    PLUME_HESSIAN_PARTIAL = 2    /**< projected where the term or constraint set has partial_projection,
                                    exact elsewhere */
};

/** values[nnz] <- obj_factor * Hess f(u) + sum_c lambda_c Hess g_c(u) on the fixed pattern;
 * lambda may be NULL (no constraint part). project is a PLUME_HESSIAN_* mode (any other non-zero
 * value: PROJECTED), PROJECTED giving a PSD matrix for projected Newton. */
plume_status plume_problem_hessian(plume_problem *p, const double *u, double obj_factor,
                                             const double *lambda, int project, double *values);

/** g[ncons] <- g(u); *max_rel (may be NULL) <- max_c |g_c| / scale_c. */
plume_status plume_problem_constraints(plume_problem *p, const double *u, double *g, double *max_rel);

/** Jacobian of g on the free dofs as triplets in a fixed order: nnz, row and column arrays
 * (owned by the problem, valid until destroy). */
void plume_problem_jacobian_pattern(const plume_problem *p, plume_index *nnz,
                                              const plume_index **rows, const plume_index **cols);
/** values[nnz] <- the Jacobian of g at u (NULL: use x) in the order of plume_problem_jacobian_pattern;
 * PLUME_EINVAL before finalize. */
plume_status plume_problem_jacobian(plume_problem *p, const double *u, double *values);

/** Generalised forces at the current x on every unknown (plume_problem_ndof: the vertices' dim*nv
 * and the extras after them): grad W + J^T lambda, including the prescribed dofs, where they are
 * the reactions the supports exert (negated). lambda may be NULL. */
plume_status plume_problem_forces(plume_problem *p, const double *lambda, double *force);
/** The same forces and, in *energy (may be NULL), the energy they are the gradient of: one
 * evaluation where plume_problem_objective and plume_problem_forces would take two. */
plume_status plume_problem_energy_forces(plume_problem *p, const double *lambda, double *energy, double *force);

/** max |grad f| over every dof, prescribed ones included (where it is the support reaction), at
 * the last evaluation of a gradient — but at least the round-off floor 1e-6 * length_scale *
 * (largest Hessian diagonal at the state finalize saw): the force scale that residuals are
 * measured against, so that a body at rest is not judged by its round-off gradients. */
double plume_problem_force_scale(const plume_problem *p);

/** Terms whose stencils follow the state (plume_term.update, e.g., contact pairs): recomputes them
 * at the current x and, when any changed, rebuilds the Hessian pattern (*pattern_changed = 1;
 * solvers created before must then be recreated, their symbolic analysis is stale). The force
 * floor of finalize is kept. After finalize, never during a solve. */
plume_status plume_problem_update_terms(plume_problem *p, int *pattern_changed, plume_err *err);

/** Calls every term's rebase (plume_term.rebase) on the problem's x: the start of a step, before
 * its lag. */
plume_status plume_problem_rebase_terms(plume_problem *p);

/** The first term named `name` (plume_term.name) as the problem holds it, or NULL. */
const plume_term *plume_problem_term(const plume_problem *p, const char *name);

/** The ctx of the first term named `name` (plume_term.name), or NULL: what built the term reads
 * its own data through it. */
void *plume_problem_term_ctx(const plume_problem *p, const char *name);

/** The state of the stateful terms (plume_term.commit), every term's state_get in order: its size
 * in doubles, or -1 when a term with commit offers no state_size (the state cannot be saved). */
plume_index plume_problem_state_size(const plume_problem *p);
/** Writes that state to s[0 .. plume_problem_state_size - 1]. */
void plume_problem_state_get(const plume_problem *p, double *s);
/** Sets it from s (as plume_problem_state_get wrote it), each term's kept state too; PLUME_EINVAL
 * names the term that refused its part (terms before it already set). */
plume_status plume_problem_state_set(plume_problem *p, const double *s, plume_err *err);
/** The name of the i-th term (from 0) that offers per-stencil states (plume_term.states), NULL past
 * the last. */
const char *plume_problem_states_term(const plume_problem *p, int i);

/** 1 when a term has a rebase. */
int plume_problem_rebases(const plume_problem *p);

/** Calls every term's lag (plume_term.lag) with x (full vector): the start of a time step. */
plume_status plume_problem_lag_terms(plume_problem *p, const double *x);

/** 1 when a term limits steps (plume_term.max_step): solvers then ask plume_problem_max_step. */
int plume_problem_limits_steps(const plume_problem *p);

/** The largest alpha in [0, 1] such that every term stays defined along u + s du, s in [0, alpha]
 * (u, du on the free dofs; prescribed dofs stay where x holds them). 1 without such terms.
 * Sets x's free part to u. */
plume_status plume_problem_max_step(plume_problem *p, const double *u, const double *du, double *alpha);

/** The same for a motion dx of every dof (3 nv or 2 nv values, prescribed ones included) from
 * the current x: e.g., the handles' move at the start of a time step. */
plume_status plume_problem_max_motion(plume_problem *p, const double *dx, double *alpha);

/** Where a problem's evaluations spent their time since create (CPU seconds of the calling thread,
 * which other processes on the machine do not inflate; benchmarks and profiles). Evaluations
 * inside terms (a contact term's narrow phase) count where they are called. */
typedef struct {
    long objective_calls;           /**< energy, with or without its gradient (objective, residuals, forces) */
    double objective_seconds;       /**< CPU seconds in those calls */
    long hessian_calls;             /**< plume_problem_hessian calls */
    double hessian_eval_seconds;    /**< CPU seconds in the terms' and constraints' element blocks */
    double hessian_scatter_seconds; /**< CPU seconds adding the blocks into the sparse values */
    long constraint_calls;          /**< constraint values and Jacobians */
    double constraint_seconds;      /**< CPU seconds in those calls */
} plume_problem_timing;

/** Copies the counters into *t (zeroes when p is NULL). */
void plume_problem_timing_get(const plume_problem *p, plume_problem_timing *t);

/** Relative stationarity of the Lagrangian f + lambda.g at u, on the free dofs:
 * ||grad f + J^T lambda||_inf / max(force scale, ||grad f||_inf, ||J^T lambda||_inf), with the
 * force scale above (so a loaded body at equilibrium is measured against its reactions);
 * 0 when everything vanishes. */
plume_status plume_problem_kkt_residual(plume_problem *p, const double *u, const double *lambda,
                                                  double *rel_residual);

#ifdef __cplusplus
}
#endif
#endif
