#include "status.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

const char *plume_strerror(plume_status s)
{
    switch (s) {
    case PLUME_OK: return "ok";
    case PLUME_EINVAL: return "invalid input";
    case PLUME_ENOMEM: return "out of memory";
    case PLUME_EIO: return "input/output error";
    case PLUME_EFORMAT: return "malformed file";
    case PLUME_EDEP: return "dependency failure";
    case PLUME_ESINGULAR: return "singular matrix";
    case PLUME_EINFEASIBLE: return "infeasible problem";
    }
    return "unknown status";
}

plume_status plume_err_set(plume_err *err, plume_status s, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return s;
}

void plume_free(void *p)
{
    free(p);
}
