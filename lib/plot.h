/* plume: charts of curves as PNG and SVG through gnuplot. */
#ifndef PLUME_PLOT_H
#define PLUME_PLOT_H

#include "status.h"
#include "curves.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Draws stress-strain (left) and wbar-strain (right) of `ncurves` curves with their labels into
 * png_path and the same chart as SVG beside it (extension replaced by .svg). Runs gnuplot;
 * PLUME_EDEP with a message if gnuplot is missing or fails. Strain is shown in %, stress in Pa. */
plume_status plume_plot_curves(const char *png_path, const char *title, const plume_curve *curves,
                               const char *const *labels, int ncurves, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
