/* Mesh-independent anisotropic bending from a per-triangle second fundamental form: the 6-vertex
 * shape-operator stencil (DESIGN.md "Bending is a property of the surface, not of the mesh's
 * edges"; issue 8).
 *
 * Why not the hinge. macro/bending.c measures one normal curvature per edge (the dihedral angle)
 * and must guess the direction-dependent stiffness of that one curvature; the guess is exact only
 * when each triangle has an edge along the cylinder axis. It stores 0.66 D_long for the cylinder
 * that bends the barbs on the barb-aligned equilateral rows and +160 % on a right-triangle grid
 * for curvature at 30 degrees to the grid. An orthotropic plate needs the whole curvature tensor
 * (k11, k22, k12) in the barb frame, with the twist, so this term builds that tensor per triangle.
 *
 * Stencil and fit. Triangle T = (x0, x1, x2) (counter-clockwise in X) and three further vertices
 * p1, p2, p3: normally p_k is the vertex across T's edge opposite x_{k-1} (the edge
 * (x_k, x_{k+1}) mod 3) in the neighbouring triangle. In the current shape, with
 * e1 = x1 - x0, e2 = x2 - x0, N = e1 x e2, L = |N|, n = N / L, the heights of the stencil vertices
 * above T's plane are
 *     h_k = n . (p_k - x0) = V_k / L,   V_k = det[e1, e2, q_k],  q_k = p_k - x0.
 * In the flat material space, lambda_0..2 are T's barycentric coordinates (extended linearly), g_i
 * their constant gradients. The quadratics vanishing at T's three vertices are exactly
 * span{lambda_1 lambda_2, lambda_2 lambda_0, lambda_0 lambda_1} (6 quadratic monomials, 3
 * conditions), so the height field w = sum_j c_j q_j with q_j = lambda_{j+1} lambda_{j+2} is fitted
 * through w(P_k) = h_k, P_k the reference position of p_k:
 *     M c = h,  M[k][j] = q_j(P_k)   (M constant per triangle, inverted at create),
 * and the second fundamental form pulled back to material coordinates is the Hessian of w:
 *     II = sum_j c_j (g_{j+1} g_{j+2}^T + g_{j+2} g_{j+1}^T).
 * If the deformed surface is any quadratic map x(X) the height field above T's plane is a
 * quadratic vanishing at T's vertices, the fit reproduces it, and II = n . x_{,ab} exactly,
 * on ANY triangulation: no edge direction, valence or symmetry of the mesh enters. For a smooth
 * surface the cubic remainder costs O(h) per triangle, and the energy error is O(h) at worst
 * (it cancels to O(h^2) where the stencil is nearly symmetric; measured below).
 * In the barb frame (d, d_perp) the curvatures are linear in c, hence in h:
 *     kappa = (k11, k22, k12) = (d^T II d, d_perp^T II d_perp, d^T II d_perp) = Q c = Q M^-1 h = B h,
 * B a constant 3x3 per triangle.
 *
 * Energy. Orthotropic plate (bending.h):
 *     E_T = A/2 (kappa - kappa_rest)^T Dv (kappa - kappa_rest),
 *     Dv = [D_long D_12 0; D_12 D_trans 0; 0 0 4 D_66]  (kappa holds k12, not 2 k12),
 * so a cylinder of curvature k at angle phi to the barbs (II = k c c^T) stores
 * A/2 k^2 (D_long cos^4 + D_trans sin^4 + (2 D_12 + 4 D_66) cos^2 sin^2), the continuum energy.
 * kappa_rest = B h_rest with h_rest the heights in rest_x (0 for a flat rest), so
 *     E_T = 1/2 (h - h_rest)^T K (h - h_rest),  K = A B^T Dv B,
 * and create stores only K (PSD when Dv is) and h_rest per triangle.
 *
 * Derivatives (exact, closed form). With f = K (h - h_rest), dE/dx = sum_k f_k grad h_k. In the
 * variables y = (e1, e2, q_k), grad V = (e2 x q, q x e1, N), grad L = (e2 x n, n x e1, 0), so
 *     grad h = (grad V - h grad L) / L   (= (e2 x q_perp, q_perp x e1, N) / L, q_perp the part of q in
 *     T's plane); the vertices get (x1, x2, p_k) = (e1, e2, q) parts and x0 minus their sum.
 * Second derivatives: V is trilinear, its Hessian has the off-diagonal blocks
 *     V_{e1 e2} = -[q]x, V_{e1 q} = [e2]x, V_{e2 q} = -[e1]x (and transposes);
 * L = |N| with dN/de1 = A1 = -[e2]x, dN/de2 = A2 = [e1]x has
 *     L_{ab} = A_a^T (I - n n^T) A_b / L + C_ab,  C_{e1 e2} = -[n]x = -C_{e2 e1},  C_aa = 0,
 * and differentiating h = V / L twice and substituting grad V = L grad h + h grad L,
 *     Hess h = (Hess V - grad h grad L^T - grad L grad h^T - h Hess L) / L.
 * Hess L does not depend on k, so the three heights share it. The 18x18 block is
 *     J^T K J + sum_k f_k Hess h_k,  J = [grad h_1; grad h_2; grad h_3] (3 x 18),
 * built in the 15 variables (e1, e2, q_1, q_2, q_3) and mapped to the 6 vertices (x0's rows and
 * columns are minus the sums), upper triangle mirrored so that the block is exactly symmetric.
 *
 * PSD treatment. With project != 0 the block is the Gauss-Newton part J^T K J alone: PSD by
 * construction since K is, no eigen-decomposition (an 18x18 Jacobi would cost more than the rest
 * of the evaluation). It drops f_k Hess h_k, which vanishes at the rest shape and is small while
 * the curvature change times the element size is small; the projected Newton still converges
 * to the exact minimiser because the gradient is exact.
 *
 * Boundary triangles. An edge on the boundary has no opposite vertex. Dropping that row of the
 * fit (or the term) leaves a curvature the boundary triangles do not see: an O(h) energy
 * deficit, the hinge's -1/n. Instead the missing p_k is replaced by the vertex of T's 2-ring
 * (3-ring if the 2-ring has no good one) that maximises the conditioning of M, so the fit of
 * every triangle stays exact for quadratics. The measure is the row-normalised determinant
 *     s(M) = |det M| / (|M_1| |M_2| |M_3|)  in [0, 1]
 * (the sine-like volume of the three rows: 1 orthogonal, 0 singular; scale-free, since M holds
 * products of barycentrics), divided by the distance of the farthest stencil vertex from T's
 * centroid in units of T's longest edge, because the cubic remainder of a smooth surface grows
 * with that distance. A complete natural stencil is kept if s >= SHAPE_GOOD_STENCIL; otherwise (the six
 * points near a common conic) all three vertices are chosen anew from the ring. No stencil with
 * s >= SHAPE_MIN_STENCIL: PLUME_EINVAL (a mesh of one or two triangles has none).
 *
 * Why this and not midedge normals. The discrete shape operators of Grinspun et al. 2006
 * ("Computing discrete shape operators on general meshes") and libshell's midedge formulations
 * build II from a normal on each edge. libshell's MidedgeAverage takes the mean of the two face
 * normals: its angle to T depends on the neighbour's shape, so like the hinge it is exact only
 * when T and its neighbour mirror each other and it is not consistent on irregular meshes. The
 * midedge-angle variants (MidedgeAngleSin/Tan/Theta) fix that with an extra unknown per edge (a
 * Morley-type nonconforming element): consistent, but the term interface, the problems and the
 * solvers carry vertex unknowns only, and those extra angles have no mass, no constraint and no
 * meaning for the inextensible barbs. The stencil here uses vertex unknowns only, is exact for
 * quadratic surfaces on every triangulation, and costs one 18x18 block per triangle (the
 * midedge forms have the same 6-vertex support).
 *
 * Collapse. A current triangle with L^2 <= SHAPE_COLLAPSED_REL |e1|^2 |e2|^2 has no normal,
 * hence no heights: eval returns PLUME_EINVAL (the hinge, whose angle stays defined, instead
 * keeps its energy and exerts no force). A solver's line search treats that as a failed step.
 *
 * Measured (tests/test_shape_bending.c, bench/bench_bending.c). A 1 x 0.8 patch bent to k = 1,
 * curvature along material x and at 30 degrees to it, barbs at 0, 30, 45, 90 degrees to the
 * curvature, D_long/D_trans = 2500 and isotropic, on right-triangle grids, the same grid turned
 * 45 degrees, near-equilateral rows along and across the axis, and jittered random Delaunay
 * meshes: the stored energy over the continuum plate's is 0.9942-0.9988 at h = 1/12, 0.9985-0.9997
 * at 1/24 and 0.9996-0.9999 at 1/48, the error falling by about 4 at each halving (O(h^2): the
 * heights are measured from the chord plane, not the tangent plane; the stiff direction's
 * pollution, D_long/D_trans times the squared spurious k11, stays below that). The hinge, given
 * the same continuum (twist D_twist = (D_long + D_trans)/4, which its law assumes), stores
 * 0.66-2.95 of it on the isotropic and barb-along cases and 7.5-4900 times the soft mode when the
 * curvature runs across the barbs on a mesh not aligned with them (bench, h = 1/24). Every
 * triangle's fit is exact for quadratic surfaces, boundary ones included (tested on all five
 * families to 1e-6). Stencil quality s at h = 1/24: 0.77 on the regular lattices' interiors,
 * >= 0.577 on their boundary replacements, >= 0.10 on the Delaunay meshes.
 * Cost at 40k triangles (bench, -O2): create 14-25 ms; energy + gradient + exact blocks 56-60 ms,
 * with the Gauss-Newton blocks 39-42 ms (the hinge: 25 ms exact, 780-940 ms projected by Jacobi
 * at a large bend, where most of its blocks are indefinite).
 *
 * Nothing is allocated after create. */
