/** \file
 * plume: build a problem of your own, the extension point: a mesh, energy terms and constraints (plume_term, plume_constraint: write your own, or use the membrane, bending and inextensibility terms), a problem that sums them, the solvers, and quasi-static load stepping. */
#ifndef PLUME_PUBLIC_PROBLEM_H
#define PLUME_PUBLIC_PROBLEM_H

#include "base.h"


#ifdef __cplusplus
extern "C" {
#endif

/* ---- the mesh ---- */
/** A triangle mesh. All arrays are owned by the mesh and freed by plume_mesh_destroy.
 * Inputs (set by whoever builds the mesh): nv, nt, dim, X, x, tri, barb_dir, material.
 * Outputs of plume_mesh_build_topology: edges, edge_tri, hinges, boundary. */
typedef struct {
    plume_index nv;        /**< vertices */
    plume_index nt;        /**< triangles */
    int dim;               /**< 2: planar mode (x in R^2), 3: shell mode (x in R^3) */
    double *X;             /**< [2*nv] reference positions, material space */
    double *x;             /**< [dim*nv] current positions */
    plume_index *tri;      /**< [3*nt] vertex ids, counter-clockwise in X */
    double *barb_dir;      /**< [2*nt] unit barb direction d per triangle, material space */
    int *material;         /**< [nt] material id per triangle */

    plume_index ne;        /**< edges (topology output) */
    plume_index *edges;    /**< [2*ne] vertex ids, i < j, sorted by (i, j) */
    plume_index *edge_tri; /**< [2*ne] adjacent triangles; second is -1 on the boundary */
    plume_index nh;        /**< interior hinges = interior edges */
    plume_index *hinges;   /**< [4*nh] (edge v0, edge v1, opposite in tri 0, opposite in tri 1) */
    unsigned char *boundary; /**< [nv] 1 if the vertex lies on the boundary */
} plume_mesh;

/** Allocates a mesh with nv vertices and nt triangles in `dim` dimensions; arrays zeroed,
 * barb_dir set to (1, 0), material to 0. Free with plume_mesh_destroy. PLUME_EINVAL (negative
 * counts, dim not 2 or 3) and PLUME_ENOMEM with a message in err (NULL allowed). */
PLUME_API plume_status plume_mesh_create(plume_index nv, plume_index nt, int dim, plume_mesh **out, plume_err *err);

/** Frees the mesh and every array it holds, sets *m = NULL; NULL-safe. */
PLUME_API void plume_mesh_destroy(plume_mesh **m);

/** Copies X into x (z = 0 in shell mode): the rest state. */
PLUME_API void plume_mesh_reset_current(plume_mesh *m);

/** Checks indices, orientation and non-degenerate areas; builds edges, edge_tri, hinges and
 * boundary flags. Fails with PLUME_EINVAL (message in err) on a bad or non-manifold mesh. */
PLUME_API plume_status plume_mesh_build_topology(plume_mesh *m, plume_err *err);

/** Signed reference area of triangle t. */
PLUME_API double plume_mesh_ref_area(const plume_mesh *m, plume_index t);

/** Total reference area. */
PLUME_API double plume_mesh_total_area(const plume_mesh *m);


/* ---- energy terms and constraints ---- */
/** What the stateful terms of a problem did at an equilibrium (plume_term.commit,
 * plume_problem_commit_terms). */
typedef struct {
    int changed;        /**< the state changed: the stepper solves again at the same load */
    int overshoot;      /**< nothing changed, but a change lands too far past its threshold: the
                           stepper halves its increment */
    long released;      /**< links let go */
    long reengaged;     /**< links caught again */
    double energy_drop; /**< J, >= 0: the terms' energy at x before the commit minus after */
} plume_commit_report;

/** An energy term is a sum over stencils; each stencil couples `arity` vertices. With d = dim and
 * k = arity*d + nextra, the term adds its energy to *energy and its gradient to grad (full vector of
 * plume_problem_ndof entries: dim*nv vertex-major, then any extra unknowns) and, when hblocks is non-NULL, writes one dense k x k row-major
 * Hessian block per stencil at hblocks + s*k*k (overwritten, not added). When `project` is
 * non-zero each block is projected to the nearest positive semidefinite matrix.
 * Any of energy/grad/hblocks may be NULL. `ctx` belongs to the term; `destroy` frees it.
 * Fill it with designated initialisers, size first: `plume_term t = {.size = sizeof(plume_term),
 * .name = "springs", ...}`; members left out are 0, the defaults. */
typedef struct {
    size_t size;                /**< sizeof(plume_term) as the caller compiled it (a struct that grows:
                                   the library reads only that much, docs/library.md); 0 is refused */
    const char *name;           /**< name in error messages ("membrane", ...); a string that outlives the term */
    int arity;                  /**< vertices per stencil */
    plume_index nstencil;       /**< number of stencils */
    const plume_index *stencil; /**< [nstencil*arity], owned by ctx */
    /** Adds the energy and gradient and writes the Hessian blocks at x (full vector), as
     * above; a non-zero status aborts the evaluation (e.g., PLUME_EINVAL for an inverted element). */
    plume_status (*eval)(void *ctx, int dim, const double *x, double *energy, double *grad,
                         double *hblocks, int project);
    void (*destroy)(void *ctx); /**< frees ctx; NULL when there is nothing to free */
    void *ctx;                  /**< the term's data, passed to every callback */
    /** Optional (NULL for fixed stencils): terms whose stencils follow the state, such as contact
     * pairs. Recomputes the stencils at positions x (full vector), returns the new array
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
     * densities per triangle, docs/paraview-output.md). */
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
    /** Unknowns of a stencil beyond its vertices' coordinates (0, the default: none): scalars the
     * problem holds after the vertices (plume_problem_add_unknowns), such as the edge angles of
     * midedge bending. A stencil's block is then k x k with k = arity*dim + nextra, the vertex
     * coordinates first, its extras last; eval, hess_range and energies read them in x and write
     * their gradient in grad (full vectors of plume_problem_ndof entries). Not with update or
     * padded. */
    int nextra;
    /** [nstencil*nextra] the extras of each stencil as indices of the full vector, each in
     * [dim*nv, plume_problem_ndof); owned by ctx. */
    const plume_index *extra;
    /** Optional (NULL: nothing to re-base): a term whose extras are coordinates in frames it keeps
     * (the edge angles of midedge bending) re-expresses them at a step's start: it may change its
     * frames and rewrite its own extras in x (full vector), its energy at x unchanged. Called by
     * the steppers (statics, dynamics) between solves, never inside one. */
    plume_status (*rebase)(void *ctx, int dim, double *x);
    /** Optional (NULL: a term without a state of its own): links that let go and catch again
     * between solves, such as barbule hooks (docs/unzipping.md). Called by
     * plume_problem_commit_terms at an equilibrium x (full vector), never inside a solve: the
     * term updates its state there and reports what it did in *r (zeroed before the call). When
     * `may_cut` is non-zero and a change would land too far past its threshold, the term may
     * change nothing and set r->overshoot instead: the stepper then halves its load increment. */
    plume_status (*commit)(void *ctx, int dim, const double *x, int may_cut, plume_commit_report *r);
    /** Optional, with commit: keeps the term's state (save non-zero) or returns to the kept one
     * (save 0), so that a load increment that fails after a commit is undone whole. */
    plume_status (*keep)(void *ctx, int save);
    /** Optional (NULL: not offered): each stencil's state, written to s[0 .. nstencil-1] (hooks: 1
     * engaged, 0 let go). Output uses it (plume_fields_add_links). */
    plume_status (*states)(void *ctx, int *s);
    /** Optional, with commit (NULL: the state cannot be saved, and a traction checkpoint refuses
     * the problem): how many doubles hold everything commit changes. */
    plume_index (*state_size)(void *ctx);
    /** With state_size: writes that state to s[0 .. state_size - 1]. */
    void (*state_get)(void *ctx, double *s);
    /** With state_size: sets the state from s (as state_get wrote it) and keeps it (as keep with
     * save non-zero); PLUME_EINVAL for values state_get cannot have written, nothing changed then.
     * A restart that sets it back repeats a run bit for bit. */
    plume_status (*state_set)(void *ctx, const double *s);
} plume_term;

/** A set of m equality constraints g_c(x) = 0; constraint c couples the `arity` vertices of
 * stencil c. eval writes g (m values) and, if jac is non-NULL, the dense gradient of each
 * constraint with respect to its stencil's k = arity*dim coordinates at jac + c*k.
 * hess writes, per constraint, the k x k block of lambda_c * Hessian(g_c) at hblocks + c*k*k;
 * with project != 0 a block is projected to PSD. `scale` (m values, owned by ctx) gives the
 * natural size of each g_c, so |g_c| / scale_c is the relative violation reported by solvers.
 * Filled as plume_term is, size first: `{.size = sizeof(plume_constraint), ...}`. */
typedef struct {
    size_t size;                /**< sizeof(plume_constraint) as the caller compiled it; 0 is refused */
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


/* ---- the problem ---- */
/** Opaque problem handle: terms, constraints, prescribed dofs, the state x and every workspace
 * (plume_problem_create, freed by plume_problem_destroy). */
typedef struct plume_problem plume_problem;

/** A problem over nv vertices with dim coordinates each (dof = dim*vertex + axis).
 * length_scale: a typical size of the body (m), used by solvers for step-size tolerances.
 * Free with plume_problem_destroy. PLUME_EINVAL (nv <= 0, dim not 2 or 3, length_scale not
 * finite and > 0) and PLUME_ENOMEM with a message in err (NULL allowed). */
PLUME_API plume_status plume_problem_create(plume_index nv, int dim, double length_scale, plume_problem **out,
                                            plume_err *err);

/** Frees the problem, calling every term's and constraint set's destroy; sets *p = NULL; NULL-safe. */
PLUME_API void plume_problem_destroy(plume_problem **p);

/** Adds a term. The problem takes ownership of its ctx (freed with `destroy`) on success and on
 * failure. Only before plume_problem_finalize (PLUME_EINVAL after it, or without eval, arity or
 * stencil; the message in err says which). */
PLUME_API plume_status plume_problem_add_term(plume_problem *p, const plume_term *t, plume_err *err);

/** The per-stencil states (plume_term.states; barbule hooks and split lines: 1 engaged, 0 let go)
 * of the first term named `name`, written to states[0 .. *n - 1]; states NULL: only *n, its
 * stencil count. A program records the links' states this way between steps (apps/traction's
 * "hooks" table). PLUME_EINVAL naming the term when the problem has none of that name or it
 * offers no states. */
PLUME_API plume_status plume_problem_term_states(const plume_problem *p, const char *name, int *states, plume_index *n,
                                                 plume_err *err);

/** Adds a constraint set, with the same ownership rule as plume_problem_add_term: the problem
 * owns its ctx on success and on failure. PLUME_EINVAL after finalize, without eval or hess, or
 * with m > 0 and no stencil or scale; the message in err says which. */
PLUME_API plume_status plume_problem_add_constraint(plume_problem *p, const plume_constraint *c, plume_err *err);

/** Appends n scalar unknowns after the vertices' coordinates (edge angles, ...; terms reach them
 * through plume_term.extra) and sets *first to the index of the first in the full vector: the
 * first call's is dim*nv. Before finalize; they start at 0 (set them in plume_problem_x, which
 * this call moves: take the pointer again afterwards). PLUME_EINVAL after finalize or for n <= 0,
 * PLUME_ENOMEM, with a message in err. */
PLUME_API plume_status plume_problem_add_unknowns(plume_problem *p, plume_index n, plume_index *first, plume_err *err);

/** Length of the full vector: dim*nv coordinates, then the unknowns plume_problem_add_unknowns
 * added. */
PLUME_API plume_index plume_problem_ndof(const plume_problem *p);

/** Marks a coordinate as prescribed (its value is whatever plume_problem_x holds). Before finalize;
 * PLUME_EINVAL after it or for a dof out of range, naming the vertex and component in err. */
PLUME_API plume_status plume_problem_fix_dof(plume_problem *p, plume_index dof, plume_err *err);

/** Calls every term's commit (plume_term.commit) at the problem's x, an equilibrium, and sums
 * their reports into *r (zeroed first; changed and overshoot are either's). After finalize,
 * never during a solve. Without stateful terms *r stays zero. */
PLUME_API plume_status plume_problem_commit_terms(plume_problem *p, int may_cut, plume_commit_report *r,
                                                  plume_err *err);

/** Calls every stateful term's keep (plume_term.keep): save non-zero keeps the current state, 0
 * returns to the kept one. */
PLUME_API plume_status plume_problem_keep_terms(plume_problem *p, int save, plume_err *err);

/** 1 when a term has a commit (the problem has a state beyond its positions). */
PLUME_API int plume_problem_commits(const plume_problem *p);

/** Builds the free-dof map, the Hessian sparsity (terms and constraints) and the Jacobian
 * sparsity; drops constraints whose stencil is entirely prescribed. Allocates every workspace
 * the evaluations need, so nothing is allocated afterwards. */
PLUME_API plume_status plume_problem_finalize(plume_problem *p, plume_err *err);

/** Number of vertices, as created. */
PLUME_API plume_index plume_problem_nvert(const plume_problem *p);

/** Number of free (unknown) coordinates, the length of u; set by finalize. */
PLUME_API plume_index plume_problem_nfree(const plume_problem *p);

/** Number of kept constraints (rows of g), after finalize. */
PLUME_API plume_index plume_problem_ncons(const plume_problem *p);

/** Full vector (plume_problem_ndof: dim*nv coordinates, then any added unknowns): set prescribed
 * values and the initial guess here. */
PLUME_API double *plume_problem_x(plume_problem *p);
/** u (nfree values) <- the free part of x. */
PLUME_API void plume_problem_gather(const plume_problem *p, double *u);

/** f(u) and, if grad != NULL, its gradient (nfree). Sets x's free part to u (u may be NULL: use x). */
PLUME_API plume_status plume_problem_objective(plume_problem *p, const double *u, double *f, double *grad);


/* ---- the membrane term ---- */
/** Orthotropic membrane moduli in the barb frame (x along the barbs), 3D moduli in Pa: what
 * homogenisation gives, a fit finds and a membrane material holds. */
typedef struct {
    double E_xx;  /**< Young's modulus along the barbs (Pa) */
    double E_yy;  /**< Young's modulus across the barbs (Pa) */
    double nu_xy; /**< Poisson's ratio: contraction across the barbs under a pull along them */
    double G_xy;  /**< in-plane shear modulus (Pa) */
} plume_ortho;

/** One membrane material: the moduli (Pa) in the barb frame, thickness h (m) and the compression
 * coefficient kappa (Pa; 0 disables the term). */
typedef struct {
    plume_ortho moduli; /**< E_xx, E_yy, nu_xy, G_xy */
    double h;     /**< thickness (m) */
    double kappa; /**< compression coefficient (Pa); 0 disables the compression term */
    int log_barrier; /**< 0: the cubic compression term (default); 1: a log barrier
                        kappa/12 (J - 1 - ln J) for J < 1 in its place (supplementary §8: it blows
                        up as J -> 0, and the paper found the solver could not converge with it) */
} plume_membrane_material;

/** Creates a term over every triangle of `mesh`: triangle t uses mats[mesh->material[t]] (ids
 * must be in [0, nmat), else PLUME_EINVAL) and mesh->barb_dir[t]. Reference geometry is precomputed (copied), so the
 * mesh may be freed afterwards. The term's stencils are the triangles (arity 3). */
PLUME_API plume_status plume_membrane_term_create(const plume_mesh *mesh, int dim,
                                                  const plume_membrane_material *mats, int nmat,
                                                  plume_term *out, plume_err *err);

/** As plume_membrane_term_create, with material i's plane-stress tensor tensors[9 i .. 9 i + 8]
 * (Pa, row-major, Voigt order E11, E22, 2E12 in the barb frame, symmetric positive definite) in
 * place of its moduli' orthotropic one: C13 and C23 couple the normal strains and the shear, as in
 * the cell of inclined barbules (plume_homog_result.C; docs/monoclinic-vane.md). The materials'
 * h, kappa and log_barrier still apply, and their moduli are still checked. tensors NULL: the
 * moduli's tensors. PLUME_EINVAL naming the material for a tensor that is not finite, symmetric
 * or positive definite. */
PLUME_API plume_status plume_membrane_term_create_tensor(const plume_mesh *mesh, int dim,
                                                         const plume_membrane_material *mats, const double *tensors,
                                                         int nmat, plume_term *out, plume_err *err);


/* ---- the inextensibility constraint ---- */
/** A constraint set over `n` edges (pairs of vertex ids, copied) whose rest lengths are taken
 * from the reference positions X (2D, material space). Scale of constraint c is L_c^2, so the
 * relative violation |g|/L^2 is about twice the relative change of length. */
PLUME_API plume_status plume_edge_length_create(const plume_index *edges, plume_index n, const double *X,
                                                plume_index nv, plume_constraint *out, plume_err *err);


/* ---- the bending term ---- */
/** Bending stiffness of one material (N m): for an isotropic plate D_long = D_trans =
 * E t^3 / (12 (1 - nu^2)), D_coupling = nu D, D_twist = (1 - nu) D / 2.
 * The orthotropic plate energy density, k11 along d, k22 across, k12 the twist in the barb frame:
 *     1/2 (D_long k11^2 + D_trans k22^2 + 2 D_coupling k11 k22 + 4 D_twist k12^2).
 * D_twist and D_coupling are read only by the shape-operator term (docs/theory-bending.md); the
 * hinge term below ignores them (a hinge sees one normal curvature, not the twist). They come
 * after D_long and D_trans so that `{D_long, D_trans}` initialisers keep meaning what they did,
 * with both new fields zero (gcc -Wextra flags such partial initialisers: spell the zeros out or
 * use designated initialisers). D_twist == 0 means "derive it by Huber's approximation for
 * orthotropic plates", D_coupling + 2 D_twist = sqrt(D_long D_trans), i.e.
 * D_twist = (sqrt(D_long D_trans) - D_coupling) / 2 (isotropic: D_coupling + 2 D_twist = D).
 * All four must be finite and >= 0, and D_coupling^2 <= D_long D_trans (a positive semidefinite
 * plate). */
typedef struct {
    double D_long;     /**< curvature along the barb direction d (bending the barbs) */
    double D_trans;    /**< curvature across the barbs */
    double D_twist;    /**< D_66, twist; 0: (sqrt(D_long D_trans) - D_coupling) / 2 (Huber) */
    double D_coupling; /**< D_12, Poisson-type coupling of k11 and k22 */
} plume_bending_material;

/** A term over every interior edge (hinge) of a shell-mode mesh (dim 3, topology built): stencil
 * (edge v0, edge v1, opposite 0, opposite 1) as in mesh->hinges. Each hinge uses the materials and
 * barb directions of its two triangles (mats[mesh->material[t]], averaged over the two). Exact
 * gradient and Hessian; with project != 0 Hessian blocks are projected to PSD. Rest dihedral
 * angles are taken from mesh->X (flat: 0) unless rest_x (3*nv, may be NULL) gives a curved rest
 * shape. Errors (PLUME_EINVAL, message): dim != 3, negative/NaN stiffness, material id out of
 * range, a degenerate triangle. D_twist and D_coupling are ignored (not validated either). */
PLUME_API plume_status plume_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                                 const double *rest_x, plume_term *out, plume_err *err);


/* ---- solver options ---- */
/** How the native solver globalises a constrained step. */
typedef enum {
    PLUME_LS_FILTER = 0, /**< Ipopt's filter line search (Waechter & Biegler 2006) with a second-order
                            correction; default */
    PLUME_LS_MERIT = 1   /**< Armijo on the l1 merit f + mu |g|_1 with a second-order correction */
} plume_line_search;

/** How the native solver globalises its Newton steps (plume_solver_opts.curved_search and
 * .trust_region in one name, for scenes and apps). */
typedef enum {
    PLUME_GLOBAL_CURVED_LINE_SEARCH = 0, /**< line search along the geodesic-acceleration curve; default */
    PLUME_GLOBAL_LINE_SEARCH = 1,        /**< line search along the straight Newton step */
    PLUME_GLOBAL_TRUST_REGION = 2        /**< adaptive-regularisation trust region */
} plume_globalization;

/** "curved_line_search" | "line_search" | "trust_region"; PLUME_EINVAL otherwise */
PLUME_API plume_status plume_globalization_parse(const char *s, plume_globalization *out);

/** The name plume_globalization_parse accepts for g (static string); "unknown" out of range. */
PLUME_API const char *plume_globalization_name(plume_globalization g);

/** How the native solver factorises a constrained Newton step. */
typedef enum {
    PLUME_KKT_LDL = 0,      /**< quasi-definite KKT matrix, CHOLMOD simplicial LDL^T */
    PLUME_KKT_ELIMINATE = 1 /**< multipliers eliminated: SPD H + J^T J / dc, CHOLMOD supernodal LL^T */
} plume_kkt_mode;

/** Options of every solver backend (the native ones read all of them, Ipopt the tolerances and the
 * cap); fill with plume_solver_opts_default, then change fields. */
typedef struct {
    size_t size;           /**< sizeof the caller's struct, set by plume_solver_opts_default: the
                              library reads only that much (a struct that grows, docs/library.md) */
    int max_iter;          /**< iteration cap; default 100 */
    double tol_kkt;        /**< relative KKT residual (see plume_problem_kkt_residual); default 1e-9 */
    double tol_violation;  /**< max relative constraint violation; default 1e-10 */
    double tol_step;       /**< also converged when max|du| <= tol_step * length_scale and the
                              violation is met; default 1e-13 */
    double max_step;       /**< newton: a direction longer than max_step * length_scale is taken
                              as a sign of a singular Hessian and regularised; default 100 */
    int inertia_corrections; /**< newton, exact-Hessian path: Ipopt's inertia correction (0: off, the
                              projected Hessian whenever the exact one is not positive definite);
                              default 1. A shift that made the matrix positive definite is reused,
                              divided by 3, at the next failure, and grown 8x until it works */
    double inertia_max_shift; /**< the largest shift tried, relative to the largest Hessian diagonal,
                              before falling back to the projected Hessian; default 1 */
    plume_kkt_mode kkt;    /**< newton with constraints; default PLUME_KKT_ELIMINATE (the same
                              iterates as LDL^T, faster factorisations:
                              docs/theory-constraints.md) */
    plume_line_search line_search; /**< newton with constraints; default PLUME_LS_FILTER */
    int reuse_factorization; /**< newton: chord steps (the last factorisation of this solve) in
                                the end game, where the last two Newton steps predict a contraction
                                below 1e-2 a step; each must cut the KKT residual by reuse_rate
                                (else it is undone and the iteration refactorises), and they stop
                                once their rate predicts more than 4 to converge; default 1
                                (docs/theory-constraints.md) */
    double reuse_rate;     /**< the factor by which a chord step must cut the KKT residual, in (0, 1);
                              default 0.25 */
    int kkt_refine;        /**< newton, eliminated KKT: factorise with a 1e3 times larger multiplier
                              regularisation and refine the solution iteratively against the
                              requested one (a Cholesky factor of H + J^T J / dc, whose constraint
                              part is 1e8 times the Hessian's, loses 8 digits of H), to a linear
                              residual of min(1e-2, KKT residual) times the nonlinear one (inexact
                              Newton); default 1 */
    int verbose;           /**< print one line per iteration on stderr; default 0 */
    int partial_projection; /**< newton, exact-Hessian path: when the exact Hessian is not positive
                              definite, project the terms whose projection is a cheap closed form
                              (plume_term.partial_projection: shape bending, edge-length
                              constraints) before shifting the whole matrix; default 1 */
    int curved_search;     /**< newton without constraints: a full step the line search refuses is
                              retried along u + alpha du + alpha^2/2 a, a the geodesic acceleration
                              (docs/solver-nonconvexity.md); default 1 */
    int trust_region;      /**< newton: globalise by an adaptive-regularisation trust region (a
                              shift sigma I added to the factorised matrix, grown when the step's
                              actual decrease of the l1 merit falls short of the quadratic model's
                              and shrunk when it matches) instead of the line search; default 0 */
    int exact_hessian_first; /**< newton without constraints: factorise the exact Hessian first and
                                fall back to the PSD-projected one if it is not positive definite;
                                default 1 */
    int stall_iterations;  /**< newton: stop (PLUME_REASON_STALLED) after this many iterations in a
                              row that cut neither the KKT residual nor the constraint violation to
                              half of its best in this solve; 0 (default): only max_iter stops */
} plume_solver_opts;

/** Fills o (size bytes) with the defaults each field names and sets o->size; call it through the
 * macro plume_solver_opts_default(o), which passes sizeof *o. */
PLUME_API void plume_solver_opts_default_sized(plume_solver_opts *o, size_t size);
/** Fills *o with the defaults (plume_solver_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_solver_opts_default(o) plume_solver_opts_default_sized((o), sizeof(plume_solver_opts))


/* ---- the solvers ---- */
/** The solver backends (names "newton", "ipopt", "linearized"). */
typedef enum {
    PLUME_SOLVER_NEWTON = 0,    /**< the native projected Newton / SQP (docs/theory-constraints.md) */
    PLUME_SOLVER_IPOPT = 1,     /**< Ipopt, interior point with exact Hessians */
    PLUME_SOLVER_LINEARIZED = 2 /**< one full Newton step of the native solver, no convergence sought */
} plume_solver_kind;

/** Parses "newton" | "ipopt" | "linearized"; PLUME_EINVAL otherwise. */
PLUME_API plume_status plume_solver_kind_parse(const char *s, plume_solver_kind *out);

/** The name plume_solver_kind_parse accepts for k (static string); "unknown" out of range. */
PLUME_API const char *plume_solver_kind_name(plume_solver_kind k);

/** Opaque solver: one backend over one finalised problem (plume_solver_create, freed by
 * plume_solver_destroy). */
typedef struct plume_solver plume_solver;

/** Creates a solver for a finalised problem (kept by reference, not owned) with the options o
 * (copied; NULL: the defaults). Symbolic analysis of the sparse systems happens here, once.
 * PLUME_EINVAL for a problem not finalised or options out of range (or not filled by
 * plume_solver_opts_default), with a message naming them in err (NULL allowed). */
PLUME_API plume_status plume_solver_create(plume_solver_kind kind, plume_problem *p,
                                           const plume_solver_opts *o, plume_solver **out, plume_err *err);

/** Frees the solver (not the problem); sets *s = NULL; NULL-safe. */
PLUME_API void plume_solver_destroy(plume_solver **s);

/** Solves from u (nfree, in: start, out: result) and lambda (ncons, in: guess, out: multipliers
 * of the Lagrangian f + lambda.g). The problem's x holds the result on return. Returns an error
 * status only for errors (bad input, memory, dependency); convergence is in rep->reason. */
PLUME_API plume_status plume_solver_solve(plume_solver *s, double *u, double *lambda, plume_solve_report *rep);


/* ---- load stepping ---- */
/** Where each solve of a load increment starts. */
typedef enum {
    PLUME_PREDICT_NONE = 0,  /**< the last equilibrium */
    PLUME_PREDICT_SECANT = 1, /**< the last equilibrium plus the secant through the last two, scaled to the
                                increment (first-order continuation; from the second increment on). Its
                                error is O(increment^2) where the last equilibrium's is O(increment): on
                                the shell benchmarks it takes 35-56 % fewer Newton iterations to the same
                                equilibria (docs/benchmarks.md). A solve that fails from it is retried from
                                the last equilibrium before the increment is cut */
    PLUME_PREDICT_TANGENT = 2, /**< the tangent (consistent) predictor on every increment: one linear solve
                                with the tangent at the last equilibrium for the response to the load
                                increment and the prescribed dofs' move (plume_solver_predict; one more
                                factorisation an increment; native solvers only). Retried from the last
                                equilibrium as the secant is */
    PLUME_PREDICT_SECANT_TANGENT = 3 /**< the secant where it is available, the tangent where it is not
                                (the first increment) */
} plume_predictor;

/** Options of the load-stepping driver (plume_statics_opts_default). */
typedef struct {
    size_t size;          /**< sizeof the caller's struct, set by plume_statics_opts_default */
    int steps;            /**< nominal load steps; default 10 */
    int max_cuts;         /**< an increment is halved at most this often below the nominal one; default 10 */
    plume_predictor predictor; /**< default PLUME_PREDICT_TANGENT (docs/solver-nonconvexity.md); with
                                  Ipopt, which has no tangent solve, the tangent ones act as the secant */
    plume_solver_kind solver;      /**< the backend of every solve; default newton */
    const plume_solver_opts *solver_opts; /**< its options (read at plume_statics_create); NULL
                                             (default): plume_solver_opts_default's */
} plume_statics_opts;

/** Fills o (size bytes) with the defaults each field names and sets o->size; call it through the
 * macro plume_statics_opts_default(o). */
PLUME_API void plume_statics_opts_default_sized(plume_statics_opts *o, size_t size);
/** Fills *o with the defaults (plume_statics_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_statics_opts_default(o) plume_statics_opts_default_sized((o), sizeof(plume_statics_opts))

/** Sets the loads (and any load-dependent prescribed positions in plume_problem_x) for a load
 * factor in [0, 1]. */
typedef void (*plume_load_scaler)(void *user, double factor);

/** What one nominal step took. */
typedef struct {
    int step;              /**< 1-based nominal step */
    double factor;         /**< load factor reached (step / steps when converged) */
    int substeps;          /**< converged solves taken (1 when nothing was cut) */
    int cuts;              /**< times an increment was halved */
    int iterations;        /**< solver iterations, failed attempts included */
    int factorizations;    /**< numeric factorisations (native solvers), failed attempts included */
    int backtracks;        /**< newton's line-search rejections (plume_solve_report) */
    int shifts;            /**< newton's inertia shifts (plume_solve_report) */
    int predictions;       /**< tangent predictor solves (each one factorisation, counted in
                              factorizations, not in iterations) */
    int predictor_retries; /**< solves that failed from the predictor and were retried from the last
                              equilibrium */
    double max_violation;  /**< over the converged sub-steps */
    int converged;         /**< the step reached its factor */
    plume_reason reason;   /**< why the first failed attempt stopped (CONVERGED when none failed) */
    double seconds;        /**< wall time of the step's solves */
} plume_load_step_report;

/** Opaque load-stepping driver over one problem: the load factor, the solver and the saved
 * states (plume_statics_create, freed by plume_statics_destroy). */
typedef struct plume_statics plume_statics;

/** Takes a finalised problem whose x holds the unloaded state, and the scaler of its loads with
 * its data `user`; free_user (may be NULL) frees user when the driver is destroyed, or at once
 * if creation fails. The problem stays the caller's and must outlive the driver. */
PLUME_API plume_status plume_statics_create(plume_problem *p, const plume_statics_opts *o, plume_load_scaler scale,
                                            void *user, void (*free_user)(void *), plume_statics **out, plume_err *err);

/** Frees the driver and its solver and calls free_user(user); not the problem. Sets *s = NULL;
 * NULL-safe. */
PLUME_API void plume_statics_destroy(plume_statics **s);

/** Advances to the next nominal factor. Not converging at the smallest increment is reported
 * (state left at the last equilibrium), not an error; so is calling it after the last step
 * (rep->converged = 0, reason CONVERGED, nothing done). */
PLUME_API plume_status plume_statics_step(plume_statics *s, plume_load_step_report *rep);

/** The load factor of the last equilibrium (0 before the first step). */
PLUME_API double plume_statics_factor(const plume_statics *s);

/** The predictor's name, "none", "secant", "tangent" or "secant_tangent" (static string; "unknown"
 * out of range). */
PLUME_API const char *plume_predictor_name(plume_predictor k);

/** The predictor named "none", "secant", "tangent" or "secant_tangent" into *k; PLUME_EINVAL (no
 * message) for another name. */
PLUME_API plume_status plume_predictor_parse(const char *name, plume_predictor *k);


#ifdef __cplusplus
}
#endif
#endif
