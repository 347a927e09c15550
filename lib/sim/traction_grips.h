/** \file
 * plume: the traction sample's grips and sides (lib/sim/traction.c): which vertices the grips hold,
 * the reaction they measure, the sides' mean transverse displacement, and barbs that would tie the
 * two grips together. */
#ifndef PLUME_TRACTION_GRIPS_H
#define PLUME_TRACTION_GRIPS_H

#include "../core/mesh.h"
#include "../core/status.h"

/* Which vertices sit on the grips and on the free sides (reference coordinates). */
typedef struct {
    plume_index *top, ntop, *left, nleft, *right, nright;
    unsigned char *bottom_flag, *top_flag;
    double lx, peel; /* the top grip moves by delta * plume_traction_grip_shape(g, X) */
} plume_traction_grips;

/** Finds the grips (y = 0, y = ly) and the free sides (x = 0, x = lx, sorted by y) in the reference
 * coordinates; PLUME_EINVAL (message) when the mesh's bounding box is not the sample's. peel: how
 * the top grip turns (plume_traction_opts.peel); top_free: the share of the top edge, from x = 0,
 * that the top grip leaves free (plume_traction_opts.top_grip_free). */
plume_status plume_traction_grips_find(const plume_mesh *m, double lx, double ly, double peel, double top_free,
                                       plume_traction_grips *g, plume_err *err);

/** How far a top-grip point at X moves per unit grip displacement: 1 - peel + peel X / lx (1 for a
 * straight pull; 0 at x = 0 and 1 at x = lx for a full peel). */
static inline double plume_traction_grip_shape(const plume_traction_grips *g, double X)
{
    return 1.0 - g->peel + g->peel * X / g->lx;
}
void plume_traction_grips_free(plume_traction_grips *g);

/** The trapezoidal integral over y of u_x along a side (vertices sorted by Y). */
double plume_traction_side_integral(const plume_mesh *m, const double *x, int dim, const plume_index *v,
                                    plume_index n);

/** The y-reaction on the moving grip as the virtual work of `force` over the field shape(X) Y/ly
 * (traction_grips.c says why): the force at the grip's far end that does the grip's work. */
double plume_traction_reaction_virtual_work(const plume_mesh *m, const plume_traction_grips *g, const double *force,
                                            int dim, double ly);

/** PLUME_EINFEASIBLE (message) when a chain of the nrigid inextensible edges joins the two grips. */
plume_status plume_traction_barbs_stretch_check(const plume_mesh *mesh, const plume_traction_grips *g,
                                                const plume_index *rigid_edges, plume_index nrigid, plume_err *err);

#endif
