/* Tests of the anisotropic hinge bending term (macro/shell/bending.c): cylinder energies against
 * 1/2 D k^2 per unit area under refinement (barbs along x, along y and at 30 degrees on
 * barb-aligned grids; isotropic plates on the equilateral lattice in every direction), the
 * single-hinge formula and its anisotropic stiffness, finite-difference checks of the gradient and
 * Hessian (random folds of both signs, near flat, curved rest shape), PSD projection, rigid-motion
 * invariance, angle wrapping, collapsed triangles, the term interface and every input error. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "term_fd.h"
#include "test_rng.h"
#include "bend_meshes.h"
#include "../lib/core/dense.h"
#include "../lib/core/mesh.h"
#include "../macro/shell/bending.h"

#define PI 3.14159265358979323846

/* The vane of supplementary Table 3 (a): EI_perp (bending the barbs) and the transverse modulus,
 * N m. Their ratio, 2500, is the anisotropy every cylinder test runs at. */
static const plume_bending_material MAT_VANE = {2.5e-4, 1e-7, 0.0, 0.0};

/* ---- meshes ------------------------------------------------------------------------------ */

enum { GRID_RIGHT = 0, GRID_EQUI = 1 };

/* n x n cells of size h: vertex (i, j) at R(rot) (i h u + j h w) with u = (1, 0) and
 * w = (0, 1) (GRID_RIGHT: squares cut along the diagonal u + w) or w = (1/2, sqrt3/2) (GRID_EQUI:
 * rhombi cut along the short diagonal into equilateral triangles). Edges lie along R(rot) u and
 * R(rot) w (and a diagonal), so with rot = the barb angle the grid is barb-aligned. Every triangle
 * gets barb direction (cos barb, sin barb), material 0; topology built; x = X (z = 0). */
static plume_mesh *grid_mesh(int n, double h, int kind, double rot_deg, double barb_deg)
{
    plume_mesh *m = NULL;
    if (plume_mesh_create((plume_index)(n + 1) * (n + 1), 2 * (plume_index)n * n, 3, &m, NULL) != PLUME_OK)
        return NULL;
    const double w[2] = {kind == GRID_EQUI ? 0.5 : 0.0, kind == GRID_EQUI ? sqrt(3.0) / 2.0 : 1.0};
    const double c = cos(rot_deg * PI / 180.0), s = sin(rot_deg * PI / 180.0);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            const double X = h * (i + j * w[0]), Y = h * j * w[1];
            m->X[2 * (j * (n + 1) + i)] = c * X - s * Y;
            m->X[2 * (j * (n + 1) + i) + 1] = s * X + c * Y;
        }
    plume_index t = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const plume_index a = j * (n + 1) + i, b = a + 1, cc = a + n + 2, d = a + n + 1;
            const plume_index right[6] = {a, b, cc, a, cc, d}, equi[6] = {a, b, d, b, cc, d};
            memcpy(m->tri + 3 * t, kind == GRID_EQUI ? equi : right, sizeof right);
            t += 2;
        }
    for (plume_index q = 0; q < m->nt; q++) {
        m->barb_dir[2 * q] = cos(barb_deg * PI / 180.0);
        m->barb_dir[2 * q + 1] = sin(barb_deg * PI / 180.0);
    }
    plume_err err;
    if (plume_mesh_build_topology(m, &err) != PLUME_OK) {
        plume_mesh_destroy(&m);
        return NULL;
    }
    plume_mesh_reset_current(m);
    return m;
}

static double term_energy(const plume_term *t, const double *x)
{
    double E = 0.0;
    if (t->eval(t->ctx, 3, x, &E, NULL, NULL, 0) != PLUME_OK)
        return NAN;
    return E;
}

/* Relative error of the bending energy of an n x n patch (side 1) bent into a cylinder of
 * curvature k in direction curv_deg, against 1/2 D k^2 * area. */
