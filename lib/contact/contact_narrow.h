/** \file
 * plume: narrow-phase mathematics of shell contact (docs/design.md "Contact (many feathers)"): squared
 * distances of point–triangle and edge–edge pairs with exact gradients and Hessians, the edge–edge
 * mollifier, and the barrier and penalty pair potentials of incremental-potential contact (Li et
 * al. 2020, "Incremental Potential Contact", ACM TOG 39(4)).
 *
 * Every pair function works on one 12-vector x of plain doubles, vertex-major (x[3*i + k] is
 * coordinate k of vertex i):
 *   point–triangle: vertices p, t0, t1, t2;     edge–edge: vertices ea0, ea1, eb0, eb1.
 * Gradients are 12-vectors and Hessians 12 x 12 row-major matrices with respect to that x. Nothing
 * here allocates or keeps state, so a term may call these functions from its element loop. */
#ifndef PLUME_CONTACT_NARROW_H
#define PLUME_CONTACT_NARROW_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Which feature of the triangle is closest to the point; the squared distance of that pair is
 * then the smooth point–point, point–line or point–plane function (Li et al., 2020). */
typedef enum {
    PLUME_CONTACT_PT_T0 = 0, /**< point–point: p and t0 */
    PLUME_CONTACT_PT_T1,     /**< point–point: p and t1 */
    PLUME_CONTACT_PT_T2,     /**< point–point: p and t2 */
    PLUME_CONTACT_PT_E01,    /**< point–line: p and the line through t0, t1 */
    PLUME_CONTACT_PT_E12,    /**< point–line: p and the line through t1, t2 */
    PLUME_CONTACT_PT_E20,    /**< point–line: p and the line through t2, t0 */
    PLUME_CONTACT_PT_FACE,   /**< point–plane: p and the plane of the triangle */
    PLUME_CONTACT_PT_NTYPES  /**< the number of point–triangle types (not a type) */
} plume_contact_pt_type;

/** Which features of two segments are closest: 4 endpoint–endpoint, 4 endpoint–line, line–line. */
typedef enum {
    PLUME_CONTACT_EE_A0B0 = 0, /**< point–point ea0, eb0 */
    PLUME_CONTACT_EE_A0B1,     /**< point–point ea0, eb1 */
    PLUME_CONTACT_EE_A1B0,     /**< point–point ea1, eb0 */
    PLUME_CONTACT_EE_A1B1,     /**< point–point ea1, eb1 */
    PLUME_CONTACT_EE_A0_EB,    /**< point–line ea0 and the line through eb0, eb1 */
    PLUME_CONTACT_EE_A1_EB,    /**< point–line ea1 and the line through eb0, eb1 */
    PLUME_CONTACT_EE_B0_EA,    /**< point–line eb0 and the line through ea0, ea1 */
    PLUME_CONTACT_EE_B1_EA,    /**< point–line eb1 and the line through ea0, ea1 */
    PLUME_CONTACT_EE_LINES,    /**< line–line: the two supporting lines */
    PLUME_CONTACT_EE_NTYPES    /**< the number of edge–edge types (not a type) */
} plume_contact_ee_type;

/** Two edges whose sin^2(angle) is below this are classified as parallel (never LINES), and a
 * triangle whose (width / longest edge)^2 is below it as flat (never FACE): the line–line and
 * point–plane formulas divide by |n|^2, whose rounding error relative to itself grows like
 * eps / sin, while the endpoint fallback overestimates the distance by at most L sin. At
 * sin = 1e-8 ~ sqrt(eps) both errors are ~1e-8 L (ipc-toolkit uses 2.5e-16 for the same
 * reason). */
#define PLUME_CONTACT_PARALLEL_SIN2 1e-16

/** IPC's mollifier threshold scale: eps_x = 1e-3 |ea_rest|^2 |eb_rest|^2 (Li et al., 2020). */
#define PLUME_CONTACT_MOLLIFIER_SCALE 1e-3

