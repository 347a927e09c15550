/* plume (private, not installed): the library's side of the options structs that grow
 * (docs/development.md, "Structs that grow"). Such a struct's first member is `size_t size`, the
 * sizeof the caller compiled against, set by the struct's _default macro; the library reads and
 * writes only that many bytes, so a program built against an older, smaller struct keeps working
 * with a library whose struct has grown at its end. */
#ifndef PLUME_CORE_OPTS_H
#define PLUME_CORE_OPTS_H

#include <stddef.h>

#include "status.h"

/* Takes the caller's struct src (size set) into dst, which holds the library's defaults and is
 * dst_size bytes: dst gets the caller's first min(size, dst_size) bytes, the rest keeps the
 * defaults, and dst's size becomes dst_size. A size of 0 or one too small to hold the size member
 * is refused (PLUME_EINVAL naming the struct `name`: it was not filled by its _default macro). */
plume_status plume_opts_take(void *dst, size_t dst_size, const void *src, const char *name, plume_err *err);

/* Fills the caller's struct dst of `size` bytes from the library's full struct src (full_size
 * bytes): its first min(size, full_size) bytes, then size. */
void plume_opts_give(void *dst, size_t size, const void *src, size_t full_size);

#endif