static double cylinder_error(int n, int kind, double rot_deg, double barb_deg, double curv_deg,
                             const plume_bending_material *mat, double D_expected)
{
    plume_mesh *m = grid_mesh(n, 1.0 / n, kind, rot_deg, barb_deg);
    if (!m)
        return NAN;
    const double k = 1.3;
    plume_term t;
    plume_err err;
    double rel = NAN;
    if (plume_bending_term_create(m, mat, 1, NULL, &t, &err) == PLUME_OK) {
        bm_map_cylinder(m, curv_deg, k, m->x);
        const double E = term_energy(&t, m->x);
        const double ref = 0.5 * D_expected * k * k * plume_mesh_total_area(m);
        rel = (E - ref) / ref;
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
    return rel;
}

/* The cylinder energy on 16, 32 and 64 cells a side: |error| must shrink at each refinement and
 * be below 2 % on the finest (the free boundary, whose outer triangles have no hinge along the
 * axis, costs O(h); the interior is exact). */
static void check_cylinder(const char *what, int kind, double rot_deg, double barb_deg, double curv_deg,
                           const plume_bending_material *mat, double D_expected)
{
    double e[3];
    for (int r = 0; r < 3; r++)
        e[r] = cylinder_error(16 << r, kind, rot_deg, barb_deg, curv_deg, mat, D_expected);
    fprintf(stderr, "    %-44s relative error n=16: %+.4f  n=32: %+.4f  n=64: %+.4f\n", what, e[0], e[1],
            e[2]);
    CHECK(isfinite(e[0]) && isfinite(e[1]) && isfinite(e[2]));
    /* (a patch whose boundary triangles all have their axis edge inside is exact from the start) */
    CHECK(fabs(e[1]) < fabs(e[0]) || fabs(e[0]) < 1e-12);
    CHECK(fabs(e[2]) < fabs(e[1]) || fabs(e[1]) < 1e-12);
    CHECK(fabs(e[2]) < 0.02);
}

/* barbs along x on the regular grid (its edges lie along the barbs) */
void test_bending_cylinder_barbs_x(void)
{
    /* axis perpendicular to the barbs: curvature along d bends the barbs */
    check_cylinder("barbs x, axis _|_ barbs (D_long)", GRID_RIGHT, 0.0, 0.0, 0.0, &MAT_VANE, MAT_VANE.D_long);
    check_cylinder("barbs x, axis // barbs (D_trans)", GRID_RIGHT, 0.0, 0.0, 90.0, &MAT_VANE, MAT_VANE.D_trans);
}

/* barbs along y on the same grid */
void test_bending_cylinder_barbs_y(void)
{
    check_cylinder("barbs y, axis _|_ barbs (D_long)", GRID_RIGHT, 0.0, 90.0, 90.0, &MAT_VANE, MAT_VANE.D_long);
    check_cylinder("barbs y, axis // barbs (D_trans)", GRID_RIGHT, 0.0, 90.0, 0.0, &MAT_VANE, MAT_VANE.D_trans);
    /* the same with the opposite barb sign and the barb direction not normalised */
    check_cylinder("barbs -y, axis _|_ barbs (D_long)", GRID_RIGHT, 0.0, 270.0, 90.0, &MAT_VANE,
                   MAT_VANE.D_long);
}

/* barbs at 30 degrees on a grid rotated with them (barb-aligned); on the equilateral barb-aligned
 * lattice (rows along the barbs, as the aligned patch mesher builds them) the soft mode too */
void test_bending_cylinder_barbs_30(void)
{
    check_cylinder("barbs 30, aligned, axis _|_ barbs (D_long)", GRID_RIGHT, 30.0, 30.0, 30.0, &MAT_VANE,
                   MAT_VANE.D_long);
    check_cylinder("barbs 30, aligned, axis // barbs (D_trans)", GRID_RIGHT, 30.0, 30.0, 120.0, &MAT_VANE,
                   MAT_VANE.D_trans);
    check_cylinder("barbs 30, equilateral, axis // barbs (D_trans)", GRID_EQUI, 30.0, 30.0, 120.0, &MAT_VANE,
                   MAT_VANE.D_trans);
    check_cylinder("barbs 0, equilateral, axis // barbs (D_trans)", GRID_EQUI, 0.0, 0.0, 90.0, &MAT_VANE,
                   MAT_VANE.D_trans);
}

/* The constant 1/2: an isotropic plate on the equilateral lattice stores 1/2 D k^2 per unit area
 * for a cylinder in any direction (every 15 degrees checked), and on the right-triangle grid for
 * the axes along its three edge families. */
void test_bending_cylinder_isotropic(void)
{
    const plume_bending_material iso = {3.0, 3.0, 0.0, 0.0};
    char what[64];
    for (int a = 0; a < 180; a += 15) {
        snprintf(what, sizeof what, "isotropic, equilateral, curvature at %d", a);
        check_cylinder(what, GRID_EQUI, 0.0, 0.0, (double)a, &iso, iso.D_long);
    }
    check_cylinder("isotropic, right grid, curvature at 0", GRID_RIGHT, 0.0, 0.0, 0.0, &iso, iso.D_long);
    check_cylinder("isotropic, right grid, curvature at 90", GRID_RIGHT, 0.0, 0.0, 90.0, &iso, iso.D_long);
    /* axis along the diagonals: the whole patch is exact (no boundary deficit to shrink) */
    const double e = cylinder_error(16, GRID_RIGHT, 0.0, 0.0, 135.0, &iso, iso.D_long);
    CHECK(fabs(e) < 1e-12);
}

/* ---- one hinge ------------------------------------------------------------------------------- */

/* Two triangles on the edge (0,0)-(1,0): x2 = (0.3, 0.8) above, x3 = (0.6, -0.7) below. */
static plume_mesh *hinge_mesh(double barb_deg, int order)
{
    plume_mesh *m = NULL;
    if (plume_mesh_create(4, 2, 3, &m, NULL) != PLUME_OK)
        return NULL;
    const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.3, 0.8, 0.6, -0.7};
    memcpy(m->X, X, sizeof X);
    /* two vertex orders of the same triangles: the stencil must come out the same way */
    const plume_index t0[6] = {0, 1, 2, 1, 0, 3}, t1[6] = {2, 0, 1, 3, 1, 0};
    memcpy(m->tri, order ? t1 : t0, sizeof t0);
    for (int t = 0; t < 2; t++) {
        m->barb_dir[2 * t] = 2.0 * cos(barb_deg * PI / 180.0); /* not normalised on purpose */
        m->barb_dir[2 * t + 1] = 2.0 * sin(barb_deg * PI / 180.0);
    }
    plume_err err;
    if (plume_mesh_build_topology(m, &err) != PLUME_OK) {
        plume_mesh_destroy(&m);
        return NULL;
    }
    plume_mesh_reset_current(m);
    return m;
}

