/** \file
 * plume: a growable planar straight-line graph (points and segments), the input every mesher in
 * plume builds for the constrained Delaunay triangulation (lib/core/cdt.h). */
#ifndef PLUME_PSLG_H
#define PLUME_PSLG_H

#include "export.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Zero-initialise ({0}) before use; arrays owned, freed by plume_pslg_free. */
typedef struct {
    double *p;          /**< [2 n] points */
    plume_index n;      /**< points in use */
    plume_index cap;    /**< points allocated */
    plume_index *s;     /**< [2 ns] segments (point ids) */
    plume_index ns;     /**< segments in use */
    plume_index scap;   /**< segments allocated */
} plume_pslg;

/** Appends a point; returns its id, or -1 when memory runs out. */
plume_index plume_pslg_point(plume_pslg *g, double x, double y);
/** Appends the segment (a, b); 0, or -1 when memory runs out. */
int plume_pslg_segment(plume_pslg *g, plume_index a, plume_index b);
/** Frees the points and segments and zeroes the graph, ready for reuse. */
void plume_pslg_free(plume_pslg *g);

/** Barb direction for an angle (degrees) from the pulling axis y toward +x: d = (sin a, cos a),
 * exact on the axes (0, 90, 180 degrees). */
void plume_barb_direction(double angle_deg, double d[2]);

#ifdef __cplusplus
}
#endif
#endif
