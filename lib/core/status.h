/** \file
 * plume: status codes and human-readable error messages shared by every module. */
#ifndef PLUME_STATUS_H
#define PLUME_STATUS_H

#include "../../include/plume/base.h"

#include "export.h"
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
