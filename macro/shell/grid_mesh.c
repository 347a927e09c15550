#include "grid_mesh.h"

#include <math.h>

plume_status plume_grid_mesh(double lx, double ly, long nx, long ny, const double d[2], int dim, plume_mesh **out,
                             plume_err *err)
{
    if (!out || !(lx > 0.0) || !(ly > 0.0) || !isfinite(lx) || !isfinite(ly))
        return plume_err_set(err, PLUME_EINVAL, "grid mesh: lx and ly must be finite and > 0 (got %g, %g)", lx, ly);
    if (nx < 1 || ny < 1 || (double)nx * (double)ny > 2.5e6)
        return plume_err_set(err, PLUME_EINVAL, "grid mesh: %ld x %ld cells (need >= 1 each, at most 5e6 triangles)",
                             nx, ny);
    if (dim != 2 && dim != 3)
        return plume_err_set(err, PLUME_EINVAL, "grid mesh: dim must be 2 or 3 (got %d)", dim);
    double dir[2] = {1.0, 0.0};
    if (d) {
        double l = hypot(d[0], d[1]);
        if (!(l > 0.0) || !isfinite(l))
            return plume_err_set(err, PLUME_EINVAL, "grid mesh: the barb direction must be a non-zero vector");
        dir[0] = d[0] / l, dir[1] = d[1] / l;
    }
    plume_mesh *m = NULL;
    plume_status st = plume_mesh_create((nx + 1) * (ny + 1), 2 * nx * ny, dim, &m, err);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "grid mesh: out of memory");
    for (long j = 0; j <= ny; j++)
        for (long i = 0; i <= nx; i++) {
            plume_index v = j * (nx + 1) + i;
            m->X[2 * v] = lx * (double)i / (double)nx;
            m->X[2 * v + 1] = ly * (double)j / (double)ny;
        }
    plume_index t = 0;
    for (long j = 0; j < ny; j++)
        for (long i = 0; i < nx; i++) {
            plume_index a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, e = a + nx + 1;
            const plume_index tris[2][3] = {{a, b, c}, {a, c, e}};
            for (int k = 0; k < 2; k++, t++) {
                for (int q = 0; q < 3; q++)
                    m->tri[3 * t + q] = tris[k][q];
                m->barb_dir[2 * t] = dir[0];
                m->barb_dir[2 * t + 1] = dir[1];
                m->material[t] = 0;
            }
        }
    plume_mesh_reset_current(m);
    if ((st = plume_mesh_build_topology(m, err)) != PLUME_OK) {
        plume_mesh_destroy(&m);
        return st;
    }
    *out = m;
    return PLUME_OK;
}
