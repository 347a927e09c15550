/* plume (private, not installed): the state of a traction run (lib/sim/traction.c), shared with its
 * checkpoint (lib/sim/traction_checkpoint.c). */
#ifndef PLUME_INTERNAL_TRACTION_RUN_H
#define PLUME_INTERNAL_TRACTION_RUN_H

#include "../../core/mesh.h"
#include "../../core/problem.h"
#include "../../solve/solver.h"
#include "../traction.h"
#include "../traction_grips.h"

/* The last two converged states of a run (positions, multipliers, grip displacements), the
 * predictor's history: a is the latest. */
typedef struct {
    double *xa, *xb, *la, *lb;
    double da, db;
} history;

/* plume_traction_run's inputs and workspaces, shared by the jobs it is split into */
typedef struct {
    const plume_mesh *mesh;
    plume_problem *p;
    const plume_traction_opts *o;
    plume_traction_grips g;
    plume_solver *solver;    /* created at the first step */
    int dim;
    double *x;               /* the problem's positions */
    plume_index n, m;        /* free dofs, constraints */
    double *u, *lambda, *lambda_saved, *force;
    history h;
    double inc;              /* the current increment (adaptive stepping) */
    double nominal;          /* the nominal increment of the current leg (grip displacement) */
    /* the energy balance: the reaction and energy at the last accepted equilibrium, the energy at
     * rest, the sums over the accepted increments, and the current increment's share */
    double F_eq, E_eq, E_rest;
    double work, gross_work, dissipated, peak;
    long released, reengaged;
    int cascade, events;
    struct {
        double work, dissipated, F, E, peak;
        long released, reengaged;
        int cascade, events;
    } inc_energy;
} traction_run;

#endif
