/** \file
 * plume: an end moment on a rotation-free shell — a conservative follower moment M about a fixed
 * axis a, applied to an end (a set of vertices) through its second row (the vertices next to it):
 *     W = -M phi,  phi = the angle, about a, of t = mean(x_end) - mean(x_row) from its rest value.
 * Bending a strip whose end carries M = 2 pi EI / L rolls it into a full circle (phi = 2 pi). */
#ifndef PLUME_MOMENT_H
#define PLUME_MOMENT_H

#include "export.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A shell-mode (dim 3) term over the end vertices end[0..nend) and the second row
 * row[0..nrow) (disjoint sets; arrays copied), moment M (N m) about the unit axis `axis`
 * (normalised here), rest positions X3 (3 nv) from which phi is measured. phi is continued
 * across +-pi from the last evaluation, so it counts whole turns as long as it changes by less
 * than pi between two evaluations. Errors (PLUME_EINVAL, message): empty sets, a vertex in both,
 * a zero or non-finite axis or moment, an end whose rest direction t is parallel to the axis. */
plume_status plume_moment_term_create(const plume_index *end, plume_index nend, const plume_index *row,
                                                plume_index nrow, const double axis[3], double moment, const double *X3,
                                                plume_term *out, plume_err *err);

/** Scales the moment to factor * M (load stepping). */
void plume_moment_scale(plume_term *t, double factor);

/** phi (radians) at the last evaluation: the end's rotation about the axis. */
double plume_moment_angle(const plume_term *t);

#ifdef __cplusplus
}
#endif
#endif
