/** \file
 * plume: charts of curves as PNG and SVG through gnuplot. */
#ifndef PLUME_PLOT_H
#define PLUME_PLOT_H

#include "../core/export.h"
#include "../core/status.h"
#include "curves.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Draws stress-strain (left) and wbar-strain (right) of `ncurves` curves with their labels into
 * png_path and the same chart as SVG beside it (extension replaced by .svg). Runs gnuplot;
 * PLUME_EDEP with a message if gnuplot is missing or fails. Strain is shown in %, stress in Pa. */
PLUME_API plume_status plume_plot_curves(const char *png_path, const char *title, const plume_curve *curves,
                                         const char *const *labels, int ncurves, plume_err *err);

/** Axis labels replacing the defaults (NULL fields keep them). */
typedef struct {
    const char *stress_label; /**< left panel, default "nominal stress (Pa)" */
    const char *wbar_label;   /**< right panel, default "w-bar (average relative width change)" */
    const char *x_label;      /**< both panels, default "nominal strain (%)" */
    double x_scale;           /**< x drawn = x_scale * curve.strain; 0 selects 100 (percent) */
    int small_key;            /**< 1: a smaller legend font, for charts with many series */
    const int *color;         /**< per curve: gnuplot colour index 1..8 (NULL: curve k gets k + 1, which
                                 repeats after 8), so that families share a colour */
    const int *point;         /**< per curve: gnuplot point type (NULL: 7, a filled circle) */
    int key_below;            /**< 1: the legend under each panel in columns, clear of the data */
} plume_plot_axes;

/** plume_plot_curves with other axis labels (axes may be NULL). */
PLUME_API plume_status plume_plot_curves_axes(const char *png_path, const char *title, const plume_plot_axes *axes,
                                              const plume_curve *curves, const char *const *labels, int ncurves,
                                              plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
