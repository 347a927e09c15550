/* Mesh-independent anisotropic bending from a per-triangle second fundamental form: the 6-vertex
 * shape-operator fit with slopes shared across edges (docs/design.md "Bending is a property of the
 * surface, not of the mesh's edges").
 *
 * Why not the hinge. macro/shell/bending.c measures one normal curvature per edge (the dihedral angle)
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
 *
 * Shared edge slopes: the patch test. A fit exact for quadratics in every triangle is not enough
 * for the equilibria to converge. For the linear plate, a constant curvature is the exact
 * solution of pure bending, and the discrete equilibrium holds there only if the discrete total
 * curvature sum_T A_T II_T(w) depends on boundary values alone (a discrete divergence theorem);
 * otherwise interior vertices feel forces of the order of the boundary moments and the solution
 * converges to a wrong answer. The own fit alone fails this on irregular meshes: on random
 * Delaunay meshes the interior forces are 0.64 of the boundary ones, and the elastica converges
 * to a tip 2.3 % too far whatever the mesh size (regular grids pass by symmetry). Hence II is
 * written through the divergence theorem on T,
 *     A II = integral over dT of grad w (x) n_out = sum_e l_e beta_e N_e N_e^T,
 * exact for the fitted quadratic (the tangential part of grad w integrates to zero along each
 * edge, and the normal slope is linear along it: the midpoint rule is exact), with beta_e the
 * slope of the surface across edge e at its midpoint, along the outward normal N_e, above T's
 * plane. beta_e is then taken as the mean of the two estimates of that slope: T's own fit, and
 * the neighbour's fit (its quadratic through its own vertices and its three points, in T's frame:
 * heights above T's plane, so no angle between the planes enters). Both are exact for quadratics,
 * so II still is; and the two triangles now use the same surface gradient at the edge midpoint,
 * so the total curvature telescopes to the boundary and the patch test passes to rounding
 * (tests/test_shape_bending.c, the patch test, on all five families). A boundary edge keeps
 * T's own slope. The only kernel is the linear functions (beta = 0 on every edge forces the
 * piecewise linear interpolant to have a continuous gradient). The cost: a triangle's energy
 * depends on its own points and its neighbours' (typically 12 vertices instead of 6).
 * In the barb frame (d, d_perp) the curvatures are linear in the slopes, hence in the heights h of
 * all these points above T's plane:
 *     kappa = (k11, k22, k12) = (d^T II d, d_perp^T II d_perp, d^T II d_perp) = B h,
 * B a constant 3 x n per triangle (n the number of points beyond T's vertices).
 *
 * Clamped edges. A boundary edge whose vertices a clamp holds has no neighbour, but the surface
 * must leave it with zero slope. The missing p_k is then the mirror image of T's own vertex x_k
 * through the plane that holds the edge and the rest normal: g = x_k - 2 m (m . (x_k - x_a)), m the
 * fixed unit normal of that plane. Every quadratic that meets the clamp with zero slope is even
 * about the edge, so the fit stays exact for it; g is affine in x_k and x_a, and the chain rule
 * through it is exact (the points' gradient and block map onto the vertices through
 * (I - 2 m m^T, 2 m m^T)). The second-row clamp (the row next to the clamp keeps its rest height)
 * instead bends the strip from half an element in: an error 3 h / (2 L) in a cantilever's tip.
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
 * Derivatives (exact, closed form). With f = K (h - h_rest), dE/dx = sum_k f_k grad h_k (k over
 * the n points). In the variables y = (e1, e2, q_k), grad V = (e2 x q, q x e1, N), grad L = (e2 x n, n x e1, 0), so
 *     grad h = (grad V - h grad L) / L   (= (e2 x q_perp, q_perp x e1, N) / L, q_perp the part of q in
 *     T's plane); the vertices get (x1, x2, p_k) = (e1, e2, q) parts and x0 minus their sum.
 * Second derivatives: V is trilinear, its Hessian has the off-diagonal blocks
 *     V_{e1 e2} = -[q]x, V_{e1 q} = [e2]x, V_{e2 q} = -[e1]x (and transposes);
 * L = |N| with dN/de1 = A1 = -[e2]x, dN/de2 = A2 = [e1]x has
 *     L_{ab} = A_a^T (I - n n^T) A_b / L + C_ab,  C_{e1 e2} = -[n]x = -C_{e2 e1},  C_aa = 0,
 * and differentiating h = V / L twice and substituting grad V = L grad h + h grad L,
 *     Hess h = (Hess V - grad h grad L^T - grad L grad h^T - h Hess L) / L.
 * Hess L does not depend on k, so the heights share it. The block is
 *     J^T K J + sum_k f_k Hess h_k,  J = [grad h_1; ...; grad h_n],
 * built on the n + 3 points directly, its upper triangle only, then mirrored (exactly symmetric):
 * J's row k is nonzero on T's vertices and on p_k alone (where it is n), so J^T K J is three
 * n x 3 products with K and outer products with n; the curvature part, written in the variables
 * (e1, e2, q_1..q_n), has no (q_k, q_l) blocks and goes to the points through x0's rows and
 * columns being minus the sums (shape_hessian_points). Mirrored points then go to the vertices
 * through the mirror maps.
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
 * points near a common conic) all three vertices are chosen anew from the ring. A ring of more
 * than SHAPE_MAX_CANDIDATES vertices (a fan round one vertex) offers that many, spread round T,
 * since every triple is tried. No stencil with
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
 * Cost at 40k triangles, against the hinge (whose blocks, projected by Jacobi at a large bend where
 * most are indefinite, cost 25 times its exact ones): docs/benchmarks.md, "Bending term".
 *
 * Nothing is allocated after create. */
#include "shape_bending.h"
#include "internal/shape_stencil.h"
#include "../../lib/core/vec3.h"

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

/* Room for the points of a triangle: its 3 vertices and 3 own points, and from each of three
 * neighbours at most its opposite vertex and its 3 points: 18 (slots never outnumber points). */
#define SHAPE_MAX_POINTS 24


/* A point of a triangle's stencil: a vertex (a slot of the triangle's vertex list) or, on a
 * clamped edge, the mirror image of one, x_src - 2 m (m . (x_src - x_anchor)). */
typedef struct {
    int src;     /* slot of the vertex */
    int anchor;  /* -1, or the slot of a vertex on the mirror plane */
    double m[3]; /* unit normal of the mirror plane (anchor >= 0) */
} shape_point;

