/* The membrane element (DESIGN.md "Equations every part agrees on"; supplementary eq. 6).
 *
 * Everything is written in terms of G = F R = Ds B with B = Dm^-1 R precomputed per triangle:
 * the Green strain in the barb frame is E = (G^T G - I)/2 and J = |g1 x g2| for the columns g1, g2
 * of G (planar mode embeds G in 3D with z = 0, so J = |det F|). The energy density, its gradient
 * dpsi/dG and its Hessian (2 dim x 2 dim) are computed in G in closed form, projected there when
 * asked (G -> x is a linear surjection, so PSD in G gives PSD in x; shell mode splits the 6x6
 * block into in-plane 4x4 and normal 2x2 parts first), and mapped to the three vertices with
 * G[:,c] = sum_v W[v][c] x_v. Nothing is allocated after create. */
#include "membrane.h"
#include "internal/vec3.h"

#include "dense.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Below this area ratio the current triangle is collapsed and the second derivative of J, which
 * divides by J, is dropped; the first derivative (a unit normal) stays well defined down to 0. */
#define MEMBRANE_J_TINY 1e-14

/* A reference triangle whose doubled area is below this fraction of its squared edge lengths is
 * degenerate up to rounding (collinear points computed in floating point): Dm^-1 would be noise. */
#define MEMBRANE_DEGENERATE_REL (64.0 * DBL_EPSILON)

/* A material as the element uses it. C is orthotropic in the barb frame, so of the plane-stress
 * tensor only C11, C12 = C21, C22 and C33 are non-zero (DESIGN.md, membrane energy). */
typedef struct {
    double C11, C12, C22, C33;
    double kappa; /* compression coefficient (Pa) */
    int log_barrier;
} mem_mat;

typedef struct {
    double Ah;   /* reference area times thickness */
    double B[4]; /* Dm^-1 R, row-major 2x2 */
    int mat;
} mem_tri;

typedef struct {
    int dim;
    plume_index nt;
    plume_index *stencil; /* [3*nt] */
    mem_tri *tri;         /* [nt] */
    mem_mat *mat;         /* [nmat] */
} mem_ctx;

/* 1 - nu_xy nu_yx, the plane-stress denominator; > 0 iff C is positive definite (moduli > 0). */
static double plane_stress_det(const plume_membrane_material *m)
{
    double nu_yx = m->nu_xy * m->E_yy / m->E_xx;
    return 1.0 - m->nu_xy * nu_yx;
}

