/** \file
 * plume: the options of the nonlinear solvers (tolerances, caps, and how the native solver factorises
 * and globalises its steps). */
#ifndef PLUME_SOLVE_OPTIONS_H
#define PLUME_SOLVE_OPTIONS_H

#include "../../include/plume/problem.h"

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Sets curved_search and trust_region for g. */
void plume_solver_opts_set_globalization(plume_solver_opts *o, plume_globalization g);

/* *full gets the defaults, then the caller's options `given` over them (plume_solver_opts.size bytes;
 * NULL: the defaults alone). PLUME_EINVAL when given was not filled by plume_solver_opts_default. */
plume_status plume_solver_opts_take(plume_solver_opts *full, const plume_solver_opts *given, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
