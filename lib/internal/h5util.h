/* plume (private, not installed): HDF5 error handling shared by lib/curves.c and lib/frames.c —
 * silencing HDF5's automatic error printing for the duration of a call, and the innermost
 * message of its error stack for our own error text. Includes hdf5.h, so it stays private. */
#ifndef PLUME_INTERNAL_H5UTIL_H
#define PLUME_INTERNAL_H5UTIL_H

#include <hdf5.h>
#include <stdio.h>

typedef struct {
    H5E_auto2_t func;
    void *data;
} h5_quiet;

static inline void quiet_begin(h5_quiet *q)
{
    q->func = NULL;
    q->data = NULL;
    H5Eget_auto2(H5E_DEFAULT, &q->func, &q->data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static inline void quiet_end(const h5_quiet *q)
{
    H5Eset_auto2(H5E_DEFAULT, q->func, q->data);
}

typedef struct {
    char text[160];
} h5_detail;

static inline herr_t h5_detail_cb(unsigned n, const H5E_error2_t *e, void *data)
{
    h5_detail *d = data;
    if (n == 0 && e && e->desc)
        snprintf(d->text, sizeof d->text, "%s", e->desc);
    return 0;
}

/* The most specific message on HDF5's current error stack (walked from the innermost call), or
 * "unknown HDF5 error"; used to give EIO messages a cause. */
static inline const char *h5_cause(h5_detail *d)
{
    d->text[0] = '\0';
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, h5_detail_cb, d);
    if (!d->text[0])
        snprintf(d->text, sizeof d->text, "unknown HDF5 error");
    return d->text;
}

#endif
