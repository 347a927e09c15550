/** \file
 * plume: edge-length (inextensibility) constraints g = |x_i - x_j|^2 - L_ij^2 = 0 (docs/design.md). */
#ifndef PLUME_EDGE_LENGTH_H
#define PLUME_EDGE_LENGTH_H

#include "export.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A constraint set over `n` edges (pairs of vertex ids, copied) whose rest lengths are taken
 * from the reference positions X (2D, material space). Scale of constraint c is L_c^2, so the
 * relative violation |g|/L^2 is about twice the relative change of length. */
PLUME_API plume_status plume_edge_length_create(const plume_index *edges, plume_index n, const double *X,
                                                plume_index nv, plume_constraint *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