#include "shape_bending.h"
#include "../lib/internal/vec3.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A reference triangle whose doubled area is below this fraction of its squared edge lengths is
 * degenerate up to rounding (the membrane's and the hinge's test). */
#define SHAPE_DEGENERATE_REL (64.0 * DBL_EPSILON)

/* A current triangle with |N|^2 <= this * |e1|^2 |e2|^2 (sine of its angle at x0 below 1e-14)
 * has collapsed: its normal is undefined. */
#define SHAPE_COLLAPSED_REL 1e-28

/* Row-normalised determinant s(M) (see top) above which a complete natural stencil is kept, and
 * below which no stencil is accepted at all. s is affine-invariant (barycentric coordinates
 * are): every regular lattice, right-triangle or equilateral, has s = 0.77 inside; below 1e-3
 * height errors would be amplified a thousandfold. */
#define SHAPE_GOOD_STENCIL 0.1
#define SHAPE_MIN_STENCIL 1e-3

/* Rings searched for replacement stencil vertices, nearest first. */
#define SHAPE_MAX_RING 3

typedef struct {
    double K[9];  /* A B^T Dv B, symmetric */
    double h0[3]; /* rest heights */
} shape_tri;

typedef struct {
    plume_index nt;
    plume_index *stencil; /* [6*nt] (x0, x1, x2, p1, p2, p3) */
    shape_tri *tri;       /* [nt] */
} shape_ctx;

