/** \file
 * plume: what a solve reports, whichever backend ran it: why it stopped and what it took. */
#ifndef PLUME_SOLVE_REPORT_H
#define PLUME_SOLVE_REPORT_H

#include "../../include/plume/base.h"

#include "../core/export.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
