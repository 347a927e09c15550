/** \file
 * plume: orthotropic bending with one unknown per edge (docs/theory-bending-midedge.md): each
 * edge carries a director, the unit normal of the surface at its midpoint, as one angle theta
 * about the edge; each triangle measures the normal slope across each of its edges from that
 * director and its own three vertices, and its curvature from the three slopes (Morley's
 * triangle on the current face). A triangle's energy depends on 9 + 3 scalars only.
 *
 * Standalone for now: the functions work on a vertex array x [3 nv] and an edge array theta [ne]
 * (edge ids of mesh->edges), not on a plume_problem's state, which carries vertex unknowns only
 * (the doc says what must change to plug it in). Energy per triangle, in its barb frame:
 *     A/2 (k - k_rest)^T Dv (k - k_rest),  Dv = [D_long D_coupling 0; D_coupling D_trans 0; 0 0 4 D_twist],
 * the plate energy of shape_bending.h with the same moduli (D_twist == 0: Huber's rule). */
#ifndef PLUME_MIDEDGE_BENDING_H
#define PLUME_MIDEDGE_BENDING_H

#include "../../lib/core/export.h"
#include "../../lib/core/mesh.h"
#include "bending.h"

#ifdef __cplusplus
extern "C" {
#endif

/** n . d / |d| below this: the director lies within half a degree of the triangle's plane, a
 * slope of more than 100 across half an element; no smooth surface is near, the kernel fails. */
#define MIDEDGE_MIN_COS 1e-2

/** |r0 - (r0 . t) t| below this: the edge has turned within half a degree of its reference
 * vector since the last re-basing, and the frame no longer resolves the angle. */
#define MIDEDGE_MIN_FRAME 1e-2

/** The numbers of one triangle, as the face kernel reads them (built by
 * plume_midedge_bending_create; a test may fill one by hand). Slot k is the edge opposite the
 * triangle's vertex k, from vertex k+1 to vertex k+2 (mod 3). */
typedef struct {
    double K[9];     /**< 3x3 row-major stiffness of the slopes: A B^T Dv B (symmetric PSD) */
    double s0[3];    /**< rest slopes */
    double c[3][3];  /**< g_k = sum_j c[k][j] x_j: the current image F N_k of edge k's outward unit material normal */
    double sigma[3]; /**< +1 when the mesh edge of slot k runs from vertex k+1 to k+2, -1 otherwise */
    double B[9];     /**< 3x3 row-major: the curvature (bb, tt, bt) in the barb frame is B s (bt: kappa_12) */
} plume_midedge_face;

/** The face kernel: energy 1/2 (s - s0)^T K (s - s0) of one triangle at vertices xv (9: x0, x1,
 * x2) and edge angles th (3, slot order), the edges' reference vectors r0[k] (unit, see
 * plume_midedge_bending_lag). Writes E, the gradient g (12: the 9 vertex coordinates, then the
 * three angles) and, when H is non-NULL, the 12x12 row-major Hessian (project != 0: the
 * Gauss-Newton part J^T K J alone, PSD). g may be NULL. Returns 0, or -1 when the triangle has
 * collapsed, a director is within MIDEDGE_MIN_COS of the triangle's plane or an edge has turned
 * onto its reference vector (nothing written then). */
int plume_midedge_face_eval(const plume_midedge_face *f, const double xv[9], const double th[3],
                            const double *const r0[3], double *E, double g[12], double H[144], int project);

/** The slope s_k of slot k alone (for tests): -(g_k . d) / (n . d), d the edge's director. */
int plume_midedge_face_slope(const plume_midedge_face *f, const double xv[9], int k, double th, const double r0[3],
                             double *s);

/** The unit director of an edge whose current vector is E (from its first vertex to its second,
 * as the angle's sense is taken), at angle th about E from the reference vector r0: the part of
 * r0 perpendicular to E, normalised, turned by th about E. Returns -1 (d not written) when E
 * is zero or lies within MIDEDGE_MIN_FRAME of r0's line. */
int plume_midedge_director(const double E[3], double th, const double r0[3], double d[3]);

/** The angle th at which plume_midedge_director(E, th, r0) points along the part of d
 * perpendicular to E. */
double plume_midedge_angle(const double E[3], const double r0[3], const double d[3]);

/** A midedge bending energy over a shell-mode mesh; opaque. */
typedef struct plume_midedge_bending plume_midedge_bending;

/** Builds the term for a mesh in shell mode (dim 3, topology built) with materials mats[nmat]
 * (indexed by mesh->material) and barb directions mesh->barb_dir (normalised here). Rest shape
 * mesh->X at z = 0 unless rest_x (3 nv, may be NULL) gives a curved one; the rest director of an
 * edge is the mean of its faces' rest normals turned perpendicular to it, and theta = 0 is that
 * director (until the first plume_midedge_bending_lag). Errors (PLUME_EINVAL with a message):
 * dim != 3, no topology, a bad stiffness or D_coupling^2 > D_long D_trans, ids out of range, a
 * barb direction of zero length, a degenerate reference or rest triangle, rest faces folded onto
 * each other across an edge; PLUME_ENOMEM. */
plume_status plume_midedge_bending_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                          const double *rest_x, plume_midedge_bending **out, plume_err *err);

/** Options of plume_midedge_bending_create_opts (all zero: the defaults above). rest_dir (3 ne,
 * may be NULL) gives the rest director of each edge instead of the mean of its faces' normals:
 * any vector on the faces' side, made perpendicular to the rest edge and normalised here. A
 * curved rest on an irregular mesh needs it: the mean normal is the surface's normal at the
 * edge's midpoint only up to O(h), and the rest curvatures inherit the error (a cylinder's change
 * of curvature off by 40 % at h = 1/8 on a random Delaunay mesh, against 0.3 % with the true
 * normals; docs/theory-bending-midedge.md, "Rest state"). */
