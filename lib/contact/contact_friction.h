/** \file
 * plume: lagged Coulomb friction between shells (incremental potential contact, Li et al., 2020,
 * ACM TOG 39(4), §5). Over a step, each contact pair keeps what it had at the lagged positions
 * x_lag (the start of the step, or the previous lagged iterate): its normal force magnitude
 * lambda, the closest points' weights and a tangent basis P. Its tangential relative
 * displacement is then linear in x,
 *   u = T^T (x - x_lag),   T = Gamma^T P  (12 x 2),
 * and friction is the smooth dissipative potential D(x) = mu lambda f0(|u|) whose gradient has
 * magnitude mu lambda while sliding (|u| >= eps_u) and fades to 0 linearly when sticking.
 *
 * Pair functions use the 12-vector layout of contact_narrow.h (vertex-major; point–triangle
 * p, t0, t1, t2; edge–edge ea0, ea1, eb0, eb1) and allocate nothing. */
#ifndef PLUME_CONTACT_FRICTION_H
#define PLUME_CONTACT_FRICTION_H

#include "../core/export.h"
#include "contact.h"
#include "contact_narrow.h"
#include "../core/status.h"
#include "../core/term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The friction frame of one pair at its lagged positions (output of the basis functions). */
typedef struct {
    int is_edge_edge; /**< 0: point–triangle, 1: edge–edge */
    int type;         /**< plume_contact_pt_type or plume_contact_ee_type it was built for */
    double coef[2];   /**< closest-point parameters of the type: point–edge: alpha along the edge's
                         line; face: barycentric (b1, b2) of t1, t2; line–line: (alpha, beta) along
                         ea and eb; unused entries 0 */
    double w[4];      /**< vertex weights: the relative displacement of the closest points (side a
                         minus side b: the point or ea minus the triangle or eb) is
                         sum_i w[i] dx_i; they sum to 0, so translations give none */
    double P[6];      /**< 3 x 2 row-major orthonormal tangent basis, both columns orthogonal to the
                         contact normal (P[2 k + j]: component k of column j) */
    double T[24];     /**< 12 x 2 row-major, T[2 (3 i + k) + j] = w[i] P[2 k + j]: u = T^T dx */
} plume_friction_basis;

/** The frame of a point–triangle pair x = (p, t0, t1, t2) for the smooth-distance type `type`
 * (contact_narrow.h): point–point: P spans the plane normal to p - t_i; point–edge: P = (edge
 * direction, edge x (p - edge start)) normalised; face: P = (t1 - t0, n x (t1 - t0)) normalised.
 * Where the normal is undefined (p on the feature: d = 0, which the penalty allows) any
 * orthonormal P of the remaining freedom is used. PLUME_EINVAL: NULL, non-finite x, type out of
 * range; PLUME_ESINGULAR: the type's edge or triangle is degenerate (classify never returns
 * such a type). */
plume_status plume_friction_pt_basis(const double x[12], plume_contact_pt_type type, plume_friction_basis *b);

/** The same for an edge–edge pair x = (ea0, ea1, eb0, eb1): endpoint–endpoint as point–point,
 * endpoint–line as point–edge, line–line: P = (ea, (ea x eb) x ea) normalised. ESINGULAR for a
 * zero-length edge's line or parallel lines. */
plume_status plume_friction_ee_basis(const double x[12], plume_contact_ee_type type, plume_friction_basis *b);

/** Classifies the pair (plume_contact_pt_classify / ee_classify) and builds its frame. */
plume_status plume_friction_pair_basis(int is_edge_edge, const double x[12], plume_friction_basis *b);

/** IPC's friction mollifier with threshold eps_u > 0 (a displacement, eps_v dt), y >= 0:
 *   f0(y) = -y^3/(3 eps_u^2) + y^2/eps_u + eps_u/3 for y < eps_u, y beyond (C^2: f0'' = 0 at
 *   eps_u from both sides);
 *   f1 = f0' = 2 y/eps_u - y^2/eps_u^2, 1 beyond;   f1y = f1(y)/y = 2/eps_u - y/eps_u^2, 1/y beyond;
 *   f2y = y d(f1/y)/dy = -y/eps_u^2, -1/y beyond.
 * f1y and f2y are what the Hessian needs (mu lambda T (f1y I + f2y uh uh^T) T^T, uh = u/|u|);
 * both are finite at y = 0 (f1y = 2/eps_u, f2y = 0). Any output may be NULL. PLUME_EINVAL: y < 0
 * or not finite, eps_u <= 0 or not finite. */
plume_status plume_friction_mollifier(double y, double eps_u, double *f0, double *f1, double *f1y, double *f2y);

