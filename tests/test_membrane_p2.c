/* Tests of the quadratic planar membrane element (lib/core/membrane_p2.c): finite-difference checks of
 * gradient and Hessian, patch test, rigid motions, PSD projection, the linear-elastic limit, the
 * in-plane bending of a strip where linear triangles lock, and every input error. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "test_rng.h"
#include "../lib/core/dense.h"
#include "../lib/core/membrane.h"
#include "../lib/core/membrane_p2.h"
#include "../lib/core/mesh.h"

#define PI 3.14159265358979323846
#define KK 12 /* dofs of one element */

static const plume_membrane_material MAT_ANISO = {{300.0, 2.0, 0.4, 1.2}, 0.02, 0.0, 0};
static const plume_membrane_material MAT_ISO = {{10.0, 10.0, 0.3, 10.0 / 2.6}, 0.02, 0.0, 0};

/* records a failure when err > tol * scale, printing the context */
#define CHECK_ERR(err, tol, scale, what)                                                          \
    do {                                                                                          \
        double e_ = (err), s_ = (scale);                                                          \
        if (!(e_ <= (tol) * s_)) {                                                                \
            plume_test_failures++;                                                                \
            fprintf(stderr, "    CHECK_ERR failed %s:%d: %s: error %.3g > %.3g * %.3g\n", __FILE__, \
                    __LINE__, what, e_, (double)(tol), s_);                                       \
        }                                                                                         \
    } while (0)

static double max_abs(const double *a, long n)
{
    double m = 0.0;
    for (long i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* ---- P2 meshes ------------------------------------------------------------------------------ */

/* A quadratic mesh: corners first (the linear mesh's vertices keep their ids), then one node at
 * the midpoint of every edge. */
typedef struct {
    plume_index nn, nt, nc; /* nodes, triangles, corner nodes */
    double *X;              /* [2 nn] */
    plume_index *tri6;      /* [6 nt] */
    int *material;          /* [nt] */
    double *barb_dir;       /* [2 nt] */
    int *boundary;          /* [nn] 1 for nodes on a boundary edge */
} p2_mesh;

static void p2_mesh_free(p2_mesh *m)
{
    free(m->X);
    free(m->tri6);
    free(m->material);
    free(m->barb_dir);
    free(m->boundary);
    memset(m, 0, sizeof *m);
}

/* Adds the mid-edge nodes to the linear mesh (nv corners Xc, triangles tri3); barbs at `angle`
 * (radians), materials alternating over nmat. Returns 0 on allocation failure. */
static int p2_from_p1(plume_index nv, const double *Xc, plume_index nt, const plume_index *tri3, double angle,
                      int nmat, p2_mesh *m)
{
    memset(m, 0, sizeof *m);
    const plume_index maxn = nv + 3 * nt;
    const size_t ne_max = (size_t)(3 * nt + 1);
    plume_index *ea = malloc(sizeof(plume_index) * ne_max), *eb = malloc(sizeof(plume_index) * ne_max);
    int *ecount = calloc(ne_max, sizeof *ecount);
    m->X = malloc(sizeof(double) * (size_t)(2 * maxn));
    m->tri6 = malloc(sizeof(plume_index) * (size_t)(6 * nt));
    m->material = malloc(sizeof(int) * (size_t)nt);
    m->barb_dir = malloc(sizeof(double) * (size_t)(2 * nt));
    m->boundary = calloc((size_t)maxn, sizeof(int));
    if (!ea || !eb || !ecount || !m->X || !m->tri6 || !m->material || !m->barb_dir || !m->boundary) {
        free(ea);
        free(eb);
        free(ecount);
        p2_mesh_free(m);
        return 0;
    }
    memcpy(m->X, Xc, sizeof(double) * (size_t)(2 * nv));
    plume_index ne = 0;
    for (plume_index t = 0; t < nt; t++) {
        const plume_index *v = tri3 + 3 * t;
        for (int e = 0; e < 3; e++) {
            plume_index a = v[e], b = v[(e + 1) % 3], k = 0;
            for (; k < ne; k++)
                if ((ea[k] == a && eb[k] == b) || (ea[k] == b && eb[k] == a))
                    break;
            if (k == ne) {
                ea[ne] = a;
                eb[ne] = b;
                m->X[2 * (nv + ne)] = 0.5 * (Xc[2 * a] + Xc[2 * b]);
                m->X[2 * (nv + ne) + 1] = 0.5 * (Xc[2 * a + 1] + Xc[2 * b + 1]);
                ne++;
            }
            ecount[k]++;
            m->tri6[6 * t + e] = v[e];
            m->tri6[6 * t + 3 + e] = nv + k;
        }
        m->material[t] = (int)(t % nmat);
        m->barb_dir[2 * t] = cos(angle);
        m->barb_dir[2 * t + 1] = sin(angle);
    }
    for (plume_index k = 0; k < ne; k++)
        if (ecount[k] == 1)
            m->boundary[ea[k]] = m->boundary[eb[k]] = m->boundary[nv + k] = 1;
    m->nn = nv + ne;
    m->nt = nt;
    m->nc = nv;
    free(ea);
    free(eb);
    free(ecount);
    return 1;
}

/* A quadrilateral with an interior vertex: 4 triangles of different shapes, 13 nodes. */
static int small_p2(double angle, p2_mesh *m)
{
    const double X[10] = {0.0, 0.0, 1.3, 0.1, 1.1, 0.9, -0.2, 1.2, 0.45, 0.55};
    const plume_index tri[12] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
    return p2_from_p1(5, X, 4, tri, angle, 2, m);
}

/* Perturbed 4x4 grid, cells split along alternating diagonals: 18 triangles, 49 nodes. */
static int grid_p2(rng64 *r, double angle, p2_mesh *m)
{
    double X[32];
    plume_index tri[54];
    const double xs[4] = {0.0, 0.7, 1.9, 3.0}, ys[4] = {0.0, 0.5, 1.6, 2.2};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            int v = 4 * j + i, inner = i > 0 && i < 3 && j > 0 && j < 3;
            X[2 * v] = xs[i] + (inner ? urange(r, -0.15, 0.15) : 0.0);
            X[2 * v + 1] = ys[j] + (inner ? urange(r, -0.15, 0.15) : 0.0);
        }
    int t = 0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            plume_index a = 4 * j + i, b = a + 1, c = a + 5, d = a + 4;
            plume_index T[6] = {a, b, c, a, c, d}, T2[6] = {a, b, d, b, c, d};
            memcpy(tri + 3 * t, (i + j) % 2 ? T2 : T, sizeof T);
            t += 2;
        }
    return p2_from_p1(16, X, 18, tri, angle, 1, m);
}