/** Closest feature of the triangle (t0, t1, t2) to the point p, x = (p, t0, t1, t2): the Voronoi
 * region of p (signs of dot products, no division); a flat triangle (see
 * PLUME_CONTACT_PARALLEL_SIN2) gets the nearest of its three segments. PLUME_EINVAL if x or type
 * is NULL or x is not finite. */
plume_status plume_contact_pt_classify(const double x[12], plume_contact_pt_type *type);

/** Closest features of the segments (ea0, ea1) and (eb0, eb1), x = (ea0, ea1, eb0, eb1): the
 * clamped minimiser of the segment–segment distance; (nearly) parallel or zero-length edges get the
 * nearest of the four endpoint–segment pairs (ipc-toolkit's fallback), so LINES is never returned
 * where the line–line formula is singular. PLUME_EINVAL if x or type is NULL or x is not finite. */
plume_status plume_contact_ee_classify(const double x[12], plume_contact_ee_type *type);

/** Squared distance d2 of the smooth function of `type` (point–point, point–line or point–plane)
 * at x = (p, t0, t1, t2), with its gradient g[12] and Hessian H[144] (row-major). g and H may be
 * NULL (not computed). With the type from plume_contact_pt_classify, d2 is the squared
 * point–triangle distance. PLUME_EINVAL: x or d2 NULL, type out of range, x not finite;
 * PLUME_ESINGULAR: the type's line or plane is undefined (zero-length edge, zero-area triangle;
 * classify never returns such a type). */
plume_status plume_contact_pt_distance2(const double x[12], plume_contact_pt_type type, double *d2,
                                                  double *g, double *H);

/** The same for an edge–edge pair x = (ea0, ea1, eb0, eb1) and one of the 9 edge–edge types;
 * PLUME_ESINGULAR for a zero-length edge's line or for exactly parallel lines. */
plume_status plume_contact_ee_distance2(const double x[12], plume_contact_ee_type type, double *d2,
                                                  double *g, double *H);

/** Squared point–triangle distance only (classify + distance2) of x = (p, t0, t1, t2), the
 * function continuous collision detection samples. NULL or non-finite input: PLUME_EINVAL. */
plume_status plume_contact_pt_dist2(const double x[12], double *d2);
/** Squared edge–edge distance only (classify + distance2) of x = (ea0, ea1, eb0, eb1), parallel
 * and zero-length edges included. NULL or non-finite input: PLUME_EINVAL. */
plume_status plume_contact_ee_dist2(const double x[12], double *d2);

/** The mollifier threshold eps_x = PLUME_CONTACT_MOLLIFIER_SCALE |ea|^2 |eb|^2 of an edge–edge pair
 * at its rest positions xrest = (ea0, ea1, eb0, eb1). Computed once per pair by the caller.
 * PLUME_EINVAL: NULL or non-finite input. */
plume_status plume_contact_ee_mollifier_threshold(const double xrest[12], double *eps_x);

/** IPC's edge–edge mollifier m(c), c = |(ea1 - ea0) x (eb1 - eb0)|^2 (Li et al., 2020):
 * m = -c^2/eps_x^2 + 2 c/eps_x for c < eps_x, else 1; C^1 in c at eps_x, m(0) = 0. Outputs m and its
 * gradient g[12] and Hessian H[144] with respect to x (g, H may be NULL). PLUME_EINVAL: x or m NULL,
 * x not finite, eps_x not finite or <= 0. */
plume_status plume_contact_ee_mollifier(const double x[12], double eps_x, double *m, double *g,
                                                  double *H);

/* ---- pair potentials (docs/design.md "Contact": kept exactly) ---------------------------------- */

/** b(d) = -(d - dhat)^2 ln(d / dhat) for 0 < d < dhat, 0 for d >= dhat, and its first and second
 * derivatives in d (db, d2b may be NULL). C^2 at dhat, +inf as d -> 0+, convex and decreasing
 * on (0, dhat). d <= 0 (or NaN): PLUME_ESINGULAR with *b = +INFINITY and zero derivatives — an
 * infeasible trial point, never a value to use. dhat not finite or <= 0, b NULL: PLUME_EINVAL. */
plume_status plume_contact_barrier(double d, double dhat, double *b, double *db, double *d2b);

