/** \file
 * plume: broad phase of shell contact and the exact intersection audit (docs/design.md "Contact (many
 * feathers)"). Axis-aligned boxes are paired by CGAL's box_intersection_d; triangle pairs of the
 * audit are tested with CGAL's exact predicates. CGAL stays in lib/contact/contact_cgal.cpp. */
#ifndef PLUME_CONTACT_BROAD_H
#define PLUME_CONTACT_BROAD_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** One pair of ids (box, vertex/triangle or edge/edge ids, depending on the call). */
typedef struct {
    plume_index a; /**< first id (box of the first set, vertex, or the lower edge id) */
    plume_index b; /**< second id (box of the second set, triangle, or the higher edge id) */
} plume_contact_pair;

/** A growable list of pairs owned by the caller: start from {0} (or reuse one from an earlier call);
 * the library sets n and grows p with realloc only when cap is too small, so a list reused across
 * calls stops allocating. Free with plume_contact_pairs_free. */
typedef struct {
    plume_index n;         /**< output: pairs found */
    plume_index cap;       /**< capacity of p, in pairs */
    plume_contact_pair *p; /**< [cap]; pairs sorted by (a, b) */
} plume_contact_pairs;

/** Frees p and zeroes the list; NULL-safe. */
void plume_contact_pairs_free(plume_contact_pairs *pairs);

/* --- Generic box intersection ------------------------------------------------------------------
 * A box is 6 doubles: lo x, lo y, lo z, hi x, hi y, hi z (finite, lo <= hi). Boxes are closed:
 * boxes that only touch (a face, an edge or a corner) intersect. These calls copy the boxes into
 * temporary arrays (CGAL reorders what it is given); the contact handle below reuses its memory. */

/** All pairs (i, j), i a box of a (na boxes), j a box of b (nb boxes), whose boxes intersect; each
 * once, sorted. na or nb may be 0. PLUME_EINVAL (message in err) on NULL arrays with a positive
 * count, negative counts, non-finite coordinates or lo > hi; PLUME_ENOMEM; PLUME_EDEP if CGAL threw. */
plume_status plume_contact_box_pairs(plume_index na, const double *a, plume_index nb, const double *b,
                                               plume_contact_pairs *out, plume_err *err);

/** All pairs (i, j), i < j, of intersecting boxes within one set (never (i, i), never twice). */
plume_status plume_contact_box_self_pairs(plume_index n, const double *boxes, plume_contact_pairs *out,
                                                    plume_err *err);

/* --- Candidate pairs of a triangle surface -----------------------------------------------------
 * Every pair whose primitives may come closer than dhat during a step, for the narrow phase:
 * point-triangle (vertex v, triangle t), v not a corner of t, and edge-edge (edge a, edge b), a < b,
 * with no shared vertex. Each primitive's box bounds it at the step's start x and end x1 (a
 * vertex moving on a straight line between them stays inside) and is inflated by dhat/2 on every
 * side, so a pair closer than dhat at any time of the step is a candidate (proof in
 * contact_broad.c). Candidates are a superset: the narrow phase computes the distances. */

/** Options of the candidate search (plume_contact_broad_opts_default). */
typedef struct {
    int self_contact; /**< 1: every pair of non-adjacent primitives (within a body too);
                         0: only pairs of primitives of different bodies (needs body). Default 1. */
    int reuse;        /**< 1: keep the pairs of boxes inflated by a reach R at a reference placement, and
                         answer each update whose boxes fit in them (every vertex within R - r of
                         its reference, r the update's inflation) by testing those pairs alone: the
                         same candidates, in the same order, without a new search. For a handle
                         queried again and again as a body moves a little (a contact term: the
                         stencil updates and every Newton step's CCD). Default 0. */
    const plume_index *weld; /**< NULL (default), or [nv] (copied): the vertex each one stands for when
                         adjacency is decided, so that primitives sharing a welded vertex are never
                         a pair: the two lips of a split line (a copy welded to its original,
                         macro/shell/split_lines.h) touch where they coincide as neighbours do */
} plume_contact_broad_opts;

/** Fills o with the defaults (self_contact 1, reuse 0). */
void plume_contact_broad_opts_default(plume_contact_broad_opts *o);

/** Opaque broad phase of one triangle surface: its topology, edges, box arrays and candidate lists,
 * reused from update to update (plume_contact_broad_create, freed by plume_contact_broad_destroy). */
typedef struct plume_contact_broad plume_contact_broad;