/** D = mu lambda f0(|u|), u = T^T (x - xlag), with the exact gradient g[12] = mu lambda f1y T u and
 * Hessian H[144] = mu lambda T C T^T, C = f1y I + f2y uh uh^T (g, H may be NULL). C's eigenvalues
 * are f1y (across u) and f1' = f1y + f2y >= 0 (along u), so the exact H is PSD; they are clamped
 * at 0 against round-off, which is IPC's projection of the 2 x 2 core. mu lambda = 0 gives zeros.
 * PLUME_EINVAL: NULL T, x, xlag or D; mu or lambda < 0 or not finite; eps_u <= 0; non-finite
 * x, xlag or T. */
plume_status plume_friction_pair_energy(double mu, double lambda, double eps_u, const double T[24], const double x[12],
                                                  const double xlag[12], double *D, double *g, double *H);

/** The lagged normal force magnitude lambda of a pair at distance d, the true force |dE/dd| of the
 * pair potential of o (contact_narrow.h):
 *   barrier  lambda = -kappa b'(d) = kappa |b'(d)|   (0 < d < dhat; 0 at d >= dhat),
 *   penalty  lambda = stiffness (dhat - d)            (0 <= d < dhat; 0 at d >= dhat).
 * ipc-toolkit writes its barrier in d^2 and uses -kappa (db/d(d^2)) 2 d: the same chain rule, so
 * lambda is the force in both. The edge–edge mollifier is left out, as in IPC. PLUME_EINVAL: NULL,
 * bad options, d not finite or d < 0; barrier at d = 0: PLUME_ESINGULAR. */
plume_status plume_friction_normal_force(const plume_contact_opts *o, double d, double *lambda);

/** lambda of a pair x from its classified distance (point–triangle or edge–edge). */
plume_status plume_friction_pair_normal_force(const plume_contact_opts *o, int is_edge_edge, const double x[12],
                                                        double *lambda);

/* ---- the friction term ------------------------------------------------------------------- */

/** Options of the friction term (plume_friction_opts_default). */
typedef struct {
    double mu;    /**< Coulomb coefficient (>= 0); 0 gives a term that costs nothing. Default 0.3 */
    double eps_v; /**< sliding-speed threshold (m/s), below which a pair sticks; default 1e-3 (IPC) */
    double dt;    /**< the time step (s) over which x - x_lag is travelled: eps_u = eps_v dt (m);
                     default 1e-2, plume_dynamics_opts' default */
} plume_friction_opts;

/** Fills o with the defaults (mu 0.3, eps_v 1e-3 m/s, dt 1e-2 s); NULL-safe. */
void plume_friction_opts_default(plume_friction_opts *o);

/** One lagged contact pair: its four vertices in the layout above and its normal force. */
typedef struct {
    int is_edge_edge;  /**< 0: v = (p, t0, t1, t2); 1: v = (ea0, ea1, eb0, eb1) */
    plume_index v[4];  /**< distinct vertices < nv */
    double lambda;     /**< normal force magnitude (>= 0), e.g., plume_friction_pair_normal_force */
} plume_friction_pair;

/** Opaque handle on a friction term's data, owned by the term (and so by the problem that holds
 * it): through it the caller sets the lagged pairs; never freed by the caller. */
typedef struct plume_friction plume_friction;

/** A friction term (dim 3) over nv vertices, with no pair yet. *out is ready for
 * plume_problem_add_term, which takes ownership; *handle (may be NULL) stays valid as long as the
 * problem and serves plume_friction_set_pairs. Its Hessian blocks are PSD whether or not the
 * solver asks for projection. Errors name what is wrong. */
plume_status plume_friction_term_create(plume_index nv, const plume_friction_opts *o, plume_term *out,
                                                  plume_friction **handle, plume_err *err);

/** Lags the friction: copies the pairs (npairs of them; pairs may be NULL when npairs is 0) and
 * their positions in x_lag [3 nv], classifies each pair there and keeps its frame. The pairs
 * become the term's stencils at its next update (plume_problem_update_terms, or plume_term.update
 * called directly), which reports changed = 1 when the vertex lists differ from the current ones;
 * until then evaluations use the previous pairs, so the problem's Hessian pattern and the term
 * never disagree. Allocates (outside any solve). On error nothing changes. PLUME_EINVAL: NULL f or
 * x_lag, npairs < 0, a vertex out of range or repeated in a pair, lambda < 0 or not finite,
 * non-finite lagged positions. */
plume_status plume_friction_set_pairs(plume_friction *f, plume_index npairs, const plume_friction_pair *pairs,
                                                const double *x_lag, plume_err *err);

/** Makes the term lag itself from contact term c (lib/contact/contact.h) at the start of every time step
 * (plume_term.lag, called by the stepper): the contact's pairs within reach there, each with its
 * normal force (plume_friction_pair_normal_force, pairs with lambda 0 dropped), become the pairs.
 * c must outlive the term (both belong to one problem). */
plume_status plume_friction_follow_contact(plume_friction *f, const plume_contact *c);

/** eps_u = eps_v dt of the term (m). */
double plume_friction_eps_u(const plume_friction *f);

#ifdef __cplusplus
}
#endif
#endif
