/** \file
 * plume: run a traction test of a vane sample: the macro model (the orthotropic vane with inextensible barbs), the resolved microstructure, and the bending tests of the plate and shell. */
#ifndef PLUME_PUBLIC_TRACTION_H
#define PLUME_PUBLIC_TRACTION_H

#include "problem.h"
#include "curves.h"
#include "homogenize.h"


#ifdef __cplusplus
extern "C" {
#endif

/* ---- the traction test ---- */
/** Options of the traction test (plume_traction_opts_default; lx, ly and h have no default). */
typedef struct {
    size_t size;         /**< sizeof the caller's struct, set by plume_traction_opts_default */
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
    const plume_solver_opts *solver_opts; /**< its options; NULL (default): plume_solver_opts_default's */
    int progress;        /**< progress line on stderr: 0 off, 1 when stderr is a terminal, 2 always */
    /** Optional (NULL: none): called with each state of the curve, the rest state as step 0 and
     * then every nominal step that converged (strain, positions x: dim * nv); a status other than
     * PLUME_OK stops the run with that status (output written by it, e.g., --vtk). */
    plume_status (*on_step)(void *user, int step, double strain, const double *x);
    void *on_step_user;  /**< passed to on_step as `user` */
    int max_settles;     /**< problems with stateful terms (plume_term.commit: barbule hooks,
                            docs/unzipping.md): at every equilibrium of the loading steps the terms
                            commit; a change is solved again at the same grips, up to this many
                            times (>= 0; default 100; a state still changing after them fails the
                            step); an overshoot undoes and halves the increment as a failed solve
                            does (at the smallest increment the change is made anyway) */
    const double *path;  /**< Optional (NULL: one leg from 0 to strain_max): the strains the grips
                            go to in turn (npath values, each finite and > -1, none equal to the one
                            before; the first leg starts at 0): load, unload, reload. Each leg takes
                            `steps` steps, so the curve has 1 + npath * steps points; strain_max is
                            then not used */
    int npath;           /**< entries of path, 1 to 1000 */
    double peel;         /**< in [0, 1], default 0: the top grip turns as it pulls, a point at x moving
                            by delta (1 - peel + peel x / lx); 1 holds its x = 0 end and pulls the
                            x = lx end by delta (a zipper: the barbs' separation test). The reaction
                            is then the force at the pulled end that does the grip's work */
    double top_grip_free; /**< in [0, 1), default 0: the share of the top edge, from x = 0, that the
                            top grip leaves free; the grip holds x >= top_grip_free lx only (a barb
                            pulled by its end, free to bend: the separation test) */
    const char *checkpoint; /**< Optional (NULL: none): an HDF5 file the run's whole state is written to
                            after every nominal step, replaced atomically (an interrupted write leaves
                            the last one whole): the positions, multipliers, predictor history, the
                            stateful terms' state (plume_term.state_size; a term with commit and
                            without it is refused), the solver's memory, the curve and the sums so
                            far, and each curve point's per-stencil states (hooks' and split lines',
                            plume_traction_checkpoint_states). docs/hdf5-layout.md */
    const char *restart;    /**< Optional (NULL: from rest): a checkpoint of a run with the same sample,
                            schedule, solver and problem sizes (compared; what differs is named, the
                            message beginning "restart: "). The run continues after its step: the
                            curve, counts, energies and states come out bit for bit as the run that
                            never stopped (times excepted). on_step is called for the new steps only */
    int stop_after;         /**< > 0: the run ends after nominal step stop_after of its schedule (a
                            restarted run's steps counted from the start), its checkpoint written:
                            the curve then has stop_after + 1 points, converged stays 1. 0: none */
} plume_traction_opts;

/** Fills o (size bytes) with the defaults each field names (progress 1, on_step NULL; lx, ly, h
 * left 0) and sets o->size; call it through the macro plume_traction_opts_default(o). */
PLUME_API void plume_traction_opts_default_sized(plume_traction_opts *o, size_t size);
/** Fills *o with the defaults (plume_traction_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_traction_opts_default(o) plume_traction_opts_default_sized((o), sizeof(plume_traction_opts))

/** The default element edge (m) of a macro traction sample lx x ly: min(lx, ly) / 20, the one default
 * apps/traction, apps/fit, the flat interface and Python share. */
PLUME_API double plume_traction_default_edge(double lx, double ly);

/** The default barb spacing d_B (m) of a resolved specimen of width ly (along the pull): 0.086 ly,
 * the spacing of supplementary Figure 10 (left); apps/traction's --dB-rel and the flat
 * interface's micro model start from it. */
PLUME_API double plume_traction_default_barb_spacing(double ly);

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
    int cuts;                 /**< adaptive stepping: increments halved after a failed solve or an overshoot */
    int overshoot_cuts;       /**< of those, the ones a stateful term's overshoot asked for */
    int substeps;             /**< adaptive stepping: intermediate equilibria solved between the nominal
                                 steps (the curve holds the nominal strains only) */
    double max_violation;     /**< max relative constraint violation over the converged steps */
    double seconds;           /**< wall time of the whole run */
    int factorizations;       /**< native solvers: numeric factorisations */
    double factor_seconds;    /**< native solvers: time in numeric factorisations */
    /* the energy balance over the converged steps (J), kept whether or not a term has a state */
    double work;              /**< the moving grip's work: its reaction integrated over every increment
                                 by the trapezoidal rule */
    double stored_energy;     /**< the problem's energy at the last equilibrium */
    double dissipated_energy; /**< what the stateful terms' commits gave up: the energy lost from each
                                 equilibrium to the one solved again after a commit at the same grips */
    double energy_balance_error; /**< (work - stored - dissipated) / gross work, the gross work the sum of
                                    the increments' |work| (0 when none was done): the quadrature's error
                                    along the elastic paths, <= 1e-2 expected */
    long released;            /**< links the stateful terms let go (barbule hooks) */
    long reengaged;           /**< links they caught again */
    int largest_cascade;      /**< most links let go at one equilibrium, its solves again included */
    int release_events;       /**< commits that let links go: released / release_events is the mean
                                 number that go together */
    double peak_stress;       /**< Pa: the largest nominal stress at any equilibrium, sub-steps included,
                                 before the commits there (the curve holds the nominal steps only) */
} plume_traction_result;

