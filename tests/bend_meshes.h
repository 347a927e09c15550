/* Mesh families and the cylinder map shared by tests/test_shape_bending.c and
 * bench/bench_bending.c (bending that must not depend on the mesh). Header-only,
 * static functions; a patch Lx x Ly (in its own frame) triangulated five ways:
 *   BM_RIGHT        right-triangle grid, edges along x, y and a diagonal
 *   BM_RIGHT45      the same grid with the patch rotated 45 degrees
 *   BM_EQUI_ALONG   near-equilateral rows along the cylinder axis (material y)
 *   BM_EQUI_ACROSS  near-equilateral rows across it (along material x)
 *   BM_DELAUNAY     Delaunay triangulation (CGAL) of seeded jittered random points
 * The cylinders bend with their curvature along material x (axis along y). */
#ifndef PLUME_TEST_BEND_MESHES_H
#define PLUME_TEST_BEND_MESHES_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_rng.h"
#include "../lib/core/cdt.h"
#include "../lib/core/mesh.h"
#include "../macro/shell/bending.h"

#define BM_PI 3.14159265358979323846

enum { BM_RIGHT = 0, BM_RIGHT45, BM_EQUI_ALONG, BM_EQUI_ACROSS, BM_DELAUNAY, BM_NFAMILY };

static const char *const bm_family_name[BM_NFAMILY] __attribute__((unused)) = {"right grid", "right grid 45", "equi rows // axis",
                                                       "equi rows _|_ axis", "random Delaunay"};

/* Finishes a mesh: barbs at barb_deg, material 0, topology, x = X. NULL on failure. */
static inline plume_mesh *bm_finish(plume_mesh *m, double barb_deg)
{
    for (plume_index t = 0; t < m->nt; t++) {
        m->barb_dir[2 * t] = cos(barb_deg * BM_PI / 180.0);
        m->barb_dir[2 * t + 1] = sin(barb_deg * BM_PI / 180.0);
        m->material[t] = 0;
    }
    if (plume_mesh_build_topology(m, NULL) != PLUME_OK) {
        plume_mesh_destroy(&m);
        return NULL;
    }
    plume_mesh_reset_current(m);
    return m;
}

/* Rows of points y_j = j Ly / nrow (j = 0..nrow), each sorted by x in [0, Lx], zipped into
 * triangles row by row, then rotated by rot_deg. equi: odd rows are staggered by half a cell
 * (with the two ends on the sides), which gives near-equilateral triangles; otherwise every row
 * is x_i = i Lx / ncol (squares cut along a diagonal). */
static inline plume_mesh *bm_rows_mesh(int ncol, int nrow, double Lx, double Ly, int equi, double rot_deg, double barb_deg)
{
    const int maxrow = ncol + 2;
    const plume_index nv_max = (plume_index)(nrow + 1) * maxrow;
    double *px = malloc(sizeof(double) * (size_t)nv_max), *py = malloc(sizeof(double) * (size_t)nv_max);
    int *rs = malloc(sizeof(int) * (size_t)(nrow + 2));
    plume_index *tri = malloc(sizeof(plume_index) * 3 * (size_t)(2 * nv_max));
    plume_mesh *m = NULL;
    if (!px || !py || !rs || !tri)
        goto done;
    plume_index nv = 0, nt = 0;
    for (int j = 0; j <= nrow; j++) {
        rs[j] = (int)nv;
        const double y = Ly * j / nrow;
        if (equi && j % 2) {
            px[nv] = 0.0, py[nv++] = y;
            for (int i = 0; i < ncol; i++)
                px[nv] = Lx * (i + 0.5) / ncol, py[nv++] = y;
            px[nv] = Lx, py[nv++] = y;
        } else {
            for (int i = 0; i <= ncol; i++)
                px[nv] = Lx * i / ncol, py[nv++] = y;
        }
    }
    rs[nrow + 1] = (int)nv;
    for (int j = 0; j < nrow; j++) {
        int i = rs[j], k = rs[j + 1];
        const int ie = rs[j + 1] - 1, ke = rs[j + 2] - 1;
        while (i < ie || k < ke) {
            if (k == ke || (i < ie && px[i + 1] <= px[k + 1] + 1e-12)) {
                tri[3 * nt] = i, tri[3 * nt + 1] = i + 1, tri[3 * nt + 2] = k;
                i++;
            } else {
                tri[3 * nt] = i, tri[3 * nt + 1] = k + 1, tri[3 * nt + 2] = k;
                k++;
            }
            nt++;
        }
    }
    if (plume_mesh_create(nv, nt, 3, &m, NULL) != PLUME_OK) {
        m = NULL;
        goto done;
    }
    const double c = cos(rot_deg * BM_PI / 180.0), s = sin(rot_deg * BM_PI / 180.0);
    for (plume_index v = 0; v < nv; v++) {
        m->X[2 * v] = c * px[v] - s * py[v];
        m->X[2 * v + 1] = s * px[v] + c * py[v];
    }
    memcpy(m->tri, tri, sizeof(plume_index) * 3 * (size_t)nt);
    m = bm_finish(m, barb_deg);
done:
    free(px);
    free(py);
    free(rs);
    free(tri);
    return m;
}