/* the flap x3 rotated about the edge by alpha toward +z (the normal side), x2 by beta */
static void fold_hinge(double *x, double alpha, double beta)
{
    const double p[12] = {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.3, 0.8 * cos(beta), 0.8 * sin(beta),
                          0.6, -0.7 * cos(alpha), 0.7 * sin(alpha)};
    memcpy(x, p, sizeof p);
}

/* E = 1/2 D_e |e|^2/(A1 + A2) (theta - theta0)^2 exactly, theta the fold angle with its sign,
 * D_e = D_long cos^2 phi + D_trans sin^2 phi, phi between the edge normal and the barbs */
void test_bending_single_hinge(void)
{
    const plume_bending_material mat = {5.0, 0.2, 0.0, 0.0};
    const double A = 0.5 * 0.8 + 0.5 * 0.7, l2 = 1.0;
    for (int order = 0; order < 2; order++) {
        for (int ib = 0; ib < 5; ib++) {
            const double barb = 25.0 * ib; /* edge along x: phi = 90 - barb */
            plume_mesh *m = hinge_mesh(barb, order);
            CHECK(m != NULL);
            if (!m)
                return;
            const double phi = (90.0 - barb) * PI / 180.0;
            const double De = mat.D_long * cos(phi) * cos(phi) + mat.D_trans * sin(phi) * sin(phi);
            const double kappa = 0.5 * De * l2 / A;
            plume_term t;
            plume_err err;
            CHECK(plume_bending_term_create(m, &mat, 1, NULL, &t, &err) == PLUME_OK);
            CHECK(t.nstencil == 1);
            double x[12];
            const double angles[] = {0.7, -0.7, 2.0, -2.9, 1e-4, -3e-5};
            for (size_t i = 0; i < sizeof angles / sizeof angles[0]; i++) {
                /* the fold shared between the two flaps: theta = alpha + beta */
                fold_hinge(x, 0.25 * angles[i], 0.75 * angles[i]);
                CHECK_REL(term_energy(&t, x), kappa * angles[i] * angles[i], 1e-12, 1e-300);
            }
            t.destroy(t.ctx);

            /* a rest shape folded by +0.5: zero energy there, (theta - 0.5)^2 elsewhere, so the
             * sign of theta is consistent between the rest shape and the current one */
            double rest[12];
            fold_hinge(rest, 0.5, 0.0);
            CHECK(plume_bending_term_create(m, &mat, 1, rest, &t, &err) == PLUME_OK);
            fold_hinge(x, 0.2, 0.3);
            CHECK(fabs(term_energy(&t, x)) < 1e-28 * kappa);
            fold_hinge(x, -0.5, 0.0);
            CHECK_REL(term_energy(&t, x), kappa * 1.0, 1e-12, 0.0);
            fold_hinge(x, 0.0, 0.0);
            CHECK_REL(term_energy(&t, x), kappa * 0.25, 1e-12, 0.0);
            t.destroy(t.ctx);
            plume_mesh_destroy(&m);
        }
    }
}

/* theta > 0 when the surface bends toward its normal (the CCW side of the reference): a cylinder
 * rest shape with the centre on +z is at rest when bent that way, and costs 4x when bent the
 * other way */