/* Per triangle: its vertex slots are ctx->stencil[arity t .. + nslot) (the row is padded with
 * its first vertex, whose padded blocks stay zero); its points ctx->pts[pt .. + npt), the first
 * three its own vertices; the energy 1/2 (h - h0)^T K (h - h0) over the heights h of points
 * 3..npt-1 above the triangle's plane, K (n x n, n = npt - 3) and h0 at ctx->dbl + kh. */
typedef struct {
    int nslot, npt;
    int plain; /* no mirrored point: point j is slot j */
    size_t pt, kh;
} shape_tri;

typedef struct {
    plume_index nt;
    int arity, maxpt;
    plume_index *stencil; /* [arity nt] */
    shape_tri *tri;       /* [nt] */
    shape_point *pts;
    double *dbl;
    double *work; /* eval scratch, sized for maxpt and arity at create */
} shape_ctx;

/* [v]x, the cross-product matrix: [v]x w = v x w */
static void skew(const double v[3], double S[3][3])
{
    S[0][0] = 0.0, S[0][1] = -v[2], S[0][2] = v[1];
    S[1][0] = v[2], S[1][1] = 0.0, S[1][2] = -v[0];
    S[2][0] = -v[1], S[2][1] = v[0], S[2][2] = 0.0;
}

/* Positions of the points of triangle t (3 per point) from positions x (3 per vertex). */
static void gather_points(const shape_ctx *ctx, plume_index t, const double *x, double *xv)
{
    const shape_tri *T = &ctx->tri[t];
    const plume_index *s = ctx->stencil + (size_t)ctx->arity * t;
    const shape_point *P = ctx->pts + T->pt;
    for (int j = 0; j < T->npt; j++) {
        const double *p = x + 3 * s[P[j].src];
        double *o = xv + 3 * j;
        memcpy(o, p, 3 * sizeof *o);
        if (P[j].anchor < 0)
            continue;
        const double *a = x + 3 * s[P[j].anchor], *m = P[j].m;
        const double d = m[0] * (p[0] - a[0]) + m[1] * (p[1] - a[1]) + m[2] * (p[2] - a[2]);
        for (int i = 0; i < 3; i++)
            o[i] -= 2.0 * d * m[i];
    }
}

/* Geometry of T (its points at xv) and the heights h[j] of points j = 3..npt-1 above its plane
 * (h[0..2] = 0). Returns 0 if T has collapsed. */
typedef struct {
    double e1[3], e2[3], N[3], n[3];
    double L;
} shape_geom;

static int shape_geometry(const double *xv, int npt, shape_geom *G, double *h)
{
    for (int i = 0; i < 3; i++) {
        G->e1[i] = xv[3 + i] - xv[i];
        G->e2[i] = xv[6 + i] - xv[i];
    }
    cross3(G->e1, G->e2, G->N);
    const double L2 = dot3(G->N, G->N);
    if (!(L2 > SHAPE_COLLAPSED_REL * dot3(G->e1, G->e1) * dot3(G->e2, G->e2)) || !isfinite(L2))
        return 0;
    G->L = sqrt(L2);
    for (int i = 0; i < 3; i++)
        G->n[i] = G->N[i] / G->L;
    h[0] = h[1] = h[2] = 0.0;
    for (int j = 3; j < npt; j++) {
        const double q[3] = {xv[3 * j] - xv[0], xv[3 * j + 1] - xv[1], xv[3 * j + 2] - xv[2]};
        h[j] = dot3(G->n, q);
    }
    return 1;
}

/* The Hessian in the points, J^T K J + [!gauss_newton] sum_k f_k Hess h_k, written to Hv (3 npt x
 * 3 npt, row stride ld, exactly symmetric). gy[9 j ..] holds grad h_j's parts on e1, e2 and q_j (the
 * last is n); f[k] = (K dh)_k; K is n x n over points 3..npt-1.
 * Gauss-Newton part: grad h_k on the points is (c_k, a_k, b_k) on T's vertices (a_k, b_k its e1
 * and e2 parts, c_k = -(a_k + b_k + n)) and n on p_k alone, so with U_B the n x 3 rows of vertex B
 * and KU_B = K U_B, the blocks are U_A^T KU_B (T's vertices), KU_A[l] n^T (vertex A, point p_l) and
 * K_kl n n^T (points p_k, p_l): no y-space matrix and no mapping of it.
 * Curvature part: in y it has no (q_k, q_l) blocks; its (e_a, e_b) blocks are
 *     -(w_a gL_b^T + gL_a w_b^T) - S Hess L_ab  - [q_s]x on (e1, e2), w_a = sum_k c_k g_a,k,
 * q_s = sum_k c_k q_k, c_k = f_k / L, and its (e_a, q_k) blocks c_k ([e2]x, -[e1]x)_a - c_k gL_a n^T;
 * the points' blocks follow from y_b = x_{b+1} - x_0 (x0's rows and columns minus the sums).
 * Only the upper triangle is computed, then mirrored. */
/* The block's Gauss-Newton part J^T K J on the points, from the structure of J (row k: the
 * triangle's vertices and point k), upper triangle. */
static void gauss_newton_points(const shape_geom *G, int npt, const double *K, const double *gy, double *Hv, int ld)
{
    const int n = npt - 3;
    const double *nn = G->n;
    double U[3][SHAPE_MAX_POINTS][3], KU[3][SHAPE_MAX_POINTS][3];
    for (int k = 0; k < n; k++) {
        const double *g = gy + 9 * (3 + k);
        for (int i = 0; i < 3; i++) {
            U[1][k][i] = g[i];
            U[2][k][i] = g[3 + i];
            U[0][k][i] = -(g[i] + g[3 + i] + nn[i]);
        }
    }
    for (int B = 0; B < 3; B++)
        for (int l = 0; l < n; l++) {
            double s0 = 0.0, s1 = 0.0, s2 = 0.0;
            const double *Kl = K + (size_t)l * n;
            for (int k = 0; k < n; k++) {
                s0 += Kl[k] * U[B][k][0];
                s1 += Kl[k] * U[B][k][1];
                s2 += Kl[k] * U[B][k][2];
            }
            KU[B][l][0] = s0, KU[B][l][1] = s1, KU[B][l][2] = s2;
        }
    /* T's vertices: U_A^T KU_B, A <= B (the upper half of a diagonal block) */
    for (int A = 0; A < 3; A++)
        for (int B = A; B < 3; B++)
            for (int i = 0; i < 3; i++)
                for (int j = A == B ? i : 0; j < 3; j++) {
                    double v = 0.0;
                    for (int l = 0; l < n; l++)
                        v += U[A][l][i] * KU[B][l][j];
                    Hv[(size_t)(3 * A + i) * ld + 3 * B + j] = v;
                }
    /* vertex A with point p_l, and points with points */
    for (int A = 0; A < 3; A++)
        for (int i = 0; i < 3; i++) {
            double *row = Hv + (size_t)(3 * A + i) * ld + 9;
            for (int l = 0; l < n; l++)
                for (int j = 0; j < 3; j++)
                    row[3 * l + j] = KU[A][l][i] * nn[j];
        }
    for (int k = 0; k < n; k++)
        for (int i = 0; i < 3; i++) {
            double *row = Hv + (size_t)(9 + 3 * k + i) * ld + 9;
            const double ni = nn[i];
            for (int l = k; l < n; l++) {
                const double kn = K[(size_t)k * n + l] * ni;
                for (int j = l == k ? i : 0; j < 3; j++)
                    row[3 * l + j] = kn * nn[j];
            }
        }
}

