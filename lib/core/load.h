/** \file
 * plume: dead loads — constant forces on vertices, energy -sum_v f_v . x_v. */
#ifndef PLUME_LOAD_H
#define PLUME_LOAD_H

#include "export.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A term applying force forces[dim*k ...] (N) to vertex vertices[k], k < n (arrays copied; the
 * term owns its copies, freed by its destroy). plume_load_scale multiplies every force (load
 * stepping). */
plume_status plume_load_term_create(const plume_index *vertices, plume_index n, int dim, const double *forces,
                                              plume_term *out, plume_err *err);
/** Sets every force of a term made by plume_load_term_create to `factor` times the force it was
 * created with (not cumulative: factor 1 restores the original load). */
void plume_load_scale(plume_term *load, double factor);

#ifdef __cplusplus
}
#endif
#endif
