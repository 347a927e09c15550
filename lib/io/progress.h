/** \file
 * plume: a one-line progress indicator on stderr for long runs. */
#ifndef PLUME_PROGRESS_H
#define PLUME_PROGRESS_H

#include "../../include/plume/base.h"

#include "../core/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A progress line's state, filled by plume_progress_start (no allocation, nothing to free). */
typedef struct {
    const char *label;  /**< printed at the start of the line (borrowed; "" for NULL) */
    int total;          /**< steps expected; <= 0: unknown (no "/total" and no eta) */
    int enabled;        /**< 0: silent (e.g., --quiet, or stderr not a terminal and not forced) */
    double t_start;     /**< plume_wall_seconds() at the start */
} plume_progress;

/** Starts a progress line; enabled when stderr is a terminal or `force` is non-zero. */
void plume_progress_start(plume_progress *p, const char *label, int total, int force);
/** Rewrites the line as "\r<label> step k/total [info]  elapsed 1.2 s  eta 3.4 s", padded with
 * spaces to 79 columns so a shorter line hides a longer previous one ("eta ? s" before step 1). */
void plume_progress_update(plume_progress *p, int k, const char *info);
/** Ends the line with a newline and disables p (a second call prints nothing); nothing when disabled. */
void plume_progress_finish(plume_progress *p);

/** CPU time of the whole process (every thread) in seconds, for benchmarks. */
double plume_cpu_seconds(void);

#ifdef __cplusplus
}
#endif
#endif
