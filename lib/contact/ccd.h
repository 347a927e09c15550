/** \file
 * plume: continuous collision detection of point–triangle and edge–edge pairs moving linearly over
 * a step, by Additive CCD (Li, Kaufman, Jiang, "Codimensional Incremental Potential Contact", ACM
 * TOG 40(4), 2021, Algorithm 1). ACCD needs only the pair's distance: the relative speed of the
 * two closest points is at most l_p (a bound from the vertex displacements), so advancing by
 * eta * gap / l_p can never close the gap. Conservative by construction, with no root finding; a
 * barrier line search limits its step to the smallest toi over the candidate pairs.
 *
 * Positions follow x(t) = x0 + t (x1 - x0), t in [0, t_max], with x0, x1 12-vectors in the
 * vertex order of contact_narrow.h: (p, t0, t1, t2) or (ea0, ea1, eb0, eb1). The gap is
 * d(t) - min_distance, d the unsigned pair distance of contact_narrow.h. Nothing allocates.
 *
 * Rounding: the guarantees below hold up to the error of the computed distance, ~1e-16 L for
 * primitives of size L and at most ~1e-8 L for edges within 1e-8 rad of parallel or triangles
 * flatter than that (the fallback of PLUME_CONTACT_PARALLEL_SIN2 overestimates by up to L sin).
 * The (1 - eta) s gap(0) margin absorbs it unless gap(0) is below ~1e-6 L. */
#ifndef PLUME_CCD_H
#define PLUME_CCD_H

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Options of one CCD call (plume_ccd_opts_default; a NULL pointer means the defaults). */
typedef struct {
    double s;            /**< in (0, 1): toi is where the gap may have shrunk to s gap(0); default 0.1 */
    double min_distance; /**< xi >= 0: a thickness, the gap is d - xi; default 0 */
    double eta;          /**< in (0, 1): steps after the first advance eta gap / l_p; default 0.9 */
    long max_iter;       /**< >= 1: cap on distance evaluations per call; default 1000000 */
} plume_ccd_opts;

/** What one call did (optional output). */
typedef struct {
    long iterations;  /**< distance evaluations after the start one */
    int hit;          /**< 1: toi < t_max (the gap may fall below s gap(0) after toi, or capped) */
    int capped;       /**< 1: max_iter was reached; toi is the last certified time (safe, early) */
    double gap_start; /**< d(0) - xi */
    double gap_toi;   /**< d(toi) - xi as evaluated (first step: certified analytically) */
} plume_ccd_report;

/** Fills o with the defaults above (s 0.1, min_distance 0, eta 0.9, max_iter 10^6); NULL-safe. */
void plume_ccd_opts_default(plume_ccd_opts *o);

/** Conservative time of impact of a point–triangle pair over [0, t_max] (0 < t_max <= 1).
 * On PLUME_OK, *toi in (0, t_max] with
 *   gap(t) >= (1 - eta) s gap(0) > 0 for every t in [0, toi], and gap(toi) >= s gap(0);
 * *toi = t_max when the gap stays above s gap(0) over the whole step (no contact), and also when
 * the pair has no relative motion. A pair already at gap(0) <= 0 returns PLUME_EINFEASIBLE with
 * *toi = 0 (no step is safe). PLUME_EINVAL: NULL x0, x1, toi, non-finite coordinates, t_max
 * outside (0, 1], options out of range (o NULL means the defaults). rep may be NULL. */
plume_status plume_ccd_point_triangle(const double x0[12], const double x1[12], double t_max,
                                                const plume_ccd_opts *o, double *toi, plume_ccd_report *rep);

/** The same for an edge–edge pair (ea0, ea1, eb0, eb1), including parallel and zero-length edges. */
plume_status plume_ccd_edge_edge(const double x0[12], const double x1[12], double t_max,
                                           const plume_ccd_opts *o, double *toi, plume_ccd_report *rep);

#ifdef __cplusplus
}
#endif
#endif
