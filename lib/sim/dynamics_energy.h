/* plume (private, not installed): the energy ledger of the implicit Euler stepper
 * (lib/sim/dynamics.c; docs/apps/feather.md, "The energy balance"). At every accepted step it adds the
 * handles' work and what the step gave up, so that
 *     work = (KE - KE0) + (U - U0) + numerical + commits + residual,
 * U the potential (every term but the inertia's quadratic part: elastic, contact, gravity), KE the
 * kinetic energy of the lumped masses. With v' = (x' - x) / dt and the step's stationarity at the
 * free dofs, M (v' - v) / dt = -(grad U(x') + J^T lambda) there (J^T lambda: the constraints'
 * forces at x', lambda the step's multipliers), so per step exactly
 *     dKE + 1/2 |v' - v|_M^2 = W_h - (grad U(x') + J^T lambda) . dx,
 * W_h = sum over prescribed dofs of F(x') dx, F the problem's forces (the handles' reactions).
 * Implicit Euler's numerical dissipation is then exactly
 *     1/2 |v' - v|_M^2 + (grad U(x') + J^T lambda) . dx - dU,
 * dU the integral of grad U along the chord from x to x'. The ledger takes that integral by
 * Simpson's rule (grad U at the ends and the midpoint; the extras' chord included), the piece halved
 * while its integral and U's change over it disagree (a barrier entered within the step; at most
 * PLUME_LEDGER_LEVELS - 1 times, PLUME_LEDGER_BUDGET pieces more a step), which leaves the rule's error as the residual, plus whatever else
 * moves energy unaccounted
 * (lagged friction's work, a gradient that is not its energy's). A step whose stateful terms commit
 * (split lines) changes U at the commit's point: the chord is cut there, each piece integrated with
 * the terms' state along it, and the commit's energy drop at that point is the jump (commits: the
 * energy the stateful terms gave up, plume_commit_report). Where grad U cannot be evaluated at a
 * midpoint (a contact barrier's domain), the piece falls back to the trapezoidal rule, counted. */
#ifndef PLUME_DYNAMICS_ENERGY_H
#define PLUME_DYNAMICS_ENERGY_H

#include "../core/problem.h"

/* Simpson pieces are halved at most this many times less one, into at most this many more pieces a
 * step */
#define PLUME_LEDGER_LEVELS 12
#define PLUME_LEDGER_BUDGET 256

typedef struct {
    int started;                 /* the ledger's start state is measured */
    plume_index nd, ndof;        /* 3 nv; the vertices' and the extras' unknowns */
    double *grad;                /* [ndof] grad U at the last state (without the constraints' forces) */
    double *force, *mid, *end;   /* [ndof] workspace */
    double *xend;                /* [ndof] a segment's end while grad U is taken at its midpoint */
    double *seg, *seg_grad;      /* [ndof] the step's current segment start (x, extras) and grad U there */
    double path;                 /* grad U's integral along the step's segments so far */
    double seg_u;                /* U at the segment's start */
    double *level_x[PLUME_LEDGER_LEVELS], *level_g[PLUME_LEDGER_LEVELS]; /* [ndof] each, allocated when
                                    a piece is halved that far: its midpoint and grad U there */
    long pieces;                 /* Simpson pieces taken (a step without commits: 1 unless halved) */
    int budget;                  /* the halvings left to this step (PLUME_LEDGER_BUDGET at its start) */
    double ke0, u0, ke, u;       /* J: at the start and at the last state */
    double work, gross_work;     /* the prescribed dofs' work, its sum of |step work| */
    double numerical, commits;   /* implicit Euler's dissipation; the stateful terms' */
    double peak_change;          /* the largest |KE - KE0| + |U - U0| reached */
    int trapezoid_steps;         /* pieces whose midpoint could not be evaluated (trapezoidal rule) */
} plume_energy_ledger;

/* The inertia the ledger subtracts: lumped masses (nv), the target x~ (3 nv) and 1 / dt^2. */
typedef struct {
    plume_index nv;
    const double *mass, *xt;
    double inv_dt2;
} plume_ledger_inertia;

/* For nv vertices of a problem of ndof unknowns (the vertices' and the extras'). */
plume_status plume_ledger_alloc(plume_energy_ledger *l, plume_index nv, plume_index ndof);
void plume_ledger_free(plume_energy_ledger *l);
/* The start: U, grad U and KE at the problem's x and velocities v. */
plume_status plume_ledger_start(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in,
                                const double *v);
/* A step attempt starts at (x0, extras e0), the last state's. */
void plume_ledger_begin(plume_energy_ledger *l, const double *x0, const double *e0);
/* The stateful terms commit at the problem's x: before, the segment up to x in their state; after,
 * grad U there in the new state (only needed when the state changed). */
plume_status plume_ledger_before_commit(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in);
plume_status plume_ledger_after_commit(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in);
/* An accepted step from (x0, extras e0, v0) to the problem's x = x1 with velocities v1; commits:
 * the energy its stateful terms gave up. The problem's x is the step's end again on return, and its
 * last evaluation (plume_problem_force_scale) is there. */
plume_status plume_ledger_step(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                               const plume_ledger_inertia *in, const double *x0, const double *e0, const double *v0,
                               const double *v1, double commits);
/* (work - dKE - dU - numerical - commits) / max(gross work, peak change); 0 before any change */
double plume_ledger_error(const plume_energy_ledger *l);

#endif
