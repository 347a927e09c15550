/** \file
 * plume: the bending test of a plate specimen, one procedure for both scales (docs/bending-homogenisation.md,
 * "Both scales in bending"): a shell-mode specimen [0, lx] x [0, ly] — the resolved barbs and barbules
 * of a layout (plume_specimen_mesh, micro/cell_mesh.h) or the homogeneous plate with the homogenised moduli
 * (plume_plate_specimen below) — loaded by self-equilibrated end moments and measured by the
 * curvature fitted in its centre.
 *
 * Loads (PLUME_BEND_EDGE_MOMENTS, the default): the boundary loads of the uniform state, i.e. the
 * work of a uniform moment on the shell's own discrete curvatures, sum_T A_T mbar . kappa_T, which
 * the shape operator's discrete divergence theorem puts on the boundary: the end moment m_yy per
 * unit width at y = 0 and y = ly (cylinder: m_yy lx about the x axis at each end) or the
 * Kirchhoff corner forces 2 m_xy of a uniform twisting moment (twist: 2 m_xy lx about the y axis).
 * For a homogeneous plate of any D the uniform state D^-1 m is then the discrete solution, on any
 * mesh. PLUME_BEND_END_STRIPS instead spreads vertical dead forces over each end strip
 * (y <= c and y >= ly - c, c = end_strip * ly), f_v = A_v (a + b (x - xc) + g (y - yc)), A_v the
 * vertex's lumped area, with no resultant and the same end moment: their departure from the
 * uniform state's loads makes end layers, which a strongly orthotropic plate carries across the
 * whole specimen (docs/bending-homogenisation.md). PLUME_BEND_UNIFORM_CURVATURE takes the same
 * construction with the specimen's own phases: the boundary loads of its uniform-curvature state,
 * which for a twisted laminate grip every barb. Either way the two ends carry opposite moments:
 * the specimen is free, held only against rigid motion by six fixed coordinates at three vertices
 * near its centre, which carry no reaction.
 *
 * Measure: the height z(X) of the vertices of the central window (window * lx by window * ly) is
 * fitted, weighted by lumped area, with a quadratic
 * c0 + c1 x + c2 y + 1/2 (k_xx x^2 + 2 k_xy x y + k_yy y^2); the periodic fluctuation of a
 * microstructure averages out. For a homogeneous plate of tensor D (specimen frame) the centre
 * is the uniform state kappa = D^-1 m, so bending gives m_yy / k_yy = 1 / (D^-1)_yy and twist
 * m_xy / (2 k_xy) = 1 / (D^-1)_66.
 *
 * The test is geometrically exact (the shell's own terms) but meant for the linear range: the load
 * is refused when the curvature it produces, times the specimen's length, exceeds max_rotation.
 * The linearized solver is the linear plate (every step solved from the rest state); the native
 * Newton's KKT tolerance is taken relative to the end loads, which in a soft direction lie far
 * below the problem's round-off floor. */
#ifndef PLUME_PLATE_BENDING_H
#define PLUME_PLATE_BENDING_H

#include "../lib/io/curves.h"
#include "../lib/core/export.h"
#include "../lib/core/membrane.h"
#include "../lib/core/mesh.h"
#include "../lib/core/problem.h"
#include "../lib/solve/solver.h"
#include "bending.h"

#ifdef __cplusplus
extern "C" {
#endif

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
    plume_solver_opts solver_opts; /**< defaults of lib/solve/solver.h */
} plume_bend_opts;

/** Fills o with the defaults each field names (moment 1). */
PLUME_API void plume_bend_opts_default(plume_bend_opts *o);

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
 * as micro/cell_plate.h takes each phase. */
PLUME_API void plume_plate_of_membrane(const plume_membrane_material *m, plume_bending_material *b);

/** A shell-mode specimen of the planar mesh `planar` (its X, triangles, material ids and barb
 * directions, copied; planar is the caller's): membrane mem[material[t]] (lib/core/membrane.h) and
 * shape-operator bending bend[material[t]] (macro/shape_bending.h, phase-aware stencils: no fit
 * spans two materials) per triangle, nmat materials. This is how a resolved micro specimen (plume_specimen_mesh's mesh, phases by plume_plate_of_membrane) and
 * the homogeneous plate become the same kind of shell. The caller owns *mesh and *p (not
 * finalised). Errors: the terms' (PLUME_EINVAL with a message), PLUME_ENOMEM. */
PLUME_API plume_status plume_shell_specimen(const plume_mesh *planar, const plume_membrane_material *mem,
                                            const plume_bending_material *bend, int nmat, plume_mesh **mesh,
                                            plume_problem **p, plume_err *err);

/** The homogeneous plate specimen: an unaligned (quality Delaunay) mesh of edge `edge` with barbs at
 * angle_deg from y (macro/patch_mesh.h), shell mode, membrane `mem` and shape-operator bending
 * `bend` (macro/shape_bending.h). The caller owns *mesh and *p (not finalised). Errors as
 * plume_patch_mesh and the terms' (PLUME_EINVAL with a message). */
PLUME_API plume_status plume_plate_specimen(double lx, double ly, double angle_deg, double edge,
                                            const plume_membrane_material *mem, const plume_bending_material *bend,
                                            plume_mesh **mesh, plume_problem **p, plume_err *err);

/** The moment per unit width that bends (or twists) a homogeneous plate of tensor D (N m, Voigt
 * (k11, k22, 2 k12) in the barb frame, row-major, micro/cell_plate.h) with barbs at angle_deg from
 * y to the curvature `curvature` (1/m) in the test above: curvature / (D_s^-1)_yy, or
 * curvature / (D_s^-1)_66 twisted, D_s the tensor in the specimen frame. *stiffness (may be NULL)
 * gets that ratio. PLUME_EINVAL for a D that is not positive definite. */
PLUME_API plume_status plume_bend_expected(const double D[9], double angle_deg, plume_bend_load load, double curvature,
                                           double *moment, double *stiffness, plume_err *err);

/** The bending moduli packed in the fitter's four slots (micro/fit.h fits a plume_ortho):
 * E_xx = D_long, E_yy = D_trans, G_xy = D_twist (searched in log space) and nu_xy =
 * D_coupling / sqrt(D_long D_trans) (linearly, in (-1, 1)). */
PLUME_API void plume_bend_pack(const plume_bending_material *b, plume_ortho *m);
/** The inverse of plume_bend_pack: D_long = E_xx, D_trans = E_yy, D_twist = G_xy and
 * D_coupling = nu_xy sqrt(E_xx E_yy); unchecked. */
PLUME_API void plume_bend_unpack(const plume_ortho *m, plume_bending_material *b);

/** The plate test as a model of the bending moduli, for apps/fit (micro/fit.h, plume_fit_model). */
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

/** plume_fit_model for the plate: runs curve icurve of ctx (a plume_plate_model) with the bending
 * moduli packed in m (plume_bend_unpack) and returns it as a plume_curve with strain = curvature
 * (1/m), stress = moment (N m / m), wbar = 0 (arrays malloc'ed, owned by out). A run that does
 * not converge, or moduli the plate refuses (D_coupling^2 > D_long D_trans), give PLUME_EINFEASIBLE. */
PLUME_API plume_status plume_plate_model_curve(void *ctx, const plume_ortho *m, int icurve, plume_curve *out,
                                               plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