void test_bending_sign_convention(void)
{
    plume_mesh *m = grid_mesh(6, 1.0 / 6, GRID_EQUI, 0.0, 0.0);
    CHECK(m != NULL);
    if (!m)
        return;
    const plume_bending_material iso = {1.0, 1.0, 0.0, 0.0};
    double *rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
    double *flip = malloc(sizeof(double) * 3 * (size_t)m->nv);
    CHECK(rest && flip);
    if (rest && flip) {
        bm_map_cylinder(m, 30.0, 2.0, rest);
        memcpy(flip, rest, sizeof(double) * 3 * (size_t)m->nv);
        for (plume_index v = 0; v < m->nv; v++)
            flip[3 * v + 2] = -flip[3 * v + 2];
        plume_term flat, curved;
        CHECK(plume_bending_term_create(m, &iso, 1, NULL, &flat, NULL) == PLUME_OK);
        CHECK(plume_bending_term_create(m, &iso, 1, rest, &curved, NULL) == PLUME_OK);
        const double Eflat = term_energy(&flat, rest);
        CHECK(Eflat > 0.0);
        CHECK(term_energy(&curved, rest) < 1e-28);
        CHECK_REL(term_energy(&curved, m->x), Eflat, 1e-12, 0.0);
        CHECK_REL(term_energy(&curved, flip), 4.0 * Eflat, 1e-9, 0.0);
        CHECK_REL(term_energy(&flat, flip), Eflat, 1e-12, 0.0);
        flat.destroy(flat.ctx);
        curved.destroy(curved.ctx);
    }
    free(rest);
    free(flip);
    plume_mesh_destroy(&m);
}

/* ---- derivatives ------------------------------------------------------------------------------ */

/* random folds of a 3x3 patch (theta of both signs up to ~2), materials alternating */
void test_bending_fd_random(void)
{
    rng64 r = {0x5eed1234abcdULL};
    const plume_bending_material mats[2] = {{2.0, 0.3, 0.0, 0.0}, {0.5, 1.5, 0.0, 0.0}};
    for (int trial = 0; trial < 6; trial++) {
        plume_mesh *m = grid_mesh(3, 0.4, trial % 2 ? GRID_EQUI : GRID_RIGHT, 20.0 * trial, 35.0 * trial);
        CHECK(m != NULL);
        if (!m)
            return;
        for (plume_index q = 0; q < m->nt; q++)
            m->material[q] = (int)(q % 2);
        double *rest = NULL;
        if (trial >= 3) { /* curved rest shape */
            rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
            CHECK(rest != NULL);
            if (!rest)
                break;
            bm_map_cylinder(m, 10.0 * trial, 1.5, rest);
            for (plume_index i = 0; i < 3 * m->nv; i++)
                rest[i] += urange(&r, -0.05, 0.05);
        }
        plume_term t;
        plume_err err;
        CHECK(plume_bending_term_create(m, mats, 2, rest, &t, &err) == PLUME_OK);
        /* a random smooth fold plus noise */
        bm_map_cylinder(m, urange(&r, 0.0, 180.0), urange(&r, -2.5, 2.5), m->x);
        for (plume_index i = 0; i < 3 * m->nv; i++)
            m->x[i] += urange(&r, -0.12, 0.12);
        term_fd_check(&t, m->nv, m->x, 1e-6, 2e-7, trial < 3 ? "random fold" : "random fold, curved rest");
        t.destroy(t.ctx);
        free(rest);
        plume_mesh_destroy(&m);
    }
}

/* one hinge at chosen angles: both signs, past pi/2, near flat (1e-4), and a curved rest angle;
 * a random rigid motion and edge-vertex shifts so that no coordinate is special */
void test_bending_fd_angles(void)
{
    rng64 r = {0xfeedULL};
    const plume_bending_material mat = {1.7, 0.4, 0.0, 0.0};
    const double cases[][2] = {{0.9, 0.0}, {-0.9, 0.0}, {2.6, 0.0},  {-2.6, 0.0},
                               {1e-4, 0.0}, {-1e-4, 0.0}, {0.3, -1.1}, {-1e-4, 0.8}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        plume_mesh *m = hinge_mesh(40.0, (int)(c % 2));
        CHECK(m != NULL);
        if (!m)
            return;
        double rest[12], *restp = NULL;
        if (cases[c][1] != 0.0) {
            fold_hinge(rest, cases[c][1], 0.0);
            restp = rest;
        }
        plume_term t;
        CHECK(plume_bending_term_create(m, &mat, 1, restp, &t, NULL) == PLUME_OK);
        double x[12];
        fold_hinge(x, 0.6 * cases[c][0], 0.4 * cases[c][0]);
        /* stretch the current triangles a little (the angle is unchanged by in-plane moves of the
         * opposite vertices along their own planes, but the derivatives are not) */
        x[3] += 0.2;
        x[6] += urange(&r, -0.2, 0.2);
        x[9] += urange(&r, -0.2, 0.2);
        const double Q[9] = {0.36, 0.48, -0.8, -0.8, 0.6, 0.0, 0.48, 0.64, 0.6}; /* a rotation */
        double y[12];
        for (int v = 0; v < 4; v++)
            for (int i = 0; i < 3; i++)
                y[3 * v + i] = Q[3 * i] * x[3 * v] + Q[3 * i + 1] * x[3 * v + 1] + Q[3 * i + 2] * x[3 * v + 2] +
                               0.1 * (i + 1);
        char what[64];
        snprintf(what, sizeof what, "theta %g, theta0 %g", cases[c][0], cases[c][1]);
        term_fd_check(&t, 4, y, fabs(cases[c][0]) < 1e-3 ? 1e-7 : 1e-6, 2e-7, what);
        t.destroy(t.ctx);
        plume_mesh_destroy(&m);
    }
}

