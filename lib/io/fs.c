#include "fs.h"

#include <errno.h>
#include <stdio.h>
#include <sys/stat.h>

int plume_make_dirs(const char *path)
{
    char buf[4200];
    if (!path || snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return errno = path ? ENAMETOOLONG : EINVAL, -1;
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return -1;
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return -1;
    struct stat st;
    if (stat(buf, &st) != 0 || !S_ISDIR(st.st_mode))
        return errno = ENOTDIR, -1;
    return 0;
}
