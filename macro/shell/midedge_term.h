/** \file
 * plume: midedge bending (midedge_bending.h) as a term of a problem. The edge angles become
 * unknowns of the problem, after the vertices' coordinates (plume_problem_add_unknowns): edge e's
 * unknown is phi_e = L_e theta_e, its angle times its rest length, so that it is a length like the
 * coordinates (the solvers' step tests are lengths times length_scale) and its force dE/dphi a
 * force (the KKT residual compares it with the vertices'). Each triangle is a stencil of its three
 * vertices and its three edges' unknowns (plume_term.nextra = 3): a 12x12 block.
 *
 * The frames the angles are measured in are re-based at every step's start (plume_term.rebase):
 * each edge's reference vector becomes its director and its angle 0. The term's state is its
 * frames with the edge unknowns; a frames file stores both, so a restart continues bit for bit. */
#ifndef PLUME_MIDEDGE_TERM_H
#define PLUME_MIDEDGE_TERM_H

#include "../../lib/core/problem.h"
#include "midedge_bending.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Options of plume_midedge_term_add (all zero: none). */
typedef struct {
    const double *rest_dir;    /**< [3 ne] rest directors (plume_midedge_bending_opts), or NULL */
    /** [nv] or NULL: the rigid group holding each vertex, 0 for none (a clamp, a handle: one number
     * each, > 0). The angle of an edge whose two vertices share a group is fixed: its director is
     * the rest director carried by the group's frame (three of its vertices, internal/midedge_anchor.h),
     * so the surface leaves a clamp in the clamp's plane and turns with a turning handle; the edges
     * of a group whose vertices lie on one line keep the directors they start with (the mean of
     * their faces' normals; plume_midedge_term_group_anchored says which groups have frames). */
    const int *group;
    /** [nv] or NULL: bit a (1, 2, 4 for x, y, z) when the vertex lies on a symmetry plane normal to
     * axis a (its coordinate a held). An edge whose two vertices share such a plane (the same bit,
     * the same rest coordinate) and no group is a symmetry edge: its director stays in the plane
     * (a symmetric surface's normal does), its angle fixed at its rest director, which must lie in
     * the plane (PLUME_EINVAL naming the edge otherwise: the rest is not symmetric there). */
    const unsigned char *sym;
} plume_midedge_term_opts;

/** The term's data, kept by the problem (its ctx) and readable by whoever built it. */
typedef struct plume_midedge_term plume_midedge_term;

/** Adds the edge unknowns (mesh->ne of them, the first at *first) and the term to p, which owns
 * it. Call it after the vertex part of plume_problem_x(p) holds the start positions: each edge's
 * angle starts at the mean of its faces' current normals (the rest director on held edges), and
 * the held edges' unknowns are fixed. *term (may be NULL) gets the term's data, valid while p
 * lives. Errors as plume_midedge_bending_create's, and PLUME_EINVAL when a start angle is undefined
 * (a face collapsed at the start). */
plume_status plume_midedge_term_add(plume_problem *p, const plume_mesh *mesh, const plume_bending_material *mats,
                                    int nmat, const double *rest_x, const plume_midedge_term_opts *o,
                                    plume_index *first, plume_midedge_term **term, plume_err *err);

/** The name of the term in its problem (plume_problem_term_ctx finds it by it). */
#define PLUME_MIDEDGE_TERM_NAME "midedge bending"

/** A term for output that reads t, the term of problem p, without owning it: its triangles'
 * energies (energies) and the energy (eval, no gradient or blocks) at the positions it is given
 * (3 nv) and the angles p's x holds (the state, between steps); valid while p lives. PLUME_ENOMEM. */
plume_status plume_midedge_term_view(plume_midedge_term *t, plume_problem *p, plume_term *out);

/** A view's curvatures (its ctx, plume_term.ctx of plume_midedge_term_view's term): each triangle's
 * kappa = B s (bb, tt, bt in its barb frame, 1/m) at positions x (3 nv) and the problem's angles, in
 * kappa [3 nt] (plume_fields_set_curvatures takes it). PLUME_ESINGULAR when a slope is undefined. */
plume_status plume_midedge_term_view_curvatures(void *view_ctx, int dim, const double *x, double *kappa);

/** The bending energy the term sums (its mesh, frames, faces). */
const plume_midedge_bending *plume_midedge_term_bending(const plume_midedge_term *t);

/** The edge angles theta[ne] of the full vector x. */
void plume_midedge_term_angles(const plume_midedge_term *t, const double *x, double *theta);

/** The edges' unit directors at the full vector x, d[3 ne]. */
void plume_midedge_term_directors(const plume_midedge_term *t, const double *x, double *d);

/** The edges (mesh->ne), and the index of the first edge unknown in the problem's full vector. */
plume_index plume_midedge_term_nedge(const plume_midedge_term *t);
plume_index plume_midedge_term_first(const plume_midedge_term *t);

/** The frames the angles are measured in, r0 [3 ne]: with the edge unknowns, the term's state (a
 * frames file stores both, and a restart sets both back). */
const double *plume_midedge_term_frames(const plume_midedge_term *t);

/** 1 when group g (plume_midedge_term_opts.group) has anchors: its edges' directors turn with it. */
int plume_midedge_term_group_anchored(const plume_midedge_term *t, int g);

/** Sets the frames to r0 [3 ne], bit for bit (plume_midedge_bending_set_frames). */
plume_status plume_midedge_term_set_frames(plume_midedge_term *t, const double *r0, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