/* ---- projection, invariance, wrapping, degenerate states ---------------------------------------- */

static double min_eig12(const double *B)
{
    double A[144], lam[12], V[144];
    memcpy(A, B, sizeof A);
    plume_dense_sym_eig(12, A, lam, V);
    return lam[0];
}

void test_bending_projection(void)
{
    rng64 r = {0xabcdef01ULL};
    const plume_bending_material mat = {2.0, 0.5, 0.0, 0.0};
    plume_mesh *m = grid_mesh(4, 0.3, GRID_RIGHT, 10.0, 70.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_term t;
    CHECK(plume_bending_term_create(m, &mat, 1, NULL, &t, NULL) == PLUME_OK);
    const size_t nb = 144 * (size_t)t.nstencil;
    double *H = malloc(sizeof(double) * nb), *P = malloc(sizeof(double) * nb);
    CHECK(H && P);
    if (H && P) {
        /* at rest every block is 2 kappa g g^T (PSD): projection leaves it bit for bit */
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, 0) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, P, 1) == PLUME_OK);
        CHECK(memcmp(H, P, sizeof(double) * nb) == 0);
        int indefinite = 0;
        for (int trial = 0; trial < 4; trial++) {
            bm_map_cylinder(m, urange(&r, 0.0, 180.0), urange(&r, -3.0, 3.0), m->x);
            for (plume_index i = 0; i < 3 * m->nv; i++)
                m->x[i] += urange(&r, -0.1, 0.1);
            CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, 0) == PLUME_OK);
            CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, P, 1) == PLUME_OK);
            for (plume_index s = 0; s < t.nstencil; s++) {
                const double *h = H + 144 * s, *p = P + 144 * s;
                const double scale = term_max_abs(h, 144);
                const double lh = min_eig12(h), lp = min_eig12(p);
                indefinite += lh < -1e-10 * scale;
                CHECK(lp >= -1e-12 * scale);
                /* exactly symmetric, translation modes in the null space */
                for (int i = 0; i < 12; i++)
                    for (int j = 0; j < 12; j++)
                        CHECK(p[i * 12 + j] == p[j * 12 + i]);
                for (int i = 0; i < 12; i++)
                    for (int c = 0; c < 3; c++) {
                        const double s4 = p[i * 12 + c] + p[i * 12 + 3 + c] + p[i * 12 + 6 + c] + p[i * 12 + 9 + c];
                        CHECK(fabs(s4) <= 1e-12 * scale);
                    }
                /* an indefinite block moves by its negative part only: P - H is PSD */
                double D[144];
                for (int i = 0; i < 144; i++)
                    D[i] = p[i] - h[i];
                CHECK(min_eig12(D) >= -1e-10 * scale);
                if (lh >= 1e-9 * scale) /* clearly PSD: unchanged */
                    CHECK(memcmp(h, p, sizeof D) == 0);
            }
        }
        CHECK(indefinite > 0); /* the test saw the projection at work */
    }
    free(H);
    free(P);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