static plume_status p2_term(const p2_mesh *m, const plume_membrane_material *mats, int nmat, plume_term *t)
{
    return plume_membrane_p2_term_create(m->X, m->nn, m->tri6, m->nt, m->material, m->barb_dir, mats, nmat, t,
                                         NULL);
}

/* x = F X + c + a smooth bend (quadratic and sine terms) + per-node noise: not affine */
static void curved(rng64 *r, const p2_mesh *m, double amin, double amax, double bend, double noise, double *x)
{
    double a = urange(r, amin, amax), b = urange(r, amin, amax), s = urange(r, -0.3, 0.3);
    double phi = urange(r, -PI, PI);
    double F[4] = {cos(phi) * a, cos(phi) * s - sin(phi) * b, sin(phi) * a, sin(phi) * s + cos(phi) * b};
    double c[2] = {urange(r, -1, 1), urange(r, -1, 1)}, k[4];
    for (int i = 0; i < 4; i++)
        k[i] = urange(r, -bend, bend);
    for (plume_index v = 0; v < m->nn; v++) {
        const double X = m->X[2 * v], Y = m->X[2 * v + 1];
        x[2 * v] = F[0] * X + F[1] * Y + c[0] + k[0] * X * Y + k[1] * sin(2.0 * Y) + noise * urange(r, -1, 1);
        x[2 * v + 1] = F[2] * X + F[3] * Y + c[1] + k[2] * X * X + k[3] * sin(1.5 * X) + noise * urange(r, -1, 1);
    }
}

/* ---- independent P2 shape functions and the dense Hessian ------------------------------------ */

/* The 6-point degree-4 rule (the element's), for the quadrature points of the J checks. */
static const double QL[6][3] = {{0.108103018168070, 0.445948490915965, 0.445948490915965},
                                {0.445948490915965, 0.108103018168070, 0.445948490915965},
                                {0.445948490915965, 0.445948490915965, 0.108103018168070},
                                {0.816847572980459, 0.091576213509771, 0.091576213509771},
                                {0.091576213509771, 0.816847572980459, 0.091576213509771},
                                {0.091576213509771, 0.091576213509771, 0.816847572980459}};

/* Gradients (material frame) of the 6 quadratic shape functions of triangle t at barycentric L;
 * returns the signed doubled area. grad L_i = perp(P_{i+2} - P_{i+1}) / (2A). */
static double p2_shape_grad(const p2_mesh *m, plume_index t, const double L[3], double dN[6][2])
{
    const plume_index *v = m->tri6 + 6 * t;
    const double *P[3] = {m->X + 2 * v[0], m->X + 2 * v[1], m->X + 2 * v[2]};
    const double det = (P[1][0] - P[0][0]) * (P[2][1] - P[0][1]) - (P[2][0] - P[0][0]) * (P[1][1] - P[0][1]);
    double gL[3][2];
    for (int i = 0; i < 3; i++) {
        const double *p = P[(i + 1) % 3], *q = P[(i + 2) % 3];
        gL[i][0] = (p[1] - q[1]) / det;
        gL[i][1] = (q[0] - p[0]) / det;
    }
    for (int c = 0; c < 2; c++) {
        for (int i = 0; i < 3; i++)
            dN[i][c] = (4.0 * L[i] - 1.0) * gL[i][c];
        for (int e = 0; e < 3; e++) {
            int i = e, j = (e + 1) % 3;
            dN[3 + e][c] = 4.0 * (L[i] * gL[j][c] + L[j] * gL[i][c]);
        }
    }
    return det;
}

/* The smallest det F over the quadrature points of every triangle of x. */
static double min_J(const p2_mesh *m, const double *x, double *maxJ)
{
    double jmin = INFINITY, jmax = -INFINITY;
    for (plume_index t = 0; t < m->nt; t++)
        for (int q = 0; q < 6; q++) {
            double dN[6][2], F[4] = {0, 0, 0, 0};
            p2_shape_grad(m, t, QL[q], dN);
            for (int a = 0; a < 6; a++)
                for (int i = 0; i < 2; i++)
                    for (int c = 0; c < 2; c++)
                        F[2 * i + c] += x[2 * m->tri6[6 * t + a] + i] * dN[a][c];
            double J = F[0] * F[3] - F[1] * F[2];
            jmin = fmin(jmin, J);
            jmax = fmax(jmax, J);
        }
    if (maxJ)
        *maxJ = jmax;
    return jmin;
}

/* Energy, gradient (fresh) and, if H, the assembled dense Hessian (2 nn square) of a dim-2 term of
 * any arity. blocks: room for the term's blocks when H is asked for. */
static double term_all2(const plume_term *t, plume_index nn, const double *x, double *g, double *H, double *blocks,
                        int project)
{
    const long n = 2 * (long)nn, ar = t->arity, ka = 2 * ar;
    double e = 0.0;
    if (g)
        memset(g, 0, sizeof(double) * (size_t)n);
    CHECK(t->eval(t->ctx, 2, x, &e, g, H ? blocks : NULL, project) == PLUME_OK);
    if (H) {
        memset(H, 0, sizeof(double) * (size_t)(n * n));
        for (plume_index s = 0; s < t->nstencil; s++) {
            const plume_index *v = t->stencil + ar * s;
            const double *B = blocks + s * ka * ka;
            for (int a = 0; a < ar; a++)
                for (int i = 0; i < 2; i++)
                    for (int b = 0; b < ar; b++)
                        for (int j = 0; j < 2; j++)
                            H[(2 * v[a] + i) * n + 2 * v[b] + j] += B[(2 * a + i) * ka + 2 * b + j];
        }
    }
    return e;
}

/* Central differences in dim 2: gradient against energy, Hessian against gradient, relative to
 * the largest entry of each; prints the figures and asserts them within tol. */
