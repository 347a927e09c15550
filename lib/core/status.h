/** \file
 * plume: status codes and human-readable error messages shared by every module. */
#ifndef PLUME_STATUS_H
#define PLUME_STATUS_H

#include "export.h"
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Index type for vertices, dofs and sparse entries; matches CHOLMOD's _l_ (SuiteSparse_long). */
typedef long plume_index;

/** Every library call returns one of these; 0 is success, negative values are errors.
 * Convergence outcomes are not errors: they are a reason in the solver report. */
typedef enum {
    PLUME_OK = 0,          /**< success */
    PLUME_EINVAL = -1,     /**< invalid input (a parameter out of range, inconsistent sizes) */
    PLUME_ENOMEM = -2,     /**< allocation failed */
    PLUME_EIO = -3,        /**< file could not be read or written */
    PLUME_EFORMAT = -4,    /**< a file was read but its content is malformed */
    PLUME_EDEP = -5,       /**< a dependency (CHOLMOD, Ipopt, CGAL, HDF5, gnuplot) failed */
    PLUME_ESINGULAR = -6,  /**< a matrix could not be factorised */
    PLUME_EINFEASIBLE = -7 /**< the problem as posed has no solution (e.g., barbs spanning both grips) */
} plume_status;

/** Short static name of a status ("invalid input", ...). Never NULL. */
PLUME_API const char *plume_strerror(plume_status s);

/** A human message that travels with an error: functions that can fail on user input take an
 * optional `plume_err *` (NULL allowed) and fill `msg` with what went wrong, naming the file,
 * line, key or parameter. */
typedef struct {
    char msg[768]; /**< the message, NUL-terminated, truncated to fit; left as it was when no error
                        was set, so zero-initialise the struct */
} plume_err;

/** printf-style; safe with err == NULL. Returns `s` so callers can `return plume_err_set(...)`. */
PLUME_API plume_status plume_err_set(plume_err *err, plume_status s, const char *fmt, ...)
#if defined(__GNUC__)
              __attribute__((format(printf, 3, 4)))
#endif
              ;

#ifdef __cplusplus
}
#endif
#endif