/** Frees the curve's arrays and zeroes the curve (the rest of r is left); NULL-safe. */
PLUME_API void plume_traction_result_free(plume_traction_result *r);

/** The per-stencil states (1 engaged, 0 let go) of the term `term` ("hooks", "splits") at every
 * point of the curve a traction checkpoint holds (plume_traction_opts.checkpoint): *rows points
 * (the rest state first), *cols stencils, row by row into states (NULL: the counts only). A program
 * that records the states itself (apps/traction's hooks table) takes the restarted run's earlier
 * rows from here. PLUME_EIO (unreadable), PLUME_EFORMAT (no such table, named), PLUME_EINVAL. */
PLUME_API plume_status plume_traction_checkpoint_states(const char *path, const char *term, int *states, long *rows,
                                                        plume_index *cols, plume_err *err);

/** Clamps the grips of `p` (created over mesh->nv vertices, terms and constraints added, not
 * finalised), finalises it and runs the test. `rigid_edges` (n pairs; may be 0) are the
 * inextensible edges: if a chain of them links the two grips the sample cannot stretch and the
 * call fails with PLUME_EINFEASIBLE and a message, before any solve. Non-convergence of a step
 * is not an error: the run stops there (except for `linearized`, which never converges by
 * design and runs every step) and the result says which step and why. */
PLUME_API plume_status plume_traction_run(const plume_mesh *mesh, plume_problem *p, const plume_index *rigid_edges,
                                          plume_index nrigid, const plume_traction_opts *o,
                                          plume_traction_result *res, plume_err *err);


