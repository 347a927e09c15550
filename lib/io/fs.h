/** \file
 * plume: file-system helpers shared by the apps and the flat interface. */
#ifndef PLUME_FS_H
#define PLUME_FS_H

#include "../core/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** mkdir -p: creates path and its missing parents (0777 before umask). 0 when path is a directory
 * on return; -1 with errno set otherwise (ENAMETOOLONG, ENOTDIR when path names something else). */
PLUME_API int plume_make_dirs(const char *path);

#ifdef __cplusplus
}
#endif
#endif
