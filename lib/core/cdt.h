/** \file
 * plume: constrained Delaunay triangulation (CGAL, behind a C++ shim with C entry points). */
#ifndef PLUME_CDT_H
#define PLUME_CDT_H

#include "export.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Input of a triangulation. All arrays are owned by the caller. */
typedef struct {
    plume_index npoints;       /**< number of input points */
    const double *points;      /**< [2*npoints] */
    plume_index nsegments;     /**< number of constrained segments (0: none) */
    const plume_index *segments; /**< [2*nsegments] point ids: constrained edges (kept as edges,
                                    possibly split by refinement into collinear pieces) */
    plume_index nholes;        /**< number of hole seeds (0: none) */
    const double *holes;       /**< [2*nholes] a point inside each hole; the region reached from it
                                  without crossing a constrained segment is removed */
    int remove_exterior;       /**< 1: drop triangles outside the outermost constrained boundary */
    double max_edge;           /**< > 0: refine (CGAL Delaunay mesher) until edges are <= max_edge;
                                  0: no refinement, vertices are exactly the input points */
    double min_angle_bound;    /**< refinement shape bound B (CGAL criteria 0.125 ~ 20.7 deg);
                                  0 selects 0.125 */
} plume_cdt_input;

/** Output, allocated by plume_cdt_triangulate with malloc, freed by plume_cdt_output_free. */
typedef struct {
    plume_index npoints;       /**< number of output points (>= the input's) */
    double *points;            /**< [2*npoints]; the input points come first, in input order */
    plume_index ntriangles;    /**< number of triangles */
    plume_index *triangles;    /**< [3*ntriangles] counter-clockwise */
} plume_cdt_output;

/** Triangulates; never throws; on failure returns PLUME_EINVAL (bad input: NaN, out-of-range
 * segment ids, zero points) or PLUME_EDEP (CGAL raised), with a message in err. */
plume_status plume_cdt_triangulate(const plume_cdt_input *in, plume_cdt_output *out, plume_err *err);
/** Frees the arrays of an output filled by plume_cdt_triangulate and zeroes it; NULL-safe. */
void plume_cdt_output_free(plume_cdt_output *out);

#ifdef __cplusplus
}
#endif
#endif
