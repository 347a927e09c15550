/* plume: opening user input files (lib/io/input_file.h). */
#include "input_file.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

FILE *plume_input_fopen(const char *path, const char *mode, const char *what, plume_err *err)
{
    /* "<what> '<path>'" or, without what, "<path>" starts every message */
    char who[4200];
    snprintf(who, sizeof who, what ? "%s '%s'" : "%s%s", what ? what : "", path ? path : "(no path)");
    struct stat st;
    if (!path || stat(path, &st) != 0) {
        plume_err_set(err, PLUME_EIO, "%s: cannot open: %s", who, path ? strerror(errno) : "no path given");
        return NULL;
    }
    if (!S_ISREG(st.st_mode)) {
        plume_err_set(err, PLUME_EIO, "%s: is not a regular file (%s)", who,
                      S_ISDIR(st.st_mode)    ? "a directory"
                      : S_ISFIFO(st.st_mode) ? "a FIFO: not read, it could block forever"
                                             : "a device or socket");
        return NULL;
    }
    FILE *f = fopen(path, mode);
    if (!f)
        plume_err_set(err, PLUME_EIO, "%s: cannot open: %s", who, strerror(errno));
    return f;
}