/** p(d) = (dhat - d)^2 / 2 for 0 <= d < dhat, 0 for d >= dhat (multiply by the stiffness), with
 * derivatives (dp, d2p may be NULL); defined at d = 0, where pairs may interpenetrate. d < 0 or
 * not finite, dhat not finite or <= 0, p NULL: PLUME_EINVAL. */
plume_status plume_contact_penalty(double d, double dhat, double *p, double *dp, double *d2p);

/** The pair potential of contact. */
typedef enum {
    PLUME_CONTACT_BARRIER = 0, /**< kappa b(d); needs continuous collision detection (ccd.h) */
    PLUME_CONTACT_PENALTY = 1  /**< stiffness (dhat - d)^2 / 2 */
} plume_contact_model;

/** Parameters of the pair potential. */
typedef struct {
    plume_contact_model model; /**< barrier (default) or penalty */
    double dhat;      /**< activation distance (> 0, in length units of x); pairs at d >= dhat cost 0 */
    double stiffness; /**< kappa of the barrier, or the penalty stiffness (>= 0) */
    int project_psd;  /**< the 12 x 12 Hessian blocks: 0 exact; PLUME_CONTACT_PROJECT_EIGEN the nearest
                         PSD matrix (eigen-decomposition); PLUME_CONTACT_PROJECT_GAUSS_NEWTON (the
                         default) phi''(d) grad d grad d^T, the exact H = phi'' grad d grad d^T +
                         phi' Hess d without the distance's curvature: PSD in closed form, the
                         normal stiffness kept (the same as the nearest PSD matrix for two points,
                         whose Hess d is PSD and orthogonal to grad d). Mollified edge-edge pairs
                         (near-parallel edges) are projected by eigen-decomposition either way.
                         The contact term (contact.h) gives the exact blocks on the solver's
                         exact-Hessian path and these on its projected ones */
} plume_contact_opts;

/** Values of plume_contact_opts.project_psd besides 0 (exact blocks). */
enum {
    PLUME_CONTACT_PROJECT_EIGEN = 1,       /**< the nearest PSD matrix, by eigen-decomposition */
    PLUME_CONTACT_PROJECT_GAUSS_NEWTON = 2 /**< phi''(d) grad d grad d^T, PSD in closed form (default) */
};

/** Defaults: barrier, dhat = 1e-3 (IPC's 1e-3 of a unit scene: set it from the scene's size),
 * stiffness 1, Gauss-Newton blocks (why, with measurements: docs/theory-contact.md). */
void plume_contact_opts_default(plume_contact_opts *o);

/** Energy E of one point–triangle pair x = (p, t0, t1, t2): stiffness * phi(d) with phi the
 * barrier b or penalty p of the unsigned point–triangle distance d, with its gradient g[12] and
 * Hessian H[144] (g, H may be NULL; made PSD as o->project_psd says). Pairs at d >= dhat
 * return E = 0 and zeros without computing derivatives. type (may be NULL) receives the
 * classification. Barrier at d = 0: PLUME_ESINGULAR with E = +INFINITY (infeasible trial point).
 * Penalty at d = 0 exactly: E = stiffness dhat^2/2 with zero g and H (d is not differentiable
 * there). PLUME_EINVAL: NULL o, x or E, x not finite, bad options. */
plume_status plume_contact_pt_energy(const plume_contact_opts *o, const double x[12], double *E,
                                               double *g, double *H, plume_contact_pt_type *type);

/** The same for an edge–edge pair x = (ea0, ea1, eb0, eb1), multiplied by the mollifier
 * m(x) of threshold eps_x (from plume_contact_ee_mollifier_threshold) so the energy stays C^1 as
 * the edges turn parallel: E = m stiffness phi(d). eps_x = 0 disables the mollifier (m = 1);
 * eps_x < 0 or not finite: PLUME_EINVAL. */
plume_status plume_contact_ee_energy(const plume_contact_opts *o, const double x[12], double eps_x,
                                               double *E, double *g, double *H, plume_contact_ee_type *type);

#ifdef __cplusplus
}
#endif
#endif