/* Adds the curvature part sum_k f_k Hess h_k on the points (its few nonzero blocks), upper
 * triangle. */
static void add_curvature_points(const shape_geom *G, const double *xv, int npt, const double *f, const double *h,
                                 const double *gy, double *Hv, int ld)
{
    const int n = npt - 3;
    const double *nn = G->n;
    const double iL = 1.0 / G->L;
    double gL[2][3], Se1[3][3], Se2[3][3];
    cross3(G->e2, nn, gL[0]);
    cross3(nn, G->e1, gL[1]);
    skew(G->e1, Se1);
    skew(G->e2, Se2);
    double w[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, qs[3] = {0.0, 0.0, 0.0}, S = 0.0;
    double Cq[SHAPE_MAX_POINTS][2][3][3]; /* (e_a, q_k) */
    double D[3][3] = {{0.0}}, Rq[2][3][3] = {{{0.0}}}; /* sum_k of (e1 + e2, q_k), of (q_k, e_a) */
    for (int k = 0; k < n; k++) {
        const int j = 3 + k;
        const double c = f[k] * iL;
        const double q[3] = {xv[3 * j] - xv[0], xv[3 * j + 1] - xv[1], xv[3 * j + 2] - xv[2]};
        const double *g = gy + 9 * j;
        S += c * h[j];
        for (int i = 0; i < 3; i++) {
            qs[i] += c * q[i];
            w[0][i] += c * g[i];
            w[1][i] += c * g[3 + i];
        }
        for (int i = 0; i < 3; i++)
            for (int jj = 0; jj < 3; jj++) {
                const double c0 = c * (Se2[i][jj] - gL[0][i] * nn[jj]);
                const double c1 = -c * (Se1[i][jj] + gL[1][i] * nn[jj]);
                Cq[k][0][i][jj] = c0;
                Cq[k][1][i][jj] = c1;
                Rq[0][jj][i] += c0;
                Rq[1][jj][i] += c1;
            }
    }
    /* (e_a, e_b), a <= b, the upper half of a diagonal block */
    double Cee[2][2][3][3], Sq[3][3], A[2][3][3], PA[2][3][3], Sn[3][3];
    skew(qs, Sq);
    skew(nn, Sn);
    for (int i = 0; i < 3; i++)
        for (int jj = 0; jj < 3; jj++) {
            A[0][i][jj] = -Se2[i][jj];
            A[1][i][jj] = Se1[i][jj];
        }
    for (int a = 0; a < 2; a++)
        for (int jj = 0; jj < 3; jj++) {
            const double nA = nn[0] * A[a][0][jj] + nn[1] * A[a][1][jj] + nn[2] * A[a][2][jj];
            for (int i = 0; i < 3; i++)
                PA[a][i][jj] = A[a][i][jj] - nn[i] * nA;
        }
    for (int a = 0; a < 2; a++)
        for (int b = a; b < 2; b++)
            for (int i = 0; i < 3; i++)
                for (int jj = 0; jj < 3; jj++) {
                    /* (A_a^T P A_b)_{ij} = sum_m A_a[m][i] (P A_b)[m][j] (P^2 = P) */
                    double v = (A[a][0][i] * PA[b][0][jj] + A[a][1][i] * PA[b][1][jj] + A[a][2][i] * PA[b][2][jj]) * iL;
                    if (a != b)
                        v -= Sn[i][jj];
                    double e = -(w[a][i] * gL[b][jj] + gL[a][i] * w[b][jj]) - S * v;
                    if (a != b)
                        e -= Sq[i][jj];
                    Cee[a][b][i][jj] = e;
                }
    for (int i = 0; i < 3; i++) /* the lower halves of the diagonal blocks, and (e2, e1) */
        for (int jj = 0; jj < 3; jj++) {
            if (jj < i)
                Cee[0][0][i][jj] = Cee[0][0][jj][i], Cee[1][1][i][jj] = Cee[1][1][jj][i];
            Cee[1][0][i][jj] = Cee[0][1][jj][i];
        }
    /* R_b = column sums of y-block column e_b, D = sum_k (e1 + e2, q_k) */
    double R[2][3][3];
    for (int b = 0; b < 2; b++)
        for (int i = 0; i < 3; i++)
            for (int jj = 0; jj < 3; jj++)
                R[b][i][jj] = Cee[0][b][i][jj] + Cee[1][b][i][jj] + Rq[b][i][jj];
    for (int k = 0; k < n; k++)
        for (int i = 0; i < 3; i++)
            for (int jj = 0; jj < 3; jj++) {
                const double dk = Cq[k][0][i][jj] + Cq[k][1][i][jj];
                D[i][jj] += dk;
                Hv[(size_t)i * ld + 9 + 3 * k + jj] -= dk;
                Hv[(size_t)(3 + i) * ld + 9 + 3 * k + jj] += Cq[k][0][i][jj];
                Hv[(size_t)(6 + i) * ld + 9 + 3 * k + jj] += Cq[k][1][i][jj];
            }
    for (int i = 0; i < 3; i++)
        for (int jj = 0; jj < 3; jj++) {
            if (jj >= i) {
                Hv[(size_t)i * ld + jj] += R[0][i][jj] + R[1][i][jj] + D[i][jj];
                Hv[(size_t)(3 + i) * ld + 3 + jj] += Cee[0][0][i][jj];
                Hv[(size_t)(6 + i) * ld + 6 + jj] += Cee[1][1][i][jj];
            }
            Hv[(size_t)i * ld + 3 + jj] -= R[0][i][jj];
            Hv[(size_t)i * ld + 6 + jj] -= R[1][i][jj];
            Hv[(size_t)(3 + i) * ld + 6 + jj] += Cee[0][1][i][jj];
        }
}

static void shape_hessian_points(const shape_geom *G, const double *xv, int npt, const double *K, const double *f,
                                 const double *h, const double *gy, int gauss_newton, double *Hv, int ld)
{
    gauss_newton_points(G, npt, K, gy, Hv, ld);
    const int n = npt - 3;
    int curved = 0; /* no force on any height (the rest shape): the block is its Gauss-Newton part */
    for (int k = 0; k < n && !gauss_newton; k++)
        curved |= f[k] != 0.0;
    if (curved)
        add_curvature_points(G, xv, npt, f, h, gy, Hv, ld);
    const int nv = 3 * npt;
    for (int r = 1; r < nv; r++)
        for (int c = 0; c < r; c++)
            Hv[(size_t)r * ld + c] = Hv[(size_t)c * ld + r];
}

/* Adds the 3-vector v of point j to the slots it depends on, in out (stride 1 per coordinate,
 * `step` between coordinates): v to src, or (I - P) v to src and P v to anchor, P = 2 m m^T. */
static void point_to_slots(const shape_point *p, const double v[3], double *out, size_t step)
{
    if (p->anchor < 0) {
        for (int i = 0; i < 3; i++)
            out[(size_t)(3 * p->src + i) * step] += v[i];
        return;
    }
    const double d = 2.0 * (v[0] * p->m[0] + v[1] * p->m[1] + v[2] * p->m[2]);
    for (int i = 0; i < 3; i++) {
        out[(size_t)(3 * p->src + i) * step] += v[i] - d * p->m[i];
        out[(size_t)(3 * p->anchor + i) * step] += d * p->m[i];
    }
}

/* Triangle t's energy 1/2 (h - h0)^T K (h - h0) into *e, with its points xv, their heights h and
 * the forces f = K (h - h0) (the gradient's factors); 0 for a degenerate triangle. */
static int tri_energy(const shape_ctx *ctx, plume_index t, const double *x, double *xv, double *h, double *f,
                      shape_geom *G, double *e)
{
    const shape_tri *T = &ctx->tri[t];
    const int npt = T->npt, n = npt - 3;
    const double *K = ctx->dbl + T->kh, *h0 = K + (size_t)n * n;
    gather_points(ctx, t, x, xv);
    if (!shape_geometry(xv, npt, G, h))
        return 0;
    double s2 = 0.0;
    for (int k = 0; k < n; k++) {
        double s = 0.0;
        for (int l = 0; l < n; l++)
            s += K[k * n + l] * (h[3 + l] - h0[l]);
        f[k] = s;
        s2 += s * (h[3 + k] - h0[k]);
    }
    *e = 0.5 * s2;
    return 1;
}

/* The energy, gradient and blocks of triangles first .. first + count - 1 (hblocks: triangle
 * first's block first). */
static plume_status shape_eval_range(const shape_ctx *ctx, const double *x, plume_index first, plume_index count,
                                     double *energy, double *grad, double *hblocks, int project)
{
    const int mp = ctx->maxpt, ka = 3 * ctx->arity;
    double *xv = ctx->work, *h = xv + 3 * mp, *f = h + mp, *gy = f + mp, *gv = gy + 9 * mp, *ga = gv + 3 * mp;
    double *Hv = ga + ka, *Ht = Hv + (size_t)9 * mp * mp;
    double E = 0.0;
    for (plume_index t = first; t < first + count; t++) {
        const shape_tri *T = &ctx->tri[t];
        const shape_point *P = ctx->pts + T->pt;
        const int npt = T->npt, n = npt - 3;
        const double *K = ctx->dbl + T->kh;
        shape_geom G;
        double e;
        if (!tri_energy(ctx, t, x, xv, h, f, &G, &e))
            return PLUME_ESINGULAR; /* a degenerate triangle: no normal, no curvature */
        E += e;
        if (!grad && !hblocks)
            continue;
        /* grad h_j in y = (e1, e2, q_j): (grad V - h grad L) / L */
        const double iL = 1.0 / G.L;
        double gL[2][3];
        cross3(G.e2, G.n, gL[0]);
        cross3(G.n, G.e1, gL[1]);
        for (int j = 3; j < npt; j++) {
            const double q[3] = {xv[3 * j] - xv[0], xv[3 * j + 1] - xv[1], xv[3 * j + 2] - xv[2]};
            double a[3], b[3];
            cross3(G.e2, q, a);
            cross3(q, G.e1, b);
            double *g = gy + 9 * j;
            for (int i = 0; i < 3; i++) {
                g[i] = (a[i] - h[j] * gL[0][i]) * iL;
                g[3 + i] = (b[i] - h[j] * gL[1][i]) * iL;
                g[6 + i] = G.n[i];
            }
        }
        if (grad) {
            memset(gv, 0, sizeof(double) * 3 * (size_t)npt);
            for (int k = 0; k < n; k++) {
                const double *g = gy + 9 * (3 + k);
                for (int i = 0; i < 3; i++) {
                    gv[3 + i] += f[k] * g[i];
                    gv[6 + i] += f[k] * g[3 + i];
                    gv[3 * (3 + k) + i] += f[k] * g[6 + i];
                }
            }
            for (int j = 1; j < npt; j++)
                for (int i = 0; i < 3; i++)
                    gv[i] -= gv[3 * j + i];
            memset(ga, 0, sizeof(double) * (size_t)ka);
            for (int j = 0; j < npt; j++)
                point_to_slots(&P[j], gv + 3 * j, ga, 1);
            const plume_index *s = ctx->stencil + (size_t)ctx->arity * t;
            for (int v = 0; v < T->nslot; v++)
                for (int i = 0; i < 3; i++)
                    grad[3 * s[v] + i] += ga[3 * v + i];
        }
        if (hblocks) {
            const int nv = 3 * npt;
            double *Hb = hblocks + (size_t)(t - first) * (size_t)ka * (size_t)ka;
            if (T->plain) { /* point j is slot j: the block is Hv, padded with zeros */
                shape_hessian_points(&G, xv, npt, K, f, h, gy, project != 0, Hb, ka);
                for (int r = 0; r < ka; r++)
                    memset(Hb + (size_t)r * ka + (r < nv ? nv : 0), 0,
                           sizeof(double) * (size_t)(r < nv ? ka - nv : ka));
                continue;
            }
            shape_hessian_points(&G, xv, npt, K, f, h, gy, project != 0, Hv, nv);
            /* Ht = Hv T (columns to slots), then the block = T^T Ht (rows to slots) */
            memset(Ht, 0, sizeof(double) * (size_t)nv * (size_t)ka);
            for (int r = 0; r < nv; r++)
                for (int j = 0; j < npt; j++)
                    point_to_slots(&P[j], Hv + (size_t)r * nv + 3 * j, Ht + (size_t)r * ka, 1);
            memset(Hb, 0, sizeof(double) * (size_t)ka * (size_t)ka);
            for (int c = 0; c < ka; c++)
                for (int j = 0; j < npt; j++) {
                    const double v[3] = {Ht[(size_t)(3 * j) * ka + c], Ht[(size_t)(3 * j + 1) * ka + c],
                                         Ht[(size_t)(3 * j + 2) * ka + c]};
                    point_to_slots(&P[j], v, Hb + c, (size_t)ka);
                }
            for (int r = 0; r < ka; r++)
                for (int c = r + 1; c < ka; c++)
                    Hb[(size_t)r * ka + c] = Hb[(size_t)c * ka + r] =
                        0.5 * (Hb[(size_t)r * ka + c] + Hb[(size_t)c * ka + r]);
        }
    }
    if (energy)
        *energy += E;
    return PLUME_OK;
}

static plume_status shape_eval(void *vctx, int dim, const double *x, double *energy, double *grad,
                               double *hblocks, int project)
{
    const shape_ctx *ctx = vctx;
    if (!ctx || !x || dim != 3)
        return PLUME_EINVAL;
    return shape_eval_range(ctx, x, 0, ctx->nt, energy, grad, hblocks, project);
}

static plume_status shape_hess_range(void *vctx, int dim, const double *x, plume_index first, plume_index count,
                                     double *hblocks, int project)
{
    const shape_ctx *ctx = vctx;
    if (!ctx || !x || dim != 3 || !hblocks || first < 0 || count < 0 || count > ctx->nt - first)
        return PLUME_EINVAL;
    return shape_eval_range(ctx, x, first, count, NULL, NULL, hblocks, project);
}

static plume_status shape_energies(void *vctx, int dim, const double *x, double *e)
{
    const shape_ctx *ctx = vctx;
    if (!ctx || !x || !e || dim != 3)
        return PLUME_EINVAL;
    const int mp = ctx->maxpt;
    double *xv = ctx->work, *h = xv + 3 * mp, *f = h + mp;
    for (plume_index t = 0; t < ctx->nt; t++) {
        shape_geom G;
        if (!tri_energy(ctx, t, x, xv, h, f, &G, &e[t]))
            return PLUME_ESINGULAR;
    }
    return PLUME_OK;
}

static void shape_destroy(void *vctx)
{
    shape_ctx *ctx = vctx;
    if (!ctx)
        return;
    free(ctx->stencil);
    free(ctx->tri);
    free(ctx->pts);
    free(ctx->dbl);
    free(ctx->work);
    free(ctx);
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


/* One triangle's own fit (first pass of create): its reference data, its three fitted points
 * (vertex v, or the mirror of v through the plane with normal m that holds anchor vertex a),
 * their reference positions P, the inverse of M, and its neighbours across its edges. */
typedef struct {
    ref_tri R;
    plume_index v[3], a[3]; /* a[k] = -1: p_k is vertex v[k] */
    double m[3][3], P[3][2];
    double Mi[3][3];
    plume_index nb[3]; /* triangle across edge k (x_{k+1}, x_{k+2}), or -1 */
} own_fit;

/* Builder of one triangle's slots and points (second pass). */
typedef struct {
    plume_index *slot; /* global vertex of each slot */
    int nslot, npt;
    shape_point *pt;
    double *coef[3]; /* per edge of T: the coefficient of each point's height in its slope */
} tri_build;

static int slot_of(tri_build *b, plume_index v)
{
    for (int i = 0; i < b->nslot; i++)
        if (b->slot[i] == v)
            return i;
    b->slot[b->nslot] = v;
    return b->nslot++;
}

/* Index of the point (vertex v, or its mirror through (anchor, m)); mirrors are never shared. */
static int point_of(tri_build *b, plume_index v, plume_index anchor, const double m[3])
{
    const int s = slot_of(b, v);
    if (anchor < 0)
        for (int j = 0; j < b->npt; j++)
            if (b->pt[j].anchor < 0 && b->pt[j].src == s)
                return j;
    shape_point *p = &b->pt[b->npt];
    p->src = s;
    p->anchor = anchor < 0 ? -1 : slot_of(b, anchor);
    if (anchor >= 0)
        memcpy(p->m, m, sizeof p->m);
    for (int k = 0; k < 3; k++)
        b->coef[k][b->npt] = 0.0;
    return b->npt++;
}

/* d(lambda_i lambda_j)/dN at reference point X of triangle R: the derivatives of the three fit
 * quadratics q_j = lambda_{j+1} lambda_{j+2} along N, and of the three barycentrics (a). */
static void fit_slopes(const ref_tri *R, const double X[2], const double N[2], double d[3], double a[3])
{
    double l[3], gn[3];
    barycentric(R, X, l);
    for (int i = 0; i < 3; i++)
        gn[i] = a[i] = R->g[i][0] * N[0] + R->g[i][1] * N[1];
    for (int j = 0; j < 3; j++) {
        const int p = (j + 1) % 3, q = (j + 2) % 3;
        d[j] = gn[p] * l[q] + gn[q] * l[p];
    }
}

/* First pass for triangle t: own stencil (natural, ghost or from the ring), its fit. */
/* T's reference triangle: its first vertex, twice its area and the barycentric gradients. */
static plume_status reference_triangle(const plume_mesh *mesh, plume_index t, ref_tri *R, plume_err *err)
{
    const plume_index *tv = mesh->tri + 3 * t;
    const double *X0 = mesh->X + 2 * tv[0], *X1 = mesh->X + 2 * tv[1], *X2 = mesh->X + 2 * tv[2];
    const double ax = X1[0] - X0[0], ay = X1[1] - X0[1], bx = X2[0] - X0[0], by = X2[1] - X0[1];
    R->X0[0] = X0[0];
    R->X0[1] = X0[1];
    R->det = ax * by - ay * bx;
    const double scl = ax * ax + ay * ay + bx * bx + by * by + (bx - ax) * (bx - ax) + (by - ay) * (by - ay);
    if (!isfinite(R->det) || !(fabs(R->det) > SHAPE_DEGENERATE_REL * scl))
        return plume_err_set(err, PLUME_EINVAL, "shape bending: triangle %ld: degenerate reference triangle (area %g)",
                             (long)t, 0.5 * R->det);
    /* lambda_1 = cross(X - X0, b) / det, lambda_2 = cross(a, X - X0) / det */
    R->g[1][0] = by / R->det;
    R->g[1][1] = -bx / R->det;
    R->g[2][0] = -ay / R->det;
    R->g[2][1] = ax / R->det;
    R->g[0][0] = -R->g[1][0] - R->g[2][0];
    R->g[0][1] = -R->g[1][1] - R->g[2][1];
    return PLUME_OK;
}

/* The natural stencil: p_k the vertex across the edge (tv[k+1], tv[k+2]) (across[k], and the
 * neighbour nb[k]); -1 on a boundary edge, and (phase-aware) across a neighbour of another
 * material, which still shares its slope estimate but whose vertex is not fitted. */
static void natural_stencil(const plume_mesh *mesh, plume_index t, int phase_aware, const search_ws *W, own_fit *F,
                            plume_index p[3], plume_index across[3])
{
    const plume_index *tv = mesh->tri + 3 * t;
    for (int k = 0; k < 3; k++) {
        const plume_index a = tv[(k + 1) % 3], b = tv[(k + 2) % 3];
        p[k] = across[k] = F->nb[k] = -1;
        for (plume_index s = W->vstart[a]; s < W->vstart[a + 1]; s++) {
            const plume_index u = W->vtri[s];
            if (u == t)
                continue;
            const plume_index *uv = mesh->tri + 3 * u;
            int hasb = 0;
            for (int j = 0; j < 3; j++)
                hasb |= uv[j] == b;
            if (!hasb)
                continue;
            for (int j = 0; j < 3; j++)
                if (uv[j] != a && uv[j] != b) {
                    across[k] = uv[j];
                    p[k] = phase_aware && mesh->material[u] != mesh->material[t] ? -1 : uv[j];
                    F->nb[k] = u;
                }
        }
    }
}

/* Clamped boundary edges: the missing p_k is the mirror image of T's own vertex x_k through the
 * plane of the edge and the rest normal (its reference point in F->P[k] and gr, the plane's unit
 * normal in F->m[k], the edge's first vertex in F->a[k]; -1 elsewhere). */
static plume_status clamp_mirrors(const plume_mesh *mesh, plume_index t, const double *rest_x,
                                  const unsigned char *clamped, const plume_index across[3], own_fit *F,
                                  plume_index p[3], ghost_ref *gr, plume_err *err)
{
    const plume_index *tv = mesh->tri + 3 * t;
    for (int k = 0; k < 3; k++) {
        const plume_index a = tv[(k + 1) % 3], b = tv[(k + 2) % 3];
        F->a[k] = -1;
        if (!clamped || across[k] >= 0 || !clamped[a] || !clamped[b])
            continue;
        const double *Xa = mesh->X + 2 * a, *Xb = mesh->X + 2 * b, *Xc = mesh->X + 2 * tv[k];
        const double ex = Xb[0] - Xa[0], ey = Xb[1] - Xa[1], el = hypot(ex, ey);
        const double nx = -ey / el, ny = ex / el;
        const double d = nx * (Xc[0] - Xa[0]) + ny * (Xc[1] - Xa[1]);
        F->P[k][0] = Xc[0] - 2.0 * d * nx;
        F->P[k][1] = Xc[1] - 2.0 * d * ny;
        gr->gp[k] = F->P[k];
        p[k] = tv[k];
        F->a[k] = a;
        double *m = F->m[k];
        if (rest_x) { /* the plane through the edge and the rest triangle's normal */
            const double *r0 = rest_x + 3 * tv[0], *r1 = rest_x + 3 * tv[1], *r2 = rest_x + 3 * tv[2];
            const double *ra = rest_x + 3 * a, *rb = rest_x + 3 * b;
            double u[3], w[3], nr[3], e[3];
            for (int i = 0; i < 3; i++) {
                u[i] = r1[i] - r0[i];
                w[i] = r2[i] - r0[i];
                e[i] = rb[i] - ra[i];
            }
            cross3(u, w, nr);
            cross3(nr, e, m);
        } else {
            m[0] = nx, m[1] = ny, m[2] = 0.0;
        }
        const double ml = sqrt(dot3(m, m));
        if (!(ml > 0.0) || !isfinite(ml))
            return plume_err_set(err, PLUME_EINVAL,
                                 "shape bending: triangle %ld: clamped edge (%ld, %ld) has no mirror plane in rest_x",
                                 (long)t, (long)a, (long)b);
        for (int i = 0; i < 3; i++)
            m[i] /= ml;
    }
    return PLUME_OK;
}

static plume_status own_stencil(const plume_mesh *mesh, plume_index t, const double *rest_x,
                                const unsigned char *clamped, int phase_aware, search_ws *W, own_fit *F,
                                plume_err *err)
{
    ref_tri *R = &F->R;
    plume_status st = reference_triangle(mesh, t, R, err);
    if (st != PLUME_OK)
        return st;
    plume_index p[3], across[3];
    natural_stencil(mesh, t, phase_aware, W, F, p, across);
    ghost_ref gr = {{NULL, NULL, NULL}};
    if ((st = clamp_mirrors(mesh, t, rest_x, clamped, across, F, p, &gr, err)) != PLUME_OK)
        return st;
    W->phase = phase_aware ? mesh->material[t] : -1;
    double q = plume_shape_choose_stencil(mesh, t, R, &gr, W, p);
    if (q >= 0.0 && !(q >= SHAPE_MIN_STENCIL) && phase_aware) {
        /* the phase is too thin to hold a well-conditioned stencil: the whole mesh's */
        for (int k = 0; k < 3; k++)
            if (F->a[k] < 0)
                p[k] = across[k];
        W->phase = -1;
        q = plume_shape_choose_stencil(mesh, t, R, &gr, W, p);
    }
    W->phase = -1;
    if (q < 0.0)
        return plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
    if (!(q >= SHAPE_MIN_STENCIL))
        return plume_err_set(err, PLUME_EINVAL,
                             "shape bending: triangle %ld: no well-conditioned 6-vertex stencil in its %d-ring "
                             "(the mesh has too few vertices around it for a quadratic fit)",
                             (long)t, SHAPE_MAX_RING);
    double M[3][3];
    for (int k = 0; k < 3; k++) {
        F->v[k] = p[k];
        if (F->a[k] < 0) {
            F->P[k][0] = mesh->X[2 * p[k]];
            F->P[k][1] = mesh->X[2 * p[k] + 1];
        }
        fit_row(R, F->P[k], M[k]);
    }
    if (!inv3(M, F->Mi))
        return plume_err_set(err, PLUME_EINVAL, "shape bending: triangle %ld: singular stencil", (long)t);
    return PLUME_OK;
}

/* Second pass for triangle t: the points and, per edge k, the coefficients of the slope
 * beta_k across it (see top): beta_k = w s_k(own fit) + (1 - w) s_k(neighbour's fit, in T's
 * frame), w = 1/2 with a neighbour and averaging, 1 otherwise. Returns B (3 x npt, kappa = B h). */
static void tri_slopes(const plume_mesh *mesh, plume_index t, const own_fit *fits, int average, tri_build *b,
                       double d_barb[2], double *B)
{
    const plume_index *tv = mesh->tri + 3 * t;
    const own_fit *F = &fits[t];
    b->nslot = b->npt = 0;
    for (int k = 0; k < 3; k++)
        point_of(b, tv[k], -1, NULL);
    int own[3];
    for (int k = 0; k < 3; k++)
        own[k] = point_of(b, F->v[k], F->a[k], F->m[k]);
    const double A = 0.5 * fabs(F->R.det);
    double W[3][3]; /* kappa_r = sum_k W[r][k] beta_k */
    const double dp[2] = {-d_barb[1], d_barb[0]};
    for (int k = 0; k < 3; k++) {
        const double *Xa = mesh->X + 2 * tv[(k + 1) % 3], *Xb = mesh->X + 2 * tv[(k + 2) % 3];
        const double *Xc = mesh->X + 2 * tv[k];
        const double ex = Xb[0] - Xa[0], ey = Xb[1] - Xa[1], l = hypot(ex, ey);
        double N[2] = {ey / l, -ex / l};
        const double mid[2] = {0.5 * (Xa[0] + Xb[0]), 0.5 * (Xa[1] + Xb[1])};
        if (N[0] * (Xc[0] - mid[0]) + N[1] * (Xc[1] - mid[1]) > 0.0)
            N[0] = -N[0], N[1] = -N[1]; /* outward */
        const double nd = N[0] * d_barb[0] + N[1] * d_barb[1], np = N[0] * dp[0] + N[1] * dp[1];
        W[0][k] = l / A * nd * nd;
        W[1][k] = l / A * np * np;
        W[2][k] = l / A * nd * np;
        const plume_index u = F->nb[k];
        const double w = average && u >= 0 ? 0.5 : 1.0;
        /* own fit: s = sum_j d_j c_j, c = Mi h_own */
        double d[3], a[3];
        fit_slopes(&F->R, mid, N, d, a);
        for (int i = 0; i < 3; i++) {
            double s = 0.0;
            for (int j = 0; j < 3; j++)
                s += d[j] * F->Mi[j][i];
            b->coef[k][own[i]] += w * s;
        }
        if (w == 1.0)
            continue;
        /* the neighbour's fit in T's frame: q = sum_i z_i lambda_i + sum_j c_j q_j through its
         * vertices (heights z) and its points (heights h'), c = Mi' (h' - Lam z) */
        const own_fit *U = &fits[u];
        const plume_index *uv = mesh->tri + 3 * u;
        fit_slopes(&U->R, mid, N, d, a);
        double mtd[3]; /* Mi'^T d */
        for (int p = 0; p < 3; p++)
            mtd[p] = d[0] * U->Mi[0][p] + d[1] * U->Mi[1][p] + d[2] * U->Mi[2][p];
        double cz[3] = {a[0], a[1], a[2]};
        for (int p = 0; p < 3; p++) {
            double lam[3];
            barycentric(&U->R, U->P[p], lam);
            for (int i = 0; i < 3; i++)
                cz[i] -= lam[i] * mtd[p];
            const int j = point_of(b, U->v[p], U->a[p], U->m[p]);
            b->coef[k][j] += 0.5 * mtd[p];
        }
        for (int i = 0; i < 3; i++)
            b->coef[k][point_of(b, uv[i], -1, NULL)] += 0.5 * cz[i];
    }
    for (int r = 0; r < 3; r++)
        for (int j = 0; j < b->npt; j++)
            B[r * b->npt + j] = W[r][0] * b->coef[0][j] + W[r][1] * b->coef[1][j] + W[r][2] * b->coef[2][j];
}

plume_status plume_shape_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                             const double *rest_x, plume_term *out, plume_err *err)
{
    return plume_shape_bending_term_create_opts(mesh, mats, nmat, rest_x, NULL, out, err);
}

/* The inputs' checks, each failure a message naming the material, triangle or coordinate. */
static plume_status check_shape_inputs(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                       const double *rest_x, plume_err *err)
{
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
    plume_status st = plume_plate_moduli_check(mats, nmat, "shape bending", err);
    if (st != PLUME_OK)
        return st;
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
    return PLUME_OK;
}

/* The unit barb direction of triangle t. */
static void unit_barb_dir(const plume_mesh *mesh, plume_index t, double d[2])
{
    const double dl = hypot(mesh->barb_dir[2 * t], mesh->barb_dir[2 * t + 1]);
    d[0] = mesh->barb_dir[2 * t] / dl;
    d[1] = mesh->barb_dir[2 * t + 1] / dl;
}

/* The layout of every triangle's slots, points and K (a first pass over the slopes), the stencil
 * width and the workspaces sized by it. */
static plume_status shape_layout(shape_ctx *ctx, const plume_mesh *mesh, const own_fit *fits, int average,
                                 tri_build *tb, double *Bm, plume_err *err)
{
    const plume_index nt = ctx->nt;
    ctx->tri = malloc((size_t)(nt + 1) * sizeof *ctx->tri);
    if (!ctx->tri)
        return plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
    size_t npts = 0, ndbl = 0;
    int arity = 1, maxpt = 3;
    for (plume_index t = 0; t < nt; t++) {
        double d[2];
        unit_barb_dir(mesh, t, d);
        tri_slopes(mesh, t, fits, average, tb, d, Bm);
        shape_tri *T = &ctx->tri[t];
        T->nslot = tb->nslot;
        T->npt = tb->npt;
        T->plain = tb->nslot == tb->npt;
        for (int j = 0; j < tb->npt; j++)
            T->plain &= tb->pt[j].anchor < 0 && tb->pt[j].src == j;
        T->pt = npts;
        T->kh = ndbl;
        npts += (size_t)tb->npt;
        ndbl += (size_t)(tb->npt - 3) * (size_t)(tb->npt - 2);
        arity = tb->nslot > arity ? tb->nslot : arity;
        maxpt = tb->npt > maxpt ? tb->npt : maxpt;
    }
    ctx->arity = arity;
    ctx->maxpt = maxpt;
    const size_t ka = 3 * (size_t)arity, mp = (size_t)maxpt;
    ctx->stencil = malloc(((size_t)arity * (size_t)nt + 1) * sizeof *ctx->stencil);
    ctx->pts = malloc((npts + 1) * sizeof *ctx->pts);
    ctx->dbl = malloc((ndbl + 1) * sizeof *ctx->dbl);
    ctx->work = malloc((17 * mp + ka + 9 * mp * mp + 3 * mp * ka) * sizeof *ctx->work);
    if (!ctx->stencil || !ctx->pts || !ctx->dbl || !ctx->work)
        return plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
    return PLUME_OK;
}

/* Triangle t's stencil (padded to the width with its first vertex), points, K = A B^T Dv B over
 * points 3.. and rest heights h0 (0 for a flat rest). */
static plume_status shape_triangle(shape_ctx *ctx, const plume_mesh *mesh, const plume_bending_material *mats,
                                   const own_fit *fits, int average, const double *rest_x, plume_index t,
                                   tri_build *tb, double *Bm, plume_err *err)
{
    const int arity = ctx->arity;
    const plume_bending_material *mat = &mats[mesh->material[t]];
    double d[2];
    unit_barb_dir(mesh, t, d);
    tri_slopes(mesh, t, fits, average, tb, d, Bm);
    shape_tri *T = &ctx->tri[t];
    plume_index *sv = ctx->stencil + (size_t)arity * t;
    for (int i = 0; i < arity; i++)
        sv[i] = tb->slot[i < tb->nslot ? i : 0];
    memcpy(ctx->pts + T->pt, tb->pt, (size_t)tb->npt * sizeof *tb->pt);
    const double D66 = mat->D_twist > 0.0 ? mat->D_twist
                                          : fmax(0.0, 0.5 * (sqrt(mat->D_long * mat->D_trans) - mat->D_coupling));
    const double Dv[3][3] = {{mat->D_long, mat->D_coupling, 0.0}, {mat->D_coupling, mat->D_trans, 0.0},
                             {0.0, 0.0, 4.0 * D66}};
    const double A = 0.5 * fabs(fits[t].R.det);
    const int np = tb->npt, n = np - 3;
    double *K = ctx->dbl + T->kh, *h0 = K + (size_t)n * n;
    for (int a = 0; a < n; a++)
        for (int b = a; b < n; b++) {
            double s = 0.0;
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++)
                    s += Bm[r * np + 3 + a] * Dv[r][c] * Bm[c * np + 3 + b];
            K[a * n + b] = K[b * n + a] = A * s;
        }
    for (int k = 0; k < n; k++)
        h0[k] = 0.0;
    if (rest_x) {
        double xv[3 * SHAPE_MAX_POINTS], hr[SHAPE_MAX_POINTS];
        shape_geom G;
        gather_points(ctx, t, rest_x, xv);
        if (!shape_geometry(xv, np, &G, hr))
            return plume_err_set(err, PLUME_EINVAL, "shape bending: triangle %ld is degenerate in rest_x", (long)t);
        memcpy(h0, hr + 3, (size_t)n * sizeof *h0);
    }
    return PLUME_OK;
}