/* Delaunay triangulation of the rectangle's boundary points (spacing about h, jittered along the
 * sides) and interior points on a grid of spacing h jittered by +-0.35 h, seeded. */
static inline plume_mesh *bm_delaunay_mesh(double h, double Lx, double Ly, unsigned long long seed, double barb_deg)
{
    rng64 r = {seed * 2654435761ULL + 0x9e3779b97f4a7c15ULL};
    const int nx = (int)ceil(Lx / h - 1e-9), ny = (int)ceil(Ly / h - 1e-9);
    const plume_index cap = (plume_index)(nx + 1) * (ny + 1) + 8;
    double *pts = malloc(sizeof(double) * 2 * (size_t)cap);
    plume_mesh *m = NULL;
    if (!pts)
        return NULL;
    plume_index np = 0;
    const double hx = Lx / nx, hy = Ly / ny;
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            double x = i * hx, y = j * hy;
            const int bx = i == 0 || i == nx, by = j == 0 || j == ny;
            if (!bx)
                x += urange(&r, -0.35, 0.35) * hx;
            if (!by)
                y += urange(&r, -0.35, 0.35) * hy;
            pts[2 * np] = x, pts[2 * np + 1] = y;
            np++;
        }
    plume_cdt_input in;
    memset(&in, 0, sizeof in);
    in.npoints = np;
    in.points = pts;
    plume_cdt_output out;
    memset(&out, 0, sizeof out);
    if (plume_cdt_triangulate(&in, &out, NULL) == PLUME_OK &&
        plume_mesh_create(out.npoints, out.ntriangles, 3, &m, NULL) == PLUME_OK) {
        memcpy(m->X, out.points, sizeof(double) * 2 * (size_t)out.npoints);
        memcpy(m->tri, out.triangles, sizeof(plume_index) * 3 * (size_t)out.ntriangles);
        m = bm_finish(m, barb_deg);
    }
    plume_cdt_output_free(&out);
    free(pts);
    return m;
}

/* A family's mesh of the Lx x Ly patch at spacing about h (h divides Lx, Ly for the grids). */
static inline plume_mesh *bm_family_mesh(int family, double h, double Lx, double Ly, double barb_deg)
{
    const int nx = (int)lround(Lx / h), ny = (int)lround(Ly / h);
    const int nrow_e = (int)lround(Ly / (h * sqrt(3.0) / 2.0));
    switch (family) {
    case BM_RIGHT:
        return bm_rows_mesh(nx, ny, Lx, Ly, 0, 0.0, barb_deg);
    case BM_RIGHT45:
        return bm_rows_mesh(nx, ny, Lx, Ly, 0, 45.0, barb_deg);
    case BM_EQUI_ALONG: /* rows along material y: build along x over (Ly, Lx) and turn by 90 */
        return bm_rows_mesh((int)lround(Ly / h), (int)lround(Lx / (h * sqrt(3.0) / 2.0)), Ly, Lx, 1, 90.0, barb_deg);
    case BM_EQUI_ACROSS:
        return bm_rows_mesh(nx, nrow_e, Lx, Ly, 1, 0.0, barb_deg);
    case BM_DELAUNAY:
        return bm_delaunay_mesh(h, Lx, Ly, 12345ULL + (unsigned long long)lround(1.0 / h), barb_deg);
    default:
        return NULL;
    }
}

