/** \file
 * plume: rigid motions of kinematic bodies and handles — rotations as rotation vectors (axis times
 * angle, radians) and unit quaternions, and keyframed motions: a translation piecewise linear
 * between keys and a rotation about a pivot interpolated by slerp (the shortest arc, constant
 * angular speed between keys), both constant outside the keys. */
#ifndef PLUME_RIGID_MOTION_H
#define PLUME_RIGID_MOTION_H

#include "export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Unit quaternion q = (w, x, y, z) of the rotation by |r| about r / |r| (the identity for r = 0). */
void plume_quat_from_rotvec(const double r[3], double q[4]);

/** out = R(q) v; out may alias v. */
void plume_quat_rotate(const double q[4], const double v[3], double out[3]);

/** out = a b (first b, then a). */
void plume_quat_mul(const double a[4], const double b[4], double out[4]);

/** Spherical interpolation from a (s = 0) to b (s = 1) along the shorter arc. */
void plume_quat_slerp(const double a[4], const double b[4], double s, double out[4]);

/** A keyframed rigid motion (arrays borrowed): a point y at rest goes to
 *   pivot + offset(t) + R(t) (y - pivot). */
typedef struct {
    int nkeys;               /**< number of keys (>= 1) */
    const double *times;     /**< [nkeys], increasing (s) */
    const double *offsets;   /**< [3 nkeys] translations (m) */
    const double *rotations; /**< [3 nkeys] rotation vectors (radians) or NULL: no rotation */
    const double *pivot;     /**< [3] the rotation's centre at rest; NULL = origin */
} plume_rigid_motion;

/** The motion at time t as a quaternion q and a translation c: y -> c + R(q) y. */
void plume_rigid_motion_at(const plume_rigid_motion *m, double t, double q[4], double c[3]);

/** y at time t (out may alias y). */
void plume_rigid_motion_apply(const plume_rigid_motion *m, double t, const double y[3], double out[3]);

#ifdef __cplusplus
}
#endif
#endif
