#include "patch_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/cdt.h"
#include "../../lib/core/pslg.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

plume_status plume_patch_kind_parse(const char *s, plume_patch_kind *out)
{
    if (s && strcmp(s, "aligned") == 0)
        *out = PLUME_PATCH_ALIGNED;
    else if (s && strcmp(s, "unaligned") == 0)
        *out = PLUME_PATCH_UNALIGNED;
    else
        return PLUME_EINVAL;
    return PLUME_OK;
}

void plume_patch_barb_direction(double angle_deg, double d[2])
{
    plume_barb_direction(angle_deg, d);
}

typedef plume_pslg geometry; /* lib/core/pslg.h */

/* Boundary points are tracked per side by their parameter so that corners and barb ends are
 * shared exactly: side 0 bottom (t = x), 1 right (t = y), 2 top (t = x), 3 left (t = y). */
typedef struct {
    double t;
    plume_index id;
} side_point;

typedef struct {
    side_point *v[4];
    plume_index n[4];
} sides;

static int cmp_side_point(const void *a, const void *b)
{
    double x = ((const side_point *)a)->t, y = ((const side_point *)b)->t;
    return (x > y) - (x < y);
}

static double snap(double v, double lo, double hi, double tol)
{
    if (fabs(v - lo) <= tol)
        return lo;
    if (fabs(v - hi) <= tol)
        return hi;
    return v;
}

/* Returns the id of the boundary point at (x, y) (snapped to the sides within tol), creating it
 * if new. Only boundary points are searched: O(sqrt N) per query. */