/* ---- sample meshes ---- */
/** How a rectangular sample is meshed (names "aligned", "unaligned"). */
typedef enum {
    PLUME_PATCH_ALIGNED = 0,  /**< corner-exact: a barb line through every corner of the sample, the
                                 others uniformly between (<= edge sqrt(3)/2 apart), vertices on them
                                 every ~`edge` (and boundary points only where they meet the sides),
                                 barb segments kept as edges: every triangle owns a barb edge
                                 (docs/theory-constraints.md) */
    PLUME_PATCH_UNALIGNED = 1 /**< quality Delaunay mesh (CGAL refinement) that ignores the barbs */
} plume_patch_kind;

/** Parses "aligned" | "unaligned" into *out; PLUME_EINVAL (no message) otherwise. */
PLUME_API plume_status plume_patch_kind_parse(const char *s, plume_patch_kind *out);

/** Meshes the rectangle at target edge length `edge` (m) with barbs at `angle_deg` in [0, 180].
 * Every triangle gets barb_dir = d, material 0; topology is built; x = X (z = 0 in shell mode).
 * Errors (PLUME_EINVAL, message names the parameter): non-finite or non-positive sizes, edge
 * larger than the sample, angle out of range, more than ~5e6 triangles requested. */
PLUME_API plume_status plume_patch_mesh(double lx, double ly, double angle_deg, double edge, plume_patch_kind kind,
                                        int dim, plume_mesh **out, plume_err *err);


/* ---- the vane ---- */
/** The macroscale vane's material and how its barbs are modelled (plume_vane_default). */
typedef struct {
    plume_ortho moduli;   /**< Pa */
    double h;             /**< thickness, m */
    double kappa;         /**< compression coefficient (Pa); 0 disables it */
    int constraint;       /**< 1: barb edges inextensible; 0: penalty (E_xx only) */
    double align_tol;     /**< |sin| of the angle below which an edge counts as barb-aligned; default 1e-6 */
} plume_vane;

/** Fills v with a dimensionless default: E_xx 1e4, E_yy 1, nu_xy 0, G_xy 1, h 1, kappa 0,
 * constraint on, align_tol 1e-6. Callers set the moduli and thickness of their sample. */
PLUME_API void plume_vane_default(plume_vane *v);

/** The vane's membrane material (its moduli, thickness and kappa). */
PLUME_API plume_membrane_material plume_vane_material(const plume_vane *v);

/** Validates the moduli and thickness (message names the parameter: "E_yy must be finite and > 0"). */
PLUME_API plume_status plume_vane_check(const plume_vane *v, plume_err *err);

/** Adds the vane membrane (every triangle, material 0) and, when v->constraint is set, the
 * inextensibility constraint of the barb edges to `p` (created over mesh->nv vertices).
 * If barb_edges/nbarb are non-NULL they receive the constrained edges (malloc'ed; NULL/0 when
 * the constraint is off). */
PLUME_API plume_status plume_vane_add(plume_problem *p, const plume_mesh *m, const plume_vane *v,
                                      plume_index **barb_edges, plume_index *nbarb, plume_err *err);
/** As plume_vane_add, with the membrane's plane-stress tensor C (Pa, row-major, Voigt order E11,
 * E22, 2E12 in the barb frame; plume_homog_result.C) in place of the moduli's orthotropic one:
 * the vane of a cell whose normal strains and shear are coupled (inclined barbules,
 * docs/monoclinic-vane.md). v's moduli are still checked (the penalty mode uses E_xx). C NULL:
 * plume_vane_add. */
PLUME_API plume_status plume_vane_add_tensor(plume_problem *p, const plume_mesh *m, const plume_vane *v,
                                             const double C[9], plume_index **barb_edges, plume_index *nbarb,
                                             plume_err *err);


