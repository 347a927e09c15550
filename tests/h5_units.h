/* String attributes of an HDF5 object in tests: h5_string_attr any one, h5_units the "units" one of
 * the object at `obj` (e.g. "/frames/0/x") in the HDF5 file
 * `path`, into buf; 0, or -1 when the file, the object or the attribute is missing. */
#ifndef PLUME_TESTS_H5_UNITS_H
#define PLUME_TESTS_H5_UNITS_H

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>

/* the variable-length string attribute `name` of object `obj` in buf; 0, or -1 when absent or not a string */
static inline int h5_string_attr(const char *path, const char *obj, const char *name, char *buf, size_t n)
{
    int rc = -1;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return -1;
    if (H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0) {
        hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT), t = H5Aget_type(a);
        char *s = NULL;
        if (a >= 0 && t >= 0 && H5Tis_variable_str(t) > 0 && H5Aread(a, t, &s) >= 0 && s) {
            snprintf(buf, n, "%s", s);
            H5free_memory(s);
            rc = 0;
        }
        if (t >= 0)
            H5Tclose(t);
        if (a >= 0)
            H5Aclose(a);
    }
    H5Fclose(f);
    return rc;
}

static inline int h5_units(const char *path, const char *obj, char *buf, size_t n)
{
    return h5_string_attr(path, obj, "units", buf, n);
}

#endif
