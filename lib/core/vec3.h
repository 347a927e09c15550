/* plume (private, not installed): the 3-vector products the shell terms share, and the gather of
 * a contact pair's four vertices. */
#ifndef PLUME_INTERNAL_VEC3_H
#define PLUME_INTERNAL_VEC3_H

#include "status.h"

static inline void cross3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void sub3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[0] - b[0];
    c[1] = a[1] - b[1];
    c[2] = a[2] - b[2];
}

/* out = the 12 coordinates of vertices v[0..3] of x (3 per vertex): a contact pair's layout */
static inline void gather12(const double *x, const plume_index *v, double out[12])
{
    for (int a = 0; a < 4; a++)
        for (int k = 0; k < 3; k++)
            out[3 * a + k] = x[3 * v[a] + k];
}

#endif
