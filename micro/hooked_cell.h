/** \file
 * plume (micro): the periodic cell of a layout with hooks, opened at its barbules' distal joins and
 * held there by one hook (docs/unzipping.md, "The separation law of a barb line"). The barbule's
 * nodes on the cell's top edge, periodic images of the next barb's bottom edge in the bonded cell,
 * get copies periodic only along the barbs, and the hook holds each copy to its image; the
 * membrane and the hook are each wrapped by the periodic map, so the hook's force enters the
 * cell's average stress. The separation law (separation_cell.c) and the hooked cell's tensor
 * (separation_tensor.c) are measured on it. */
#ifndef PLUME_MICRO_HOOKED_CELL_H
#define PLUME_MICRO_HOOKED_CELL_H

#include "../include/plume/homogenize.h"
#include "../lib/core/hooks.h"
#include "cell_mesh.h"
#include "periodic.h"

/* The cell opened at its distal joins: its mesh and quadratic triangles with the copies, the
 * periodic map extended to them, and the hook's pairs. */
typedef struct {
    plume_cell cell;          /* mesh, quad, master, shift owned here */
    plume_index ncopy;        /* copies: vertices nv0 .. nv0 + ncopy - 1 */
    plume_index npairs;
    plume_index *pairs;       /* [2 npairs] (copy, image) */
} opened_cell;

/* The opened cell's problem: the membrane and the hook, each wrapped periodically; non-masters
 * and the anchor (the master at the origin) fixed. */
typedef struct {
    opened_cell oc;
    plume_hooks *hooks;       /* borrowed by the hook term; freed after the problem */
    plume_term hook;          /* that term (its keep saves and restores the hook's state) */
    plume_problem *p;
    plume_solver *s;
    plume_periodic *per[2];   /* membrane, hook */
    double *u, *grad, *xfull; /* xfull [2 nv]: every vertex, periodic images placed */
    double F[4];
    int iterations, solves;
} plume_hooked_cell;

/** Meshes the layout's bonded cell, opens it and builds its problem with the layout's hook law,
 * F = I. PLUME_EINVAL for an invalid layout or one without explicit barbules held by hooks (the
 * message begins with `what`). Free with plume_hooked_cell_free, also after an error. */
plume_status plume_hooked_cell_init(plume_hooked_cell *c, const plume_layout *l, const char *what, plume_err *err);

/** Frees what plume_hooked_cell_init built. */
void plume_hooked_cell_free(plume_hooked_cell *c);

/** Solves at the average deformation gradient F (row-major; the previous fluctuation on the new
 * affine map): the average membrane stress P (N/m, row-major, membrane and hook) and the energy
 * (J); c->xfull then holds every vertex. PLUME_EINFEASIBLE with the reason when the solve does not
 * converge. */
plume_status plume_hooked_cell_solve_F(plume_hooked_cell *c, const double F[4], double P[4], double *energy,
                                       plume_err *err);

/** plume_hooked_cell_solve_F at the opening e, F = [1 0; 0 1 + e] (no stretch along the stiff barbs,
 * no shear): the traction across the barb line, its magnitude |(P_xy, P_yy)| and its normal part
 * P_yy (N/m). Only the hook crosses the line, so the magnitude is the hook's force per period. */
plume_status plume_hooked_cell_open(plume_hooked_cell *c, double e, double *traction, double *normal, double *energy,
                                    plume_err *err);

/** The hook's load |F| / strength at the last solve. */
double plume_hooked_cell_load(const plume_hooked_cell *c);

#endif