void test_bending_rigid_invariance(void)
{
    rng64 r = {0x77ULL};
    const plume_bending_material mat = {1.2, 0.1, 0.0, 0.0};
    plume_mesh *m = grid_mesh(3, 0.5, GRID_EQUI, 15.0, 15.0);
    CHECK(m != NULL);
    if (!m)
        return;
    double *rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
    CHECK(rest != NULL);
    if (!rest) {
        plume_mesh_destroy(&m);
        return;
    }
    bm_map_cylinder(m, 80.0, 0.7, rest);
    plume_term t;
    CHECK(plume_bending_term_create(m, &mat, 1, rest, &t, NULL) == PLUME_OK);
    const long n = 3 * (long)m->nv;
    double *y = malloc(sizeof(double) * (size_t)n), *g = calloc((size_t)n, sizeof *g);
    double *gy = calloc((size_t)n, sizeof *gy);
    double *H = malloc(sizeof(double) * 144 * (size_t)t.nstencil), *Hy = malloc(sizeof(double) * 144 * (size_t)t.nstencil);
    CHECK(y && g && gy && H && Hy);
    if (y && g && gy && H && Hy) {
        bm_map_cylinder(m, 20.0, -1.9, m->x);
        for (long i = 0; i < n; i++)
            m->x[i] += urange(&r, -0.1, 0.1);
        double Q[3][3];
        bm_rigid_motion(m->nv, m->x, Q, y);
        double E = 0.0, Ey = 0.0;
        CHECK(t.eval(t.ctx, 3, m->x, &E, g, H, 0) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, y, &Ey, gy, Hy, 0) == PLUME_OK);
        CHECK(E > 0.0);
        CHECK_REL(Ey, E, 1e-11, 0.0);
        const double gs = term_max_abs(g, n);
        double gerr = 0.0;
        for (plume_index v = 0; v < m->nv; v++)
            for (int i = 0; i < 3; i++) {
                const double Rg = Q[i][0] * g[3 * v] + Q[i][1] * g[3 * v + 1] + Q[i][2] * g[3 * v + 2];
                gerr = fmax(gerr, fabs(gy[3 * v + i] - Rg));
            }
        CHECK(gerr <= 1e-11 * gs);
        /* Hessian blocks: H_y = (I4 x Q) H (I4 x Q)^T */
        double herr = 0.0, hs = 0.0;
        for (plume_index st = 0; st < t.nstencil; st++) {
            const double *h = H + 144 * st, *hy = Hy + 144 * st;
            hs = fmax(hs, term_max_abs(h, 144));
            for (int a = 0; a < 4; a++)
                for (int b = 0; b < 4; b++)
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++) {
                            double v = 0.0;
                            for (int p = 0; p < 3; p++)
                                for (int q = 0; q < 3; q++)
                                    v += Q[i][p] * h[(3 * a + p) * 12 + 3 * b + q] * Q[j][q];
                            herr = fmax(herr, fabs(hy[(3 * a + i) * 12 + 3 * b + j] - v));
                        }
        }
        CHECK(herr <= 1e-11 * hs);
        /* a pure translation changes nothing at all in the angles: energy to rounding */
        const double shift[3] = {3.0, -1.0, 7.5};
        for (long i = 0; i < n; i++)
            y[i] = m->x[i] + shift[i % 3];
        Ey = 0.0;
        CHECK(t.eval(t.ctx, 3, y, &Ey, NULL, NULL, 0) == PLUME_OK);
        CHECK_REL(Ey, E, 1e-11, 0.0);
    }
    free(y);
    free(g);
    free(gy);
    free(H);
    free(Hy);
    free(rest);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* A rest angle near pi: folding a little past pi (atan2 jumps to -pi) costs the small difference,
 * not (2 pi)^2 */
