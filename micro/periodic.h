/** \file
 * plume: periodic boundary conditions by construction — a wrapper that lets any term defined on a
 * periodic cell's vertices act on the cell's master vertices, with x_v = x_master(v) + Fbar shift_v
 * (Fbar the imposed macroscopic deformation gradient), and gives the cell's average stress. */
#ifndef PLUME_PERIODIC_H
#define PLUME_PERIODIC_H

#include "../lib/core/export.h"
#include "../lib/core/problem.h"
#include "../lib/core/term.h"
#include "cell_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque handle on a periodic wrapper's data, owned by the wrapped term (and so by the problem
 * that holds it): sets Fbar and reads the average stress; never freed by the caller. */
typedef struct plume_periodic plume_periodic;

/** Wraps `inner` (a planar term over the cell mesh's vertices; ownership is taken, also on
 * failure). `*out` is the wrapped term to add to a problem over the cell's nv vertices, in which
 * the non-master vertices must be fixed (their coordinates are never read). `*handle` stays
 * valid while the term lives (the problem owns it) and sets Fbar / reads the average stress. */
plume_status plume_periodic_term_create(const plume_cell *cell, const plume_term *inner, plume_periodic **handle,
                                                  plume_term *out, plume_err *err);

/** Puts a cell problem (created over the cell mesh's nv vertices, not finalised) at rest and holds
 * it: every vertex at its reference position, the non-master vertices fixed (the wrapper never
 * reads them) and one anchor fixed against rigid translation, the master at the origin if there
 * is one (so that Fbar X = 0 there), else the master of vertex 0. */
void plume_periodic_hold(const plume_cell *cell, plume_problem *p, plume_err *err);

/** Sets the macroscopic deformation gradient (2x2 row-major); identity at creation. */
void plume_periodic_set_macro(plume_periodic *h, const double Fbar[4]);

/** Average first Piola–Kirchhoff membrane stress (N/m, 2x2 row-major) = (1/A_cell) dW/dFbar, from
 * the forces of the last evaluation that computed a gradient (call plume_problem_objective with a
 * gradient at the equilibrium first). Exact at equilibrium of the master vertices. */
void plume_periodic_average_stress(const plume_periodic *h, double P[4]);

#ifdef __cplusplus
}
#endif
#endif
