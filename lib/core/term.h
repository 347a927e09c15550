/** \file
 * plume: the energy-term and constraint interfaces every model plugs into a problem. */
#ifndef PLUME_TERM_H
#define PLUME_TERM_H

#include "../../include/plume/problem.h"

#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
