/* Rigid motions: quaternion helpers and keyframed motions (rigid_motion.h). */
#include "rigid_motion.h"

#include <math.h>
#include <string.h>

void plume_quat_from_rotvec(const double r[3], double q[4])
{
    double a = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    /* sin(a/2)/a by its series near 0, so tiny rotations stay exact to rounding */
    double s = a > 1e-8 ? sin(0.5 * a) / a : 0.5 - a * a / 48.0;
    q[0] = cos(0.5 * a);
    q[1] = s * r[0], q[2] = s * r[1], q[3] = s * r[2];
}

void plume_quat_rotate(const double q[4], const double v[3], double out[3])
{
    /* v + 2 w (u x v) + 2 u x (u x v), u the vector part */
    const double *u = q + 1;
    double t[3] = {2.0 * (u[1] * v[2] - u[2] * v[1]), 2.0 * (u[2] * v[0] - u[0] * v[2]), 2.0 * (u[0] * v[1] - u[1] * v[0])};
    double o[3] = {v[0] + q[0] * t[0] + u[1] * t[2] - u[2] * t[1], v[1] + q[0] * t[1] + u[2] * t[0] - u[0] * t[2],
                   v[2] + q[0] * t[2] + u[0] * t[1] - u[1] * t[0]};
    memcpy(out, o, sizeof o);
}

void plume_quat_mul(const double a[4], const double b[4], double out[4])
{
    double o[4] = {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                   a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                   a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                   a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
    memcpy(out, o, sizeof o);
}

void plume_quat_slerp(const double a[4], const double b[4], double s, double out[4])
{
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], sb = 1.0;
    if (d < 0.0) /* q and -q are the same rotation: take the shorter arc */
        d = -d, sb = -1.0;
    double wa, wb;
    if (d > 1.0 - 1e-12) { /* nearly equal: linear, then normalised */
        wa = 1.0 - s, wb = s;
    } else {
        double th = acos(d), st = sin(th);
        wa = sin((1.0 - s) * th) / st, wb = sin(s * th) / st;
    }
    double n = 0.0;
    for (int k = 0; k < 4; k++) {
        out[k] = wa * a[k] + sb * wb * b[k];
        n += out[k] * out[k];
    }
    n = sqrt(n);
    for (int k = 0; k < 4; k++)
        out[k] /= n;
}

void plume_rigid_motion_at(const plume_rigid_motion *m, double t, double q[4], double c[3])
{
    static const double zero[3] = {0.0, 0.0, 0.0};
    const double *pv = m->pivot ? m->pivot : zero;
    int k = 0;
    double s = 0.0;
    if (t <= m->times[0] || m->nkeys == 1) {
        k = 0;
    } else {
        while (k + 1 < m->nkeys && m->times[k + 1] < t)
            k++;
        if (k + 1 >= m->nkeys)
            k = m->nkeys - 1;
        else
            s = (t - m->times[k]) / (m->times[k + 1] - m->times[k]);
    }
    int k1 = s > 0.0 ? k + 1 : k;
    double off[3];
    for (int a = 0; a < 3; a++)
        off[a] = (1.0 - s) * m->offsets[3 * k + a] + s * m->offsets[3 * k1 + a];
    q[0] = 1.0, q[1] = q[2] = q[3] = 0.0;
    if (m->rotations) {
        double qa[4], qb[4];
        plume_quat_from_rotvec(m->rotations + 3 * k, qa);
        plume_quat_from_rotvec(m->rotations + 3 * k1, qb);
        plume_quat_slerp(qa, qb, s, q);
    }
    /* c = pivot + off - R pivot */
    double rp[3];
    plume_quat_rotate(q, pv, rp);
    for (int a = 0; a < 3; a++)
        c[a] = pv[a] + off[a] - rp[a];
}

void plume_rigid_motion_apply(const plume_rigid_motion *m, double t, const double y[3], double out[3])
{
    double q[4], c[3], r[3];
    plume_rigid_motion_at(m, t, q, c);
    plume_quat_rotate(q, y, r);
    for (int a = 0; a < 3; a++)
        out[a] = c[a] + r[a];
}