/* [v]x, the cross-product matrix: [v]x w = v x w */
static void skew(const double v[3], double S[3][3])
{
    S[0][0] = 0.0, S[0][1] = -v[2], S[0][2] = v[1];
    S[1][0] = v[2], S[1][1] = 0.0, S[1][2] = -v[0];
    S[2][0] = -v[1], S[2][1] = v[0], S[2][2] = 0.0;
}

static double det3(double M[3][3])
{
    return M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
           M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
}

/* Geometry of T and its three heights at positions x (3 per vertex) for stencil s. */
typedef struct {
    double e1[3], e2[3], N[3], n[3], q[3][3];
    double L;
    double h[3];
    int collapsed;
} shape_geom;

static void shape_geometry(const double *x, const plume_index *s, shape_geom *G)
{
    const double *x0 = x + 3 * s[0], *x1 = x + 3 * s[1], *x2 = x + 3 * s[2];
    for (int i = 0; i < 3; i++) {
        G->e1[i] = x1[i] - x0[i];
        G->e2[i] = x2[i] - x0[i];
    }
    cross3(G->e1, G->e2, G->N);
    const double L2 = dot3(G->N, G->N);
    G->collapsed = !(L2 > SHAPE_COLLAPSED_REL * dot3(G->e1, G->e1) * dot3(G->e2, G->e2)) || !isfinite(L2);
    G->L = sqrt(L2);
    for (int i = 0; i < 3; i++)
        G->n[i] = G->collapsed ? 0.0 : G->N[i] / G->L;
    for (int k = 0; k < 3; k++) {
        const double *p = x + 3 * s[3 + k];
        for (int i = 0; i < 3; i++)
            G->q[k][i] = p[i] - x0[i];
        G->h[k] = dot3(G->n, G->q[k]);
    }
}

/* The 18x18 block (row-major) J^T K J + [!gn] sum_k f_k Hess h_k; gy[k][b] is grad h_k's part in
 * y-block b (0: e1, 1: e2, 2: q_k). */
