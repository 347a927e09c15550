/* Tests of the membrane element (lib/core/membrane.c) and the dense symmetric kernels it uses
 * (lib/core/dense.c): finite-difference checks of gradient and Hessian, PSD projection, patch test,
 * analytic densities, rotation invariance, and every input error. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "test_rng.h"
#include "../lib/core/dense.h"
#include "../lib/core/membrane.h"
#include "../lib/core/mesh.h"

#define PI 3.14159265358979323846

/* ---- helpers ---------------------------------------------------------------------------- */

/* rng64, urand, urange: tests/test_rng.h */

/* random rotation from a random unit quaternion */
static void random_rotation(rng64 *r, double Q[9])
{
    double q[4], n = 0.0;
    do {
        n = 0.0;
        for (int i = 0; i < 4; i++) {
            q[i] = urange(r, -1.0, 1.0);
            n += q[i] * q[i];
        }
    } while (n < 0.05 || n > 1.0);
    n = sqrt(n);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    double M[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                   2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    memcpy(Q, M, sizeof M);
}

static double max_abs(const double *a, long n)
{
    double m = 0.0;
    for (long i = 0; i < n; i++)
        if (fabs(a[i]) > m)
            m = fabs(a[i]);
    return m;
}

/* records a failure when err > tol * scale, printing the context */
#define CHECK_ERR(err, tol, scale, what)                                                      \
    do {                                                                                      \
        double e_ = (err), s_ = (scale);                                                      \
        if (!(e_ <= (tol) * s_)) {                                                            \
            plume_test_failures++;                                                            \
            fprintf(stderr, "    CHECK_ERR failed %s:%d: %s: error %.3g > %.3g * %.3g\n",     \
                    __FILE__, __LINE__, what, e_, (double)(tol), s_);                         \
        }                                                                                     \
    } while (0)

static const plume_membrane_material MAT_ANISO = {{300.0, 2.0, 0.4, 1.2}, 0.02, 0.0, 0};
static const plume_membrane_material MAT_ISO = {{10.0, 10.0, 0.3, 10.0 / 2.6}, 0.02, 0.0, 0};

/* A small irregular mesh: a quadrilateral with an interior vertex, 4 triangles of different
 * shapes, alternating the two materials. */
static plume_mesh *small_mesh(double barb_angle_deg, double barb_len)
{
    plume_mesh *m = NULL;
    if (plume_mesh_create(5, 4, 3, &m, NULL) != PLUME_OK)
        return NULL;
    const double X[10] = {0.0, 0.0, 1.3, 0.1, 1.1, 0.9, -0.2, 1.2, 0.45, 0.55};
    const plume_index tri[12] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4};
    memcpy(m->X, X, sizeof X);
    memcpy(m->tri, tri, sizeof tri);
    double a = barb_angle_deg * PI / 180.0;
    for (int t = 0; t < 4; t++) {
        m->barb_dir[2 * t] = barb_len * cos(a);
        m->barb_dir[2 * t + 1] = barb_len * sin(a);
        m->material[t] = t % 2;
    }
    return m;
}

/* Current area / reference area of triangle t (= J, the area ratio). */
static double tri_J(const plume_mesh *m, int dim, const double *x, plume_index t)
{
    const plume_index *v = m->tri + 3 * t;
    double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
    for (int i = 0; i < dim; i++) {
        a[i] = x[dim * v[1] + i] - x[dim * v[0] + i];
        b[i] = x[dim * v[2] + i] - x[dim * v[0] + i];
    }
    double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 2.0 / fabs(plume_mesh_ref_area(m, t));
}

