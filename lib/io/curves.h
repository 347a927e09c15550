/** \file
 * plume: result curves and moduli in HDF5 (layout of docs/design.md), written atomically. */
#ifndef PLUME_CURVES_H
#define PLUME_CURVES_H

#include "../../include/plume/curves.h"

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