static void shape_hessian(const shape_geom *G, const double K[9], const double f[3], double gy[3][3][3],
                          int gauss_newton, double *H)
{
    double Hy[15][15];
    memset(Hy, 0, sizeof Hy);
    /* Gauss-Newton part: y-block index of gy[k][b] is b < 2 ? b : 2 + k */
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++) {
            const double Kkl = K[3 * k + l];
            if (Kkl == 0.0)
                continue;
            for (int a = 0; a < 3; a++) {
                const int A = a < 2 ? a : 2 + k;
                for (int b = 0; b < 3; b++) {
                    const int B = b < 2 ? b : 2 + l;
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++)
                            Hy[3 * A + i][3 * B + j] += Kkl * gy[k][a][i] * gy[l][b][j];
                }
            }
        }
    if (!gauss_newton) {
        const double iL = 1.0 / G->L;
        double gL[2][3];
        cross3(G->e2, G->n, gL[0]);
        cross3(G->n, G->e1, gL[1]);
        /* sum_k (f_k / L) Hess V_k and the grad h grad L^T terms */
        double qs[3] = {0.0, 0.0, 0.0}, S = 0.0;
        double Se1[3][3], Se2[3][3];
        skew(G->e1, Se1);
        skew(G->e2, Se2);
        for (int k = 0; k < 3; k++) {
            const double c = f[k] * iL;
            S += c * G->h[k];
            for (int i = 0; i < 3; i++)
                qs[i] += c * G->q[k][i];
            const int Q = 2 + k;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    Hy[i][3 * Q + j] += c * Se2[i][j];     /* V_{e1 q} = [e2]x */
                    Hy[3 * Q + j][i] += c * Se2[i][j];
                    Hy[3 + i][3 * Q + j] -= c * Se1[i][j]; /* V_{e2 q} = -[e1]x */
                    Hy[3 * Q + j][3 + i] -= c * Se1[i][j];
                }
            for (int a = 0; a < 3; a++) {
                const int A = a < 2 ? a : Q;
                for (int b = 0; b < 2; b++)
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++) {
                            const double v = c * gy[k][a][i] * gL[b][j];
                            Hy[3 * A + i][3 * b + j] -= v;
                            Hy[3 * b + j][3 * A + i] -= v;
                        }
            }
        }
        double Sq[3][3];
        skew(qs, Sq);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                Hy[i][3 + j] -= Sq[i][j]; /* V_{e1 e2} = -[q]x */
                Hy[3 + j][i] -= Sq[i][j];
            }
        /* - S Hess L, S = sum_k f_k h_k / L */
        if (S != 0.0) {
            double A[2][3][3], PA[2][3][3], Sn[3][3];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    A[0][i][j] = -Se2[i][j];
                    A[1][i][j] = Se1[i][j];
                }
            for (int a = 0; a < 2; a++)
                for (int j = 0; j < 3; j++) {
                    const double nA = G->n[0] * A[a][0][j] + G->n[1] * A[a][1][j] + G->n[2] * A[a][2][j];
                    for (int i = 0; i < 3; i++)
                        PA[a][i][j] = A[a][i][j] - G->n[i] * nA;
                }
            skew(G->n, Sn);
            for (int a = 0; a < 2; a++)
                for (int b = 0; b < 2; b++)
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++) {
                            /* (A_a^T P A_b)_{ij} = sum_m A_a[m][i] (P A_b)[m][j] (P^2 = P) */
                            double v = (A[a][0][i] * PA[b][0][j] + A[a][1][i] * PA[b][1][j] +
                                        A[a][2][i] * PA[b][2][j]) * iL;
                            if (a == 0 && b == 1)
                                v -= Sn[i][j];
                            else if (a == 1 && b == 0)
                                v += Sn[i][j];
                            Hy[3 * a + i][3 * b + j] -= S * v;
                        }
        }
    }
    /* exactly symmetric */
    for (int r = 0; r < 15; r++)
        for (int c = r + 1; c < 15; c++)
            Hy[r][c] = Hy[c][r] = 0.5 * (Hy[r][c] + Hy[c][r]);
    /* vertices (x0, x1, x2, p1, p2, p3): x_u for u >= 1 is y-block u - 1; x0 is minus the sum */
    /* R[i][c] = -sum_B Hy[3B + i][c]: x0's row i against y column c */
    double R[3][15];
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 15; c++) {
            double s = 0.0;
            for (int B = 0; B < 5; B++)
                s += Hy[3 * B + i][c];
            R[i][c] = -s;
        }
    for (int r = 0; r < 15; r++)
        for (int c = 0; c < 15; c++)
            H[(3 + r) * 18 + 3 + c] = Hy[r][c];
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 15; c++)
            H[i * 18 + 3 + c] = H[(3 + c) * 18 + i] = R[i][c];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int B = 0; B < 5; B++)
                s += R[i][3 * B + j];
            H[i * 18 + j] = -s;
        }
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            H[i * 18 + j] = H[j * 18 + i] = 0.5 * (H[i * 18 + j] + H[j * 18 + i]);
}

static plume_status shape_eval(void *vctx, int dim, const double *x, double *energy, double *grad,
                               double *hblocks, int project)
{
    const shape_ctx *ctx = vctx;
    if (!ctx || !x || dim != 3)
        return PLUME_EINVAL;
    double E = 0.0;
    for (plume_index t = 0; t < ctx->nt; t++) {
        const plume_index *s = ctx->stencil + 6 * t;
        const shape_tri *T = &ctx->tri[t];
        shape_geom G;
        shape_geometry(x, s, &G);
        if (G.collapsed)
            return PLUME_EINVAL;
        double dh[3], f[3];
        for (int k = 0; k < 3; k++)
            dh[k] = G.h[k] - T->h0[k];
        for (int k = 0; k < 3; k++)
            f[k] = T->K[3 * k] * dh[0] + T->K[3 * k + 1] * dh[1] + T->K[3 * k + 2] * dh[2];
        E += 0.5 * (f[0] * dh[0] + f[1] * dh[1] + f[2] * dh[2]);
        if (!grad && !hblocks)
            continue;
        /* grad h_k in y = (e1, e2, q_k): (grad V - h grad L) / L */
        const double iL = 1.0 / G.L;
        double gL[2][3], gy[3][3][3];
        cross3(G.e2, G.n, gL[0]);
        cross3(G.n, G.e1, gL[1]);
        for (int k = 0; k < 3; k++) {
            double a[3], b[3];
            cross3(G.e2, G.q[k], a);
            cross3(G.q[k], G.e1, b);
            for (int i = 0; i < 3; i++) {
                gy[k][0][i] = (a[i] - G.h[k] * gL[0][i]) * iL;
                gy[k][1][i] = (b[i] - G.h[k] * gL[1][i]) * iL;
                gy[k][2][i] = G.n[i];
            }
        }
        if (grad) {
            for (int i = 0; i < 3; i++) {
                double g1 = 0.0, g2 = 0.0;
                for (int k = 0; k < 3; k++) {
                    g1 += f[k] * gy[k][0][i];
                    g2 += f[k] * gy[k][1][i];
                    const double gp = f[k] * gy[k][2][i];
                    grad[3 * s[3 + k] + i] += gp;
                    grad[3 * s[0] + i] -= gp;
                }
                grad[3 * s[1] + i] += g1;
                grad[3 * s[2] + i] += g2;
                grad[3 * s[0] + i] -= g1 + g2;
            }
        }
        if (hblocks)
            shape_hessian(&G, T->K, f, gy, project != 0, hblocks + (size_t)t * 324);
    }
    if (energy)
        *energy += E;
    return PLUME_OK;
}

