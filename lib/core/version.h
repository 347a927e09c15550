/** \file
 * plume: the library's version, at compile time (the macros) and at run time (the library a
 * program actually loaded). */
#ifndef PLUME_VERSION_H
#define PLUME_VERSION_H

#include "../../include/plume/base.h"

#include "export.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
