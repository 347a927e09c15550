/** \file
 * plume: a microstructure layout from a JSON file or text (jansson). */
#ifndef PLUME_LAYOUT_JSON_H
#define PLUME_LAYOUT_JSON_H

#include "../include/plume/homogenize.h"

#include "../lib/core/export.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