static void shape_destroy(void *vctx)
{
    shape_ctx *ctx = vctx;
    if (!ctx)
        return;
    free(ctx->stencil);
    free(ctx->tri);
    free(ctx);
}

static int stiffness_ok(double D)
{
    return isfinite(D) && D >= 0.0;
}

/* Reference data of one triangle: barycentric gradients g[3][2] and the map
 * X -> (lambda_0, lambda_1, lambda_2). */
typedef struct {
    double X0[2], g[3][2];
    double det; /* 2 A, signed */
} ref_tri;

static void barycentric(const ref_tri *R, const double *P, double lam[3])
{
    const double dx = P[0] - R->X0[0], dy = P[1] - R->X0[1];
    lam[1] = R->g[1][0] * dx + R->g[1][1] * dy;
    lam[2] = R->g[2][0] * dx + R->g[2][1] * dy;
    lam[0] = 1.0 - lam[1] - lam[2];
}

/* Row k of M: (q_0, q_1, q_2)(P), q_j = lambda_{j+1} lambda_{j+2} */
static void fit_row(const ref_tri *R, const double *P, double row[3])
{
    double l[3];
    barycentric(R, P, l);
    row[0] = l[1] * l[2];
    row[1] = l[2] * l[0];
    row[2] = l[0] * l[1];
}

/* s(M) (see top) */
static double stencil_quality(double M[3][3])
{
    const double r0 = sqrt(M[0][0] * M[0][0] + M[0][1] * M[0][1] + M[0][2] * M[0][2]);
    const double r1 = sqrt(M[1][0] * M[1][0] + M[1][1] * M[1][1] + M[1][2] * M[1][2]);
    const double r2 = sqrt(M[2][0] * M[2][0] + M[2][1] * M[2][1] + M[2][2] * M[2][2]);
    const double den = r0 * r1 * r2;
    return den > 0.0 && isfinite(den) ? fabs(det3(M)) / den : 0.0;
}

/* Workspace of the stencil search (allocated once per create). */
typedef struct {
    plume_index *vstart, *vtri; /* vertex -> triangles CSR */
    plume_index *mark;          /* [nv] stamp of the last search that saw the vertex */
    plume_index *ring;          /* candidate vertices */
    plume_index cap, nring;
    plume_index stamp;
} search_ws;

static int ring_push(search_ws *W, plume_index v)
{
    if (W->mark[v] == W->stamp)
        return 1;
    W->mark[v] = W->stamp;
    if (W->nring == W->cap) {
        const plume_index cap = 2 * W->cap + 16;
        plume_index *r = realloc(W->ring, (size_t)cap * sizeof *r);
        if (!r)
            return 0;
        W->ring = r;
        W->cap = cap;
    }
    W->ring[W->nring++] = v;
    return 1;
}

/* Grows W->ring (which starts with T's vertices) by one ring: every vertex of a triangle incident
 * to a vertex already in it. Returns 0 on allocation failure. */
static int ring_grow(search_ws *W, const plume_mesh *m)
{
    const plume_index n0 = W->nring;
    for (plume_index r = 0; r < n0; r++) {
        const plume_index v = W->ring[r];
        for (plume_index s = W->vstart[v]; s < W->vstart[v + 1]; s++)
            for (int k = 0; k < 3; k++)
                if (!ring_push(W, m->tri[3 * W->vtri[s] + k]))
                    return 0;
    }
    return 1;
}

/* Score of a stencil: s(M) over the farthest vertex's distance to T's centroid in T's longest
 * edges (>= some positive constant). *quality gets s(M). */
static double stencil_score(const ref_tri *R, const plume_mesh *m, const plume_index p[3], const double cen[2],
                            double edge, double *quality)
{
    double M[3][3], far = 0.0;
    for (int k = 0; k < 3; k++) {
        const double *P = m->X + 2 * p[k];
        fit_row(R, P, M[k]);
        far = fmax(far, hypot(P[0] - cen[0], P[1] - cen[1]) / edge);
    }
    *quality = stencil_quality(M);
    return *quality / fmax(far, 1e-300);
}

/* Chooses p[3] for triangle t (natural opposite vertices in p, -1 where the edge is on the
 * boundary). Returns the chosen stencil's s(M) (0 if none was found), or -1 on allocation failure. */
