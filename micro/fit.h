/** \file
 * plume: fitting macroscale moduli to traction curves with NLopt — the paper's protocol, with the
 * micro model (or measurements) as the source of the curves. micro/ never calls macro/: the
 * macroscale model is reached through a callback that the caller (an app) provides. */
#ifndef PLUME_FIT_H
#define PLUME_FIT_H

#include "../include/plume/curves.h"
#include "../include/plume/fit.h"

#include "../lib/core/export.h"
#include "../lib/io/curves.h"

#ifdef __cplusplus
extern "C" {
#endif


#ifdef __cplusplus
}
#endif
#endif
