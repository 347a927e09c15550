/* plume (private, not installed): HDF5 error handling shared by lib/io/curves.c and lib/io/frames.c —
 * silencing HDF5's automatic error printing for the duration of a call, and the innermost
 * message of its error stack for our own error text. Includes hdf5.h, so it stays private. */
#ifndef PLUME_INTERNAL_H5UTIL_H
#define PLUME_INTERNAL_H5UTIL_H

#include <hdf5.h>
#include <stdio.h>

#include "../core/status.h"

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

/* Scalar attribute of file_type written from mem_type; 0, or -1 on failure. */
static inline int h5_write_attr(hid_t obj, const char *name, hid_t file_type, hid_t mem_type, const void *v)
{
    int ok = 0;
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t a = sp < 0 ? H5I_INVALID_HID : H5Acreate2(obj, name, file_type, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0 && H5Awrite(a, mem_type, v) >= 0)
        ok = 1;
    if (a >= 0)
        H5Aclose(a);
    if (sp >= 0)
        H5Sclose(sp);
    return ok ? 0 : -1;
}

static inline int h5_write_attr_double(hid_t obj, const char *name, double v)
{
    return h5_write_attr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v);
}

/* Variable-length UTF-8 strings: read back as str by h5py and h5dump alike. */
static inline int h5_write_attr_string(hid_t obj, const char *name, const char *v)
{
    int ok = 0;
    hid_t t = H5Tcopy(H5T_C_S1);
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t a = H5I_INVALID_HID;
    if (t >= 0 && sp >= 0 && H5Tset_size(t, H5T_VARIABLE) >= 0 && H5Tset_cset(t, H5T_CSET_UTF8) >= 0)
        a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0 && H5Awrite(a, t, &v) >= 0)
        ok = 1;
    if (a >= 0)
        H5Aclose(a);
    if (sp >= 0)
        H5Sclose(sp);
    if (t >= 0)
        H5Tclose(t);
    return ok ? 0 : -1;
}

static inline int h5_is_hdf5(const char *path)
{
#if H5_VERSION_GE(1, 12, 0)
    return H5Fis_accessible(path, H5P_DEFAULT) > 0;
#else
    return H5Fis_hdf5(path) > 0;
#endif
}

/* A 1D dataset of n doubles; units (may be NULL) becomes its "units" string attribute ("1": a
 * pure number). 0, or -1 on failure. */
static inline int h5_write_dataset(hid_t g, const char *name, const double *v, plume_index n, const char *units)
{
    int ok = 0;
    hsize_t dims[1] = {(hsize_t)n};
    hid_t sp = H5Screate_simple(1, dims, NULL);
    hid_t ds = sp < 0 ? H5I_INVALID_HID
                      : H5Dcreate2(g, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (ds >= 0 && (n == 0 || H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0) &&
        (!units || h5_write_attr_string(ds, "units", units) >= 0))
        ok = 1;
    if (ds >= 0)
        H5Dclose(ds);
    if (sp >= 0)
        H5Sclose(sp);
    return ok ? 0 : -1;
}

#endif