/* ---- barb lines that split ---- */
/** Barb lines of a macro vane mesh opened to split and zip again (opaque; docs/unzipping.md). */
typedef struct plume_splits plume_splits;

/** Opens `nlines` barb lines of the planar mesh `m`, aligned with barbs at angle_deg (as
 * plume_patch_mesh PLUME_PATCH_ALIGNED makes it), spread evenly across the barbs: at fractions
 * k / (nlines + 1) of the mesh's extent across them, each the nearest line of mesh edges. Each
 * line's vertices are duplicated (the triangles ahead of it take the copies): build the problem
 * on plume_splits_mesh. Errors (PLUME_EINVAL, with the reason): nlines < 1, a mesh not aligned
 * with the barbs, two lines on one line of the mesh (too many for its rows). */
PLUME_API plume_status plume_splits_open(const plume_mesh *m, double angle_deg, int nlines, plume_splits **out,
                                         plume_err *err);
/** The opened mesh (owned by s): the input's vertices first, then the copies. */
PLUME_API const plume_mesh *plume_splits_mesh(const plume_splits *s);
/** Vertex pairs holding the lines. */
PLUME_API long plume_splits_pairs(const plume_splits *s);
/** Adds the links of the lines to p (created over plume_splits_mesh(s)'s vertices, not finalised)
 * as the stateful term "splits": each pair a zero-length spring of the law's stiffness times its
 * share of the line's length that lets go at the strength times that length and catches again
 * within the capture distance. A law that opens past its peak (opening > peak_opening: the cell's
 * hooks slide) softens instead: past the strength the pair's force falls linearly to zero, the
 * energy under it the law's (docs/unzipping.md, "Softening the links of a sliding law").
 * PLUME_EINVAL for a law out of range (naming the field). */
PLUME_API plume_status plume_splits_add(plume_problem *p, const plume_splits *s, const plume_separation_law *law,
                                        plume_err *err);
/** Frees s; sets *s = NULL; NULL-safe. */
PLUME_API void plume_splits_destroy(plume_splits **s);


/* ---- the resolved specimen ---- */
/** Meshes a rectangular traction specimen [0, lx] x [0, ly] of the layout with barbs at angle_deg
 * from the y axis (as in plume_patch_mesh: d = (sin a, cos a)); strip boundaries are mesh
 * edges, the mesh is refined to edges <= plume_layout_element_edge(l, PLUME_MESH_SPECIMEN); barbule
 * layouts leave the empty space out. Always linear triangles (plume_micro_specimen adds the
 * quadratic nodes).
 * Triangles get material ids and barb_dir = d; topology is built. */
PLUME_API plume_status plume_specimen_mesh(const plume_layout *l, double lx, double ly, double angle_deg,
                                           plume_mesh **out, plume_err *err);

/** Meshes the specimen [0, lx] x [0, ly] with barbs at angle_deg from the pulling axis y
 * (plume_specimen_mesh) and creates a planar problem holding the two-material membrane of the
 * layout's element order. At order 2 *mesh is the quadratic triangles split in four (its vertices
 * are the elements' nodes). The caller owns *mesh and *p (not finalised: plume_traction_run clamps and finalises it). */
PLUME_API plume_status plume_micro_specimen(const plume_layout *l, double lx, double ly, double angle_deg,
                                            plume_mesh **mesh, plume_problem **p, plume_err *err);

/** The elements of a specimen mesh made by plume_micro_specimen for layout l: its triangles, or at
 * order 2 its quadratic triangles (each split in four in the mesh). */
PLUME_API plume_index plume_micro_specimen_elements(const plume_layout *l, const plume_mesh *mesh);

/** How converged a micro traction run is: the same test on the specimen meshed with elements twice
 * as large (half as large when the layout refuses the coarser mesh). */
