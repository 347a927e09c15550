/** \file
 * plume: the library's version, at compile time (the macros) and at run time (the library a
 * program actually loaded). */
#ifndef PLUME_VERSION_H
#define PLUME_VERSION_H

#include "export.h"

#define PLUME_VERSION_MAJOR 0       /**< major version of the headers compiled against */
#define PLUME_VERSION_MINOR 4       /**< minor version of the headers compiled against */
#define PLUME_VERSION_PATCH 0       /**< patch version of the headers compiled against */
#define PLUME_VERSION_STRING "0.4.0" /**< "MAJOR.MINOR.PATCH" of the headers compiled against */

#ifdef __cplusplus
extern "C" {
#endif

/** "MAJOR.MINOR.PATCH" of the library linked in (static string). */
PLUME_API const char *plume_version(void);

#ifdef __cplusplus
}
#endif
#endif