/* x = Q [F X; 0] + shift + noise (Q = I in 2D), F = rot(phi) [[a, s], [0, b]]. */
static void deform(rng64 *r, const plume_mesh *m, int dim, double amin, double amax, double noise,
                   double *x)
{
    double a = urange(r, amin, amax), b = urange(r, amin, amax), s = urange(r, -0.3, 0.3);
    double phi = urange(r, -PI, PI);
    double F[4] = {cos(phi) * a, cos(phi) * s - sin(phi) * b, sin(phi) * a,
                   sin(phi) * s + cos(phi) * b};
    double Q[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (dim == 3)
        random_rotation(r, Q);
    double shift[3] = {urange(r, -1, 1), urange(r, -1, 1), urange(r, -1, 1)};
    for (plume_index v = 0; v < m->nv; v++) {
        const double *X = m->X + 2 * v;
        double y[3] = {F[0] * X[0] + F[1] * X[1], F[2] * X[0] + F[3] * X[1], 0.0};
        for (int i = 0; i < dim; i++) {
            double s2 = Q[3 * i] * y[0] + Q[3 * i + 1] * y[1] + Q[3 * i + 2] * y[2];
            x[dim * v + i] = s2 + shift[i] + noise * urange(r, -1, 1);
        }
    }
}

/* Energy, gradient (fresh) and the assembled dense Hessian (n x n) of a term at x. */
static double term_all(const plume_term *t, int dim, plume_index nv, const double *x, double *g,
                       double *H, double *blocks, int project)
{
    long n = dim * nv, kk = 3 * dim;
    double e = 0.0;
    if (g)
        memset(g, 0, (size_t)n * sizeof *g);
    CHECK(t->eval(t->ctx, dim, x, &e, g, blocks, project) == PLUME_OK);
    if (H) {
        memset(H, 0, (size_t)(n * n) * sizeof *H);
        for (plume_index s = 0; s < t->nstencil; s++) {
            const plume_index *v = t->stencil + 3 * s;
            const double *B = blocks + s * kk * kk;
            for (int a = 0; a < 3; a++)
                for (int i = 0; i < dim; i++)
                    for (int b = 0; b < 3; b++)
                        for (int j = 0; j < dim; j++)
                            H[(dim * v[a] + i) * n + dim * v[b] + j] +=
                                B[(dim * a + i) * kk + dim * b + j];
        }
    }
    return e;
}

/* ---- dense kernels ------------------------------------------------------------------------ */

void test_membrane_dense_eig(void)
{
    rng64 r = {0x9E3779B97F4A7C15ULL};
    double A[30 * 30], M[30 * 30], V[30 * 30], lam[30], work[2 * 30 * 30 + 30];
    for (int n = 1; n <= 24; n++) {
        for (int rep = 0; rep < 4; rep++) {
            for (int i = 0; i < n; i++)
                for (int j = i; j < n; j++)
                    A[i * n + j] = A[j * n + i] = urange(&r, -1, 1);
            if (rep == 3) /* a repeated eigenvalue: A = I + u u^T has n-1 eigenvalues 1 */
                for (int i = 0; i < n; i++)
                    for (int j = 0; j < n; j++)
                        A[i * n + j] = (i == j) + 0.1 * (i + 1) * (j + 1);
            memcpy(M, A, (size_t)n * n * sizeof *A);
            for (int i = 0; i < n; i++) /* the lower triangle must not be read */
                for (int j = 0; j < i; j++)
                    M[i * n + j] = 1e300;
            plume_dense_sym_eig(n, M, lam, V);
            double an = max_abs(A, n * n), res = 0.0, orth = 0.0;
            for (int k = 0; k < n; k++) {
                if (k > 0)
                    CHECK(lam[k] >= lam[k - 1]);
                for (int i = 0; i < n; i++) {
                    double s = 0.0;
                    for (int j = 0; j < n; j++)
                        s += A[i * n + j] * V[j * n + k];
                    res = fmax(res, fabs(s - lam[k] * V[i * n + k]));
                }
                for (int l = 0; l < n; l++) {
                    double s = 0.0;
                    for (int i = 0; i < n; i++)
                        s += V[i * n + k] * V[i * n + l];
                    orth = fmax(orth, fabs(s - (k == l)));
                }
            }
            CHECK_ERR(res, 1e-13 * n, an, "A V - V Lambda");
            CHECK_ERR(orth, 1e-13 * n, 1.0, "V^T V - I");
        }
    }
    /* known spectrum */
    double D[4] = {2.0, 0.0, 0.0, -1.0}, Dv[2], Dw[4];
    plume_dense_sym_eig(2, D, Dv, Dw);
    CHECK(Dv[0] == -1.0 && Dv[1] == 2.0);
    CHECK(fabs(Dw[0 * 2 + 0]) == 0.0 && fabs(Dw[1 * 2 + 0]) == 1.0);

    /* projection: diag(-1, 2) rotated by 30 degrees -> diag(0, 2) rotated */
    double c = cos(PI / 6), s = sin(PI / 6);
    double P[4] = {-c * c + 2 * s * s, -c * s - 2 * s * c, -c * s - 2 * s * c, -s * s + 2 * c * c};
    plume_dense_project_psd(2, P);
    double Pe[4] = {2 * s * s, -2 * s * c, -2 * s * c, 2 * c * c};
    for (int i = 0; i < 4; i++)
        CHECK_REL(P[i], Pe[i], 1e-14, 1.0);
    /* positive definite and singular semidefinite matrices come back bit for bit */
    double Q1[4] = {2.0, 0.3, 0.3, 1.0}, Q1c[4];
    memcpy(Q1c, Q1, sizeof Q1);
    plume_dense_project_psd(2, Q1);
    CHECK(memcmp(Q1, Q1c, sizeof Q1) == 0);
    double Q2[9] = {1, 1, 0, 1, 1, 0, 0, 0, 0}, Q2c[9];
    memcpy(Q2c, Q2, sizeof Q2);
    plume_dense_project_psd(3, Q2);
    CHECK(memcmp(Q2, Q2c, sizeof Q2) == 0);
    /* larger than the stack workspace: NaN without a workspace, projected with one */
    int n = 30;
    for (int i = 0; i < n; i++)
        for (int j = i; j < n; j++)
            A[i * n + j] = A[j * n + i] = urange(&r, -1, 1);
    memcpy(M, A, sizeof(double) * n * n);
    plume_dense_project_psd(n, M);
    CHECK(isnan(M[0]) && isnan(M[n * n - 1]));
    memcpy(M, A, sizeof(double) * n * n);
    plume_dense_project_psd_work(n, M, work);
    plume_dense_sym_eig(n, M, lam, V);
    CHECK(lam[0] >= -1e-12 * fabs(lam[n - 1]));
}

/* ---- finite differences ----------------------------------------------------------------- */

/* Central differences of the energy (gradient) and of the gradient (Hessian) at x. */
static void fd_check(const plume_term *t, const plume_mesh *m, int dim, double *x, const char *what)
{
    const long n = dim * m->nv;
    double g[15], gp[15], gm[15], H[225], blocks[4 * 81];
    double step = 1e-6 * 2.0; /* 1e-6 relative to the mesh size (~2) */
    term_all(t, dim, m->nv, x, g, H, blocks, 0);
    double gerr = 0.0, herr = 0.0;
    for (long i = 0; i < n; i++) {
        double xi = x[i];
        x[i] = xi + step;
        double ep = term_all(t, dim, m->nv, x, gp, NULL, NULL, 0);
        x[i] = xi - step;
        double em = term_all(t, dim, m->nv, x, gm, NULL, NULL, 0);
        x[i] = xi;
        gerr = fmax(gerr, fabs((ep - em) / (2 * step) - g[i]));
        for (long j = 0; j < n; j++)
            herr = fmax(herr, fabs((gp[j] - gm[j]) / (2 * step) - H[j * n + i]));
    }
    CHECK_ERR(gerr, 1e-6, max_abs(g, n), what);
    CHECK_ERR(herr, 1e-5, max_abs(H, n * n), what);
    /* symmetry of the Hessian */
    double asym = 0.0;
    for (long i = 0; i < n; i++)
        for (long j = 0; j < n; j++)
            asym = fmax(asym, fabs(H[i * n + j] - H[j * n + i]));
    CHECK_ERR(asym, 1e-14, max_abs(H, n * n), what);
}

void test_membrane_fd_derivatives(void)
{
    rng64 r = {88172645463325252ULL};
    const double angles[5] = {0.0, 30.0, 45.0, 90.0, 137.0};
    char what[160];
    int nactive = 0;
    for (int dim = 2; dim <= 3; dim++) {
        for (int ia = 0; ia < 5; ia++) {
            plume_mesh *m = small_mesh(angles[ia], ia % 2 ? 2.5 : 1.0);
            CHECK(m != NULL);
            if (!m)
                return;
            /* mode 0: kappa = 0, any deformation; 1: kappa large, J < 1 (term active);
             * 2: kappa large, J > 1 (term inactive) */
            for (int mode = 0; mode < 3; mode++) {
                plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
                if (mode > 0)
                    mats[0].kappa = mats[1].kappa = 3e5;
                plume_term t;
                plume_err err;
                CHECK(plume_membrane_term_create(m, dim, mats, 2, &t, &err) == PLUME_OK);
                double x[15];
                for (int rep = 0; rep < 3; rep++) {
                    for (int tries = 0; tries < 1000; tries++) {
                        if (mode == 0)
                            deform(&r, m, dim, 0.5, 1.5, 0.1, x);
                        else if (mode == 1)
                            deform(&r, m, dim, 0.55, 0.85, 0.03, x);
                        else
                            deform(&r, m, dim, 1.1, 1.4, 0.03, x);
                        int ok = 1;
                        for (plume_index tt = 0; tt < m->nt; tt++) {
                            double J = tri_J(m, dim, x, tt);
                            if ((mode == 1 && !(J < 0.97)) || (mode == 2 && !(J > 1.03)) ||
                                fabs(J - 1.0) < 1e-3)
                                ok = 0;
                        }
                        if (ok)
                            break;
                    }
                    if (mode == 1)
                        for (plume_index tt = 0; tt < m->nt; tt++)
                            nactive += tri_J(m, dim, x, tt) < 0.97;
                    snprintf(what, sizeof what, "dim %d angle %g mode %d rep %d", dim, angles[ia],
                             mode, rep);
                    fd_check(&t, m, dim, x, what);
                }
                t.destroy(t.ctx);
            }
            plume_mesh_destroy(&m);
        }
    }
    CHECK(nactive == 2 * 5 * 3 * 4); /* every triangle of every compressive case was active */
}

/* A monoclinic tensor (C13, C23 couple the normal strains and the shear, as in a cell of inclined
 * barbules; docs/monoclinic-vane.md): the same finite differences, the compression term on and
 * off; the orthotropic material given as its own tensor is the moduli's term bit for bit; tensors
 * that are not symmetric or not positive definite are refused, naming the material. */
void test_membrane_fd_tensor(void)
{
    rng64 r = {1442695040888963407ULL};
    /* C23 / sqrt(C22 C33) = 0.9, C13 / sqrt(C11 C33) = 0.3: positive definite */
    const double C[9] = {300.0, 1.0, 0.3 * sqrt(300.0 * 1.2), 1.0, 2.0, 0.9 * sqrt(2.0 * 1.2),
                         0.3 * sqrt(300.0 * 1.2), 0.9 * sqrt(2.0 * 1.2), 1.2};
    char what[160];
    for (int dim = 2; dim <= 3; dim++) {
        for (int ia = 0; ia < 3; ia++) {
            const double angle = 30.0 + 50.0 * ia;
            plume_mesh *m = small_mesh(angle, 1.5);
            CHECK(m != NULL);
            if (!m)
                return;
            for (int mode = 0; mode < 2; mode++) {
                plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
                double tensors[18];
                memcpy(tensors, C, sizeof C);
                plume_membrane_stiffness(&mats[1], tensors + 9);
                if (mode == 1)
                    mats[0].kappa = mats[1].kappa = 3e5;
                plume_term t;
                plume_err err;
                CHECK(plume_membrane_term_create_tensor(m, dim, mats, tensors, 2, &t, &err) == PLUME_OK);
                double x[15];
                for (int rep = 0; rep < 3; rep++) {
                    deform(&r, m, dim, mode ? 0.6 : 0.5, mode ? 0.9 : 1.5, 0.05, x);
                    snprintf(what, sizeof what, "tensor: dim %d angle %g mode %d rep %d", dim, angle, mode, rep);
                    fd_check(&t, m, dim, x, what);
                }
                t.destroy(t.ctx);
            }
            plume_mesh_destroy(&m);
        }
    }
    /* the orthotropic tensor of a material's moduli: the same term */
    plume_mesh *m = small_mesh(45.0, 1.0);
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    double tensors[18];
    plume_membrane_stiffness(&mats[0], tensors);
    plume_membrane_stiffness(&mats[1], tensors + 9);
    plume_term a, b;
    plume_err err;
    CHECK(plume_membrane_term_create(m, 3, mats, 2, &a, &err) == PLUME_OK);
    CHECK(plume_membrane_term_create_tensor(m, 3, mats, tensors, 2, &b, &err) == PLUME_OK);
    double x[15], ga[15], gb[15];
    deform(&r, m, 3, 0.7, 1.3, 0.1, x);
    const double ea = term_all(&a, 3, m->nv, x, ga, NULL, NULL, 0), eb = term_all(&b, 3, m->nv, x, gb, NULL, NULL, 0);
    CHECK(ea == eb);
    CHECK(memcmp(ga, gb, (size_t)(3 * m->nv) * sizeof *ga) == 0);
    a.destroy(a.ctx);
    b.destroy(b.ctx);
    /* refused, by material */
    tensors[9 + 5] = 2.0 * tensors[9 + 7] + 1.0; /* C23 != C32 */
    CHECK(plume_membrane_term_create_tensor(m, 2, mats, tensors, 2, &a, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "material 1") && strstr(err.msg, "not symmetric"));
    memcpy(tensors, C, sizeof C);
    tensors[5] = tensors[7] = 1.01 * sqrt(C[4] * C[8]); /* |C23| > sqrt(C22 C33) */
    CHECK(plume_membrane_term_create_tensor(m, 2, mats, tensors, 1, &a, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "material 0") && strstr(err.msg, "not positive definite"));
    plume_mesh_destroy(&m);
}

/* the compression term alone, where it dominates, so its derivatives are checked on their own */
void test_membrane_fd_compression_only(void)
{
    rng64 r = {0xDEADBEEFCAFEULL};
    plume_mesh *m = small_mesh(30.0, 1.0);
    CHECK(m != NULL);
    if (!m)
        return;
    for (int dim = 2; dim <= 3; dim++) {
        plume_membrane_material mat = {{1e-6, 1e-6, 0.0, 1e-6}, 0.1, 1e3, 0};
        plume_term t;
        for (int k = 0; k < 4; k++)
            m->material[k] = 0;
        CHECK(plume_membrane_term_create(m, dim, &mat, 1, &t, NULL) == PLUME_OK);
        double x[15];
        for (int rep = 0; rep < 4; rep++) {
            deform(&r, m, dim, 0.3, 0.8, 0.02, x);
            fd_check(&t, m, dim, x, dim == 2 ? "compression 2d" : "compression 3d");
        }
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
}

/* ---- projection ----------------------------------------------------------------------------- */

void test_membrane_projection(void)
{
    rng64 r = {0x1234567887654321ULL};
    plume_mesh *m = small_mesh(45.0, 1.0);
    CHECK(m != NULL);
    if (!m)
        return;
    int n_indef = 0, n_psd = 0;
    for (int dim = 2; dim <= 3; dim++) {
        const int kk = 3 * dim;
        for (int mode = 0; mode < 2; mode++) {
            plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
            mats[0].kappa = mats[1].kappa = mode ? 3e5 : 0.0;
            plume_term t;
            CHECK(plume_membrane_term_create(m, dim, mats, 2, &t, NULL) == PLUME_OK);
            for (int rep = 0; rep < 12; rep++) {
                double x[15], Hu[4 * 81], Hp[4 * 81], M[81], lam[9], V[81];
                /* compression makes St Venant-Kirchhoff indefinite, stretching keeps it PSD */
                if (rep % 3 == 0)
                    deform(&r, m, dim, 0.4, 0.9, 0.05, x);
                else if (rep % 3 == 1)
                    deform(&r, m, dim, 1.05, 1.5, 0.02, x);
                else
                    deform(&r, m, dim, 0.5, 1.5, 0.1, x);
                double e = 0.0;
                CHECK(t.eval(t.ctx, dim, x, &e, NULL, Hu, 0) == PLUME_OK);
                CHECK(t.eval(t.ctx, dim, x, NULL, NULL, Hp, 1) == PLUME_OK);
                for (int s = 0; s < 4; s++) {
                    const double *hu = Hu + s * kk * kk, *hp = Hp + s * kk * kk;
                    memcpy(M, hp, sizeof(double) * kk * kk);
                    plume_dense_sym_eig(kk, M, lam, V);
                    CHECK(lam[0] >= -1e-10 * fmax(fabs(lam[0]), fabs(lam[kk - 1])));
                    double asym = 0.0;
                    for (int i = 0; i < kk; i++)
                        for (int j = 0; j < kk; j++)
                            asym = fmax(asym, fabs(hp[i * kk + j] - hp[j * kk + i]));
                    CHECK(asym == 0.0);
                    memcpy(M, hu, sizeof(double) * kk * kk);
                    plume_dense_sym_eig(kk, M, lam, V);
                    double scale = fmax(fabs(lam[0]), fabs(lam[kk - 1]));
                    if (lam[0] >= -1e-12 * scale) {
                        n_psd++;
                        double d = 0.0;
                        for (int i = 0; i < kk * kk; i++)
                            d = fmax(d, fabs(hp[i] - hu[i]));
                        CHECK_ERR(d, 1e-10, max_abs(hu, kk * kk), "projected PSD block changed");
                    } else {
                        n_indef++;
                    }
                }
            }
            t.destroy(t.ctx);
        }
    }
    CHECK(n_indef > 0);
    CHECK(n_psd > 0);
    plume_mesh_destroy(&m);
}

/* On the unit right triangle with barbs along x, Dm = R = I, so the rows and columns of vertices
 * 1 and 2 of a vertex block are A h times the Hessian in G itself: the projected block must hold
 * the direct 2dim x 2dim eigen-projection of the unprojected one (in shell mode the element
 * projects through an in-plane / normal split, checked here against plain Jacobi). */
void test_membrane_projection_split(void)
{
    rng64 r = {0x7777123412341234ULL};
    plume_mesh *m = NULL;
    CHECK(plume_mesh_create(3, 1, 3, &m, NULL) == PLUME_OK);
    if (!m)
        return;
    const double X[6] = {0, 0, 1, 0, 0, 1};
    memcpy(m->X, X, sizeof X);
    m->tri[0] = 0;
    m->tri[1] = 1;
    m->tri[2] = 2;
    int nchanged = 0;
    for (int dim = 2; dim <= 3; dim++) {
        const int kk = 3 * dim, k = 2 * dim;
        for (int mode = 0; mode < 2; mode++) {
            plume_membrane_material mat = MAT_ANISO;
            mat.kappa = mode ? 3e5 : 0.0;
            plume_term t;
            CHECK(plume_membrane_term_create(m, dim, &mat, 1, &t, NULL) == PLUME_OK);
            for (int rep = 0; rep < 20; rep++) {
                double x[9], Hu[81], Hp[81], S[36];
                deform(&r, m, dim, 0.4, 1.4, 0.2, x);
                CHECK(t.eval(t.ctx, dim, x, NULL, NULL, Hu, 0) == PLUME_OK);
                CHECK(t.eval(t.ctx, dim, x, NULL, NULL, Hp, 1) == PLUME_OK);
                for (int i = 0; i < k; i++)
                    for (int j = 0; j < k; j++)
                        S[i * k + j] = Hu[(dim + i) * kk + dim + j];
                double scale = max_abs(S, k * k), Sc[36];
                memcpy(Sc, S, sizeof(double) * k * k);
                plume_dense_project_psd(k, S);
                nchanged += memcmp(S, Sc, sizeof(double) * k * k) != 0;
                double d = 0.0;
                for (int i = 0; i < k; i++)
                    for (int j = 0; j < k; j++)
                        d = fmax(d, fabs(S[i * k + j] - Hp[(dim + i) * kk + dim + j]));
                CHECK_ERR(d, 1e-12, scale, dim == 2 ? "projection 2d" : "split projection 3d");
            }
            t.destroy(t.ctx);
        }
    }
    CHECK(nchanged > 10);
    plume_mesh_destroy(&m);
}

/* ---- patch test and analytic densities -------------------------------------------------- */

/* Perturbed 4x4 grid, cells split along alternating diagonals: 16 vertices (4 interior),
 * 18 triangles of different shapes. */
static plume_mesh *grid_mesh(rng64 *r)
{
    plume_mesh *m = NULL;
    if (plume_mesh_create(16, 18, 3, &m, NULL) != PLUME_OK)
        return NULL;
    const double xs[4] = {0.0, 0.7, 1.9, 3.0}, ys[4] = {0.0, 0.5, 1.6, 2.2};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            int v = 4 * j + i, inner = i > 0 && i < 3 && j > 0 && j < 3;
            m->X[2 * v] = xs[i] + (inner ? urange(r, -0.15, 0.15) : 0.0);
            m->X[2 * v + 1] = ys[j] + (inner ? urange(r, -0.15, 0.15) : 0.0);
        }
    int t = 0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) {
            plume_index a = 4 * j + i, b = a + 1, c = a + 5, d = a + 4;
            plume_index T[6] = {a, b, c, a, c, d};
            plume_index T2[6] = {a, b, d, b, c, d};
            memcpy(m->tri + 3 * t, (i + j) % 2 ? T2 : T, sizeof T);
            t += 2;
        }
    return m;
}