void test_bending_angle_wrap(void)
{
    const plume_bending_material mat = {1.0, 1.0, 0.0, 0.0};
    plume_mesh *m = hinge_mesh(0.0, 0);
    CHECK(m != NULL);
    if (!m)
        return;
    double rest[12], x[12];
    fold_hinge(rest, 3.1, 0.0);
    plume_term t;
    CHECK(plume_bending_term_create(m, &mat, 1, rest, &t, NULL) == PLUME_OK);
    const double kappa = 0.5 * 1.0 * 1.0 / (0.4 + 0.35);
    fold_hinge(x, 3.1 + 0.1, 0.0); /* theta = 3.2 - 2 pi as atan2 reports it */
    CHECK_REL(term_energy(&t, x), kappa * 0.01, 1e-9, 0.0);
    fold_hinge(x, 3.1 - 0.1, 0.0);
    CHECK_REL(term_energy(&t, x), kappa * 0.01, 1e-9, 0.0);
    double g[12] = {0};
    CHECK(t.eval(t.ctx, 3, x, NULL, g, NULL, 0) == PLUME_OK);
    CHECK(term_max_abs(g, 12) > 0.0 && term_max_abs(g, 12) < 1.0);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* A current triangle collapsed onto its edge: theta has no derivative there; the hinge keeps a
 * finite energy and exerts no force (zero block), and nothing is NaN. */
void test_bending_collapsed(void)
{
    const plume_bending_material mat = {1.0, 1.0, 0.0, 0.0};
    plume_mesh *m = hinge_mesh(0.0, 0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_term t;
    CHECK(plume_bending_term_create(m, &mat, 1, NULL, &t, NULL) == PLUME_OK);
    double x[12];
    fold_hinge(x, 0.4, 0.0);
    x[7] = 0.0; /* x2 = (0.3, 0, 0): on the edge */
    x[8] = 0.0;
    double E = 0.0, g[12] = {0}, H[144];
    for (int i = 0; i < 144; i++)
        H[i] = 1.0;
    CHECK(t.eval(t.ctx, 3, x, &E, g, H, 1) == PLUME_OK);
    CHECK(isfinite(E));
    CHECK(term_max_abs(g, 12) == 0.0);
    CHECK(term_max_abs(H, 144) == 0.0);
    /* the whole edge collapsed to a point */
    memset(x, 0, sizeof x);
    E = 0.0;
    CHECK(t.eval(t.ctx, 3, x, &E, g, H, 0) == PLUME_OK);
    CHECK(isfinite(E));
    CHECK(term_max_abs(g, 12) == 0.0);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* ---- interface and errors ---------------------------------------------------------------------- */

void test_bending_term_interface(void)
{
    const plume_bending_material mat = {1.0, 0.25, 0.0, 0.0};
    plume_mesh *m = grid_mesh(3, 0.5, GRID_RIGHT, 0.0, 0.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_term t;
    plume_err err;
    CHECK(plume_bending_term_create(m, &mat, 1, NULL, &t, &err) == PLUME_OK);
    CHECK(strcmp(t.name, "bending") == 0);
    CHECK(t.arity == 4);
    CHECK(t.nstencil == m->nh);
    CHECK(t.destroy != NULL && t.eval != NULL);
    /* the stencil is mesh->hinges, the edge possibly reversed */
    for (plume_index h = 0; h < m->nh; h++) {
        const plume_index *s = t.stencil + 4 * h, *mh = m->hinges + 4 * h;
        CHECK((s[0] == mh[0] && s[1] == mh[1]) || (s[0] == mh[1] && s[1] == mh[0]));
        CHECK(s[2] == mh[2] && s[3] == mh[3]);
    }
    bm_map_cylinder(m, 45.0, 1.0, m->x);
    const long n = 3 * (long)m->nv;
    double *g = calloc((size_t)n, sizeof *g), *g2 = calloc((size_t)n, sizeof *g2);
    double *H = malloc(sizeof(double) * 144 * (size_t)t.nstencil);
    CHECK(g && g2 && H);
    if (g && g2 && H) {
        /* energy and gradient are added to what is there; blocks are overwritten */
        double E = 0.0, E2 = 10.0;
        CHECK(t.eval(t.ctx, 3, m->x, &E, g, NULL, 0) == PLUME_OK);
        for (long i = 0; i < n; i++)
            g2[i] = 1.0;
        for (size_t i = 0; i < 144 * (size_t)t.nstencil; i++)
            H[i] = NAN;
        CHECK(t.eval(t.ctx, 3, m->x, &E2, g2, H, 0) == PLUME_OK);
        CHECK_REL(E2, 10.0 + E, 1e-14, 0.0);
        for (long i = 0; i < n; i++)
            CHECK_REL(g2[i], 1.0 + g[i], 1e-14, 1.0);
        for (size_t i = 0; i < 144 * (size_t)t.nstencil; i++)
            CHECK(isfinite(H[i]));
        /* everything optional */
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, NULL, 0) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, 1) == PLUME_OK);
        /* shell mode only */
        CHECK(t.eval(t.ctx, 2, m->x, &E, NULL, NULL, 0) == PLUME_EINVAL);
        CHECK(t.eval(t.ctx, 3, NULL, &E, NULL, NULL, 0) == PLUME_EINVAL);
    }
    free(g);
    free(g2);
    free(H);
    t.destroy(t.ctx);
    t.destroy(NULL);
    plume_mesh_destroy(&m);

    /* a mesh without interior edges is a term with no stencils, not an error */
    plume_mesh *one = NULL;
    CHECK(plume_mesh_create(3, 1, 3, &one, &err) == PLUME_OK);
    if (one) {
        const double X[6] = {0, 0, 1, 0, 0, 1};
        const plume_index tri[3] = {0, 1, 2};
        memcpy(one->X, X, sizeof X);
        memcpy(one->tri, tri, sizeof tri);
        CHECK(plume_mesh_build_topology(one, &err) == PLUME_OK);
        CHECK(plume_bending_term_create(one, &mat, 1, NULL, &t, &err) == PLUME_OK);
        CHECK(t.nstencil == 0);
        double E = 0.0;
        CHECK(t.eval(t.ctx, 3, one->x, &E, NULL, NULL, 0) == PLUME_OK && E == 0.0);
        t.destroy(t.ctx);
        plume_mesh_destroy(&one);
    }
}

/* create fails with PLUME_EINVAL, a message containing `needle`, and a zeroed term */
static int create_fails(const plume_mesh *m, const plume_bending_material *mats, int nmat, const double *rest,
                        const char *needle)
{
    plume_term t;
    memset(&t, 0xff, sizeof t);
    plume_err err;
    err.msg[0] = '\0';
    plume_status st = plume_bending_term_create(m, mats, nmat, rest, &t, &err);
    int ok = st == PLUME_EINVAL && strstr(err.msg, needle) != NULL && t.ctx == NULL && t.eval == NULL;
    if (!ok)
        fprintf(stderr, "    expected EINVAL with \"%s\", got %d: \"%s\"\n", needle, (int)st, err.msg);
    /* and without an error struct */
    if (plume_bending_term_create(m, mats, nmat, rest, &t, NULL) != PLUME_EINVAL)
        ok = 0;
    return ok;
}

void test_bending_bad_inputs(void)
{
    plume_bending_material mats[2] = {{1.0, 0.5, 0.0, 0.0}, {2.0, 0.1, 0.0, 0.0}};
    plume_mesh *m = grid_mesh(2, 0.5, GRID_RIGHT, 0.0, 0.0);
    CHECK(m != NULL);
    if (!m)
        return;
    CHECK(create_fails(NULL, mats, 2, NULL, "NULL"));
    CHECK(create_fails(m, NULL, 2, NULL, "NULL"));
    CHECK(plume_bending_term_create(m, mats, 2, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(create_fails(m, mats, 0, NULL, "nmat"));

    /* stiffness: negative, NaN, infinite */
    mats[1].D_long = -1.0;
    CHECK(create_fails(m, mats, 2, NULL, "material 1: D_long must be finite and >= 0 (got -1)"));
    mats[1].D_long = 2.0;
    mats[0].D_trans = NAN;
    CHECK(create_fails(m, mats, 2, NULL, "material 0: D_trans"));
    mats[0].D_trans = INFINITY;
    CHECK(create_fails(m, mats, 2, NULL, "material 0: D_trans"));
    mats[0].D_trans = -1e-300;
    CHECK(create_fails(m, mats, 2, NULL, "material 0: D_trans"));
    mats[0].D_trans = 0.0; /* zero stiffness is allowed */
    plume_term t;
    CHECK(plume_bending_term_create(m, mats, 2, NULL, &t, NULL) == PLUME_OK);
    t.destroy(t.ctx);
    mats[0].D_trans = 0.5;

    /* material id out of range, both ways */
    m->material[3] = 2;
    CHECK(create_fails(m, mats, 2, NULL, "triangle 3: material id 2 out of range [0, 2)"));
    m->material[3] = -1;
    CHECK(create_fails(m, mats, 2, NULL, "material id -1"));
    m->material[3] = 1;
    CHECK(create_fails(m, mats, 1, NULL, "material id 1 out of range [0, 1)"));
    m->material[3] = 0;

    /* barb direction that cannot be normalised */
    m->barb_dir[2] = 0.0;
    m->barb_dir[3] = 0.0;
    CHECK(create_fails(m, mats, 2, NULL, "barb direction"));
    m->barb_dir[2] = NAN;
    CHECK(create_fails(m, mats, 2, NULL, "barb direction"));
    m->barb_dir[2] = 1.0;

    /* rest shape with a NaN, and one with a collapsed triangle */
    double *rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
    CHECK(rest != NULL);
    if (rest) {
        memcpy(rest, m->x, sizeof(double) * 3 * (size_t)m->nv);
        rest[3 * 4 + 2] = NAN;
        CHECK(create_fails(m, mats, 2, rest, "rest_x[14] (vertex 4) is not finite"));
        memset(rest, 0, sizeof(double) * 3 * (size_t)m->nv);
        CHECK(create_fails(m, mats, 2, rest, "degenerate in rest_x"));
        free(rest);
    }

    /* a degenerate (collinear up to rounding) reference triangle */
    plume_mesh *d = NULL;
    CHECK(plume_mesh_create(4, 2, 3, &d, NULL) == PLUME_OK);
    if (d) {
        const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.5, 1e-17, 0.5, -1.0};
        const plume_index tri[6] = {0, 1, 2, 1, 0, 3};
        memcpy(d->X, X, sizeof X);
        memcpy(d->tri, tri, sizeof tri);
        if (plume_mesh_build_topology(d, NULL) == PLUME_OK)
            CHECK(create_fails(d, mats, 2, NULL, "degenerate reference triangle"));
        plume_mesh_destroy(&d);
    }

    /* topology not built */
    plume_mesh *raw = NULL;
    CHECK(plume_mesh_create(4, 2, 3, &raw, NULL) == PLUME_OK);
    if (raw) {
        const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0};
        const plume_index tri[6] = {0, 1, 2, 1, 0, 3};
        memcpy(raw->X, X, sizeof X);
        memcpy(raw->tri, tri, sizeof tri);
        CHECK(create_fails(raw, mats, 2, NULL, "topology not built"));
        plume_mesh_destroy(&raw);
    }

    /* planar mode: bending needs out-of-plane unknowns */
    plume_mesh *flat = NULL;
    CHECK(plume_mesh_create(4, 2, 2, &flat, NULL) == PLUME_OK);
    if (flat) {
        const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0};
        const plume_index tri[6] = {0, 1, 2, 1, 0, 3};
        memcpy(flat->X, X, sizeof X);
        memcpy(flat->tri, tri, sizeof tri);
        CHECK(plume_mesh_build_topology(flat, NULL) == PLUME_OK);
        CHECK(create_fails(flat, mats, 2, NULL, "dim 3"));
        plume_mesh_destroy(&flat);
    }

    /* the good inputs still work after all that */
    CHECK(plume_bending_term_create(m, mats, 2, NULL, &t, NULL) == PLUME_OK);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}
