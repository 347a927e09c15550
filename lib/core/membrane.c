/* The membrane element (docs/design.md "Equations every part agrees on"; supplementary eq. 6).
 *
 * Everything is written in terms of G = F R = Ds B with B = Dm^-1 R precomputed per triangle:
 * the Green strain in the barb frame is E = (G^T G - I)/2 and J = |g1 x g2| for the columns g1, g2
 * of G (planar mode embeds G in 3D with z = 0, so J = |det F|). The energy density, its gradient
 * dpsi/dG and its Hessian (2 dim x 2 dim) are computed in G in closed form
 * (lib/core/internal/membrane_law.h, shared with the quadratic triangle), projected there when asked
 * (G -> x is a linear surjection, so PSD in G gives PSD in x; shell mode splits the 6x6 block into
 * in-plane 4x4 and normal 2x2 parts first), and mapped to the three vertices with
 * G[:,c] = sum_v W[v][c] x_v. Nothing is allocated after create. */
#include "membrane.h"
#include "internal/membrane_law.h"
#include "vec3.h"

#include "dense.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double Ah;   /* reference area times thickness */
    double B[4]; /* Dm^-1 R, row-major 2x2 */
    int mat;
} mem_tri;

typedef struct {
    int dim;
    plume_index nt;
    plume_index *stencil;    /* [3*nt] */
    mem_tri *tri;            /* [nt] */
    plume_membrane_law *mat; /* [nmat] */
} mem_ctx;

/* 1 - nu_xy nu_yx, the plane-stress denominator; > 0 iff C is positive definite (moduli > 0). */
static double plane_stress_det(const plume_membrane_material *m)
{
    double nu_yx = m->moduli.nu_xy * m->moduli.E_yy / m->moduli.E_xx;
    return 1.0 - m->moduli.nu_xy * nu_yx;
}

