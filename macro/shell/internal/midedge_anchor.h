/* Anchored edge frames of midedge bending (midedge_bending.c): an edge held by a rigid group of
 * vertices (a clamp, a handle, a kinematic body) keeps its director fixed in that group's frame,
 * so the director turns with the group however it moves (docs/theory-bending-midedge.md,
 * "Boundary conditions"). The group's frame at x is built from three of its vertices (p0, p1, p2:
 * e1 along p1 - p0, e3 normal to p0 p1 p2, e2 = e3 x e1); edge e's reference vector at x is
 * F(x) F(rest)^T r0_rest. It depends on the anchors' positions only, which the group holds fixed
 * in a solve, so a triangle's kernel sees it as a constant. */
#ifndef PLUME_MIDEDGE_ANCHOR_H
#define PLUME_MIDEDGE_ANCHOR_H

#include "../../../lib/core/mesh.h"

/** Three anchor points this close to one line (the doubled area of p0 p1 p2 over |p1 - p0|^2)
 * give no frame. */
#define MIDEDGE_ANCHOR_MIN_SPREAD 1e-6

typedef struct {
    plume_index ne;
    plume_index *vertex; /* [3 ne]: p0, p1, p2 of edge e, or -1 when e has no anchors */
    double *local;       /* [3 ne]: r0_rest in the anchors' rest frame */
} plume_midedge_anchors;

/* Vertex v's rest position: rest_x [3 nv], or (X, 0) when rest_x is NULL. */
void plume_midedge_rest_point(const plume_mesh *m, const double *rest_x, plume_index v, double p[3]);

/* Each rigid group's anchors at rest into anchor [3 ngroup]: vertices of group g (group [nv]: 0 for
 * none, else 1 .. ngroup - 1) p0 (its first), p1 (the farthest from p0) and p2 (the farthest from
 * line p0 p1), or -1 in all three when the group has no three vertices off one line. 0, or -1 when
 * memory ran out. */
int plume_midedge_group_anchors(const plume_mesh *m, const double *rest_x, const int *group, int ngroup,
                                plume_index *anchor);

/* The anchors of the edges whose anchor[3 e] >= 0 (anchor [3 ne] may be NULL: none), from rest
 * positions rest [3 nv] and rest reference vectors r0 [3 ne]. PLUME_EINVAL (naming the edge) for
 * an anchor out of [0, nv) or three anchors on one line; PLUME_ENOMEM. */
plume_status plume_midedge_anchors_init(plume_midedge_anchors *a, plume_index ne, plume_index nv,
                                        const plume_index *anchor, const double *rest, const double *r0,
                                        plume_err *err);

void plume_midedge_anchors_free(plume_midedge_anchors *a);

/* 1 and edge e's reference vector at x [3 nv] in out, when e is anchored; 0 (out untouched) when
 * not, or when its anchors have collapsed onto a line at x. */
int plume_midedge_anchors_frame(const plume_midedge_anchors *a, const double *x, plume_index e, double out[3]);

#endif