typedef struct {
    double edge;                  /**< target element edge of the run (m) */
    double refinement_edge;       /**< target element edge of the comparison (m) */
    double stress_change;         /**< max over the common curve points of |s - s'|, over max |s| */
    double slope_change;          /**< |initial_slope - initial_slope'| / |initial_slope| */
    plume_index refinement_elements; /**< elements of the comparison mesh */
    int converged;                /**< the comparison run converged (else the changes are -1) */
    double seconds;               /**< wall time of the comparison run */
} plume_micro_convergence;

/** Runs the traction test of `run` (options o, already done on the layout l) again on the
 * comparison mesh and fills *c. o->on_step is not called. A comparison run that does not converge
 * is not an error: c->converged is 0 and the changes are -1. */
PLUME_API plume_status plume_micro_traction_convergence(const plume_layout *l, double lx, double ly, double angle_deg,
                                                        const plume_traction_opts *o, const plume_traction_result *run,
                                                        plume_micro_convergence *c, plume_err *err);


/* ---- bending tests ---- */
/** The load of the plate test (names "cylinder", "twist"). */
typedef enum {
    PLUME_BEND_CYLINDER = 0, /**< end moments about x: curvature k_yy along the specimen */
    PLUME_BEND_TWIST = 1     /**< end torques about y: twist 2 k_xy */
} plume_bend_load;

/** How the end moments are applied. */
typedef enum {
    PLUME_BEND_EDGE_MOMENTS = 0, /**< the uniform state's own boundary loads: the work of a uniform moment
                                    on the shell's discrete curvatures, which lands on the ends (cylinder)
                                    and the corners (twist); default */
    PLUME_BEND_END_STRIPS = 1,   /**< forces over each end strip, linear in position (kept for comparison:
                                    a strongly orthotropic plate turns their departure from the uniform
                                    state into large transverse modes) */
    PLUME_BEND_UNIFORM_CURVATURE = 2 /**< the boundary loads of the uniform-curvature state of the specimen's
                                    own bending energy (plume_bend_opts.phases): each phase's moment
                                    D_i kappa on its own share of the ends, scaled to the edge moments' end
                                    moment; for a homogeneous plate the same loads as the edge moments, and for
                                    a resolved laminate twisted the grip that twists every barb (the twist of
                                    a laminate is uniform: docs/bending-homogenisation.md) */
} plume_bend_loading;

/** Options of the plate test (plume_bend_opts_default). */
typedef struct {
    size_t size;          /**< sizeof the caller's struct, set by plume_bend_opts_default */
    plume_bend_load load; /**< bending or twist; default cylinder */
    plume_bend_loading loading; /**< default PLUME_BEND_EDGE_MOMENTS */
    double lx;            /**< specimen width along x (m); default 1 */
    double ly;            /**< specimen length along y, between the loaded ends (m); default 2 */
    double moment;        /**< final moment per unit width (N m / m): m_yy or m_xy; finite and > 0 (the
                             sign of a linear test carries no information) */
    int steps;            /**< curve points after the rest state; default 3 */
    double end_strip;     /**< PLUME_BEND_END_STRIPS: loaded strip at each end over ly; default 0.1 */
    double window;        /**< fitted central window over each side; default 0.5 */
    double max_rotation;  /**< largest |curvature| * max(lx, ly) accepted (rad); default 0.2 */
    const plume_bending_material *phases; /**< PLUME_BEND_UNIFORM_CURVATURE: the bending moduli of each
                                             material id of the mesh, as its shape-operator term was built
                                             (caller's array, nphases entries); default NULL */
    int nphases;          /**< entries of phases; more than the mesh's largest material id */
    plume_solver_kind solver;      /**< default newton */
    const plume_solver_opts *solver_opts; /**< its options; NULL (default): plume_solver_opts_default's */
} plume_bend_opts;

/** Fills o (size bytes) with the defaults each field names (moment 1) and sets o->size; call it
 * through the macro plume_bend_opts_default(o). */