static void fd2_check(const plume_term *t, plume_index nn, double *x, double step, double tol, const char *what)
{
    const long n = 2 * (long)nn;
    double *g = malloc(sizeof(double) * (size_t)n), *gp = malloc(sizeof(double) * (size_t)n);
    double *gm = malloc(sizeof(double) * (size_t)n), *H = malloc(sizeof(double) * (size_t)(n * n));
    double *bl = malloc(sizeof(double) * (size_t)(4 * t->arity * t->arity) * (size_t)(t->nstencil + 1));
    CHECK(g && gp && gm && H && bl);
    if (g && gp && gm && H && bl) {
        term_all2(t, nn, x, g, H, bl, 0);
        double gerr = 0.0, herr = 0.0, asym = 0.0;
        for (long i = 0; i < n; i++) {
            const double xi = x[i];
            x[i] = xi + step;
            const double ep = term_all2(t, nn, x, gp, NULL, NULL, 0);
            x[i] = xi - step;
            const double em = term_all2(t, nn, x, gm, NULL, NULL, 0);
            x[i] = xi;
            gerr = fmax(gerr, fabs((ep - em) / (2.0 * step) - g[i]));
            for (long j = 0; j < n; j++) {
                herr = fmax(herr, fabs((gp[j] - gm[j]) / (2.0 * step) - H[j * n + i]));
                asym = fmax(asym, fabs(H[i * n + j] - H[j * n + i]));
            }
        }
        const double gs = max_abs(g, n), hs = max_abs(H, n * n);
        fprintf(stderr, "    FD %-34s gradient %.1e of %.1e, Hessian %.1e of %.1e\n", what, gerr, gs, herr, hs);
        CHECK(gs > 0.0 && hs > 0.0);
        CHECK_ERR(gerr, tol, gs, what);
        CHECK_ERR(herr, tol, hs, what);
        CHECK(asym == 0.0);
    }
    free(g);
    free(gp);
    free(gm);
    free(H);
    free(bl);
}

/* ---- derivatives ------------------------------------------------------------------------------ */

void test_membrane_p2_fd_derivatives(void)
{
    rng64 r = {0x2545F4914F6CDD1DULL};
    p2_mesh m;
    CHECK(small_p2(35.0 * PI / 180.0, &m));
    if (!m.X)
        return;
    char what[96];
    /* mode 0: kappa = 0, any curved deformation; 1: cubic compression term active (J < 1 at some
     * points); 2: log barrier active */
    for (int mode = 0; mode < 3; mode++) {
        plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
        if (mode > 0)
            mats[0].kappa = mats[1].kappa = 3e5;
        mats[0].log_barrier = mats[1].log_barrier = mode == 2;
        plume_membrane_material mats0[2] = {MAT_ANISO, MAT_ISO};
        plume_term t, t0;
        CHECK(p2_term(&m, mats, 2, &t) == PLUME_OK);
        CHECK(p2_term(&m, mats0, 2, &t0) == PLUME_OK);
        for (int rep = 0; rep < 3; rep++) {
            double x[26], jmax, jmin;
            for (int tries = 0; tries < 1000; tries++) {
                if (mode == 0)
                    curved(&r, &m, 0.5, 1.5, 0.15, 0.05, x);
                else
                    curved(&r, &m, 0.6, 1.05, 0.1, 0.02, x);
                jmin = min_J(&m, x, &jmax);
                if (jmin > 0.2 && (mode == 0 || (jmin < 0.95 && jmax > 1.0)))
                    break; /* compression at some points, stretch at others */
            }
            CHECK(jmin > 0.2);
            if (mode > 0)
                CHECK(jmin < 0.95 && jmax > 1.0);
            if (mode > 0) { /* the compression term contributes */
                double e = 0.0, e0 = 0.0;
                CHECK(t.eval(t.ctx, 2, x, &e, NULL, NULL, 0) == PLUME_OK);
                CHECK(t0.eval(t0.ctx, 2, x, &e0, NULL, NULL, 0) == PLUME_OK);
                CHECK(e > 1.01 * e0);
            }
            snprintf(what, sizeof what, "mode %d rep %d (J %.2f..%.2f)", mode, rep, jmin, jmax);
            fd2_check(&t, m.nn, x, 2e-6, 1e-6, what);
        }
        t.destroy(t.ctx);
        t0.destroy(t0.ctx);
    }
    p2_mesh_free(&m);
}

/* ---- the quadrature ------------------------------------------------------------------------------ */

/* With kappa = 0 the density is a quartic polynomial over each element, so the element's 6-point
 * rule must agree with a collapsed 4 x 4 Gauss product rule (exact to degree 7) applied to
 * plume_membrane_density of the interpolated F. */
void test_membrane_p2_quadrature(void)
{
    rng64 r = {0x6A09E667F3BCC909ULL};
    const double gx[4] = {0.5 - 0.5 * 0.86113631159405258, 0.5 - 0.5 * 0.33998104358485626,
                          0.5 + 0.5 * 0.33998104358485626, 0.5 + 0.5 * 0.86113631159405258};
    const double gw[4] = {0.5 * 0.34785484513745386, 0.5 * 0.65214515486254614, 0.5 * 0.65214515486254614,
                          0.5 * 0.34785484513745386};
    p2_mesh m;
    CHECK(small_p2(1.0, &m));
    if (!m.X)
        return;
    const plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    plume_term t;
    CHECK(p2_term(&m, mats, 2, &t) == PLUME_OK);
    for (int rep = 0; rep < 4; rep++) {
        double x[26], el[4];
        curved(&r, &m, 0.5, 1.5, 0.2, 0.05, x);
        CHECK(t.energies(t.ctx, 2, x, el) == PLUME_OK);
        for (plume_index k = 0; k < m.nt; k++) {
            double ref = 0.0;
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < 4; j++) { /* (u, v) -> L1 = u, L2 = v (1 - u) */
                    const double u = gx[i], v = gx[j] * (1.0 - gx[i]);
                    const double L[3] = {1.0 - u - v, u, v};
                    double dN[6][2], F[4] = {0, 0, 0, 0};
                    const double A2 = fabs(p2_shape_grad(&m, k, L, dN));
                    for (int a = 0; a < 6; a++)
                        for (int c = 0; c < 2; c++) {
                            F[c] += x[2 * m.tri6[6 * k + a]] * dN[a][c];
                            F[2 + c] += x[2 * m.tri6[6 * k + a] + 1] * dN[a][c];
                        }
                    ref += gw[i] * gw[j] * (1.0 - gx[i]) * A2 *
                           plume_membrane_density(&mats[m.material[k]], 2, F, m.barb_dir + 2 * k);
                }
            CHECK(ref > 0.0);
            CHECK_REL(el[k], ref, 1e-12, 0.0);
        }
    }
    t.destroy(t.ctx);
    p2_mesh_free(&m);
}