typedef struct {
    const double *rest_dir; /**< [3 ne] rest directors, or NULL (borrowed) */
    /** [3 ne] or NULL (borrowed): three vertices (p0, p1, p2, not on one line at rest) of a rigid
     * group holding edge e (a clamp, a handle), or -1 in anchor[3 e] for none. An anchored edge's
     * reference vector is its rest director carried by the anchors' frame (e1 along p1 - p0, e3
     * normal to the three), read from x at every evaluation, so it turns with the group; its
     * angle is measured from there and re-basing leaves it. The anchors' own coordinates enter no
     * derivative: hold them fixed (the group does). */
    const plume_index *anchor;
} plume_midedge_bending_opts;

/** The term with options (o may be NULL). Errors as above, and PLUME_EINVAL for a rest director
 * that is not finite, lies along its edge or points away from a face's rest normal. */
plume_status plume_midedge_bending_create_opts(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                               const double *rest_x, const plume_midedge_bending_opts *o,
                                               plume_midedge_bending **out, plume_err *err);

/** Frees the term; NULL-safe, sets *b = NULL. */
void plume_midedge_bending_destroy(plume_midedge_bending **b);

/** Edges (the mesh's ne) and triangles. */
plume_index plume_midedge_bending_nedge(const plume_midedge_bending *b);
plume_index plume_midedge_bending_nface(const plume_midedge_bending *b);

/** [3 nt]: the edge id of slot k of triangle t (the edge opposite its vertex k) at 3 t + k;
 * owned by the term. The Hessian block of t is ordered (x of tri[3t..3t+2], theta of these). */
const plume_index *plume_midedge_bending_face_edges(const plume_midedge_bending *b);

/** Triangle t's kernel numbers (owned by the term). */
const plume_midedge_face *plume_midedge_bending_face(const plume_midedge_bending *b, plume_index t);

/** Adds the energy at (x [3 nv], theta [ne]) to *energy, its gradient to gx [3 nv] and gtheta
 * [ne], and writes triangle t's 12x12 block at hblocks + 144 t (project as in the face kernel).
 * Any output may be NULL. PLUME_ESINGULAR when a triangle's kernel fails (its id in err: the
 * energy is undefined there, as at a solver's trial that folded a triangle); the outputs are then
 * not accumulated in full. */
plume_status plume_midedge_bending_eval(const plume_midedge_bending *b, const double *x, const double *theta,
                                        double *energy, double *gx, double *gtheta, double *hblocks, int project,
                                        plume_err *err);

/** Writes the 12x12 blocks of triangles first .. first + count - 1 at hblocks (triangle first's
 * first), as plume_midedge_bending_eval does; PLUME_ESINGULAR when a kernel fails (its id in err). */
plume_status plume_midedge_bending_blocks(const plume_midedge_bending *b, const double *x, const double *theta,
                                          plume_index first, plume_index count, double *hblocks, int project,
                                          plume_err *err);

/** Each triangle's energy at (x, theta) in e[nt]; PLUME_ESINGULAR when a kernel fails. */
plume_status plume_midedge_bending_energies(const plume_midedge_bending *b, const double *x, const double *theta,
                                            double *e, plume_err *err);

/** Each triangle's curvature kappa = B s (bb, tt, bt in its barb frame, 1/m) at (x, theta) in
 * kappa[3 nt]; PLUME_ESINGULAR when a slope is undefined (its triangle in err). */
plume_status plume_midedge_bending_curvatures(const plume_midedge_bending *b, const double *x, const double *theta,
                                              double *kappa, plume_err *err);

/** The unit director of edge e at (x, theta[e]). */
void plume_midedge_bending_director(const plume_midedge_bending *b, const double *x, const double *theta,
                                    plume_index e, double d[3]);

/** The angle of edge e at x whose director is d (any vector not along the edge; its part
 * perpendicular to the edge counts). Inverse of plume_midedge_bending_director. */
double plume_midedge_bending_angle_of(const plume_midedge_bending *b, const double *x, plume_index e,
                                      const double d[3]);

/** Re-bases the edges' reference vectors at x: each becomes its part perpendicular to the current
 * edge, normalised, so the director at (x, theta) does not change and the frame stays far from
 * its singularity (an edge turned onto its reference vector). Call between solves (a time step's
 * start, plume_term's lag). PLUME_EINVAL when an edge has already reached the singularity. */
plume_status plume_midedge_bending_lag(plume_midedge_bending *b, const double *x, plume_err *err);

/** Re-bases the frames on the current directors: each r0 becomes the director at (x, theta) and
 * theta is set to 0, so the energy and every director are unchanged and the state is the
 * directors alone (the integration's step start, docs/theory-bending-midedge.md). PLUME_EINVAL
 * when an edge has reached its frame's singularity (theta then partly reset: call it only on a
 * state that evaluates). */
plume_status plume_midedge_bending_rebase(plume_midedge_bending *b, const double *x, double *theta, plume_err *err);

/** The edges' reference vectors r0 [3 ne] (unit; theta = 0 is the part of r0 perpendicular to
 * the edge). */
const double *plume_midedge_bending_frames(const plume_midedge_bending *b);

/** Sets the reference vectors to r0 [3 ne], copied as they are (a restart's, as
 * plume_midedge_bending_frames gave them: the director normalises the part of r0 perpendicular to
 * its edge, so any length works). PLUME_EINVAL (nothing changed) when one is not finite or of zero
 * length. */
plume_status plume_midedge_bending_set_frames(plume_midedge_bending *b, const double *r0, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