PLUME_API void plume_bend_opts_default_sized(plume_bend_opts *o, size_t size);
/** Fills *o with the defaults (plume_bend_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_bend_opts_default(o) plume_bend_opts_default_sized((o), sizeof(plume_bend_opts))

/** The name of a load: "twist" for PLUME_BEND_TWIST, else "cylinder" (static string). */
PLUME_API const char *plume_bend_load_name(plume_bend_load k);

/** The load named "cylinder" or "twist" into *k; PLUME_EINVAL (no message) for another name. */
PLUME_API plume_status plume_bend_load_parse(const char *s, plume_bend_load *k);

/** What plume_bend_run gives (free with plume_bend_result_free). */
typedef struct {
    plume_bend_curve curve; /**< rest state then `steps` points (arrays owned: plume_bend_result_free) */
    double stiffness;       /**< least-squares slope of moment over curvature through 0 (N m) */
    int converged;          /**< every step converged */
    double seconds;         /**< wall time of the run */
    double load_residual;   /**< PLUME_BEND_UNIFORM_CURVATURE: the largest interior force of the uniform state
                               over the largest end force (not applied: ~1e-10 when the uniform curvature is
                               the specimen's equilibrium, larger when its microstructure is not); else 0 */
} plume_bend_result;

/** Frees the curve's arrays and zeroes r; NULL-safe. */
PLUME_API void plume_bend_result_free(plume_bend_result *r);

/** Runs the test on a shell-mode specimen: mesh (dim 3, X over [0, lx] x [0, ly], topology built)
 * and p, its elastic terms added, not finalised (this function adds the loads, fixes the six
 * coordinates and finalises it; p is spent afterwards). Errors (PLUME_EINVAL, message naming the
 * option): options out of range, a mesh that is not a shell over the rectangle, an end strip or
 * window without vertices, PLUME_BEND_UNIFORM_CURVATURE without phases for every material id; PLUME_EINFEASIBLE: a step whose curvature exceeds max_rotation or that
 * turns a triangle over ("inverts an element"), naming the moment; solver errors pass through. A
 * step that does not converge is reported in r->converged, not as an error. r is filled on success
 * and freed on failure. */
PLUME_API plume_status plume_bend_run(const plume_mesh *mesh, plume_problem *p, const plume_bend_opts *o,
                                      plume_bend_result *r, plume_err *err);

/** The bending moduli of a homogeneous plate of membrane material m and its thickness h:
 * D = h^3 / 12 Q, Q the plane-stress tensor (isotropic: D_coupling = nu D, D_twist = (1 - nu) D / 2),
 * as the periodic plate cell takes each phase. */
PLUME_API void plume_plate_of_membrane(const plume_membrane_material *m, plume_bending_material *b);

/** A shell-mode specimen of the planar mesh `planar` (its X, triangles, material ids and barb
 * directions, copied; planar is the caller's): membrane mem[material[t]] (plume_membrane_term_create) and
 * shape-operator bending bend[material[t]] (phase-aware stencils: no fit
 * spans two materials) per triangle, nmat materials. This is how a resolved micro specimen (plume_specimen_mesh's mesh, phases by plume_plate_of_membrane) and
 * the homogeneous plate become the same kind of shell. The caller owns *mesh and *p (not
 * finalised). Errors: the terms' (PLUME_EINVAL with a message), PLUME_ENOMEM. */
PLUME_API plume_status plume_shell_specimen(const plume_mesh *planar, const plume_membrane_material *mem,
                                            const plume_bending_material *bend, int nmat, plume_mesh **mesh,
                                            plume_problem **p, plume_err *err);

/** The homogeneous plate specimen: an unaligned (quality Delaunay) mesh of edge `edge` with barbs at
 * angle_deg from y (plume_patch_mesh), shell mode, membrane `mem` and shape-operator bending
 * `bend`. The caller owns *mesh and *p (not finalised). Errors as
 * plume_patch_mesh and the terms' (PLUME_EINVAL with a message). */
