/** \file
 * plume: the energy-term and constraint interfaces every model plugs into a problem. */
#ifndef PLUME_TERM_H
#define PLUME_TERM_H

#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** An energy term is a sum over stencils; each stencil couples `arity` vertices. With d = dim and
 * k = arity*d, the term adds its energy to *energy and its gradient to grad (full vector of
 * dim*nv entries, vertex-major) and, when hblocks is non-NULL, writes one dense k x k row-major
 * Hessian block per stencil at hblocks + s*k*k (overwritten, not added). When `project` is
 * non-zero each block is projected to the nearest positive semidefinite matrix.
 * Any of energy/grad/hblocks may be NULL. `ctx` belongs to the term; `destroy` frees it. */
typedef struct {
    const char *name;           /**< name in error messages ("membrane", ...); a string that outlives the term */
    int arity;                  /**< vertices per stencil */
    plume_index nstencil;       /**< number of stencils */
    const plume_index *stencil; /**< [nstencil*arity], owned by ctx */
    /** Adds the energy and gradient and writes the Hessian blocks at x (full vector, dim*nv), as
     * above; a non-zero status aborts the evaluation (e.g., PLUME_EINVAL for an inverted element). */
    plume_status (*eval)(void *ctx, int dim, const double *x, double *energy, double *grad,
                         double *hblocks, int project);
    void (*destroy)(void *ctx); /**< frees ctx; NULL when there is nothing to free */
    void *ctx;                  /**< the term's data, passed to every callback */
    /** Optional (NULL for fixed stencils): terms whose stencils follow the state, such as contact
     * pairs. Recomputes the stencils at positions x (full vector, dim*nv), returns the new array
     * (owned by ctx, valid until the next update or destroy) and count, and *changed = 1 when the
     * set differs from the last one (the problem then rebuilds its Hessian pattern). Called by
     * plume_problem_update_terms, never inside a solve. */
    plume_status (*update)(void *ctx, int dim, const double *x, const plume_index **stencil, plume_index *nstencil,
                           int *changed);
    /** Optional (NULL: any step is allowed): the largest alpha in [0, 1] such that the term stays
     * defined (and, for contact, nothing crosses) along the whole segment x + s dx, 0 <= s <= alpha
     * (continuous collision detection). x and dx are full vectors; dx is 0 on prescribed dofs. */
    plume_status (*max_step)(void *ctx, int dim, const double *x, const double *dx, double *alpha);
    /** Optional (NULL: nothing to lag): terms that keep what they had at the start of a time step
     * (lagged friction: normal forces, tangent frames, the start positions). Called with the
     * step's start x (full vector) by plume_problem_lag_terms, before the step's stencil update. */
    plume_status (*lag)(void *ctx, int dim, const double *x);
    /** Optional (NULL: not offered): the energy of each stencil at x (full vector), written to
     * e[0 .. nstencil-1]; their sum is the energy eval adds. Output fields use it (energy
     * densities per triangle, macro/fields.h). */
    plume_status (*energies)(void *ctx, int dim, const double *x, double *e);
    /** 1: this term's projected blocks are a cheap closed form that keeps the term's stiffness and
     * drops only a curvature part (shape-operator bending: the Gauss-Newton block), so the native
     * Newton projects this term first, before shifting the whole matrix, when its exact Hessian is
     * not positive definite (PLUME_HESSIAN_PARTIAL). 0 (default): exact until everything is
     * projected. A stiff membrane in compression must stay exact: projecting it slows Newton to a
     * crawl. */
    int partial_projection;
    /** Optional (NULL: eval writes every block at once): writes the Hessian blocks of stencils
     * first .. first + count - 1 at x (full vector) to hblocks (stencil first's block at hblocks,
     * k x k each), exactly as eval would. The problem then assembles the term a few stencils at a
     * time, scattering the blocks while they are still in the cache instead of through a workspace
     * of every block (tens of MB for a large bending term). */
    plume_status (*hess_range)(void *ctx, int dim, const double *x, plume_index first, plume_index count,
                               double *hblocks, int project);
    /** 1: a stencil with fewer vertices than `arity` repeats its first vertex in its last places,
     * and the blocks' rows and columns of those places are zero; the problem does not read them.
     * 0 (default): every place of a stencil is a vertex of it. */
    int padded;
} plume_term;

/** A set of m equality constraints g_c(x) = 0; constraint c couples the `arity` vertices of
 * stencil c. eval writes g (m values) and, if jac is non-NULL, the dense gradient of each
 * constraint with respect to its stencil's k = arity*dim coordinates at jac + c*k.
 * hess writes, per constraint, the k x k block of lambda_c * Hessian(g_c) at hblocks + c*k*k;
 * with project != 0 a block is projected to PSD. `scale` (m values, owned by ctx) gives the
 * natural size of each g_c, so |g_c| / scale_c is the relative violation reported by solvers. */
typedef struct {
    const char *name;           /**< name in error messages ("edge length", ...); a string that outlives the set */
    int arity;                  /**< vertices per constraint */
    plume_index m;              /**< number of constraints */
    const plume_index *stencil; /**< [m*arity], owned by ctx */
    const double *scale;        /**< [m], owned by ctx */
    /** Writes g (m values) and, if jac is non-NULL, the m dense stencil gradients at x (full vector). */
    plume_status (*eval)(void *ctx, int dim, const double *x, double *g, double *jac);
    /** Writes the m blocks lambda_c Hess g_c at x, PSD-projected when project != 0. */
    plume_status (*hess)(void *ctx, int dim, const double *x, const double *lambda,
                         double *hblocks, int project);
    void (*destroy)(void *ctx); /**< frees ctx; NULL when there is nothing to free */
    void *ctx;                  /**< the constraint set's data, passed to every callback */
    int partial_projection; /**< as plume_term's (edge lengths: lambda clamped at 0 per edge) */
} plume_constraint;

#ifdef __cplusplus
}
#endif
#endif