/* ---- patch test, rigid motions ---------------------------------------------------------------- */

void test_membrane_p2_patch(void)
{
    rng64 r = {0xABCDEF0123456789ULL};
    const double d[2] = {cos(0.6), sin(0.6)};
    p2_mesh m;
    CHECK(grid_p2(&r, 0.6, &m));
    if (!m.X)
        return;
    double total = 0.0;
    for (plume_index t = 0; t < m.nt; t++) {
        double dN[6][2];
        total += 0.5 * p2_shape_grad(&m, t, QL[0], dN);
    }
    CHECK(fabs(total - 3.0 * 2.2) < 1e-13);
    for (int mode = 0; mode < 2; mode++) { /* 0: stretched, 1: compressed with kappa */
        plume_membrane_material mat = MAT_ANISO;
        mat.kappa = 3e5;
        plume_term t;
        CHECK(p2_term(&m, &mat, 1, &t) == PLUME_OK);
        for (int rep = 0; rep < 3; rep++) {
            double lo = mode ? 0.6 : 1.05, hi = mode ? 0.9 : 1.3;
            double a = urange(&r, lo, hi), b = urange(&r, lo, hi), s = urange(&r, -0.2, 0.2);
            double phi = urange(&r, -PI, PI), c[2] = {urange(&r, -5, 5), urange(&r, -5, 5)};
            double F[4] = {cos(phi) * a, cos(phi) * s - sin(phi) * b, sin(phi) * a, sin(phi) * s + cos(phi) * b};
            double x[98], g[98], e = 0.0, el[18], esum = 0.0;
            for (plume_index v = 0; v < m.nn; v++)
                for (int i = 0; i < 2; i++)
                    x[2 * v + i] = F[2 * i] * m.X[2 * v] + F[2 * i + 1] * m.X[2 * v + 1] + c[i];
            memset(g, 0, sizeof g);
            CHECK(t.eval(t.ctx, 2, x, &e, g, NULL, 0) == PLUME_OK);
            const double dens = plume_membrane_density(&mat, 2, F, d);
            CHECK(dens > 0.0);
            CHECK_REL(e, total * dens, 1e-12, 0.0);
            CHECK(t.energies(t.ctx, 2, x, el) == PLUME_OK);
            for (int k = 0; k < 18; k++)
                esum += el[k];
            CHECK_REL(esum, e, 1e-14, 0.0);
            double gin = 0.0, gb = 0.0, fsum[2] = {0, 0}, mom = 0.0;
            for (plume_index v = 0; v < m.nn; v++) {
                for (int i = 0; i < 2; i++) {
                    if (m.boundary[v])
                        gb = fmax(gb, fabs(g[2 * v + i]));
                    else
                        gin = fmax(gin, fabs(g[2 * v + i]));
                    fsum[i] += g[2 * v + i];
                }
                mom += x[2 * v] * g[2 * v + 1] - x[2 * v + 1] * g[2 * v];
            }
            CHECK(gb > 0.0);
            CHECK_ERR(gin, 1e-11, gb, mode ? "interior forces, compressed" : "interior forces, stretched");
            CHECK_ERR(max_abs(fsum, 2), 1e-12, gb, "net force");
            CHECK_ERR(fabs(mom), 1e-11, gb * 10.0, "net moment");
        }
        t.destroy(t.ctx);
    }
    p2_mesh_free(&m);
}

void test_membrane_p2_rigid(void)
{
    rng64 r = {0x0F1E2D3C4B5A6978ULL};
    p2_mesh m;
    CHECK(grid_p2(&r, 1.1, &m));
    if (!m.X)
        return;
    plume_membrane_material mat = MAT_ANISO;
    mat.kappa = 3e5;
    plume_term t;
    CHECK(p2_term(&m, &mat, 1, &t) == PLUME_OK);
    double x[98], g[98], e = 0.0;
    for (int rep = 0; rep < 5; rep++) {
        const double phi = urange(&r, -PI, PI), c[2] = {urange(&r, -10, 10), urange(&r, -10, 10)};
        for (plume_index v = 0; v < m.nn; v++) {
            const double X = m.X[2 * v], Y = m.X[2 * v + 1];
            x[2 * v] = cos(phi) * X - sin(phi) * Y + c[0];
            x[2 * v + 1] = sin(phi) * X + cos(phi) * Y + c[1];
        }
        e = term_all2(&t, m.nn, x, g, NULL, NULL, 0);
        /* strains of round-off size: 1e-16^2 of the stiffness times the area */
        CHECK(fabs(e) <= 1e-26 * mat.moduli.E_xx * mat.h * 6.6);
        CHECK(max_abs(g, 2 * m.nn) <= 1e-12 * mat.moduli.E_xx * mat.h);
    }
    e = term_all2(&t, m.nn, m.X, g, NULL, NULL, 0);
    CHECK(fabs(e) <= 1e-26 * mat.moduli.E_xx * mat.h * 6.6);
    CHECK(max_abs(g, 2 * m.nn) <= 1e-13 * mat.moduli.E_xx * mat.h);
    t.destroy(t.ctx);
    p2_mesh_free(&m);
}

/* ---- projection --------------------------------------------------------------------------------- */

