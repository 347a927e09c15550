/** \file
 * plume: the scene runner's parts that stay inside the library (its public half is
 * include/plume/scene.h): the acceptance rule as a function of a step's report, and the stepper. */
#ifndef PLUME_RUN_H
#define PLUME_RUN_H

#include "../../include/plume/scene.h"

#include "../../lib/core/export.h"
#include "../../lib/core/status.h"
#include "../../lib/sim/dynamics.h"
#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The acceptance rule of a step, the one every runner of a scene applies: a call of
 * plume_dynamics_advance that started at t0 and asked for h seconds is accepted when it converged,
 * or when the solver is `linearized` (one unconverged step by design) and the step advanced (the
 * time reached t0 + h within 1e-9 of max(dt, |t1|)). A step that is not accepted stops a run. */
int plume_run_accepts(plume_solver_kind solver, const plume_step_report *rep, double t0, double h, double t1,
                                double dt);

/** The run's stepper, for what the runner does not say (multipliers, masses, statistics). */
const plume_dynamics *plume_run_dynamics(const plume_run *r);

#ifdef __cplusplus
}
#endif
#endif