static int is_interior(plume_index v)
{
    int i = (int)(v % 4), j = (int)(v / 4);
    return i > 0 && i < 3 && j > 0 && j < 3;
}

void test_membrane_patch(void)
{
    rng64 r = {0xABCDEF0123456789ULL};
    plume_mesh *m = grid_mesh(&r);
    CHECK(m != NULL);
    if (!m)
        return;
    for (plume_index t = 0; t < m->nt; t++)
        CHECK(plume_mesh_ref_area(m, t) > 0.0);
    const double total = plume_mesh_total_area(m);
    double d[2] = {cos(0.6), sin(0.6)};
    for (plume_index t = 0; t < m->nt; t++) {
        m->barb_dir[2 * t] = d[0];
        m->barb_dir[2 * t + 1] = d[1];
    }
    for (int dim = 2; dim <= 3; dim++) {
        for (int mode = 0; mode < 2; mode++) { /* 0: stretched, 1: compressed with kappa */
            plume_membrane_material mat = MAT_ANISO;
            mat.kappa = 3e5;
            plume_term t;
            CHECK(plume_membrane_term_create(m, dim, &mat, 1, &t, NULL) == PLUME_OK);
            for (int rep = 0; rep < 3; rep++) {
                double F2[4], Q[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, F[6], shift[3];
                double lo = mode ? 0.6 : 1.05, hi = mode ? 0.9 : 1.3;
                double a = urange(&r, lo, hi), b = urange(&r, lo, hi), s = urange(&r, -0.2, 0.2);
                double phi = urange(&r, -PI, PI);
                F2[0] = cos(phi) * a;
                F2[1] = cos(phi) * s - sin(phi) * b;
                F2[2] = sin(phi) * a;
                F2[3] = sin(phi) * s + cos(phi) * b;
                if (dim == 3)
                    random_rotation(&r, Q);
                for (int i = 0; i < dim; i++) {
                    F[2 * i] = Q[3 * i] * F2[0] + Q[3 * i + 1] * F2[2];
                    F[2 * i + 1] = Q[3 * i] * F2[1] + Q[3 * i + 1] * F2[3];
                    shift[i] = urange(&r, -5, 5);
                }
                double x[48], g[48];
                for (plume_index v = 0; v < m->nv; v++)
                    for (int i = 0; i < dim; i++)
                        x[dim * v + i] = F[2 * i] * m->X[2 * v] + F[2 * i + 1] * m->X[2 * v + 1] +
                                         shift[i];
                memset(g, 0, sizeof g);
                double e = 0.0;
                CHECK(t.eval(t.ctx, dim, x, &e, g, NULL, 0) == PLUME_OK);
                double dens = plume_membrane_density(&mat, dim, F, d);
                CHECK(dens > 0.0);
                CHECK_REL(e, total * dens, 1e-12, 0.0);
                double gin = 0.0, gb = 0.0;
                for (plume_index v = 0; v < m->nv; v++)
                    for (int i = 0; i < dim; i++) {
                        if (is_interior(v))
                            gin = fmax(gin, fabs(g[dim * v + i]));
                        else
                            gb = fmax(gb, fabs(g[dim * v + i]));
                    }
                CHECK(gb > 0.0);
                CHECK_ERR(gin, 1e-10, gb, dim == 2 ? "interior forces 2d" : "interior forces 3d");
                /* the forces balance and their moment vanishes (2D: z-moment) */
                double fsum[3] = {0, 0, 0}, mom = 0.0;
                for (plume_index v = 0; v < m->nv; v++) {
                    for (int i = 0; i < dim; i++)
                        fsum[i] += g[dim * v + i];
                    mom += x[dim * v] * g[dim * v + 1] - x[dim * v + 1] * g[dim * v];
                }
                CHECK_ERR(max_abs(fsum, 3), 1e-12, gb, "net force");
                CHECK_ERR(fabs(mom), 1e-11, gb * 10.0, "net moment");
            }
            t.destroy(t.ctx);
        }
    }
    /* mixed materials and barb directions: the energy is the sum of area * density */
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    mats[0].kappa = 2e5;
    mats[1].kappa = 1e3;
    for (plume_index t = 0; t < m->nt; t++) {
        double a = urange(&r, 0, 2 * PI);
        m->barb_dir[2 * t] = cos(a);
        m->barb_dir[2 * t + 1] = sin(a);
        m->material[t] = (int)(t % 3 == 0);
    }
    for (int dim = 2; dim <= 3; dim++) {
        plume_term t;
        CHECK(plume_membrane_term_create(m, dim, mats, 2, &t, NULL) == PLUME_OK);
        double F[6] = {0.8, 0.1, -0.05, 0.75, 0.1, 0.2};
        double x[48], e = 0.0, expect = 0.0;
        for (plume_index v = 0; v < m->nv; v++)
            for (int i = 0; i < dim; i++)
                x[dim * v + i] = F[2 * i] * m->X[2 * v] + F[2 * i + 1] * m->X[2 * v + 1];
        CHECK(t.eval(t.ctx, dim, x, &e, NULL, NULL, 0) == PLUME_OK);
        for (plume_index k = 0; k < m->nt; k++)
            expect += plume_mesh_ref_area(m, k) *
                      plume_membrane_density(&mats[m->material[k]], dim, F, m->barb_dir + 2 * k);
        CHECK_REL(e, expect, 1e-12, 0.0);
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
}

void test_membrane_analytic(void)
{
    /* stiffness: nu_xy = 0 is diag(E_xx, E_yy, G_xy); otherwise the orthotropic formula */
    plume_membrane_material m0 = {{500.0, 3.0, 0.0, 1.5}, 0.01, 0.0, 0};
    double C[9];
    plume_membrane_stiffness(&m0, C);
    const double Cd[9] = {500.0, 0, 0, 0, 3.0, 0, 0, 0, 1.5};
    CHECK(memcmp(C, Cd, sizeof C) == 0);
    plume_membrane_material mi = {{10.0, 10.0, 0.25, 4.0}, 0.01, 0.0, 0};
    plume_membrane_stiffness(&mi, C);
    CHECK_REL(C[0], 10.0 / (1 - 0.0625), 1e-15, 0.0);
    CHECK_REL(C[1], 0.25 * 10.0 / (1 - 0.0625), 1e-15, 0.0);
    CHECK(C[1] == C[3] && C[0] == C[4] && C[8] == 4.0 && C[2] == 0.0 && C[5] == 0.0);
    plume_membrane_material ma = MAT_ANISO; /* nu_yx = 0.4 * 2 / 300 */
    plume_membrane_stiffness(&ma, C);
    double nu_yx = 0.4 * 2.0 / 300.0, D = 1.0 - 0.4 * nu_yx;
    CHECK_REL(C[0], 300.0 / D, 1e-15, 0.0);
    CHECK_REL(C[4], 2.0 / D, 1e-15, 0.0);
    CHECK_REL(C[1], nu_yx * 300.0 / D, 1e-15, 0.0);
    CHECK_REL(C[1], 0.4 * 2.0 / D, 1e-15, 0.0);

    const double angles[5] = {0.0, 30.0, 45.0, 90.0, 137.0};
    for (int ia = 0; ia < 5; ia++) {
        double a = angles[ia] * PI / 180.0, d[2] = {cos(a), sin(a)};
        for (int im = 0; im < 2; im++) {
            plume_membrane_material mat = im ? mi : ma;
            mat.kappa = 5e4;
            plume_membrane_stiffness(&mat, C);
            /* pure stretch along d: F = I + (lambda - 1) d d^T, J = lambda */
            const double lambdas[4] = {1.0, 1.01, 1.3, 0.8};
            for (int il = 0; il < 4; il++) {
                double l = lambdas[il], F[4];
                for (int i = 0; i < 2; i++)
                    for (int j = 0; j < 2; j++)
                        F[2 * i + j] = (i == j) + (l - 1.0) * d[i] * d[j];
                double E11 = 0.5 * (l * l - 1.0);
                double expect = mat.h / 2.0 * C[0] * E11 * E11;
                if (l < 1.0)
                    expect += mat.h * mat.kappa / 12.0 * pow((1.0 - l) / 6.0, 3);
                const double floor = 1e-20 * mat.h * C[0]; /* lambda = 1: zero up to rounding */
                CHECK_REL(plume_membrane_density(&mat, 2, F, d), expect, 1e-12, floor);
                /* the same in 3D, rotated out of the plane about the x axis */
                double c = cos(0.7), s = sin(0.7);
                double F3[6] = {F[0], F[1], c * F[2], c * F[3], s * F[2], s * F[3]};
                CHECK_REL(plume_membrane_density(&mat, 3, F3, d), expect, 1e-12, floor);
            }
            /* simple shear in the barb frame: G = F R = [[1, gam], [0, 1]], J = 1 */
            double gam = 0.2, Gm[4] = {1.0, gam, 0.0, 1.0}, R[4] = {d[0], -d[1], d[1], d[0]};
            double F[4]; /* F = G R^T */
            for (int i = 0; i < 2; i++)
                for (int j = 0; j < 2; j++)
                    F[2 * i + j] = Gm[2 * i] * R[2 * j] + Gm[2 * i + 1] * R[2 * j + 1];
            double expect = mat.h / 2.0 * (C[4] * pow(gam, 4) / 4.0 + C[8] * gam * gam);
            CHECK_REL(plume_membrane_density(&mat, 2, F, d), expect, 1e-12, 0.0);
        }
    }
    /* rest state: zero density, and zero energy / forces through the term */
    double I2[4] = {1, 0, 0, 1}, dx[2] = {1.0, 0.0}, dd[2] = {0.6, 0.8};
    CHECK(plume_membrane_density(&ma, 2, I2, dx) == 0.0);
    CHECK(plume_membrane_density(&ma, 2, I2, dd) <= 1e-28 * ma.moduli.E_xx * ma.h);
    CHECK(isnan(plume_membrane_density(&ma, 4, I2, dd)));

    /* a single-triangle term reproduces A * density for a stretch along its barbs */
    plume_mesh *m = NULL;
    CHECK(plume_mesh_create(3, 1, 2, &m, NULL) == PLUME_OK);
    if (!m)
        return;
    const double X[6] = {0.1, 0.2, 2.1, 0.5, 0.4, 1.7};
    memcpy(m->X, X, sizeof X);
    m->tri[0] = 0;
    m->tri[1] = 1;
    m->tri[2] = 2;
    m->barb_dir[0] = 3.0; /* not unit: normalised by the term */
    m->barb_dir[1] = 4.0;
    plume_term t;
    plume_membrane_material mat = ma;
    plume_membrane_stiffness(&mat, C);
    CHECK(plume_membrane_term_create(m, 2, &mat, 1, &t, NULL) == PLUME_OK);
    double l = 1.25, x[6], e = 0.0, g[6] = {0};
    for (int v = 0; v < 3; v++) {
        double p = X[2 * v] * 0.6 + X[2 * v + 1] * 0.8; /* component along d */
        x[2 * v] = X[2 * v] + (l - 1.0) * p * 0.6;
        x[2 * v + 1] = X[2 * v + 1] + (l - 1.0) * p * 0.8;
    }
    CHECK(t.eval(t.ctx, 2, x, &e, NULL, NULL, 0) == PLUME_OK);
    double E11 = 0.5 * (l * l - 1.0);
    CHECK_REL(e, plume_mesh_ref_area(m, 0) * mat.h / 2.0 * C[0] * E11 * E11, 1e-12, 0.0);
    e = 0.0;
    CHECK(t.eval(t.ctx, 2, X, &e, g, NULL, 0) == PLUME_OK);
    /* at rest up to the rounding of G = Dm Dm^-1 R */
    CHECK(e <= 1e-28 * C[0] * mat.h);
    CHECK(max_abs(g, 6) <= 1e-14 * C[0] * mat.h);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* ---- invariance, accumulation, degenerate current states -------------------------------- */

void test_membrane_rotation_invariance(void)
{
    rng64 r = {0x0F1E2D3C4B5A6978ULL};
    plume_mesh *m = small_mesh(137.0, 1.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    mats[0].kappa = mats[1].kappa = 3e5;
    plume_term t;
    CHECK(plume_membrane_term_create(m, 3, mats, 2, &t, NULL) == PLUME_OK);
    for (int rep = 0; rep < 10; rep++) {
        double x[15], y[15], g[15], gy[15], H[225], Hy[225], bl[4 * 81], Q[9];
        deform(&r, m, 3, 0.6, 1.4, 0.1, x);
        random_rotation(&r, Q);
        double sh[3] = {urange(&r, -3, 3), urange(&r, -3, 3), urange(&r, -3, 3)};
        for (int v = 0; v < 5; v++)
            for (int i = 0; i < 3; i++)
                y[3 * v + i] = Q[3 * i] * x[3 * v] + Q[3 * i + 1] * x[3 * v + 1] +
                               Q[3 * i + 2] * x[3 * v + 2] + sh[i];
        double e = term_all(&t, 3, 5, x, g, H, bl, 0);
        double ey = term_all(&t, 3, 5, y, gy, Hy, bl, 0);
        CHECK(e > 0.0);
        CHECK_REL(ey, e, 1e-12, 0.0);
        /* forces rotate with the body: gy = Q g, Hy = Q H Q^T (per vertex pair) */
        double gerr = 0.0, herr = 0.0;
        for (int v = 0; v < 5; v++)
            for (int i = 0; i < 3; i++) {
                double s = 0.0;
                for (int k = 0; k < 3; k++)
                    s += Q[3 * i + k] * g[3 * v + k];
                gerr = fmax(gerr, fabs(gy[3 * v + i] - s));
            }
        for (int v = 0; v < 5; v++)
            for (int w = 0; w < 5; w++)
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++) {
                        double s = 0.0;
                        for (int k = 0; k < 3; k++)
                            for (int l = 0; l < 3; l++)
                                s += Q[3 * i + k] * H[(3 * v + k) * 15 + 3 * w + l] * Q[3 * j + l];
                        herr = fmax(herr, fabs(Hy[(3 * v + i) * 15 + 3 * w + j] - s));
                    }
        CHECK_ERR(gerr, 1e-12, max_abs(g, 15), "rotated gradient");
        CHECK_ERR(herr, 1e-12, max_abs(H, 225), "rotated Hessian");
    }
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

void test_membrane_term_interface(void)
{
    rng64 r = {0x5555AAAA5555AAAAULL};
    plume_mesh *m = small_mesh(30.0, 1.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    mats[0].kappa = 1e5;
    plume_term t;
    CHECK(plume_membrane_term_create(m, 3, mats, 2, &t, NULL) == PLUME_OK);
    CHECK(strcmp(t.name, "membrane") == 0);
    CHECK(t.arity == 3 && t.nstencil == 4);
    CHECK(memcmp(t.stencil, m->tri, 12 * sizeof *m->tri) == 0);
    double x[15];
    deform(&r, m, 3, 0.7, 1.2, 0.1, x);
    plume_mesh_destroy(&m); /* the term copied what it needs */

    double e1 = 0.0, g1[15] = {0}, b1[4 * 81];
    CHECK(t.eval(t.ctx, 3, x, &e1, g1, b1, 0) == PLUME_OK);
    /* energy and gradient are added, blocks are overwritten */
    double e2 = 5.0, g2[15], b2[4 * 81];
    for (int i = 0; i < 15; i++)
        g2[i] = 1.0;
    for (int i = 0; i < 4 * 81; i++)
        b2[i] = NAN;
    CHECK(t.eval(t.ctx, 3, x, &e2, g2, b2, 0) == PLUME_OK);
    CHECK(e2 == 5.0 + e1);
    for (int i = 0; i < 15; i++)
        CHECK_REL(g2[i], 1.0 + g1[i], 1e-14, 1.0); /* added per triangle: rounding differs */
    CHECK(memcmp(b1, b2, sizeof b1) == 0);
    /* any output may be NULL; results do not depend on which were asked for */
    double e3 = 0.0, g3[15] = {0}, b3[4 * 81];
    CHECK(t.eval(t.ctx, 3, x, &e3, NULL, NULL, 0) == PLUME_OK);
    CHECK(t.eval(t.ctx, 3, x, NULL, g3, NULL, 0) == PLUME_OK);
    CHECK(t.eval(t.ctx, 3, x, NULL, NULL, b3, 0) == PLUME_OK);
    CHECK(e3 == e1 && memcmp(g3, g1, sizeof g1) == 0 && memcmp(b3, b1, sizeof b1) == 0);
    /* wrong dimension or missing x */
    CHECK(t.eval(t.ctx, 2, x, &e3, NULL, NULL, 0) == PLUME_EINVAL);
    CHECK(t.eval(t.ctx, 3, NULL, &e3, NULL, NULL, 0) == PLUME_EINVAL);
    t.destroy(t.ctx);
}

/* a current triangle collapsed to a segment or a point under the compression term: finite
 * energy, gradient and Hessian (the d2J part is dropped below J ~ 1e-14) */
void test_membrane_collapsed(void)
{
    plume_mesh *m = NULL;
    CHECK(plume_mesh_create(3, 1, 3, &m, NULL) == PLUME_OK);
    if (!m)
        return;
    const double X[6] = {0, 0, 1, 0, 0, 1};
    memcpy(m->X, X, sizeof X);
    m->tri[0] = 0;
    m->tri[1] = 1;
    m->tri[2] = 2;
    plume_membrane_material mat = MAT_ANISO;
    mat.kappa = 1e4;
    for (int dim = 2; dim <= 3; dim++) {
        plume_term t;
        CHECK(plume_membrane_term_create(m, dim, &mat, 1, &t, NULL) == PLUME_OK);
        const double xs[3][9] = {{0, 0, 0, 1, 1, 0, 2, 2, 0},          /* segment, J = 0 */
                                 {0, 0, 0, 1, 1, 0, 2, 2 + 1e-15, 0},  /* J ~ 1e-15 */
                                 {0.3, 0.3, 0, 0.3, 0.3, 0, 0.3, 0.3, 0}}; /* point */
        for (int c = 0; c < 3; c++) {
            double x[9], e = 0.0, g[9] = {0}, b[81];
            for (int v = 0; v < 3; v++)
                for (int i = 0; i < dim; i++)
                    x[dim * v + i] = xs[c][3 * v + i];
            for (int project = 0; project < 2; project++) {
                CHECK(t.eval(t.ctx, dim, x, &e, g, b, project) == PLUME_OK);
                CHECK(isfinite(e) && e > 0.0);
                for (int i = 0; i < 3 * dim; i++)
                    CHECK(isfinite(g[i]));
                for (int i = 0; i < 9 * dim * dim; i++)
                    CHECK(isfinite(b[i]));
            }
        }
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
}

/* ---- input errors ---------------------------------------------------------------------------- */

static int create_fails(const plume_mesh *m, int dim, const plume_membrane_material *mats,
                        int nmat, const char *needle1, const char *needle2)
{
    plume_term t;
    plume_err err;
    err.msg[0] = '\0';
    t.ctx = (void *)&t; /* must be cleared on failure */
    plume_status st = plume_membrane_term_create(m, dim, mats, nmat, &t, &err);
    int ok = st == PLUME_EINVAL && t.ctx == NULL && t.eval == NULL && strstr(err.msg, needle1) &&
             (!needle2 || strstr(err.msg, needle2));
    if (!ok)
        fprintf(stderr, "    unexpected: status %d, message \"%s\" (wanted \"%s\")\n", (int)st,
                err.msg, needle1);
    if (st == PLUME_OK)
        t.destroy(t.ctx);
    return ok;
}

void test_membrane_bad_inputs(void)
{
    plume_err err;
    plume_membrane_material good = MAT_ANISO, bad;
    CHECK(plume_membrane_material_check(&good, &err) == PLUME_OK);
    CHECK(plume_membrane_material_check(&good, NULL) == PLUME_OK);
    CHECK(plume_membrane_material_check(NULL, &err) == PLUME_EINVAL);

    struct {
        int field; /* 0 E_xx, 1 E_yy, 2 nu_xy, 3 G_xy, 4 h, 5 kappa */
        double value;
        const char *name;
    } cases[] = {{1, -1.0, "E_yy must be finite and > 0 (got -1)"},
                 {0, 0.0, "E_xx"},
                 {0, INFINITY, "E_xx"},
                 {3, NAN, "G_xy"},
                 {3, 0.0, "G_xy"},
                 {2, NAN, "nu_xy"},
                 {2, 13.0, "nu_xy^2"},  /* 169 >= E_xx/E_yy = 150 */
                 {2, -12.5, "nu_xy^2"}, /* 156.25 >= 150 */
                 {4, 0.0, "h must"},
                 {4, -1e-3, "h must"},
                 {5, -1.0, "kappa"},
                 {5, NAN, "kappa"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        bad = good;
        double *f[6] = {&bad.moduli.E_xx, &bad.moduli.E_yy, &bad.moduli.nu_xy, &bad.moduli.G_xy, &bad.h, &bad.kappa};
        *f[cases[i].field] = cases[i].value;
        err.msg[0] = '\0';
        CHECK(plume_membrane_material_check(&bad, &err) == PLUME_EINVAL);
        CHECK(strstr(err.msg, cases[i].name) != NULL);
        CHECK(plume_membrane_material_check(&bad, NULL) == PLUME_EINVAL);
    }
    /* the limit nu_xy^2 = E_xx/E_yy exactly is rejected too */
    bad = good;
    bad.moduli.E_xx = 4.0;
    bad.moduli.E_yy = 1.0;
    bad.moduli.nu_xy = 2.0;
    CHECK(plume_membrane_material_check(&bad, &err) == PLUME_EINVAL);

    plume_mesh *m = small_mesh(30.0, 1.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_membrane_material mats[2] = {MAT_ANISO, MAT_ISO};
    CHECK(create_fails(m, 4, mats, 2, "dim", NULL));
    CHECK(create_fails(m, 1, mats, 2, "dim", NULL));
    CHECK(create_fails(m, 3, mats, 0, "nmat", NULL));
    CHECK(create_fails(NULL, 3, mats, 2, "NULL", NULL));
    CHECK(create_fails(m, 3, NULL, 2, "NULL", NULL));
    CHECK(plume_membrane_term_create(m, 3, mats, 2, NULL, NULL) == PLUME_EINVAL);
    mats[1].moduli.E_yy = -1.0;
    CHECK(create_fails(m, 3, mats, 2, "material 1: E_yy must be finite and > 0 (got -1)", NULL));
    mats[1] = MAT_ISO;
    mats[0].moduli.G_xy = NAN;
    CHECK(create_fails(m, 3, mats, 2, "material 0: G_xy", NULL));
    mats[0] = MAT_ANISO;
    mats[0].moduli.nu_xy = 20.0;
    CHECK(create_fails(m, 3, mats, 2, "material 0: nu_xy^2", NULL));
    mats[0] = MAT_ANISO;
    mats[0].h = 0.0;
    CHECK(create_fails(m, 3, mats, 2, "material 0: h", NULL));
    mats[0] = MAT_ANISO;
    mats[0].kappa = -2.0;
    CHECK(create_fails(m, 3, mats, 2, "material 0: kappa", NULL));
    mats[0] = MAT_ANISO;
    /* material id out of range (the mesh uses ids 0 and 1) */
    CHECK(create_fails(m, 3, mats, 1, "triangle 1", "material id 1"));
    m->material[2] = -1;
    CHECK(create_fails(m, 3, mats, 2, "triangle 2", "material id -1"));
    m->material[2] = 0;
    /* zero-area reference triangle: vertex 4 moved onto the segment 1-2 */
    double keep[2] = {m->X[8], m->X[9]};
    m->X[8] = 0.5 * (m->X[2] + m->X[4]);
    m->X[9] = 0.5 * (m->X[3] + m->X[5]);
    CHECK(create_fails(m, 3, mats, 2, "triangle 1", "degenerate"));
    m->X[8] = NAN;
    CHECK(create_fails(m, 3, mats, 2, "triangle 0", "degenerate"));
    m->X[8] = keep[0];
    m->X[9] = keep[1];
    /* two vertices at the same place */
    m->X[2] = m->X[0];
    m->X[3] = m->X[1];
    CHECK(create_fails(m, 3, mats, 2, "triangle 0", "degenerate"));
    m->X[2] = 1.3;
    m->X[3] = 0.1;
    /* barb direction that cannot be normalised */
    m->barb_dir[6] = m->barb_dir[7] = 0.0;
    CHECK(create_fails(m, 2, mats, 2, "triangle 3", "barb direction"));
    m->barb_dir[6] = NAN;
    CHECK(create_fails(m, 2, mats, 2, "triangle 3", "barb direction"));
    m->barb_dir[6] = 1.0;
    /* vertex id out of range */
    m->tri[5] = 5;
    CHECK(create_fails(m, 2, mats, 2, "triangle 1", "vertex id 5"));
    m->tri[5] = 4;
    /* all fixed: it builds again */
    plume_term t;
    CHECK(plume_membrane_term_create(m, 2, mats, 2, &t, &err) == PLUME_OK);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}