PLUME_API plume_status plume_plate_specimen(double lx, double ly, double angle_deg, double edge,
                                            const plume_membrane_material *mem, const plume_bending_material *bend,
                                            plume_mesh **mesh, plume_problem **p, plume_err *err);

/** The moment per unit width that bends (or twists) a homogeneous plate of tensor D (N m, Voigt
 * (k11, k22, 2 k12) in the barb frame, row-major, plume_homogenize_bending) with barbs at angle_deg from
 * y to the curvature `curvature` (1/m) in the test above: curvature / (D_s^-1)_yy, or
 * curvature / (D_s^-1)_66 twisted, D_s the tensor in the specimen frame. *stiffness (may be NULL)
 * gets that ratio. PLUME_EINVAL for a D that is not positive definite. */
PLUME_API plume_status plume_bend_expected(const double D[9], double angle_deg, plume_bend_load load, double curvature,
                                           double *moment, double *stiffness, plume_err *err);

/** The plate test as a model of the bending moduli, for apps/fit (fit.h, plume_fit_model). */
typedef struct {
    double lx;                        /**< specimen width (m) */
    double ly;                        /**< specimen length (m) */
    double edge;                      /**< mesh edge (m) */
    plume_membrane_material membrane; /**< the plate's membrane (barb frame) */
    int ncurves;                      /**< curves the model computes (entries of angles, loads, moments) */
    const double *angles;             /**< [ncurves] barb angle from y (deg) */
    const plume_bend_load *loads;     /**< [ncurves] the load of each curve */
    const double *moments;            /**< [ncurves] final moment per unit width (N m / m) */
    int steps;                        /**< curve points after the rest state */
    plume_solver_kind solver;         /**< the test's solver; 0 is newton (apps/traction --bending and
                                         apps/fit --bending use linearized, where the membrane does not
                                         enter) */
} plume_plate_model;

/** The plate test as a model of bending curves (a plume_fit_bending_model, fit.h): runs curve icurve
 * of ctx (a plume_plate_model) with the bending moduli b and returns it as a plume_curve with
 * strain = curvature (1/m), stress = moment (N m / m), wbar = 0 (arrays malloc'ed, owned by out). A
 * run that does not converge, or moduli the plate refuses (not positive definite), give
 * PLUME_EINFEASIBLE. */
PLUME_API plume_status plume_plate_model_curve(void *ctx, const plume_bending_material *b, int icurve,
                                               plume_curve *out, plume_err *err);


/* ---- the samples of supplementary Table 1 ---- */
/** One traction sample's geometry, as read from the samples file (SI units). */
typedef struct {
    char id[32];        /**< e.g., "L01" (longitudinal) or "T07" (transverse) */
    char scenario[32];  /**< "longitudinal" | "transverse" | "tilted" */
    double lx;          /**< width across the pull (m; the file's lx_mm) */
    double ly;          /**< length along the pull, between the grips (m; the file's ly_mm) */
    double h;           /**< thickness (m; the file's h_um) */
} plume_sample;

/** Finds sample `id` in a JSON file of the form
 *
 *     {"samples": [{"id": "L01", "scenario": "longitudinal", "lx_mm": 9, "ly_mm": 18, "h_um": 73}, ...]}
 * Errors (PLUME_EIO unreadable, PLUME_EFORMAT malformed JSON with line and column, missing or
 * non-numeric key, PLUME_EINVAL non-positive/NaN dimension, unknown id) name the file. */
PLUME_API plume_status plume_sample_load(const char *path, const char *id, plume_sample *out, plume_err *err);

/** Number of samples in the file (every entry validated as by plume_sample_load). */
PLUME_API plume_status plume_sample_count(const char *path, int *count, plume_err *err);

/** Sample number `index` (0-based, file order) of the file; PLUME_EINVAL if out of range. With
 * plume_sample_count this enumerates a file without knowing its ids. */
PLUME_API plume_status plume_sample_at(const char *path, int index, plume_sample *out, plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
