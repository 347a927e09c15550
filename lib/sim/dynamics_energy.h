/* plume (private, not installed): the energy ledger of the implicit Euler stepper
 * (lib/sim/dynamics.c; docs/apps/feather.md, "The energy balance"). At every accepted step it adds the
 * handles' work and what the step gave up, so that
 *     work = (KE - KE0) + (U - U0) + numerical + commits + residual,
 * U the potential (every term but the inertia's quadratic part: elastic, contact, gravity), KE the
 * kinetic energy of the lumped masses. With v' = (x' - x) / dt and the step's stationarity at the
 * free dofs, M (v' - v) / dt = -grad U(x') there, so per step exactly
 *     dKE + 1/2 |v' - v|_M^2 = W_h - grad U(x') . dx,   W_h = sum over prescribed dofs of F(x') dx,
 * F the problem's forces (the handles' reactions). Implicit Euler's numerical dissipation is taken as
 * 1/2 |v' - v|_M^2 + 1/2 (grad U(x') - grad U(x)) . dx (>= 0 where U is convex), which leaves the
 * trapezoidal rule's error dU - 1/2 (grad U(x) + grad U(x')) . dx as the residual, plus whatever else
 * moves energy unaccounted (a commit measured at another point than the step's start, lagged
 * friction's work). commits: the energy the stateful terms gave up (plume_commit_report). */
#ifndef PLUME_DYNAMICS_ENERGY_H
#define PLUME_DYNAMICS_ENERGY_H

#include "../core/problem.h"

typedef struct {
    int started;                 /* the ledger's start state is measured */
    plume_index nd;              /* 3 nv */
    double *grad, *force;        /* [ndof] grad U at the last state (constraint forces included); workspace */
    double ke0, u0, ke, u;       /* J: at the start and at the last state */
    double work, gross_work;     /* the prescribed dofs' work, its sum of |step work| */
    double numerical, commits;   /* implicit Euler's dissipation; the stateful terms' */
    double peak_change;          /* the largest |KE - KE0| + |U - U0| reached */
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
/* The start: U, grad U and KE at the problem's x (multipliers lambda) and velocities v. */
plume_status plume_ledger_start(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                                const plume_ledger_inertia *in, const double *v);
/* An accepted step from (x0, v0) to the problem's x = x1 with velocities v1; commits: the energy
 * its stateful terms gave up. */
plume_status plume_ledger_step(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                               const plume_ledger_inertia *in, const double *x0, const double *v0, const double *v1,
                               double commits);
/* (work - dKE - dU - numerical - commits) / max(gross work, peak change); 0 before any change */
double plume_ledger_error(const plume_energy_ledger *l);

#endif