static double choose_stencil(const plume_mesh *m, plume_index t, const ref_tri *R, search_ws *W, plume_index p[3])
{
    const plume_index *tv = m->tri + 3 * t;
    double cen[2] = {0.0, 0.0}, edge = 0.0;
    for (int k = 0; k < 3; k++) {
        const double *A = m->X + 2 * tv[k], *B = m->X + 2 * tv[(k + 1) % 3];
        cen[0] += A[0] / 3.0;
        cen[1] += A[1] / 3.0;
        edge = fmax(edge, hypot(B[0] - A[0], B[1] - A[1]));
    }
    int nmiss = 0, miss[3];
    for (int k = 0; k < 3; k++)
        if (p[k] < 0)
            miss[nmiss++] = k;
    double q = 0.0;
    if (nmiss == 0) {
        stencil_score(R, m, p, cen, edge, &q);
        if (q >= SHAPE_GOOD_STENCIL)
            return q;
    }
    const plume_index nat[3] = {p[0], p[1], p[2]};
    double best = -1.0, bestq = 0.0;
    plume_index bp[3] = {-1, -1, -1};
    W->stamp++;
    W->nring = 0;
    for (int k = 0; k < 3; k++)
        if (!ring_push(W, tv[k]))
            return -1.0;
    for (int ring = 1; ring <= SHAPE_MAX_RING; ring++) {
        if (!ring_grow(W, m))
            return -1.0;
        /* candidates: the ring without T's vertices (ring[0..2]) */
        const plume_index *C = W->ring + 3;
        const plume_index nc = W->nring - 3;
        for (int full = 0; full < 2; full++) {
            /* first only the missing slots (natural vertices kept), then all three anew */
            if (full == 0 && nmiss == 0)
                continue;
            if (full == 1 && bestq >= SHAPE_GOOD_STENCIL)
                break;
            const int ns = full ? 3 : nmiss;
            int slot[3];
            for (int k = 0; k < ns; k++)
                slot[k] = full ? k : miss[k];
            /* combinations i0 < i1 < i2 of candidates for the ns slots */
            plume_index idx[3] = {0, 1, 2};
            if (nc < ns)
                continue;
            for (;;) {
                plume_index c[3] = {nat[0], nat[1], nat[2]};
                int ok = 1;
                for (int k = 0; k < ns; k++)
                    c[slot[k]] = C[idx[k]];
                if (!full)
                    for (int k = 0; k < ns; k++)
                        for (int j = 0; j < 3; j++)
                            if (j != slot[k] && c[j] == c[slot[k]])
                                ok = 0;
                if (ok) {
                    double qq;
                    const double sc = stencil_score(R, m, c, cen, edge, &qq);
                    if (qq >= SHAPE_MIN_STENCIL && sc > best) {
                        best = sc;
                        bestq = qq;
                        memcpy(bp, c, sizeof bp);
                    }
                }
                /* next combination */
                int k = ns - 1;
                while (k >= 0 && idx[k] == nc - ns + k)
                    k--;
                if (k < 0)
                    break;
                idx[k]++;
                for (int j = k + 1; j < ns; j++)
                    idx[j] = idx[j - 1] + 1;
            }
        }
        if (bestq >= SHAPE_GOOD_STENCIL)
            break;
    }
    if (bp[0] < 0)
        return 0.0;
    memcpy(p, bp, sizeof bp);
    return bestq;
}

/* 3x3 inverse by the adjugate; returns 0 if singular */
static int inv3(double M[3][3], double I[3][3])
{
    const double d = det3(M);
    if (!(fabs(d) > 0.0) || !isfinite(d))
        return 0;
    I[0][0] = (M[1][1] * M[2][2] - M[1][2] * M[2][1]) / d;
    I[0][1] = (M[0][2] * M[2][1] - M[0][1] * M[2][2]) / d;
    I[0][2] = (M[0][1] * M[1][2] - M[0][2] * M[1][1]) / d;
    I[1][0] = (M[1][2] * M[2][0] - M[1][0] * M[2][2]) / d;
    I[1][1] = (M[0][0] * M[2][2] - M[0][2] * M[2][0]) / d;
    I[1][2] = (M[0][2] * M[1][0] - M[0][0] * M[1][2]) / d;
    I[2][0] = (M[1][0] * M[2][1] - M[1][1] * M[2][0]) / d;
    I[2][1] = (M[0][1] * M[2][0] - M[0][0] * M[2][1]) / d;
    I[2][2] = (M[0][0] * M[1][1] - M[0][1] * M[1][0]) / d;
    return 1;
}

