/* plume (private): opening a file a user hands in. Only regular files are read: a FIFO, a device
 * or a directory would block forever or read garbage, so they are refused up front. */
#ifndef PLUME_INPUT_FILE_H
#define PLUME_INPUT_FILE_H

#include <stdio.h>

#include "../core/status.h"

/* fopen(path, mode) for reading, after checking that path is a regular file. On failure returns
 * NULL with err set (PLUME_EIO): "<what> '<path>': cannot open: <reason>" or "...: is not a
 * regular file (a FIFO ...)"; with what == NULL the message starts with the path alone. */
FILE *plume_input_fopen(const char *path, const char *mode, const char *what, plume_err *err);

#endif
