/* plume (private, not installed): the C entry points of the contact CGAL shim (lib/contact/contact_cgal.cpp),
 * used by lib/contact/contact_broad.c. Inputs are validated by the caller; the shim only catches what CGAL
 * or the allocator throws.
 * Note: the Makefile's .cpp rule lists the public headers but not lib/internal ones as
 * prerequisites; after changing this header, remove build/lib/contact_cgal.o. */
#ifndef PLUME_INTERNAL_CONTACT_CGAL_H
#define PLUME_INTERNAL_CONTACT_CGAL_H

#include "../contact_broad.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A box as CGAL's box_intersection_d sees it. The caller fills lo and hi in index order; the shim
 * sets id (the index, made unique across the two sets of a bipartite call) and CGAL then reorders
 * the array in place, so its order is unspecified on return. */
typedef struct {
    double lo[3], hi[3];
    plume_index id;
} plume_box;

/* Memory the pair searches reuse, owned by the caller: start from {0}, free with
 * plume_pair_ws_free. The shim grows it with realloc only when it is too small. */
typedef struct {
    plume_contact_pairs raw; /* kept pairs in CGAL's order, before sorting */
    plume_contact_pairs tmp; /* the pairs sorted by second id (the first pass of the sort) */
    plume_index *count;      /* [count_cap] offsets of the counting sorts */
    plume_index count_cap;
} plume_pair_ws;

void plume_pair_ws_free(plume_pair_ws *ws);

/* Filter on an intersecting pair of indices: nonzero keeps it. */
typedef int (*plume_box_keep_fn)(void *ctx, plume_index i, plume_index j);

/* Pairs (i, j) of intersecting closed boxes, i in a, j in b, kept by keep (NULL keeps all), into
 * out (n reset, grown with realloc, sorted by (i, j)). The coordinates of a and b are permuted
 * and the arrays reordered in place. */
plume_status plume_cgal_box_pairs(plume_box *a, plume_index na, plume_box *b, plume_index nb,
                                  plume_box_keep_fn keep, void *ctx, plume_pair_ws *ws,
                                  plume_contact_pairs *out, plume_err *err);

/* Pairs (i, j), i < j, of intersecting closed boxes within one set. scratch [n] is overwritten
 * (CGAL's self intersection scans the set against a copy of itself). */
plume_status plume_cgal_box_self_pairs(plume_box *boxes, plume_box *scratch, plume_index n,
                                       plume_box_keep_fn keep, void *ctx, plume_pair_ws *ws,
                                       plume_contact_pairs *out, plume_err *err);

/* The audit's exact stage: over intersecting pairs of the triangle boxes (boxes, scratch [ntri]),
 * the pairs of triangles sharing no vertex that intersect (exact predicates). *count gets their
 * number, *degenerate the number of zero-area triangles; pairs (or NULL) gets the list, sorted. */
plume_status plume_cgal_triangle_intersections(plume_box *boxes, plume_box *scratch, plume_index ntri,
                                               const double *x, const plume_index *tri,
                                               plume_contact_pairs *pairs, plume_index *count,
                                               plume_index *degenerate, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