plume_status plume_shape_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                             const double *rest_x, plume_term *out, plume_err *err)
{
    plume_status st = PLUME_OK;
    shape_ctx *ctx = NULL;
    search_ws W;
    memset(&W, 0, sizeof W);
    if (out)
        memset(out, 0, sizeof *out);
    if (!mesh || !mats || !out)
        return plume_err_set(err, PLUME_EINVAL, "shape bending: NULL mesh, materials or output");
    if (mesh->dim != 3)
        return plume_err_set(err, PLUME_EINVAL,
                             "shape bending: the mesh must be in shell mode (dim 3), got dim %d", mesh->dim);
    if (nmat < 1)
        return plume_err_set(err, PLUME_EINVAL, "shape bending: nmat must be >= 1 (got %d)", nmat);
    if (mesh->nv < 0 || mesh->nt < 0 ||
        (mesh->nt > 0 && (!mesh->X || !mesh->tri || !mesh->barb_dir || !mesh->material)))
        return plume_err_set(err, PLUME_EINVAL, "shape bending: mesh arrays missing or sizes negative");
    if (mesh->nt > 0 && (!mesh->edges || !mesh->edge_tri))
        return plume_err_set(err, PLUME_EINVAL,
                             "shape bending: mesh topology not built (call plume_mesh_build_topology)");
    for (int i = 0; i < nmat; i++) {
        const plume_bending_material *b = &mats[i];
        const char *names[4] = {"D_long", "D_trans", "D_twist", "D_coupling"};
        const double vals[4] = {b->D_long, b->D_trans, b->D_twist, b->D_coupling};
        for (int f = 0; f < 4; f++)
            if (!stiffness_ok(vals[f]))
                return plume_err_set(err, PLUME_EINVAL,
                                     "shape bending: material %d: %s must be finite and >= 0 (got %g)", i,
                                     names[f], vals[f]);
        if (b->D_coupling * b->D_coupling > b->D_long * b->D_trans * (1.0 + 1e-12))
            return plume_err_set(err, PLUME_EINVAL,
                                 "shape bending: material %d: D_coupling (%g) must not exceed sqrt(D_long D_trans) "
                                 "(%g): the plate would not be positive semidefinite",
                                 i, b->D_coupling, sqrt(b->D_long * b->D_trans));
    }
    for (plume_index t = 0; t < mesh->nt; t++) {
        if (mesh->material[t] < 0 || mesh->material[t] >= nmat)
            return plume_err_set(err, PLUME_EINVAL,
                                 "shape bending: triangle %ld: material id %d out of range [0, %d)", (long)t,
                                 mesh->material[t], nmat);
        for (int k = 0; k < 3; k++)
            if (mesh->tri[3 * t + k] < 0 || mesh->tri[3 * t + k] >= mesh->nv)
                return plume_err_set(err, PLUME_EINVAL,
                                     "shape bending: triangle %ld: vertex id %ld out of range [0, %ld)", (long)t,
                                     (long)mesh->tri[3 * t + k], (long)mesh->nv);
        const double dx = mesh->barb_dir[2 * t], dy = mesh->barb_dir[2 * t + 1];
        const double len = hypot(dx, dy);
        if (!isfinite(len) || !(len > 0.0))
            return plume_err_set(err, PLUME_EINVAL,
                                 "shape bending: triangle %ld: barb direction (%g, %g) cannot be normalised",
                                 (long)t, dx, dy);
    }
    if (rest_x)
        for (plume_index i = 0; i < 3 * mesh->nv; i++)
            if (!isfinite(rest_x[i]))
                return plume_err_set(err, PLUME_EINVAL,
                                     "shape bending: rest_x[%ld] (vertex %ld) is not finite (%g)", (long)i,
                                     (long)(i / 3), rest_x[i]);

    const plume_index nv = mesh->nv, nt = mesh->nt;
    ctx = calloc(1, sizeof *ctx);
    W.vstart = calloc((size_t)(nv + 2), sizeof *W.vstart);
    W.vtri = malloc((size_t)(3 * nt + 1) * sizeof *W.vtri);
    W.mark = malloc((size_t)(nv + 1) * sizeof *W.mark);
    if (!ctx || !W.vstart || !W.vtri || !W.mark) {
        st = plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
        goto cleanup;
    }
    for (plume_index v = 0; v < nv; v++)
        W.mark[v] = -1;
    ctx->nt = nt;
    ctx->stencil = malloc((size_t)(6 * nt + 1) * sizeof *ctx->stencil);
    ctx->tri = malloc((size_t)(nt + 1) * sizeof *ctx->tri);
    if (!ctx->stencil || !ctx->tri) {
        st = plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
        goto cleanup;
    }
    /* vertex -> triangles (CSR) */
    for (plume_index t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            W.vstart[mesh->tri[3 * t + k] + 2]++;
    for (plume_index v = 0; v < nv; v++)
        W.vstart[v + 2] += W.vstart[v + 1];
    for (plume_index t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            W.vtri[W.vstart[mesh->tri[3 * t + k] + 1]++] = t;

    for (plume_index t = 0; t < nt; t++) {
        const plume_index *tv = mesh->tri + 3 * t;
        const plume_bending_material *mat = &mats[mesh->material[t]];
        /* reference triangle */
        ref_tri R;
        const double *X0 = mesh->X + 2 * tv[0], *X1 = mesh->X + 2 * tv[1], *X2 = mesh->X + 2 * tv[2];
        const double ax = X1[0] - X0[0], ay = X1[1] - X0[1], bx = X2[0] - X0[0], by = X2[1] - X0[1];
        R.X0[0] = X0[0];
        R.X0[1] = X0[1];
        R.det = ax * by - ay * bx;
        const double scl = ax * ax + ay * ay + bx * bx + by * by + (bx - ax) * (bx - ax) + (by - ay) * (by - ay);
        if (!isfinite(R.det) || !(fabs(R.det) > SHAPE_DEGENERATE_REL * scl)) {
            st = plume_err_set(err, PLUME_EINVAL, "shape bending: triangle %ld: degenerate reference triangle (area %g)",
                               (long)t, 0.5 * R.det);
            goto cleanup;
        }
        /* lambda_1 = cross(X - X0, b) / det, lambda_2 = cross(a, X - X0) / det */
        R.g[1][0] = by / R.det;
        R.g[1][1] = -bx / R.det;
        R.g[2][0] = -ay / R.det;
        R.g[2][1] = ax / R.det;
        R.g[0][0] = -R.g[1][0] - R.g[2][0];
        R.g[0][1] = -R.g[1][1] - R.g[2][1];

        /* natural stencil: p_k across the edge (tv[k+1], tv[k+2]) */
        plume_index p[3];
        for (int k = 0; k < 3; k++) {
            const plume_index a = tv[(k + 1) % 3], b = tv[(k + 2) % 3];
            p[k] = -1;
            for (plume_index s = W.vstart[a]; s < W.vstart[a + 1]; s++) {
                const plume_index u = W.vtri[s];
                if (u == t)
                    continue;
                const plume_index *uv = mesh->tri + 3 * u;
                int hasb = 0;
                for (int j = 0; j < 3; j++)
                    hasb |= uv[j] == b;
                if (!hasb)
                    continue;
                for (int j = 0; j < 3; j++)
                    if (uv[j] != a && uv[j] != b)
                        p[k] = uv[j];
            }
        }
        const double q = choose_stencil(mesh, t, &R, &W, p);
        if (q < 0.0) {
            st = plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
            goto cleanup;
        }
        if (!(q >= SHAPE_MIN_STENCIL)) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "shape bending: triangle %ld: no well-conditioned 6-vertex stencil in its %d-ring "
                               "(the mesh has too few vertices around it for a quadratic fit)",
                               (long)t, SHAPE_MAX_RING);
            goto cleanup;
        }
        plume_index *sv = ctx->stencil + 6 * t;
        for (int k = 0; k < 3; k++) {
            sv[k] = tv[k];
            sv[3 + k] = p[k];
        }
        /* M, its inverse, Q (c -> kappa in the barb frame), B = Q M^-1, K = A B^T Dv B */
        double M[3][3], Mi[3][3], Q[3][3], B[3][3];
        for (int k = 0; k < 3; k++)
            fit_row(&R, mesh->X + 2 * p[k], M[k]);
        if (!inv3(M, Mi)) {
            st = plume_err_set(err, PLUME_EINVAL, "shape bending: triangle %ld: singular stencil", (long)t);
            goto cleanup;
        }
        const double dl = hypot(mesh->barb_dir[2 * t], mesh->barb_dir[2 * t + 1]);
        const double d[2] = {mesh->barb_dir[2 * t] / dl, mesh->barb_dir[2 * t + 1] / dl};
        const double dp[2] = {-d[1], d[0]};
        double gd[3], gp[3];
        for (int i = 0; i < 3; i++) {
            gd[i] = R.g[i][0] * d[0] + R.g[i][1] * d[1];
            gp[i] = R.g[i][0] * dp[0] + R.g[i][1] * dp[1];
        }
        for (int j = 0; j < 3; j++) {
            const int i = (j + 1) % 3, l = (j + 2) % 3;
            Q[0][j] = 2.0 * gd[i] * gd[l];
            Q[1][j] = 2.0 * gp[i] * gp[l];
            Q[2][j] = gd[i] * gp[l] + gd[l] * gp[i];
        }
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                B[r][c] = Q[r][0] * Mi[0][c] + Q[r][1] * Mi[1][c] + Q[r][2] * Mi[2][c];
        const double D66 = mat->D_twist > 0.0 ? mat->D_twist
                                              : fmax(0.0, 0.5 * (sqrt(mat->D_long * mat->D_trans) - mat->D_coupling));
        const double Dv[3][3] = {{mat->D_long, mat->D_coupling, 0.0}, {mat->D_coupling, mat->D_trans, 0.0},
                                 {0.0, 0.0, 4.0 * D66}};
        const double A = 0.5 * fabs(R.det);
        shape_tri *T = &ctx->tri[t];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double s = 0.0;
                for (int r = 0; r < 3; r++)
                    for (int c = 0; c < 3; c++)
                        s += B[r][a] * Dv[r][c] * B[c][b];
                T->K[3 * a + b] = A * s;
            }
        for (int a = 0; a < 3; a++)
            for (int b = a + 1; b < 3; b++)
                T->K[3 * a + b] = T->K[3 * b + a] = 0.5 * (T->K[3 * a + b] + T->K[3 * b + a]);
        T->h0[0] = T->h0[1] = T->h0[2] = 0.0;
        if (rest_x) {
            shape_geom G;
            shape_geometry(rest_x, sv, &G);
            if (G.collapsed) {
                st = plume_err_set(err, PLUME_EINVAL, "shape bending: triangle %ld is degenerate in rest_x", (long)t);
                goto cleanup;
            }
            memcpy(T->h0, G.h, sizeof T->h0);
        }
    }

    out->name = "shape bending";
    out->arity = 6;
    out->nstencil = nt;
    out->stencil = ctx->stencil;
    out->eval = shape_eval;
    out->destroy = shape_destroy;
    out->ctx = ctx;
    ctx = NULL;

cleanup:
    shape_destroy(ctx);
    free(W.vstart);
    free(W.vtri);
    free(W.mark);
    free(W.ring);
    return st;
}