void test_membrane_p2_projection(void)
{
    rng64 r = {0x1234567887654321ULL};
    p2_mesh m;
    CHECK(small_p2(0.8, &m));
    if (!m.X)
        return;
    int n_indef = 0;
    for (int mode = 0; mode < 2; mode++) {
        plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
        mats[0].kappa = mats[1].kappa = mode ? 3e5 : 0.0;
        plume_term t;
        CHECK(p2_term(&m, mats, 2, &t) == PLUME_OK);
        for (int rep = 0; rep < 8; rep++) {
            double x[26], Hu[4 * KK * KK], Hp[4 * KK * KK], M[KK * KK], lam[KK], V[KK * KK];
            /* compression makes St Venant-Kirchhoff indefinite */
            curved(&r, &m, 0.4, 0.9, 0.05, 0.02, x);
            CHECK(t.eval(t.ctx, 2, x, NULL, NULL, Hu, 0) == PLUME_OK);
            CHECK(t.eval(t.ctx, 2, x, NULL, NULL, Hp, 1) == PLUME_OK);
            for (int s = 0; s < 4; s++) {
                const double *hu = Hu + s * KK * KK, *hp = Hp + s * KK * KK;
                double asym = 0.0;
                for (int i = 0; i < KK; i++)
                    for (int j = 0; j < KK; j++)
                        asym = fmax(asym, fabs(hu[i * KK + j] - hu[j * KK + i]) +
                                              fabs(hp[i * KK + j] - hp[j * KK + i]));
                CHECK(asym == 0.0);
                memcpy(M, hp, sizeof M);
                plume_dense_sym_eig(KK, M, lam, V);
                CHECK(lam[0] >= -1e-10 * fmax(fabs(lam[0]), fabs(lam[KK - 1])));
                memcpy(M, hu, sizeof M);
                plume_dense_sym_eig(KK, M, lam, V);
                n_indef += lam[0] < -1e-6 * fabs(lam[KK - 1]);
            }
        }
        t.destroy(t.ctx);
    }
    fprintf(stderr, "    %d of 64 unprojected blocks indefinite\n", n_indef);
    CHECK(n_indef > 10); /* so that the PSD check above can fail */
    p2_mesh_free(&m);
}

/* ---- the linear-elastic limit ----------------------------------------------------------------------- */

/* At rest the Hessian of one element is the P2 linear-elastic stiffness K = sum_q w_q A h B^T C B,
 * B the strain (barb frame, Voigt) of the nodal displacements; the 3-point edge-midpoint rule is
 * exact for it (B is linear on a straight-sided triangle). */
void test_membrane_p2_linear_limit(void)
{
    const double Xc[6] = {0.3, -0.2, 2.1, 0.4, 0.7, 1.9};
    const plume_index tri[3] = {0, 1, 2};
    const double ang = 0.7, d[2] = {cos(ang), sin(ang)}, p[2] = {-sin(ang), cos(ang)};
    p2_mesh m;
    CHECK(p2_from_p1(3, Xc, 1, tri, ang, 1, &m));
    if (!m.X)
        return;
    for (int mode = 0; mode < 2; mode++) {
        plume_membrane_material mat = mode ? MAT_ISO : MAT_ANISO;
        mat.kappa = 1e3; /* inactive at rest */
        double C[9], K[KK * KK] = {0}, H[KK * KK];
        plume_membrane_stiffness(&mat, C);
        const double L3[3][3] = {{0.5, 0.5, 0.0}, {0.0, 0.5, 0.5}, {0.5, 0.0, 0.5}};
        for (int q = 0; q < 3; q++) {
            double dN[6][2], B[3][KK];
            const double A = 0.5 * fabs(p2_shape_grad(&m, 0, L3[q], dN));
            for (int a = 0; a < 6; a++) {
                const double nb = dN[a][0] * d[0] + dN[a][1] * d[1], nt = dN[a][0] * p[0] + dN[a][1] * p[1];
                for (int i = 0; i < 2; i++) {
                    B[0][2 * a + i] = d[i] * nb;
                    B[1][2 * a + i] = p[i] * nt;
                    B[2][2 * a + i] = d[i] * nt + p[i] * nb;
                }
            }
            for (int i = 0; i < KK; i++)
                for (int j = 0; j < KK; j++)
                    for (int k = 0; k < 3; k++)
                        for (int l = 0; l < 3; l++)
                            K[i * KK + j] += A * mat.h / 3.0 * B[k][i] * C[3 * k + l] * B[l][j];
        }
        plume_term t;
        CHECK(p2_term(&m, &mat, 1, &t) == PLUME_OK);
        CHECK(t.eval(t.ctx, 2, m.X, NULL, NULL, H, 0) == PLUME_OK);
        double err = 0.0;
        for (int i = 0; i < KK * KK; i++)
            err = fmax(err, fabs(H[i] - K[i]));
        fprintf(stderr, "    %s: |H - K| %.1e of %.1e\n", mode ? "isotropic" : "orthotropic", err, max_abs(K, KK * KK));
        CHECK_ERR(err, 1e-10, max_abs(K, KK * KK), "rest Hessian vs linear stiffness");
        /* rigid modes: K annihilates translations and the infinitesimal rotation */
        double u[3][KK], ku = 0.0;
        for (int a = 0; a < 6; a++) {
            u[0][2 * a] = 1.0, u[0][2 * a + 1] = 0.0;
            u[1][2 * a] = 0.0, u[1][2 * a + 1] = 1.0;
            u[2][2 * a] = -m.X[2 * a + 1], u[2][2 * a + 1] = m.X[2 * a];
        }
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < KK; i++) {
                double s = 0.0;
                for (int j = 0; j < KK; j++)
                    s += H[i * KK + j] * u[k][j];
                ku = fmax(ku, fabs(s));
            }
        CHECK_ERR(ku, 1e-12, max_abs(K, KK * KK) * 3.0, "rigid modes");
        t.destroy(t.ctx);
    }
    p2_mesh_free(&m);
}

/* ---- in-plane bending of a strip: where linear triangles lock ---------------------------------------- */

/* The strip [0, Lx] x [0, Hy] as n x m rectangles, each split into two right triangles along the
 * same diagonal. order 2: the quadratic mesh on the (2n+1) x (2m+1) grid of corners and mid-edge
 * nodes (every grid node is used); order 1: the linear mesh on the (n+1) x (m+1) corners. */
static int strip_mesh(int order, int n, int m, double Lx, double Hy, p2_mesh *s)
{
    memset(s, 0, sizeof *s);
    const int nx = order * n + 1, ny = order * m + 1, ar = 3 * order;
    s->nn = (plume_index)nx * ny;
    s->nt = 2 * (plume_index)n * m;
    s->X = malloc(sizeof(double) * (size_t)(2 * s->nn));
    s->tri6 = malloc(sizeof(plume_index) * (size_t)(ar * s->nt));
    s->material = calloc((size_t)s->nt, sizeof(int));
    s->barb_dir = malloc(sizeof(double) * (size_t)(2 * s->nt));
    if (!s->X || !s->tri6 || !s->material || !s->barb_dir) {
        p2_mesh_free(s);
        return 0;
    }
    for (int J = 0; J < ny; J++)
        for (int I = 0; I < nx; I++) {
            s->X[2 * (J * nx + I)] = Lx * I / (nx - 1);
            s->X[2 * (J * nx + I) + 1] = Hy * J / (ny - 1);
        }
#define NODE(I, J) ((plume_index)(J) * nx + (I))
    plume_index *T = s->tri6;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < n; i++) {
            const int I = order * i, J = order * j, o = order;
            plume_index a[6] = {NODE(I, J), NODE(I + o, J), NODE(I + o, J + o), 0, 0, 0};
            plume_index b[6] = {NODE(I, J), NODE(I + o, J + o), NODE(I, J + o), 0, 0, 0};
            if (order == 2) {
                plume_index am[3] = {NODE(I + 1, J), NODE(I + 2, J + 1), NODE(I + 1, J + 1)};
                plume_index bm[3] = {NODE(I + 1, J + 1), NODE(I + 1, J + 2), NODE(I, J + 1)};
                memcpy(a + 3, am, sizeof am);
                memcpy(b + 3, bm, sizeof bm);
            }
            memcpy(T, a, sizeof(plume_index) * (size_t)ar);
            memcpy(T + ar, b, sizeof(plume_index) * (size_t)ar);
            T += 2 * ar;
        }
