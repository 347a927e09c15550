/** \file
 * plume: file-system helpers shared by the apps and the flat interface. */
#ifndef PLUME_FS_H
#define PLUME_FS_H

#include "../../include/plume/base.h"

#include "../core/export.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