plume_status plume_membrane_material_check(const plume_membrane_material *m, plume_err *err)
{
    if (!m)
        return plume_err_set(err, PLUME_EINVAL, "material is NULL");
    if (!(isfinite(m->E_xx) && m->E_xx > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "E_xx must be finite and > 0 (got %g)", m->E_xx);
    if (!(isfinite(m->E_yy) && m->E_yy > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "E_yy must be finite and > 0 (got %g)", m->E_yy);
    if (!(isfinite(m->G_xy) && m->G_xy > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "G_xy must be finite and > 0 (got %g)", m->G_xy);
    if (!isfinite(m->nu_xy))
        return plume_err_set(err, PLUME_EINVAL, "nu_xy must be finite (got %g)", m->nu_xy);
    if (!(isfinite(m->h) && m->h > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "h must be finite and > 0 (got %g)", m->h);
    if (!(isfinite(m->kappa) && m->kappa >= 0.0))
        return plume_err_set(err, PLUME_EINVAL, "kappa must be finite and >= 0 (got %g)", m->kappa);
    double D = plane_stress_det(m);
    if (!(D > 0.0) || !isfinite(m->E_xx / D) || !isfinite(m->E_yy / D))
        return plume_err_set(err, PLUME_EINVAL,
                             "nu_xy^2 must be < E_xx/E_yy for a positive definite plane-stress "
                             "tensor (got nu_xy = %g, E_xx/E_yy = %g)",
                             m->nu_xy, m->E_xx / m->E_yy);
    return PLUME_OK;
}

void plume_membrane_stiffness(const plume_membrane_material *m, double C[9])
{
    double nu_yx = m->nu_xy * m->E_yy / m->E_xx;
    double D = 1.0 - m->nu_xy * nu_yx;
    C[0] = m->E_xx / D;
    C[1] = nu_yx * m->E_xx / D;
    C[2] = 0.0;
    C[3] = C[1];
    C[4] = m->E_yy / D;
    C[5] = 0.0;
    C[6] = 0.0;
    C[7] = 0.0;
    C[8] = m->G_xy;
}

static void mem_mat_set(const plume_membrane_material *mat, mem_mat *m)
{
    double C[9];
    plume_membrane_stiffness(mat, C);
    m->C11 = C[0];
    m->C12 = C[1];
    m->C22 = C[4];
    m->C33 = C[8];
    m->kappa = mat->kappa;
    m->log_barrier = mat->log_barrier;
}

/* Density per unit volume psi(G) (without h) for the columns g[0], g[1] of G (3-vectors, z = 0 in
 * planar mode). P (if non-NULL): dpsi/dg_c. HG (if non-NULL): Hessian, (2 dim)^2 row-major, the
 * entry G[i][c] having index c*dim + i.
 *
 * With e = (E11, E22, 2E12) and s = C e, a unit change of G[i][c] changes e by
 * v_(0,i) = (g0_i, 0, g1_i), v_(1,i) = (0, g1_i, g0_i), so the Hessian blocks (dim x dim) are
 *   H00 = C11 g0 g0^T + C33 g1 g1^T + s0 I,  H11 = C22 g1 g1^T + C33 g0 g0^T + s1 I,
 *   H01 = C12 g0 g1^T + C33 g1 g0^T + s2 I   (v_a . C v_b plus the geometric term S : e_a^T e_b,
 *   S = [[s0, s2], [s2, s1]] the second Piola-Kirchhoff stress in the barb frame).
 * For J = |n|, n = g0 x g1, n^ = n/J: dJ/dg0 = g1 x n^, dJ/dg1 = n^ x g0 and
 *   d2J = (dn_a . dn_b - dJ_a dJ_b) / J + n^ . (e_i x e_j) [mixed columns only], with
 *   dn_(0,i) . dn_(0,j) = d_ij |g1|^2 - g1_i g1_j,  dn_(1,i) . dn_(1,j) = d_ij |g0|^2 - g0_i g0_j,
 *   dn_(0,i) . dn_(1,j) = g0_i g1_j - d_ij g0.g1.
 * g is read only; it is not const-qualified because C11 does not convert double (*)[3] to
 * const double (*)[3] implicitly. */
static inline double density_G(const mem_mat *m, const int dim, double g[2][3], double P[2][3],
                               double *HG)
{
    const double *g0 = g[0], *g1 = g[1];
    const double c11 = dot3(g0, g0), c22 = dot3(g1, g1), c12 = dot3(g0, g1);
    const double e0 = 0.5 * (c11 - 1.0), e1 = 0.5 * (c22 - 1.0), e2 = c12;
    const double s0 = m->C11 * e0 + m->C12 * e1, s1 = m->C12 * e0 + m->C22 * e1, s2 = m->C33 * e2;
    double psi = 0.5 * (e0 * s0 + e1 * s1 + e2 * s2);

    /* compression term, supplementary eq. 6: psi_c = kappa/12 ((1-J)/6)^3 for J < 1 */
    double n[3], nh[3] = {0.0, 0.0, 0.0}, dJ0[3] = {0.0, 0.0, 0.0}, dJ1[3] = {0.0, 0.0, 0.0};
    cross3(g0, g1, n);
    const double J = sqrt(dot3(n, n));
    const int comp = m->kappa > 0.0 && J < 1.0;
    double dpc = 0.0, ddpc = 0.0;
    if (comp && m->log_barrier) {
        /* log barrier in place of the cubic term: kappa/12 (J - 1 - ln J), C1 at J = 1 */
        const double k12 = m->kappa / 12.0;
        psi += J > 0.0 ? k12 * (J - 1.0 - log(J)) : INFINITY;
        dpc = J > 0.0 ? k12 * (1.0 - 1.0 / J) : -INFINITY;
        ddpc = J > 0.0 ? k12 / (J * J) : INFINITY;
        if (J > 0.0) {
            const double iJ = 1.0 / J;
            for (int k = 0; k < 3; k++)
                nh[k] = n[k] * iJ;
            cross3(g1, nh, dJ0);
            cross3(nh, g0, dJ1);
        }
    } else if (comp) {
        const double t = (1.0 - J) / 6.0;
        psi += m->kappa / 12.0 * t * t * t;
        dpc = -m->kappa * t * t * (1.0 / 24.0); /* d psi_c / dJ */
        ddpc = m->kappa * t * (1.0 / 72.0);     /* d2 psi_c / dJ2 */
        if (J > 0.0) {
            const double iJ = 1.0 / J;
            for (int k = 0; k < 3; k++)
                nh[k] = n[k] * iJ;
            cross3(g1, nh, dJ0);
            cross3(nh, g0, dJ1);
        }
    }

    if (P) {
        /* dpsi/dG = G S, S = [[s0, s2], [s2, s1]], plus psi_c' dJ/dG */
        for (int k = 0; k < 3; k++) {
            P[0][k] = s0 * g0[k] + s2 * g1[k] + dpc * dJ0[k];
            P[1][k] = s2 * g0[k] + s1 * g1[k] + dpc * dJ1[k];
        }
    }

    if (HG) {
        const int k = 2 * dim;
        /* the compression Hessian ddpc dJ dJ^T + dpc d2J regrouped:
         * (ddpc - dpc/J) dJ_a dJ_b + (dpc/J) dn_a . dn_b + dpc n^ . (e_i x e_j) */
        double aJ = 0.0, aN = 0.0, aE = 0.0;
        if (comp) {
            if (J >= MEMBRANE_J_TINY) {
                aN = dpc / J;
                aJ = ddpc - aN;
                aE = dpc;
            } else {
                aJ = ddpc; /* collapsed: the d2J part is dropped */
            }
        }
        for (int i = 0; i < dim; i++) {
            for (int j = 0; j < dim; j++) {
                const double dij = i == j ? 1.0 : 0.0;
                double h00 = m->C11 * g0[i] * g0[j] + m->C33 * g1[i] * g1[j] + s0 * dij;
                double h11 = m->C22 * g1[i] * g1[j] + m->C33 * g0[i] * g0[j] + s1 * dij;
                double h01 = m->C12 * g0[i] * g1[j] + m->C33 * g1[i] * g0[j] + s2 * dij;
                if (comp) {
                    h00 += aJ * dJ0[i] * dJ0[j] + aN * (dij * c22 - g1[i] * g1[j]);
                    h11 += aJ * dJ1[i] * dJ1[j] + aN * (dij * c11 - g0[i] * g0[j]);
                    h01 += aJ * dJ0[i] * dJ1[j] + aN * (g0[i] * g1[j] - dij * c12);
                    if (i != j) { /* n^ . (e_i x e_j) = +-n^_l, l the third axis */
                        const int l = 3 - i - j;
                        h01 += aE * (j == (i + 1) % 3 ? nh[l] : -nh[l]);
                    }
                }
                HG[i * k + j] = h00;
                HG[(dim + i) * k + dim + j] = h11;
                HG[i * k + dim + j] = h01;
                HG[(dim + j) * k + i] = h01;
            }
        }
    }
    return psi;
}

double plume_membrane_density(const plume_membrane_material *mat, int dim, const double *F,
                              const double d[2])
{
    if (!mat || !F || !d || (dim != 2 && dim != 3))
        return NAN;
    mem_mat m;
    mem_mat_set(mat, &m);
    double len = hypot(d[0], d[1]);
    double R[2][2] = {{d[0] / len, -d[1] / len}, {d[1] / len, d[0] / len}};
    double g[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    for (int i = 0; i < dim; i++)
        for (int c = 0; c < 2; c++)
            g[c][i] = F[2 * i] * R[0][c] + F[2 * i + 1] * R[1][c];
    return mat->h * density_G(&m, dim, g, NULL, NULL);
}

plume_status plume_membrane_strain_stress(const plume_membrane_material *mat, int dim, const double *F,
                                          const double d[2], double E[3], double S[3], double *J)
{
    if (!mat || !F || !d || !E || !S || !J || (dim != 2 && dim != 3) || !(hypot(d[0], d[1]) > 0.0))
        return PLUME_EINVAL;
    mem_mat m;
    mem_mat_set(mat, &m);
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
    density_G(&m, dim, g, P, NULL);
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
        double psi =
            density_G(&ctx->mat[tr->mat], dim, g, grad ? P : NULL, hblocks ? HG : NULL);
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
        e[t] = tr->Ah * density_G(&ctx->mat[tr->mat], dim, g, NULL, NULL);
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

plume_status plume_membrane_term_create(const plume_mesh *mesh, int dim,
                                        const plume_membrane_material *mats, int nmat,
                                        plume_term *out, plume_err *err)
{
    plume_status st = PLUME_OK;
    mem_ctx *ctx = NULL;
    if (out)
        memset(out, 0, sizeof *out);
    if (!mesh || !mats || !out)
        return plume_err_set(err, PLUME_EINVAL, "membrane: NULL mesh, materials or output");
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
        mem_mat_set(&mats[i], &ctx->mat[i]);

    for (plume_index t = 0; t < nt; t++) {
        const plume_index *v = mesh->tri + 3 * t;
        for (int l = 0; l < 3; l++) {
            if (v[l] < 0 || v[l] >= mesh->nv) {
                st = plume_err_set(err, PLUME_EINVAL,
                                   "membrane: triangle %ld: vertex id %ld out of range [0, %ld)",
                                   (long)t, (long)v[l], (long)mesh->nv);
                goto cleanup;
            }
            ctx->stencil[3 * t + l] = v[l];
        }
        int mid = mesh->material[t];
        if (mid < 0 || mid >= nmat) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "membrane: triangle %ld: material id %d out of range [0, %d)",
                               (long)t, mid, nmat);
            goto cleanup;
        }
        const double *X0 = mesh->X + 2 * v[0], *X1 = mesh->X + 2 * v[1], *X2 = mesh->X + 2 * v[2];
        double d00 = X1[0] - X0[0], d01 = X2[0] - X0[0]; /* Dm = [X1-X0, X2-X0] */
        double d10 = X1[1] - X0[1], d11 = X2[1] - X0[1];
        double det = d00 * d11 - d01 * d10;
        double area = 0.5 * fabs(det);
        double scale = d00 * d00 + d10 * d10 + d01 * d01 + d11 * d11 +
                       (d01 - d00) * (d01 - d00) + (d11 - d10) * (d11 - d10);
        if (!isfinite(area) || !isfinite(scale) || !(fabs(det) > MEMBRANE_DEGENERATE_REL * scale)) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "membrane: triangle %ld: degenerate reference triangle (area %g)",
                               (long)t, area);
            goto cleanup;
        }
        double dx = mesh->barb_dir[2 * t], dy = mesh->barb_dir[2 * t + 1];
        double len = hypot(dx, dy);
        if (!isfinite(len) || !(len > 0.0)) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "membrane: triangle %ld: barb direction (%g, %g) cannot be "
                               "normalised", (long)t, dx, dy);
            goto cleanup;
        }
        dx /= len;
        dy /= len;
        /* B = Dm^-1 R, R = [d, d_perp], d_perp = (-d_y, d_x) */
        double i00 = d11 / det, i01 = -d01 / det, i10 = -d10 / det, i11 = d00 / det;
        mem_tri *tr = &ctx->tri[t];
        tr->B[0] = i00 * dx + i01 * dy;
        tr->B[1] = -i00 * dy + i01 * dx;
        tr->B[2] = i10 * dx + i11 * dy;
        tr->B[3] = -i10 * dy + i11 * dx;
        tr->Ah = area * mats[mid].h;
        tr->mat = mid;
    }

    out->name = "membrane";
    out->arity = 3;
    out->nstencil = nt;
    out->stencil = ctx->stencil;
    out->eval = membrane_eval;
    out->energies = membrane_energies;
    out->destroy = membrane_destroy;
    out->ctx = ctx;
    return PLUME_OK;

cleanup:
    membrane_destroy(ctx);
    return st;
}