#undef NODE
    for (plume_index t = 0; t < s->nt; t++) {
        s->barb_dir[2 * t] = 1.0;
        s->barb_dir[2 * t + 1] = 0.0;
    }
    return 1;
}

/* Dense Cholesky solve of the SPD system A y = b (A destroyed, n x n); 0 if not positive definite. */
static int chol_solve(int n, double *A, double *b)
{
    for (int j = 0; j < n; j++) {
        double s = A[j * n + j];
        for (int k = 0; k < j; k++)
            s -= A[j * n + k] * A[j * n + k];
        if (!(s > 0.0))
            return 0;
        A[j * n + j] = sqrt(s);
        for (int i = j + 1; i < n; i++) {
            double v = A[i * n + j];
            for (int k = 0; k < j; k++)
                v -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = v / A[j * n + j];
        }
    }
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < i; k++)
            b[i] -= A[i * n + k] * b[k];
        b[i] /= A[i * n + i];
    }
    for (int i = n - 1; i >= 0; i--) {
        for (int k = i + 1; k < n; k++)
            b[i] -= A[k * n + i] * b[k];
        b[i] /= A[i * n + i];
    }
    return 1;
}

/* The strip clamped at X = 0 (every node there fixed) under a total shear P at X = Lx, spread as
 * the parabolic shear traction 6 P s (1 - s) / Hy, s = Y / Hy, loaded consistently on the end
 * edges (3-point Gauss, exact for these polynomials). One linear solve K u = f with K the term's
 * Hessian at rest: the linear regime. Returns the work-conjugate tip deflection f.u / P, NAN on
 * failure. */
