/* plume (private, not installed): a uniform grid of square cells over a box, each cell listing
 * the items (ids) whose bounding box overlaps it; the feather mesher's spatial index. */
#ifndef PLUME_MACRO_INTERNAL_BINS_H
#define PLUME_MACRO_INTERNAL_BINS_H

#include <math.h>

#include "../../../lib/core/status.h"

/* Zeroed by plume_bins_init; arrays owned, freed by plume_bins_free. */
typedef struct {
    double x0, y0, h;
    long nx, ny;
    plume_index *head; /* [nx ny] first node, -1 */
    plume_index *next, *item;
    plume_index n, cap;
} plume_bins;

/* Cells of side h over [x0, x1] x [y0, y1] (plus one); 0, or -1 when memory runs out. */
int plume_bins_init(plume_bins *g, double x0, double y0, double x1, double y1, double h);
void plume_bins_free(plume_bins *g);
/* Registers `item` in every cell its box (xa, ya)-(xb, yb) overlaps; 0, or -1 (no memory). */
int plume_bins_add(plume_bins *g, plume_index item, double xa, double ya, double xb, double yb);

/* Cell range [r0, r1] x [r2, r3] of a box, clamped to the grid (inline: every query calls it). */
static inline void plume_bins_range(const plume_bins *g, double xa, double ya, double xb, double yb, long r[4])
{
    double lo[2] = {fmin(xa, xb), fmin(ya, yb)}, hi[2] = {fmax(xa, xb), fmax(ya, yb)};
    long i0 = (long)floor((lo[0] - g->x0) / g->h), i1 = (long)floor((hi[0] - g->x0) / g->h);
    long j0 = (long)floor((lo[1] - g->y0) / g->h), j1 = (long)floor((hi[1] - g->y0) / g->h);
    r[0] = i0 < 0 ? 0 : i0 >= g->nx ? g->nx - 1 : i0;
    r[1] = i1 < 0 ? 0 : i1 >= g->nx ? g->nx - 1 : i1;
    r[2] = j0 < 0 ? 0 : j0 >= g->ny ? g->ny - 1 : j0;
    r[3] = j1 < 0 ? 0 : j1 >= g->ny ? g->ny - 1 : j1;
}

#endif