plume_status plume_membrane_material_check(const plume_membrane_material *m, plume_err *err)
{
    if (!m)
        return plume_err_set(err, PLUME_EINVAL, "material is NULL");
    if (!(isfinite(m->moduli.E_xx) && m->moduli.E_xx > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "E_xx must be finite and > 0 (got %g)", m->moduli.E_xx);
    if (!(isfinite(m->moduli.E_yy) && m->moduli.E_yy > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "E_yy must be finite and > 0 (got %g)", m->moduli.E_yy);
    if (!(isfinite(m->moduli.G_xy) && m->moduli.G_xy > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "G_xy must be finite and > 0 (got %g)", m->moduli.G_xy);
    if (!isfinite(m->moduli.nu_xy))
        return plume_err_set(err, PLUME_EINVAL, "nu_xy must be finite (got %g)", m->moduli.nu_xy);
    if (!(isfinite(m->h) && m->h > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "h must be finite and > 0 (got %g)", m->h);
    if (!(isfinite(m->kappa) && m->kappa >= 0.0))
        return plume_err_set(err, PLUME_EINVAL, "kappa must be finite and >= 0 (got %g)", m->kappa);
    double D = plane_stress_det(m);
    if (!(D > 0.0) || !isfinite(m->moduli.E_xx / D) || !isfinite(m->moduli.E_yy / D))
        return plume_err_set(err, PLUME_EINVAL,
                             "nu_xy^2 must be < E_xx/E_yy for a positive definite plane-stress "
                             "tensor (got nu_xy = %g, E_xx/E_yy = %g)",
                             m->moduli.nu_xy, m->moduli.E_xx / m->moduli.E_yy);
    return PLUME_OK;
}

void plume_membrane_stiffness(const plume_membrane_material *m, double C[9])
{
    double nu_yx = m->moduli.nu_xy * m->moduli.E_yy / m->moduli.E_xx;
    double D = 1.0 - m->moduli.nu_xy * nu_yx;
    C[0] = m->moduli.E_xx / D;
    C[1] = nu_yx * m->moduli.E_xx / D;
    C[2] = 0.0;
    C[3] = C[1];
    C[4] = m->moduli.E_yy / D;
    C[5] = 0.0;
    C[6] = 0.0;
    C[7] = 0.0;
    C[8] = m->moduli.G_xy;
}

double plume_membrane_density(const plume_membrane_material *mat, int dim, const double *F,
                              const double d[2])
{
    return plume_membrane_density_tensor(mat, NULL, dim, F, d);
}

double plume_membrane_density_tensor(const plume_membrane_material *mat, const double *C, int dim, const double *F,
                                     const double d[2])
{
    if (!mat || !F || !d || (dim != 2 && dim != 3))
        return NAN;
    plume_membrane_law m;
    plume_membrane_law_set_tensor(mat, C, &m);
    double len = hypot(d[0], d[1]);
    double R[2][2] = {{d[0] / len, -d[1] / len}, {d[1] / len, d[0] / len}};
    double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    for (int i = 0; i < dim; i++)
        for (int c = 0; c < 2; c++)
            g[c][i] = F[2 * i] * R[0][c] + F[2 * i + 1] * R[1][c];
    return mat->h * plume_membrane_law_density_G(&m, dim, g, NULL, NULL);
}

plume_status plume_membrane_strain_stress(const plume_membrane_material *mat, int dim, const double *F,
                                          const double d[2], double E[3], double S[3], double *J)
{
    return plume_membrane_strain_stress_tensor(mat, NULL, dim, F, d, E, S, J);
}

plume_status plume_membrane_strain_stress_tensor(const plume_membrane_material *mat, const double *C, int dim,
                                                 const double *F, const double d[2], double E[3], double S[3],
                                                 double *J)
{
    if (!mat || !F || !d || !E || !S || !J || (dim != 2 && dim != 3) || !(hypot(d[0], d[1]) > 0.0))
        return PLUME_EINVAL;
    plume_membrane_law m;
    plume_membrane_law_set_tensor(mat, C, &m);
    double len = hypot(d[0], d[1]);
    double R[2][2] = {{d[0] / len, -d[1] / len}, {d[1] / len, d[0] / len}};
    double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, P[2][3], n[3];
    for (int i = 0; i < dim; i++)
        for (int c = 0; c < 2; c++)
            g[c][i] = F[2 * i] * R[0][c] + F[2 * i + 1] * R[1][c];
    const double c11 = dot3(g[0], g[0]), c22 = dot3(g[1], g[1]), c12 = dot3(g[0], g[1]);
    E[0] = 0.5 * (c11 - 1.0), E[1] = 0.5 * (c22 - 1.0), E[2] = 0.5 * c12;
    cross3(g[0], g[1], n);
    *J = sqrt(dot3(n, n));
    plume_membrane_law_density_G(&m, dim, g, P, NULL);
    /* P[c] = sum_e S_ce g_e, so (P g^T) = S C with C the Gram matrix of g: S = (P g^T) C^-1 */
    const double det = c11 * c22 - c12 * c12;
    if (!(det > 0.0)) {
        S[0] = S[1] = S[2] = NAN;
        return PLUME_OK;
    }
    const double M00 = dot3(P[0], g[0]), M01 = dot3(P[0], g[1]), M10 = dot3(P[1], g[0]), M11 = dot3(P[1], g[1]);
    const double i00 = c22 / det, i01 = -c12 / det, i11 = c11 / det;
    S[0] = M00 * i00 + M01 * i01;
    S[1] = M10 * i01 + M11 * i11;
    S[2] = 0.5 * ((M00 * i01 + M01 * i11) + (M10 * i00 + M11 * i01));
    return PLUME_OK;
}

/* Projects the shell-mode (dim 3) Hessian HG (6x6, layout of density_G) to PSD in half the
 * work. psi depends on G only through G^T G, so in the orthonormal frame (t1, t2, n^) of the
 * deformed triangle (t1 along g0, n^ the unit normal) HG splits into a 4x4 in-plane block (the
 * planar Hessian) and a 2x2 block for the normal components (the coefficients of the identity in
 * each 3x3 block: the stress); the coupling is zero up to rounding. The two blocks are projected
 * separately and rotated back, which is the projection of HG (the frame change is orthogonal).
 * Returns 0 (HG untouched) when the frame is undefined, so the caller projects HG directly. */
static int project_shell(double *HG, const double g0[3], const double n[3])
{
    double ln = sqrt(dot3(n, n)), l0 = sqrt(dot3(g0, g0));
    if (!(ln > 0.0) || !(l0 > 0.0) || !isfinite(ln) || !isfinite(l0))
        return 0;
    double T[3][3]; /* rows t1, t2, n^ */
    for (int i = 0; i < 3; i++) {
        T[0][i] = g0[i] / l0;
        T[2][i] = n[i] / ln;
    }
    cross3(T[2], T[0], T[1]);
    double H2[16], N[4], H2c[16], Nc[4];
    for (int c = 0; c < 2; c++) {
        for (int d = c; d < 2; d++) {
            const double *M = HG + 3 * c * 6 + 3 * d; /* 3x3 block (c, d), row stride 6 */
            double R[3][3];                           /* T M T^T */
            for (int a = 0; a < 3; a++) {
                double MT[3];
                for (int i = 0; i < 3; i++)
                    MT[i] = M[i * 6] * T[a][0] + M[i * 6 + 1] * T[a][1] + M[i * 6 + 2] * T[a][2];
                for (int b = 0; b < 3; b++)
                    R[b][a] = T[b][0] * MT[0] + T[b][1] * MT[1] + T[b][2] * MT[2];
            }
            for (int a = 0; a < 2; a++)
                for (int b = 0; b < 2; b++) {
                    /* mirrored from the (c <= d) blocks, upper part on the diagonal blocks, so
                     * that H2 is exactly symmetric */
                    double v = (c == d && b < a) ? R[b][a] : R[a][b];
                    H2[(2 * c + a) * 4 + 2 * d + b] = H2[(2 * d + b) * 4 + 2 * c + a] = v;
                }
            N[2 * c + d] = N[2 * d + c] = R[2][2];
        }
    }
    memcpy(H2c, H2, sizeof H2);
    memcpy(Nc, N, sizeof N);
    plume_dense_project_psd(4, H2);
    plume_dense_project_psd(2, N);
    if (memcmp(H2, H2c, sizeof H2) == 0 && memcmp(N, Nc, sizeof N) == 0)
        return 1; /* already PSD: HG stays exactly as computed */
    for (int c = 0; c < 2; c++) {
        for (int d = c; d < 2; d++) {
            for (int i = 0; i < 3; i++) {
                for (int j = 0; j < 3; j++) {
                    double v = N[2 * c + d] * T[2][i] * T[2][j];
                    for (int a = 0; a < 2; a++)
                        for (int b = 0; b < 2; b++)
                            v += T[a][i] * H2[(2 * c + a) * 4 + 2 * d + b] * T[b][j];
                    HG[(3 * c + i) * 6 + 3 * d + j] = HG[(3 * d + j) * 6 + 3 * c + i] = v;
                }
            }
        }
    }
    return 1;
}

/* The element loop is instantiated for dim = 2 and dim = 3 so that the small loops get fixed trip
 * counts; GCC does not inline a function this size on its own (forcing it measured -25% time in
 * planar mode). */
#if defined(__GNUC__)
#define MEMBRANE_SPECIALISE __attribute__((always_inline)) inline
#else
#define MEMBRANE_SPECIALISE inline
#endif

/* The element loop; returns the energy. Called with a literal dim. */
static MEMBRANE_SPECIALISE double eval_loop(const mem_ctx *ctx, const int dim, const double *x,
                                            double *grad, double *hblocks, int project)
{
    const int k = 2 * dim, kk = 3 * dim;
    double HG[36];
    double E = 0.0;
    for (plume_index t = 0; t < ctx->nt; t++) {
        const mem_tri *tr = &ctx->tri[t];
        const plume_index *vid = ctx->stencil + 3 * t;
        const double *B = tr->B;
        /* G[:,c] = sum_v W[v][c] x_v */
        const double W[3][2] = {{-(B[0] + B[2]), -(B[1] + B[3])}, {B[0], B[1]}, {B[2], B[3]}};
        const double *x0 = x + dim * vid[0], *x1 = x + dim * vid[1], *x2 = x + dim * vid[2];
        double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
        for (int i = 0; i < dim; i++) {
            const double a = x1[i] - x0[i], b = x2[i] - x0[i];
            g[0][i] = a * B[0] + b * B[2];
            g[1][i] = a * B[1] + b * B[3];
        }
        double P[2][3];
        double psi = plume_membrane_law_density_G(&ctx->mat[tr->mat], dim, g, grad ? P : NULL,
                                                  hblocks ? HG : NULL);
        E += tr->Ah * psi;
        if (grad) {
            for (int v = 0; v < 3; v++) {
                double *gv = grad + dim * vid[v];
                for (int i = 0; i < dim; i++)
                    gv[i] += tr->Ah * (W[v][0] * P[0][i] + W[v][1] * P[1][i]);
            }
        }
        if (hblocks) {
            if (project) {
                double n[3];
                cross3(g[0], g[1], n);
                if (dim == 2 || !project_shell(HG, g[0], n))
                    plume_dense_project_psd(k, HG);
            }
            /* vertex block (v, w) = Ah sum_{c,d} W[v][c] W[w][d] HG_cd, HG_cd the dim x dim
             * block of columns (c, d); computed for v <= w and mirrored, so exactly symmetric */
            double *H = hblocks + (size_t)t * kk * kk;
            for (int v = 0; v < 3; v++) {
                for (int w = v; w < 3; w++) {
                    const double a00 = tr->Ah * W[v][0] * W[w][0];
                    const double a11 = tr->Ah * W[v][1] * W[w][1];
                    const double a01 = tr->Ah * W[v][0] * W[w][1];
                    const double a10 = tr->Ah * W[v][1] * W[w][0];
                    for (int i = 0; i < dim; i++) {
                        for (int j = 0; j < dim; j++) {
                            double h = a00 * HG[i * k + j] + a11 * HG[(dim + i) * k + dim + j] +
                                       a01 * HG[i * k + dim + j] + a10 * HG[(dim + i) * k + j];
                            H[(v * dim + i) * kk + w * dim + j] = h;
                            H[(w * dim + j) * kk + v * dim + i] = h;
                        }
                    }
                }
            }
        }
    }
    return E;
}

static plume_status membrane_eval(void *vctx, int dim, const double *x, double *energy,
                                  double *grad, double *hblocks, int project)
{
    const mem_ctx *ctx = vctx;
    if (!ctx || !x || dim != ctx->dim)
        return PLUME_EINVAL;
    double E = dim == 2 ? eval_loop(ctx, 2, x, grad, hblocks, project)
                        : eval_loop(ctx, 3, x, grad, hblocks, project);
    if (energy)
        *energy += E;
    return PLUME_OK;
}

static plume_status membrane_energies(void *vctx, int dim, const double *x, double *e)
{
    const mem_ctx *ctx = vctx;
    if (!ctx || !x || !e || dim != ctx->dim)
        return PLUME_EINVAL;
    for (plume_index t = 0; t < ctx->nt; t++) {
        const mem_tri *tr = &ctx->tri[t];
        const plume_index *vid = ctx->stencil + 3 * t;
        const double *B = tr->B, *x0 = x + dim * vid[0], *x1 = x + dim * vid[1], *x2 = x + dim * vid[2];
        double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
        for (int i = 0; i < dim; i++) {
            const double a = x1[i] - x0[i], b = x2[i] - x0[i];
            g[0][i] = a * B[0] + b * B[2];
            g[1][i] = a * B[1] + b * B[3];
        }
        e[t] = tr->Ah * plume_membrane_law_density_G(&ctx->mat[tr->mat], dim, g, NULL, NULL);
    }
    return PLUME_OK;
}

static void membrane_destroy(void *vctx)
{
    mem_ctx *ctx = vctx;
    if (!ctx)
        return;
    free(ctx->stencil);
    free(ctx->tri);
    free(ctx->mat);
    free(ctx);
}

/* What plume_membrane_term_create checks before allocating: dim, the materials, the mesh's arrays. */
static plume_status check_membrane_args(const plume_mesh *mesh, int dim, const plume_membrane_material *mats,
                                        int nmat, plume_err *err)
{
    if (dim != 2 && dim != 3)
        return plume_err_set(err, PLUME_EINVAL, "membrane: dim must be 2 or 3 (got %d)", dim);
    if (nmat < 1)
        return plume_err_set(err, PLUME_EINVAL, "membrane: nmat must be >= 1 (got %d)", nmat);
    if (mesh->nv < 0 || mesh->nt < 0 || (mesh->nt > 0 && (!mesh->X || !mesh->tri ||
                                                          !mesh->barb_dir || !mesh->material)))
        return plume_err_set(err, PLUME_EINVAL, "membrane: mesh arrays missing or sizes negative");
    for (int i = 0; i < nmat; i++) {
        plume_err e;
        if (plume_membrane_material_check(&mats[i], &e) != PLUME_OK)
            return plume_err_set(err, PLUME_EINVAL, "membrane: material %d: %s", i, e.msg);
    }
    return PLUME_OK;
}

/* Triangle t's stencil (its three vertices) and reference data: B = Dm^-1 R in the barb frame and
 * Ah = area h. Fails on a vertex or material id out of range, a degenerate reference triangle or
 * a barb direction that cannot be normalised. */
static plume_status reference_triangle(const plume_mesh *mesh, const plume_membrane_material *mats, int nmat,
                                       plume_index t, plume_index stencil[3], mem_tri *tr, plume_err *err)
{
    const plume_index *v = mesh->tri + 3 * t;
    for (int l = 0; l < 3; l++) {
        if (v[l] < 0 || v[l] >= mesh->nv)
            return plume_err_set(err, PLUME_EINVAL,
                                 "membrane: triangle %ld: vertex id %ld out of range [0, %ld)",
                                 (long)t, (long)v[l], (long)mesh->nv);
        stencil[l] = v[l];
    }
    int mid = mesh->material[t];
    if (mid < 0 || mid >= nmat)
        return plume_err_set(err, PLUME_EINVAL,
                             "membrane: triangle %ld: material id %d out of range [0, %d)",
                             (long)t, mid, nmat);
    const double *X0 = mesh->X + 2 * v[0], *X1 = mesh->X + 2 * v[1], *X2 = mesh->X + 2 * v[2];
    double d00 = X1[0] - X0[0], d01 = X2[0] - X0[0]; /* Dm = [X1-X0, X2-X0] */
    double d10 = X1[1] - X0[1], d11 = X2[1] - X0[1];
    double det = d00 * d11 - d01 * d10;
    double area = 0.5 * fabs(det);
    double scale = d00 * d00 + d10 * d10 + d01 * d01 + d11 * d11 +
                   (d01 - d00) * (d01 - d00) + (d11 - d10) * (d11 - d10);
    if (!isfinite(area) || !isfinite(scale) || !(fabs(det) > MEMBRANE_DEGENERATE_REL * scale))
        return plume_err_set(err, PLUME_EINVAL,
                             "membrane: triangle %ld: degenerate reference triangle (area %g)",
                             (long)t, area);
    double dx = mesh->barb_dir[2 * t], dy = mesh->barb_dir[2 * t + 1];
    double len = hypot(dx, dy);
    if (!isfinite(len) || !(len > 0.0))
        return plume_err_set(err, PLUME_EINVAL,
                             "membrane: triangle %ld: barb direction (%g, %g) cannot be "
                             "normalised", (long)t, dx, dy);
    dx /= len;
    dy /= len;
    /* B = Dm^-1 R, R = [d, d_perp], d_perp = (-d_y, d_x) */
    double i00 = d11 / det, i01 = -d01 / det, i10 = -d10 / det, i11 = d00 / det;
    tr->B[0] = i00 * dx + i01 * dy;
    tr->B[1] = -i00 * dy + i01 * dx;
    tr->B[2] = i10 * dx + i11 * dy;
    tr->B[3] = -i10 * dy + i11 * dx;
    tr->Ah = area * mats[mid].h;
    tr->mat = mid;
    return PLUME_OK;
}

plume_status plume_membrane_tensor_check(const double C[9], plume_err *err)
{
    if (!C)
        return plume_err_set(err, PLUME_EINVAL, "membrane tensor: none given");
    for (int k = 0; k < 9; k++)
        if (!isfinite(C[k]))
            return plume_err_set(err, PLUME_EINVAL, "membrane tensor: C%d%d is not finite", k / 3 + 1, k % 3 + 1);
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (fabs(C[3 * i + j] - C[3 * j + i]) > 1e-9 * (fabs(C[3 * i + j]) + fabs(C[3 * j + i])))
                return plume_err_set(err, PLUME_EINVAL, "membrane tensor: not symmetric (C%d%d = %g, C%d%d = %g)",
                                     i + 1, j + 1, C[3 * i + j], j + 1, i + 1, C[3 * j + i]);
    /* positive definite: the leading minors (Sylvester) */
    const double m1 = C[0], m2 = C[0] * C[4] - C[1] * C[3];
    const double m3 = C[0] * (C[4] * C[8] - C[5] * C[7]) - C[1] * (C[3] * C[8] - C[5] * C[6]) +
                      C[2] * (C[3] * C[7] - C[4] * C[6]);
    if (!(m1 > 0.0 && m2 > 0.0 && m3 > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "membrane tensor: not positive definite (leading minors %g, %g, %g)",
                             m1, m2, m3);
    return PLUME_OK;
}

plume_status plume_membrane_term_create(const plume_mesh *mesh, int dim,
                                        const plume_membrane_material *mats, int nmat,
                                        plume_term *out, plume_err *err)
{
    return plume_membrane_term_create_tensor(mesh, dim, mats, NULL, nmat, out, err);
}

plume_status plume_membrane_term_create_tensor(const plume_mesh *mesh, int dim, const plume_membrane_material *mats,
                                               const double *tensors, int nmat, plume_term *out, plume_err *err)
{
    plume_status st = PLUME_OK;
    mem_ctx *ctx = NULL;
    if (out)
        memset(out, 0, sizeof *out);
    if (!mesh || !mats || !out)
        return plume_err_set(err, PLUME_EINVAL, "membrane: NULL mesh, materials or output");
    if ((st = check_membrane_args(mesh, dim, mats, nmat, err)) != PLUME_OK)
        return st;
    for (int i = 0; tensors && i < nmat; i++) {
        plume_err why;
        if (plume_membrane_tensor_check(tensors + 9 * i, &why) != PLUME_OK)
            return plume_err_set(err, PLUME_EINVAL, "membrane: material %d: %s", i, why.msg);
    }

    const plume_index nt = mesh->nt;
    ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return plume_err_set(err, PLUME_ENOMEM, "membrane: out of memory");
    ctx->dim = dim;
    ctx->nt = nt;
    ctx->stencil = malloc((size_t)(3 * nt + 1) * sizeof *ctx->stencil);
    ctx->tri = malloc((size_t)(nt + 1) * sizeof *ctx->tri);
    ctx->mat = malloc((size_t)nmat * sizeof *ctx->mat);
    if (!ctx->stencil || !ctx->tri || !ctx->mat) {
        st = plume_err_set(err, PLUME_ENOMEM, "membrane: out of memory");
        goto cleanup;
    }
    for (int i = 0; i < nmat; i++)
        plume_membrane_law_set_tensor(&mats[i], tensors ? tensors + 9 * i : NULL, &ctx->mat[i]);
    for (plume_index t = 0; t < nt; t++)
        if ((st = reference_triangle(mesh, mats, nmat, t, ctx->stencil + 3 * t, &ctx->tri[t], err)) != PLUME_OK)
            goto cleanup;

    out->name = "membrane";
    out->arity = 3;
    out->nstencil = nt;
    out->stencil = ctx->stencil;
    out->size = sizeof *out;
    out->eval = membrane_eval;
    out->energies = membrane_energies;
    out->destroy = membrane_destroy;
    out->ctx = ctx;
    return PLUME_OK;

cleanup:
    membrane_destroy(ctx);
    return st;
}