static double strip_tip_deflection(const plume_term *t, const p2_mesh *s, int order, int m, double Hy, double P)
{
    const long n = 2 * (long)s->nn;
    double *H = malloc(sizeof(double) * (size_t)(n * n)), *f = calloc((size_t)n, sizeof(double));
    double *bl = malloc(sizeof(double) * (size_t)(4 * t->arity * t->arity) * (size_t)t->nstencil);
    int *free_dof = malloc(sizeof(int) * (size_t)n);
    double *A = malloc(sizeof(double) * (size_t)(n * n)), *y = malloc(sizeof(double) * (size_t)n);
    double defl = NAN;
    if (!H || !f || !bl || !free_dof || !A || !y)
        goto done;
    term_all2(t, s->nn, s->X, NULL, H, bl, 0);
    const int nx = (int)(s->nn / (order * m + 1));
    const double gp[3] = {0.5 - 0.5 * sqrt(0.6), 0.5, 0.5 + 0.5 * sqrt(0.6)}, gw[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
    for (int e = 0; e < m; e++) { /* the end edges, nodes at J = order e .. order (e + 1) */
        const double y0 = Hy * e / m, he = Hy / m;
        for (int q = 0; q < 3; q++) {
            const double r = gp[q], sy = (y0 + r * he) / Hy, tau = 6.0 * P * sy * (1.0 - sy) / Hy;
            double N[3];
            if (order == 2) {
                N[0] = (1.0 - r) * (1.0 - 2.0 * r);
                N[1] = 4.0 * r * (1.0 - r);
                N[2] = r * (2.0 * r - 1.0);
            } else {
                N[0] = 1.0 - r;
                N[1] = r;
            }
            for (int k = 0; k <= order; k++)
                f[2 * ((long)(order * e + k) * nx + nx - 1) + 1] += gw[q] * he * tau * N[k];
        }
    }
    int nf = 0;
    for (long i = 0; i < n; i++)
        if ((free_dof[i] = s->X[2 * (i / 2)] > 0.0))
            y[nf++] = f[i];
    for (long i = 0, a = 0; i < n; i++) {
        if (!free_dof[i])
            continue;
        for (long j = 0, b = 0; j < n; j++)
            if (free_dof[j])
                A[a * nf + b++] = H[i * n + j];
        a++;
    }
    if (!chol_solve(nf, A, y))
        goto done;
    defl = 0.0;
    for (long i = 0, a = 0; i < n; i++)
        if (free_dof[i])
            defl += f[i] * y[a++] / P;
done:
    free(H);
    free(f);
    free(bl);
    free(free_dof);
    free(A);
    free(y);
    return defl;
}

void test_membrane_p2_cantilever(void)
{
    const double Lx = 10.0, Hy = 1.0, P = 1e-6, E = 1.0, nu = 0.0, G = E / (2.0 * (1.0 + nu));
    const plume_membrane_material mat = {{E, E, nu, G}, 1.0, 0.0, 0};
    const double I = Hy * Hy * Hy / 12.0;
    const double beam = P * Lx * Lx * Lx / (3.0 * E * I) + P * Lx / (5.0 / 6.0 * G * Hy);
    double rel[3];
    const int ms[3] = {1, 2, 1}, orders[3] = {2, 2, 1};
    for (int c = 0; c < 3; c++) {
        p2_mesh s;
        CHECK(strip_mesh(orders[c], 10, ms[c], Lx, Hy, &s));
        if (!s.X)
            return;
        plume_term t;
        if (orders[c] == 2) {
            CHECK(p2_term(&s, &mat, 1, &t) == PLUME_OK);
        } else {
            plume_mesh *pm = NULL;
            CHECK(plume_mesh_create(s.nn, s.nt, 2, &pm, NULL) == PLUME_OK);
            if (!pm) {
                p2_mesh_free(&s);
                return;
            }
            memcpy(pm->X, s.X, sizeof(double) * (size_t)(2 * s.nn));
            memcpy(pm->tri, s.tri6, sizeof(plume_index) * (size_t)(3 * s.nt));
            memcpy(pm->barb_dir, s.barb_dir, sizeof(double) * (size_t)(2 * s.nt));
            memcpy(pm->material, s.material, sizeof(int) * (size_t)s.nt);
            CHECK(plume_membrane_term_create(pm, 2, &mat, 1, &t, NULL) == PLUME_OK);
            plume_mesh_destroy(&pm);
        }
        const double d = strip_tip_deflection(&t, &s, orders[c], ms[c], Hy, P);
        rel[c] = (d - beam) / beam;
        fprintf(stderr, "    P%d, 10 x %d cells: tip deflection %.6g (beam theory %.6g, %+.2f %%)\n", orders[c],
                ms[c], d, beam, 100.0 * rel[c]);
        t.destroy(t.ctx);
        p2_mesh_free(&s);
    }
    CHECK(fabs(rel[0]) < 0.05); /* quadratic, one element across the height */
    CHECK(fabs(rel[1]) < 0.05 && fabs(rel[1]) <= fabs(rel[0]) + 0.005);
    CHECK(rel[2] < -0.30); /* linear triangles on the same corners lock: far too stiff */
}

/* ---- the term interface --------------------------------------------------------------------------------- */

void test_membrane_p2_term_interface(void)
{
    rng64 r = {0x5555AAAA5555AAAAULL};
    p2_mesh m;
    CHECK(small_p2(0.5, &m));
    if (!m.X)
        return;
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    mats[0].kappa = 1e5;
    plume_term t;
    CHECK(p2_term(&m, mats, 2, &t) == PLUME_OK);
    CHECK(strcmp(t.name, "membrane_p2") == 0);
    CHECK(t.arity == 6 && t.nstencil == 4 && t.energies != NULL);
    CHECK(memcmp(t.stencil, m.tri6, 24 * sizeof *m.tri6) == 0);
    double x[26];
    curved(&r, &m, 0.7, 1.2, 0.1, 0.02, x);
    p2_mesh_free(&m); /* the term copied what it needs */

    double e1 = 0.0, g1[26] = {0}, b1[4 * KK * KK];
    CHECK(t.eval(t.ctx, 2, x, &e1, g1, b1, 0) == PLUME_OK);
    CHECK(e1 > 0.0);
    /* energy and gradient are added, blocks are overwritten */
    double e2 = 5.0, g2[26], b2[4 * KK * KK];
    for (int i = 0; i < 26; i++)
        g2[i] = 1.0;
    for (int i = 0; i < 4 * KK * KK; i++)
        b2[i] = NAN;
    CHECK(t.eval(t.ctx, 2, x, &e2, g2, b2, 0) == PLUME_OK);
    CHECK(e2 == 5.0 + e1);
    for (int i = 0; i < 26; i++)
        CHECK_REL(g2[i], 1.0 + g1[i], 1e-14, 1.0);
    CHECK(memcmp(b1, b2, sizeof b1) == 0);
    /* any output may be NULL; results do not depend on which were asked for */
    double e3 = 0.0, g3[26] = {0}, b3[4 * KK * KK], el[4];
    CHECK(t.eval(t.ctx, 2, x, &e3, NULL, NULL, 0) == PLUME_OK);
    CHECK(t.eval(t.ctx, 2, x, NULL, g3, NULL, 0) == PLUME_OK);
    CHECK(t.eval(t.ctx, 2, x, NULL, NULL, b3, 0) == PLUME_OK);
    CHECK(e3 == e1 && memcmp(g3, g1, sizeof g1) == 0 && memcmp(b3, b1, sizeof b1) == 0);
    /* per-element energies sum to the energy */
    CHECK(t.energies(t.ctx, 2, x, el) == PLUME_OK);
    CHECK_REL(el[0] + el[1] + el[2] + el[3], e1, 1e-14, 0.0);
    /* planar only; x and e required */
    CHECK(t.eval(t.ctx, 3, x, &e3, NULL, NULL, 0) == PLUME_EINVAL);
    CHECK(t.eval(t.ctx, 2, NULL, &e3, NULL, NULL, 0) == PLUME_EINVAL);
    CHECK(t.energies(t.ctx, 3, x, el) == PLUME_EINVAL);
    CHECK(t.energies(t.ctx, 2, x, NULL) == PLUME_EINVAL);
    t.destroy(t.ctx);
    /* an empty term is valid */
    CHECK(plume_membrane_p2_term_create(NULL, 0, NULL, 0, NULL, NULL, mats, 2, &t, NULL) == PLUME_OK);
    e3 = 0.0;
    CHECK(t.nstencil == 0 && t.eval(t.ctx, 2, x, &e3, NULL, NULL, 0) == PLUME_OK && e3 == 0.0);
    t.destroy(t.ctx);
}

/* ---- input errors --------------------------------------------------------------------------------------- */

/* Puts every mid-edge node back at its edge's midpoint (after a corner moved). */
static void p2_remid(p2_mesh *m)
{
    for (plume_index t = 0; t < m->nt; t++)
        for (int e = 0; e < 3; e++) {
            const plume_index *v = m->tri6 + 6 * t;
            const double *A = m->X + 2 * v[e], *B = m->X + 2 * v[(e + 1) % 3];
            m->X[2 * v[3 + e]] = 0.5 * (A[0] + B[0]);
            m->X[2 * v[3 + e] + 1] = 0.5 * (A[1] + B[1]);
        }
}

typedef struct {
    const double *X;
    plume_index nn;
    const plume_index *tri6;
    plume_index nt;
    const int *material;
    const double *barb_dir;
    const plume_membrane_material *mats;
    int nmat;
} p2_args;

static p2_args args_of(const p2_mesh *m, const plume_membrane_material *mats, int nmat)
{
    p2_args a = {m->X, m->nn, m->tri6, m->nt, m->material, m->barb_dir, mats, nmat};
    return a;
}

static int create_fails(p2_args a, const char *needle1, const char *needle2)
{
    plume_term t;
    plume_err err;
    err.msg[0] = '\0';
    t.ctx = (void *)&t; /* must be cleared on failure */
    plume_status st = plume_membrane_p2_term_create(a.X, a.nn, a.tri6, a.nt, a.material, a.barb_dir, a.mats, a.nmat,
                                                    &t, &err);
    int ok = st == PLUME_EINVAL && t.ctx == NULL && t.eval == NULL && strstr(err.msg, needle1) &&
             (!needle2 || strstr(err.msg, needle2));
    if (!ok)
        fprintf(stderr, "    unexpected: status %d, message \"%s\" (wanted \"%s\")\n", (int)st, err.msg, needle1);
    if (st == PLUME_OK)
        t.destroy(t.ctx);
    return ok;
}

static int creates(const p2_mesh *m, const plume_membrane_material *mats, int nmat)
{
    plume_term t;
    plume_err err;
    err.msg[0] = '\0';
    plume_status st = plume_membrane_p2_term_create(m->X, m->nn, m->tri6, m->nt, m->material, m->barb_dir, mats, nmat,
                                                    &t, &err);
    if (st != PLUME_OK) {
        fprintf(stderr, "    unexpected failure: %s\n", err.msg);
        return 0;
    }
    t.destroy(t.ctx);
    return 1;
}

void test_membrane_p2_bad_inputs(void)
{
    p2_mesh m;
    CHECK(small_p2(0.5, &m));
    if (!m.X)
        return;
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    p2_args a;
    CHECK(creates(&m, mats, 2));
    /* NULL arguments and sizes */
    a = args_of(&m, NULL, 2);
    CHECK(create_fails(a, "NULL materials", NULL));
    a = args_of(&m, mats, 2);
    CHECK(plume_membrane_p2_term_create(a.X, a.nn, a.tri6, a.nt, a.material, a.barb_dir, mats, 2, NULL, NULL) ==
          PLUME_EINVAL);
    for (int k = 0; k < 4; k++) {
        a = args_of(&m, mats, 2);
        if (k == 0)
            a.X = NULL;
        else if (k == 1)
            a.tri6 = NULL;
        else if (k == 2)
            a.material = NULL;
        else
            a.barb_dir = NULL;
        CHECK(create_fails(a, "NULL positions, triangles, material ids or barb directions", NULL));
    }
    a = args_of(&m, mats, 2);
    a.nn = -1;
    CHECK(create_fails(a, "negative sizes", NULL));
    a = args_of(&m, mats, 2);
    a.nt = -2;
    CHECK(create_fails(a, "negative sizes", NULL));
    a = args_of(&m, mats, 0);
    CHECK(create_fails(a, "nmat must be >= 1 (got 0)", NULL));
    /* materials are checked */
    mats[1].moduli.E_yy = -1.0;
    CHECK(create_fails(args_of(&m, mats, 2), "material 1: E_yy must be finite and > 0 (got -1)", NULL));
    mats[1] = MAT_ISO;
    mats[0].kappa = -2.0;
    CHECK(create_fails(args_of(&m, mats, 2), "material 0: kappa", NULL));
    mats[0] = MAT_ANISO;
    /* ids in range: nodes (corner and mid-edge) and materials (the mesh uses 0 and 1) */
    plume_index keep = m.tri6[6 * 1 + 2];
    m.tri6[6 * 1 + 2] = m.nn;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 1: node id 13 (position 2) out of range [0, 13)", NULL));
    m.tri6[6 * 1 + 2] = keep;
    keep = m.tri6[6 * 2 + 5];
    m.tri6[6 * 2 + 5] = -1;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 2", "node id -1 (position 5)"));
    m.tri6[6 * 2 + 5] = keep;
    CHECK(create_fails(args_of(&m, mats, 1), "triangle 1: material id 1 out of range [0, 1)", NULL));
    m.material[3] = -1;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 3: material id -1", NULL));
    m.material[3] = 1;
    /* degenerate reference triangles: the centre (corner 4) moved onto the segment 1-2, mid-edge
     * nodes following; a NaN corner; two coincident corners */
    double Xkeep[26];
    memcpy(Xkeep, m.X, sizeof Xkeep);
    m.X[8] = 0.5 * (m.X[2] + m.X[4]);
    m.X[9] = 0.5 * (m.X[3] + m.X[5]);
    p2_remid(&m);
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 1: degenerate reference triangle", NULL));
    memcpy(m.X, Xkeep, sizeof Xkeep);
    m.X[0] = NAN;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 0: degenerate", NULL));
    memcpy(m.X, Xkeep, sizeof Xkeep);
    m.X[2] = m.X[0];
    m.X[3] = m.X[1];
    p2_remid(&m);
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 0: degenerate", NULL));
    memcpy(m.X, Xkeep, sizeof Xkeep);
    CHECK(creates(&m, mats, 2));
    /* barb directions that cannot be normalised */
    m.barb_dir[6] = m.barb_dir[7] = 0.0;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 3: barb direction (0, 0) cannot be normalised", NULL));
    m.barb_dir[6] = NAN;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 3: barb direction", NULL));
    m.barb_dir[6] = 1.0;
    /* mid-edge nodes off their midpoints: the boundary edge (2, 3) of triangle 2 is its own */
    const plume_index mid = m.tri6[6 * 2 + 3];
    m.X[2 * mid + 1] += 1e-9;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 2: node", "is not the midpoint of edge (2, 3)"));
    m.X[2 * mid + 1] = Xkeep[2 * mid + 1] + 1e-14; /* rounding-size offsets are accepted */
    CHECK(creates(&m, mats, 2));
    m.X[2 * mid] = NAN;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 2: node", "is not the midpoint"));
    memcpy(m.X, Xkeep, sizeof Xkeep);
    /* mid-edge nodes in the wrong order */
    keep = m.tri6[6 * 2 + 3];
    m.tri6[6 * 2 + 3] = m.tri6[6 * 2 + 4];
    m.tri6[6 * 2 + 4] = keep;
    CHECK(create_fails(args_of(&m, mats, 2), "triangle 2: node", "(position 3) is not the midpoint"));
    m.tri6[6 * 2 + 4] = m.tri6[6 * 2 + 3];
    m.tri6[6 * 2 + 3] = keep;
    CHECK(creates(&m, mats, 2));
    /* far from the origin a computed midpoint is off by the coordinates' rounding: accepted */
    for (plume_index v = 0; v < m.nc; v++) {
        m.X[2 * v] += 3.7e6;
        m.X[2 * v + 1] -= 1.3e6;
    }
    p2_remid(&m);
    CHECK(creates(&m, mats, 2));
    p2_mesh_free(&m);
}