static plume_index boundary_point(geometry *g, sides *sd, double lx, double ly, double x, double y, double tol)
{
    x = snap(x, 0.0, lx, tol);
    y = snap(y, 0.0, ly, tol);
    int on[4] = {y == 0.0, x == lx, y == ly, x == 0.0};
    for (int s = 0; s < 4; s++)
        for (plume_index k = 0; on[s] && k < sd->n[s]; k++) {
            plume_index i = sd->v[s][k].id;
            if (g->p[2 * i] == x && g->p[2 * i + 1] == y)
                return i;
        }
    if (plume_pslg_point(g, x, y) < 0)
        return -1;
    plume_index id = g->n - 1;
    for (int s = 0; s < 4; s++)
        if (on[s]) {
            sd->v[s][sd->n[s]].t = (s % 2 == 0) ? x : y;
            sd->v[s][sd->n[s]++].id = id;
        }
    return id;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Aligned meshes (docs/design.md, "Meshes that respect the fibres"). The barb lines are the chords
 * {p : nrm.p = c} of the rectangle; one passes through every corner, because the exact solution
 * of an inextensible-fibre sheet concentrates stress on the fibres through the corners (Pipkin),
 * and the others are spaced uniformly (<= edge sqrt(3)/2 apart) between consecutive corner lines.
 * Every point of the geometry lies on a barb line: the boundary points are exactly the
 * line/side intersections and the corners, the interior points sit on each line every `edge`,
 * shifted by edge/2 from one line to the next (a triangular lattice in the barb frame). Since
 * every chord is a chain of constrained segments, no triangle of the constrained Delaunay
 * triangulation can reach across a line, so its three vertices lie on two consecutive lines (or
 * on a line and an extreme corner): two of them are consecutive points of one line and the edge
 * joining them is a barb segment. Every triangle therefore owns a constrained barb edge. The
 * price: boundary points are spaced spacing / |sin| of the angle between barbs and side, so
 * barbs at a shallow angle to a side give elongated triangles along it. */
static plume_status aligned_geometry(double lx, double ly, double angle_deg, double edge, geometry *g,
                                     sides *sd)
{
    double d[2];
    plume_patch_barb_direction(angle_deg, d);
    double nrm[2] = {d[1], -d[0]}; /* barb lines are {p : nrm.p = c} */
    double tol = 1e-9 * fmax(lx, ly);
    double corners[4][2] = {{0, 0}, {lx, 0}, {lx, ly}, {0, ly}};
    double cc[4];
    for (int k = 0; k < 4; k++)
        cc[k] = nrm[0] * corners[k][0] + nrm[1] * corners[k][1];
    qsort(cc, 4, sizeof cc[0], cmp_double);
    int nc = 1; /* distinct corner lines (two corners share a line when barbs are along a side) */
    for (int k = 1; k < 4; k++)
        if (cc[k] - cc[nc - 1] > tol)
            cc[nc++] = cc[k];
    double target = edge * sqrt(3.0) / 2.0;
    long line = 0;
    for (int ci = 0; ci < nc; ci++) {
        long between = 1;
        if (ci + 1 < nc) {
            between = (long)ceil((cc[ci + 1] - cc[ci]) / target - 1e-9);
            if (between < 1)
                between = 1;
        }
        for (long j = 0; j < between; j++, line++) {
            double c = ci + 1 < nc ? cc[ci] + (cc[ci + 1] - cc[ci]) * (double)j / (double)between : cc[ci];
            /* clip the line p = c nrm + t d to the rectangle */
            double p0[2] = {c * nrm[0], c * nrm[1]};
            double tlo = -INFINITY, thi = INFINITY;
            for (int axis = 0; axis < 2; axis++) {
                double hi = axis ? ly : lx;
                if (fabs(d[axis]) < 1e-15) {
                    if (p0[axis] < -tol || p0[axis] > hi + tol)
                        tlo = INFINITY;
                    continue;
                }
                double t1 = (0.0 - p0[axis]) / d[axis], t2 = (hi - p0[axis]) / d[axis];
                tlo = fmax(tlo, fmin(t1, t2));
                thi = fmin(thi, fmax(t1, t2));
            }
            if (!(thi - tlo > tol))
                continue; /* an extreme corner: a point, added with the corners */
            /* lattice points t = shift + k edge strictly inside, none closer than `gap` to an end */
            double shift = (line % 2) ? 0.5 * edge : 0.0, gap = 0.45 * edge;
            double kfirst = ceil((tlo + gap - shift) / edge), klast = floor((thi - gap - shift) / edge);
            plume_index prev = -1;
            for (double k = kfirst - 1.0; k <= klast + 1.0; k += 1.0) {
                double t = k < kfirst ? tlo : k > klast ? thi : shift + k * edge;
                double x = p0[0] + t * d[0], y = p0[1] + t * d[1];
                int on_side = fabs(x) <= tol || fabs(x - lx) <= tol || fabs(y) <= tol || fabs(y - ly) <= tol;
                plume_index id;
                if (k < kfirst || k > klast || on_side) {
                    id = boundary_point(g, sd, lx, ly, x, y, tol);
                } else {
                    id = plume_pslg_point(g, x, y) < 0 ? -1 : g->n - 1;
                }
                if (id < 0)
                    return PLUME_ENOMEM;
                if (prev >= 0 && plume_pslg_segment(g, prev, id) < 0)
                    return PLUME_ENOMEM;
                prev = id;
            }
        }
    }
    for (int k = 0; k < 4; k++)
        if (boundary_point(g, sd, lx, ly, corners[k][0], corners[k][1], tol) < 0)
            return PLUME_ENOMEM;
    return PLUME_OK;
}

/* Unaligned meshes: corners, then points along each side so that no boundary gap exceeds `edge`. */
static plume_status fill_sides(double lx, double ly, double edge, geometry *g, sides *sd)
{
    double tol = 1e-9 * fmax(lx, ly);
    double corners[4][2] = {{0, 0}, {lx, 0}, {lx, ly}, {0, ly}};
    for (int k = 0; k < 4; k++)
        if (boundary_point(g, sd, lx, ly, corners[k][0], corners[k][1], tol) < 0)
            return PLUME_ENOMEM;
    for (int s = 0; s < 4; s++) {
        qsort(sd->v[s], (size_t)sd->n[s], sizeof(side_point), cmp_side_point);
        plume_index n0 = sd->n[s];
        for (plume_index k = 0; k + 1 < n0; k++) {
            double ta = sd->v[s][k].t, tb = sd->v[s][k + 1].t;
            long pieces = (long)ceil((tb - ta) / edge - 1e-9);
            for (long j = 1; j < pieces; j++) {
                double t = ta + (tb - ta) * (double)j / (double)pieces;
                double x = s == 0 ? t : s == 1 ? lx : s == 2 ? t : 0.0;
                double y = s == 0 ? 0.0 : s == 1 ? t : s == 2 ? ly : t;
                if (plume_pslg_point(g, x, y) < 0)
                    return PLUME_ENOMEM;
            }
        }
    }
    return PLUME_OK;
}

plume_status plume_patch_mesh(double lx, double ly, double angle_deg, double edge, plume_patch_kind kind,
                              int dim, plume_mesh **out, plume_err *err)
{
    if (!out)
        return PLUME_EINVAL;
    *out = NULL;
    if (!(lx > 0) || !(ly > 0) || !isfinite(lx) || !isfinite(ly))
        return plume_err_set(err, PLUME_EINVAL, "sample size must be finite and > 0 (got lx = %g, ly = %g m)", lx, ly);
    if (!(edge > 0) || !isfinite(edge) || edge > fmin(lx, ly))
        return plume_err_set(err, PLUME_EINVAL, "edge length must be in (0, min(lx, ly) = %g] (got %g m)",
                             fmin(lx, ly), edge);
    if (!(angle_deg >= 0.0 && angle_deg <= 180.0))
        return plume_err_set(err, PLUME_EINVAL, "barb angle must be in [0, 180] degrees (got %g)", angle_deg);
    if (lx * ly / (0.43 * edge * edge) > 5e6)
        return plume_err_set(err, PLUME_EINVAL, "edge %g m would give more than 5e6 triangles", edge);
    if (dim != 2 && dim != 3)
        return plume_err_set(err, PLUME_EINVAL, "dim must be 2 or 3");
    plume_status st = PLUME_OK;
    geometry g = {0};
    sides sd = {{0}, {0}};
    plume_cdt_output cdt = {0};
    plume_mesh *m = NULL;
    size_t side_cap = (size_t)(4.0 * (lx + ly) / edge / 0.4) + 64;
    for (int s = 0; s < 4; s++)
        if (!(sd.v[s] = malloc(side_cap * sizeof(side_point)))) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    st = kind == PLUME_PATCH_ALIGNED ? aligned_geometry(lx, ly, angle_deg, edge, &g, &sd)
                                     : fill_sides(lx, ly, edge, &g, &sd);
    if (st != PLUME_OK)
        goto cleanup;
    plume_cdt_input in = {0};
    in.npoints = g.n;
    in.points = g.p;
    in.nsegments = g.ns;
    in.segments = g.s;
    in.remove_exterior = 0;
    in.max_edge = kind == PLUME_PATCH_UNALIGNED ? edge : 0.0;
    if ((st = plume_cdt_triangulate(&in, &cdt, err)) != PLUME_OK)
        goto cleanup;
    if ((st = plume_mesh_create(cdt.npoints, cdt.ntriangles, dim, &m, err)) != PLUME_OK)
        goto cleanup;
    memcpy(m->X, cdt.points, (size_t)(2 * cdt.npoints) * sizeof *m->X);
    memcpy(m->tri, cdt.triangles, (size_t)(3 * cdt.ntriangles) * sizeof *m->tri);
    double d[2];
    plume_patch_barb_direction(angle_deg, d);
    for (plume_index t = 0; t < m->nt; t++)
        m->barb_dir[2 * t] = d[0], m->barb_dir[2 * t + 1] = d[1];
    plume_mesh_reset_current(m);
    if ((st = plume_mesh_build_topology(m, err)) != PLUME_OK)
        goto cleanup;
    *out = m;
    m = NULL;
cleanup:
    plume_mesh_destroy(&m);
    plume_cdt_output_free(&cdt);
    free(g.p);
    free(g.s);
    for (int s = 0; s < 4; s++)
        free(sd.v[s]);
    return st;
}
