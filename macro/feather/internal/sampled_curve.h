/* plume (private, not installed): a curve sampled densely (positions, arc length, tangent angle)
 * and the natural cubic spline sampling of an input polyline, for the feather mesher. */
#ifndef PLUME_MACRO_INTERNAL_SAMPLED_CURVE_H
#define PLUME_MACRO_INTERNAL_SAMPLED_CURVE_H

#include "../../../lib/core/status.h"
#include "../feather_mesh.h"

/* Samples of a curve: positions, arc length s, tangent angle a (unwrapped). */
/* Zero-initialise ({0}); arrays owned, freed by plume_sampled_curve_free. */
typedef struct {
    double *x, *y, *s, *a;
    plume_index n, cap;
} plume_sampled_curve;

void plume_sampled_curve_free(plume_sampled_curve *c);
/* Appends a sample (x, y); 0, or -1 when memory runs out. */
int plume_sampled_curve_push(plume_sampled_curve *c, double x, double y);
/* Arc length from the first sample and tangent angles by central differences, unwrapped. */
void plume_sampled_curve_finish(plume_sampled_curve *c);
/* Samples the natural cubic spline (linear for two points, chord-length parameter) through a
 * validated polyline about every h, at least 16 samples, every input point among them; appends
 * to *out. PLUME_ENOMEM on allocation failure. */
plume_status plume_sample_spline(const plume_polyline *pl, double h, plume_sampled_curve *out);

#endif
