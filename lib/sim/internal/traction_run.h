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
    /* checkpoints and restarts (traction_checkpoint.c): the per-stencil states of the terms that
     * offer them (plume_term.states, concatenated in the terms' order), one row per point of the
     * curve, kept when o->checkpoint is set; the solver's memory a restart sets back when the
     * solver is created; the factorisations of the run before the restart */
    int *hist;
    long hist_rows, hist_cap;
    plume_index hist_cols;
    double memory;
    int restarted;
    int factorizations0;
    double factor_seconds0;
} traction_run;

/* lib/sim/traction_checkpoint.c */
/* The run's whole state after curve point k (its last nominal step) into o->checkpoint, replaced
 * atomically. */
plume_status plume_traction_checkpoint_write(const traction_run *r, int k, const plume_traction_result *res,
                                             plume_err *err);
/* The state of o->restart into a run placed and allocated as the first run was (its curve, sums,
 * history, the terms' state); *k: its last nominal step. Errors begin with "restart: " and name
 * the file and what differs. */
plume_status plume_traction_checkpoint_read(traction_run *r, int *k, plume_traction_result *res, plume_err *err);
/* Appends the current per-stencil states as a row of r->hist (when o->checkpoint is set). */
plume_status plume_traction_states_record(traction_run *r, plume_err *err);

#endif
