/** \file
 * plume: traction-sample geometries from JSON (supplementary Table 1 ships in data/samples.json). */
#ifndef PLUME_SAMPLE_H
#define PLUME_SAMPLE_H

#include "../../include/plume/traction.h"

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
