/** \file
 * plume: charts of curves as PNG and SVG through gnuplot. */
#ifndef PLUME_PLOT_H
#define PLUME_PLOT_H

#include "../../include/plume/curves.h"

#include "../core/export.h"
#include "../core/status.h"
#include "curves.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
