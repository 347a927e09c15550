/** \file
 * plume: measurements of where methods fail: the
 * conditioning of the penalty model as the stiffness ratio grows (paper Figure 6), and the
 * collapse of St Venant–Kirchhoff elements under strong compression without the compression
 * term (supplementary Figure 7). */
#ifndef PLUME_STABILITY_H
#define PLUME_STABILITY_H

#include "../include/plume/experiments.h"

#include "../lib/core/export.h"
#include "../lib/core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
