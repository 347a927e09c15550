/** \file
 * plume: running gnuplot on a script (charts and renders). */
#ifndef PLUME_GNUPLOT_H
#define PLUME_GNUPLOT_H

#include <stdio.h>

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Runs `gnuplot script`, its output going to `log`. PLUME_EDEP with a message starting with
 * `who` when gnuplot is missing ("install gnuplot-nox"), fails (its last output line) or dies. */
plume_status plume_gnuplot_run(const char *script, const char *log, const char *who, plume_err *err);

/** Copies gnuplot's output `src` to "<dst>.tmp.<pid>" and renames it over `dst`, so a failed or
 * interrupted write never leaves a truncated picture under the final name. */
plume_status plume_gnuplot_install(const char *src, const char *dst, const char *who, plume_err *err);

/** Writes `s` to f as a gnuplot single-quoted string: inside one only '' is special (it stands for
 * a quote); control characters would end the command, so they become spaces. */
void plume_gnuplot_put_quoted(FILE *f, const char *s);

/** The last non-empty line of a gnuplot log (its error), into out (empty if none). */
void plume_gnuplot_log_tail(const char *path, char *out, size_t len);

#ifdef __cplusplus
}
#endif
#endif