/* A fixed rigid motion for invariance tests: the rotation Q of angle 1.1 about the axis
 * (1, 2, 2)/3, then the shift (3, -1, 7.5); y = Q x + shift for every vertex of x (3 nv). */
static inline void bm_rigid_motion(plume_index nv, const double *x, double Q[3][3], double *y)
{
    const double ax[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3}, an = 1.1, c = cos(an), s = sin(an);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            Q[i][j] = (i == j ? c : 0.0) + (1.0 - c) * ax[i] * ax[j];
    Q[0][1] -= s * ax[2], Q[0][2] += s * ax[1], Q[1][0] += s * ax[2];
    Q[1][2] -= s * ax[0], Q[2][0] -= s * ax[1], Q[2][1] += s * ax[0];
    const double shift[3] = {3.0, -1.0, 7.5};
    for (plume_index v = 0; v < nv; v++)
        for (int i = 0; i < 3; i++)
            y[3 * v + i] = Q[i][0] * x[3 * v] + Q[i][1] * x[3 * v + 1] + Q[i][2] * x[3 * v + 2] + shift[i];
}

/* Maps the flat reference onto a cylinder of curvature k whose curvature direction is the
 * material unit vector at curv_deg, isometrically (arc length along the curvature direction
 * kept); the centre of curvature is on +z. */
static inline void bm_map_cylinder(const plume_mesh *m, double curv_deg, double k, double *x)
{
    const double c[2] = {cos(curv_deg * BM_PI / 180.0), sin(curv_deg * BM_PI / 180.0)};
    const double a[2] = {-c[1], c[0]};
    for (plume_index v = 0; v < m->nv; v++) {
        const double s = c[0] * m->X[2 * v] + c[1] * m->X[2 * v + 1];
        const double w = a[0] * m->X[2 * v] + a[1] * m->X[2 * v + 1];
        const double p = sin(k * s) / k, z = (1.0 - cos(k * s)) / k;
        x[3 * v] = w * a[0] + p * c[0];
        x[3 * v + 1] = w * a[1] + p * c[1];
        x[3 * v + 2] = z;
    }
}

/* The unit normal of bm_map_cylinder's cylinder (curvature k along the material direction at
 * curv_deg) at the material midpoint of edge e: the exact director of a midedge term there. */
static inline void bm_cylinder_normal(const plume_mesh *m, plume_index e, double curv_deg, double k, double nu[3])
{
    const double c[2] = {cos(curv_deg * BM_PI / 180.0), sin(curv_deg * BM_PI / 180.0)};
    const double *Pa = m->X + 2 * m->edges[2 * e], *Pb = m->X + 2 * m->edges[2 * e + 1];
    const double s = 0.5 * (c[0] * (Pa[0] + Pb[0]) + c[1] * (Pa[1] + Pb[1]));
    nu[0] = -sin(k * s) * c[0], nu[1] = -sin(k * s) * c[1], nu[2] = cos(k * s);
}

/* Continuum energy per unit area of a cylinder of curvature k at angle phi_deg between the
 * curvature direction and the barbs: 1/2 k^2 (D_long c^4 + D_trans s^4 + (2 D_12 + 4 D_66) c^2 s^2),
 * D_66 derived by Huber's rule when D_twist == 0 (bending.h). */
static inline double bm_continuum_density(const plume_bending_material *mat, double k, double phi_deg)
{
    const double c = cos(phi_deg * BM_PI / 180.0), s = sin(phi_deg * BM_PI / 180.0);
    const double D66 = mat->D_twist > 0.0 ? mat->D_twist : 0.5 * (sqrt(mat->D_long * mat->D_trans) - mat->D_coupling);
    return 0.5 * k * k *
           (mat->D_long * c * c * c * c + mat->D_trans * s * s * s * s + (2.0 * mat->D_coupling + 4.0 * D66) * c * c * s * s);
}

#endif