/** Candidates found by one update. The arrays belong to the handle and stay valid until the next
 * update or destroy (an empty list may be NULL). */
typedef struct {
    plume_index nvt;              /**< point–triangle candidates */
    const plume_contact_pair *vt; /**< [nvt] (vertex, triangle), sorted */
    plume_index nee;              /**< edge–edge candidates */
    const plume_contact_pair *ee; /**< [nee] (edge a, edge b), a < b, ids into the handle's edges */
    double seconds;               /**< wall time of this update (boxes, CGAL, filters, sorting) */
} plume_contact_candidates;

/** Fixes the topology: nv vertices, ntri triangles tri [3*ntri] (copied), body [nv] a body id per
 * vertex (copied) or NULL for one body. Builds the unique undirected edges and allocates every box
 * array. PLUME_EINVAL (message in err) on negative counts, NULL arrays, triangle ids out of
 * [0, nv), a triangle with a repeated vertex, a triangle whose corners lie in different bodies, or
 * self_contact = 0 without body; PLUME_ENOMEM. On failure *out is NULL and nothing is kept. */
plume_status plume_contact_broad_create(plume_index nv, plume_index ntri, const plume_index *tri,
                                                  const int *body, const plume_contact_broad_opts *opts,
                                                  plume_contact_broad **out, plume_err *err);
/** Frees the handle and every array it owns (the candidates it returned included); sets *b = NULL;
 * NULL-safe. */
void plume_contact_broad_destroy(plume_contact_broad **b);

/** The unique undirected edges built at create: *edges is [2 * *ne], each (i, j) with i < j, sorted;
 * owned by the handle. Edge ids of the candidates index this array. */
void plume_contact_broad_edges(const plume_contact_broad *b, plume_index *ne, const plume_index **edges);

/** The triangles copied at create: *tri is [3 * *ntri], owned by the handle. Triangle ids of the
 * candidates index this array. */
void plume_contact_broad_triangles(const plume_contact_broad *b, plume_index *ntri, const plume_index **tri);

/** Candidates for positions x [3*nv] (start of the step) and x1 [3*nv] (end of the step, or NULL for
 * a static query), inflation dhat >= 0. Allocates only when the candidate lists outgrow their
 * capacity. PLUME_EINVAL (message in err) on NULL b/x/out, non-finite coordinates (naming the
 * vertex) or a negative or non-finite dhat; PLUME_ENOMEM; PLUME_EDEP if CGAL threw. On failure
 * out is zeroed. */
plume_status plume_contact_broad_update(plume_contact_broad *b, const double *x, const double *x1,
                                                  double dhat, plume_contact_candidates *out, plume_err *err);

/** Updates since create and their total wall time (benchmarks and reports); NULL-safe. */
void plume_contact_broad_stats(const plume_contact_broad *b, long *updates, double *seconds);

/** With reuse: how many of the updates ran a new box search (the others filtered the kept pairs);
 * 0 when b is NULL. */
long plume_contact_broad_searches(const plume_contact_broad *b);

/* --- Exact intersection audit ------------------------------------------------------------------ */

/** The result of plume_contact_count_intersections. */
typedef struct {
    plume_index intersecting; /**< pairs of triangles with no common vertex that intersect */
    plume_index degenerate;   /**< triangles with exactly collinear corners (zero area): tested as
                                 the segment or point they are, and counted here */
    double seconds;           /**< wall time of the audit */
} plume_contact_audit;

/** Counts the pairs of triangles (tri [3*ntri] over x [3*nv]) that share no vertex and intersect,
 * closed triangles, exact predicates (CGAL Epick): touching counts, a corner lying on another
 * triangle counts. Every body of a scene is one surface here (bodies share no vertex). Pairs that
 * share a vertex are never counted, even when a fold makes them cross elsewhere. Broad phase:
 * boxes without inflation. pairs (or NULL): the intersecting pairs (t1 < t2), sorted.
 * A triangle with a repeated vertex id is degenerate like any zero-area one, not an error.
 * PLUME_EINVAL (message in err) on NULL arrays, negative counts, ids out of range or non-finite
 * coordinates; PLUME_ENOMEM; PLUME_EDEP if CGAL threw. On failure *out and pairs->n are zero. */
plume_status plume_contact_count_intersections(plume_index nv, const double *x, plume_index ntri,
                                                         const plume_index *tri, plume_contact_pairs *pairs,
                                                         plume_contact_audit *out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