plume_status plume_shape_bending_term_create_opts(const plume_mesh *mesh, const plume_bending_material *mats,
                                                  int nmat, const double *rest_x, const plume_shape_bending_opts *o,
                                                  plume_term *out, plume_err *err)
{
    plume_status st = PLUME_OK;
    shape_ctx *ctx = NULL;
    own_fit *fits = NULL;
    search_ws W;
    memset(&W, 0, sizeof W);
    const unsigned char *clamped = o ? o->clamped : NULL;
    const int average = !(o && o->own_fit_only), phase_aware = o && o->phase_aware;
    if (out)
        memset(out, 0, sizeof *out);
    if (!mesh || !mats || !out)
        return plume_err_set(err, PLUME_EINVAL, "shape bending: NULL mesh, materials or output");
    if ((st = check_shape_inputs(mesh, mats, nmat, rest_x, err)) != PLUME_OK)
        return st;

    const plume_index nt = mesh->nt;
    plume_index bslot[SHAPE_MAX_POINTS];
    shape_point bpt[SHAPE_MAX_POINTS];
    double bcoef[3][SHAPE_MAX_POINTS], Bm[3 * SHAPE_MAX_POINTS];
    tri_build tb = {bslot, 0, 0, bpt, {bcoef[0], bcoef[1], bcoef[2]}};
    ctx = calloc(1, sizeof *ctx);
    fits = malloc((size_t)(nt + 1) * sizeof *fits);
    if (!ctx || !fits || plume_shape_search_init(&W, mesh) != 0) {
        st = plume_err_set(err, PLUME_ENOMEM, "shape bending: out of memory");
        goto cleanup;
    }
    ctx->nt = nt;
    for (plume_index t = 0; t < nt; t++)
        if ((st = own_stencil(mesh, t, rest_x, clamped, phase_aware, &W, &fits[t], err)) != PLUME_OK)
            goto cleanup;
    if ((st = shape_layout(ctx, mesh, fits, average, &tb, Bm, err)) != PLUME_OK)
        goto cleanup;
    for (plume_index t = 0; t < nt; t++)
        if ((st = shape_triangle(ctx, mesh, mats, fits, average, rest_x, t, &tb, Bm, err)) != PLUME_OK)
            goto cleanup;

    out->name = "shape bending";
    out->arity = ctx->arity;
    out->nstencil = nt;
    out->stencil = ctx->stencil;
    out->size = sizeof *out;
    out->eval = shape_eval;
    out->energies = shape_energies;
    out->partial_projection = 1; /* the Gauss-Newton block: closed form, the stiffness kept */
    out->hess_range = shape_hess_range;
    out->padded = 1;
    out->destroy = shape_destroy;
    out->ctx = ctx;
    ctx = NULL;

cleanup:
    shape_destroy(ctx);
    free(fits);
    plume_shape_search_free(&W);
    return st;
}
