/* Discrete anisotropic hinge bending (docs/design.md "Equations every part agrees on", Bending;
 * Grinspun et al. 2003 "Discrete Shells"; derivatives after Bridson et al. 2003 and Tamstorf &
 * Grinspun 2013, derived again below).
 *
 * Stencil and angle. Each hinge is stored as (x0, x1, x2, x3): the edge x0 -> x1, x2 opposite in
 * triangle A = (x0, x1, x2) and x3 opposite in triangle B = (x1, x0, x3), both counter-clockwise
 * in the reference X (the vertices of mesh->hinges are reordered at create so that this holds).
 * With e = x1 - x0, a = x2 - x0, b = x3 - x0 the outward normals of the two triangles are
 * nA = e x a and nB = b x e, and the signed dihedral angle is
 *     theta = atan2(e^ . (nB x nA), nA . nB),
 * robust at every angle (nB x nA is parallel to e). theta > 0 when the surface bends toward its
 * normal (a flat patch bent onto a cylinder whose centre lies on the +n side: theta > 0).
 *
 * Energy of a hinge (|e|, A1, A2 from the flat reference X; theta0 from the rest shape):
 *     E = c D_e |e|^2 / (A1 + A2) (theta - theta0)^2,   c = 1/2 (BENDING_C below).
 * Why c = 1/2 (1/6 of the classical 3 |e|^2/(A1+A2) factor): take a hinge whose edge lies along
 * the axis of a cylinder of curvature k, its opposite vertices on neighbouring generators at
 * distances w1, w2 from the edge line. Each triangle's plane holds the chord to its generator,
 * so the normals turn by k w1/2 and k w2/2: theta = k (w1 + w2)/2 exactly, and with
 * A1 + A2 = |e| (w1 + w2)/2 the hinge stores c D k^2 |e|^2 (w1 + w2)^2/4 / (|e| (w1 + w2)/2)
 * = c D k^2 (A1 + A2). A hinge whose two triangles span the same two generators is planar and
 * stores nothing. So when each triangle has one edge along the axis, the patch stores
 * c D k^2 * area, and c = 1/2 gives the 1/2 D k^2 per unit area of docs/design.md, less the boundary
 * triangles whose axis edge is on the boundary (an O(h) deficit: -1/n on n x n grids). Measured
 * (tests/test_bending.c): exact in that sense on right-triangle grids with the axis along an
 * edge family, and on the equilateral lattice for every cylinder direction (checked every 15
 * degrees). The hinge energy is not a consistent plate energy on every mesh: on a right-triangle
 * grid, an isotropic cylinder with its curvature at 30 degrees to the grid stores +160 % (+198 %
 * at 45, -12 % at 120 degrees).
 *
 * Anisotropy. The hinge's angle measures the normal curvature in the direction n = t_perp
 * across the edge (t the unit edge direction in X). With d the barb direction (the two
 * triangles' unit directions, signs matched, averaged and normalised) and phi the angle between n
 * and d,
 *     D_e = D_long cos^2(phi) + D_trans sin^2(phi) = D_long (1 - (t.d)^2) + D_trans (t.d)^2.
 * Why this law: it is n^T Dt n for the tensor Dt = D_long d d^T + D_trans d_perp d_perp^T, the
 * unique interpolation quadratic in n that gives D_long for curvature along the barbs (phi = 0:
 * the hinge is across the barbs and bends them) and D_trans across them, continuous in the barb
 * angle. It is also exactly the stiffness of an orthotropic plate bent into a cylinder of
 * curvature direction n when its twist/coupling stiffness is the mean, D_12 + 2 D_66 =
 * (D_long + D_trans)/2 (then D_long cos^4 + D_trans sin^4 + (D_long + D_trans) sin^2 cos^2 =
 * D_long cos^2 + D_trans sin^2).
 * What it gives (measured at D_long/D_trans = 2500): on barb-aligned right-triangle grids both
 * cylinders are exact (up to the boundary deficit); on any mesh whose vertices all lie on barb
 * lines (the aligned patch and feather meshes) the cylinder with its axis along the barbs bends
 * only the hinges along d and is exact with D_trans; but a hinge only sees one angle, so
 * - on the equilateral barb-aligned lattice, curvature along d also folds the hinges along d (by
 *   the sagitta of the oblique edges, 1/9 of the isotropic energy) where D_e = D_trans, and the
 *   oblique hinges carry 3/4 D_long: that cylinder stores 0.66 D_long instead of D_long;
 * - on meshes not aligned with the barbs, curvature across the barbs folds oblique hinges that
 *   carry part of D_long: the soft mode is 10^3-10^4 times too stiff.
 *
 * Derivatives (exact, closed form). Moving x2 along nA rotates A about the edge by
 * (distance)/h_A, h_A = |nA|/|e|, so with
 *     gA = |e| nA/|nA|^2,  gB = |e| nB/|nB|^2,  sA = a.e/|e|^2,  sB = b.e/|e|^2
 * (sA, sB: where the feet of x2, x3 fall along the edge) the gradient is
 *     dtheta/dx2 = gA, dtheta/dx3 = gB,
 *     dtheta/dx0 = -(1 - sA) gA - (1 - sB) gB,  dtheta/dx1 = -sA gA - sB gB,
 * (invariance under translations and rotations about the edge fixes the edge vertices' share).
 * The Hessian is the derivative of these expressions. With dl/dx0 = -e^, dl/dx1 = e^ and
 * dnA/dxj = [vA_j]x, vA_0 = a - e, vA_1 = -a, vA_2 = e (dnB/dxj = [vB_j]x, vB_0 = e - b,
 * vB_1 = b, vB_3 = -e), differentiating gA = l nA/|nA|^2 gives
 *     dgA/dxj = (1/|nA|^2) [ (dl/dxj) nA e^^T + l [vA_j]x - (2 l/|nA|^2) nA (nA x vA_j)^T ]
 * (using (I - 2 n^ n^^T) [v]x = [v]x - 2 n^ (n^ x v)^T), the same for gB, and
 *     dsA/dx2 = e/l^2, dsA/dx1 = (a - 2 sA e)/l^2, dsA/dx0 = -dsA/dx1 - dsA/dx2 (sB alike),
 * so the blocks d(dtheta/dxi)/dxj are: (2, j) = dgA/dxj, (3, j) = dgB/dxj, (2, 3) = 0,
 *     (0, j) = gA dsA/dxj^T - (1 - sA) dgA/dxj + gB dsB/dxj^T - (1 - sB) dgB/dxj,
 *     (1, j) = -gA dsA/dxj^T - sA dgA/dxj - gB dsB/dxj^T - sB dgB/dxj.
 * Only the blocks with i <= j that these give cheaply are formed ((0,0), (0,1), (1,1), and
 * (0|1, 2|3) as transposes of (2|3, 0|1)); the rest is mirrored, so the block is exactly
 * symmetric. E'' = 2 kappa (g g^T + (theta - theta0) H_theta).
 *
 * PSD projection. theta is invariant under translations, so every Hessian block annihilates the
 * three translation modes; in the orthogonal Hadamard basis of the four vertices
 * (U = 1/2 [1 1 1 1; 1 1 -1 -1; 1 -1 1 -1; 1 -1 -1 1], one row the translation) the block is a
 * 9x9 matrix plus zeros, and only that 9x9 is projected (projection commutes with orthogonal
 * changes of basis; the 12x12 Jacobi costs twice as much). A block that is already PSD (in
 * particular theta = theta0, where it is 2 kappa g g^T) is left as computed.
 *
 * Nothing is allocated after create. */
#include "bending.h"
#include "../../lib/core/vec3.h"

#include "../../lib/core/dense.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The cylinder constant c (see the derivation above): 1/2 D k^2 per unit area. */
#define BENDING_C 0.5

/* A reference triangle whose doubled area is below this fraction of its squared edge lengths is
 * degenerate up to rounding (the same test as the membrane's). */
#define BENDING_DEGENERATE_REL (64.0 * DBL_EPSILON)

/* A current triangle with |nA|^2 <= this * |e|^2 |a|^2 (sine of its angle at the edge below
 * 1e-14) is collapsed: its normal, hence theta's derivatives, are undefined. */
#define BENDING_COLLAPSED_REL 1e-28

typedef struct {
    double kappa;  /* c D_e |e|^2 / (A1 + A2) */
    double theta0; /* rest angle */
} bend_hinge;

typedef struct {
    plume_index nh;
    plume_index *stencil; /* [4*nh] (x0, x1, x2, x3) as described above */
    bend_hinge *hinge;    /* [nh] */
} bend_ctx;

/* Wraps an angle difference into (-pi, pi]: theta jumps by 2 pi through a full fold (atan2's
 * branch cut), the energy does not. */
static double wrap_angle(double d)
{
    if (d > M_PI)
        d -= 2.0 * M_PI;
    else if (d <= -M_PI)
        d += 2.0 * M_PI;
    return d;
}

/* The geometry of one hinge at the current positions. */
typedef struct {
    double e[3], a[3], b[3], nA[3], nB[3];
    double l2, lA2, lB2;
    double theta;
    int collapsed; /* a triangle or the edge has zero size: derivatives undefined */
} hinge_geom;

static void hinge_geometry(const double *x0, const double *x1, const double *x2, const double *x3,
                           hinge_geom *G)
{
    for (int i = 0; i < 3; i++) {
        G->e[i] = x1[i] - x0[i];
        G->a[i] = x2[i] - x0[i];
        G->b[i] = x3[i] - x0[i];
    }
    cross3(G->e, G->a, G->nA);
    cross3(G->b, G->e, G->nB);
    G->l2 = dot3(G->e, G->e);
    G->lA2 = dot3(G->nA, G->nA);
    G->lB2 = dot3(G->nB, G->nB);
    double m[3];
    cross3(G->nB, G->nA, m);
    const double l = sqrt(G->l2);
    /* e^ . (nB x nA) = |nA| |nB| sin theta; the 1/l keeps it in proportion with nA . nB */
    G->theta = l > 0.0 ? atan2(dot3(G->e, m) / l, dot3(G->nA, G->nB)) : 0.0;
    G->collapsed = !(G->l2 > 0.0) || !(G->lA2 > BENDING_COLLAPSED_REL * G->l2 * dot3(G->a, G->a)) ||
                   !(G->lB2 > BENDING_COLLAPSED_REL * G->l2 * dot3(G->b, G->b));
}

/* D = (1/n2) [ s nA e^^T + l [v]x - (2 l / n2) nA (nA x v)^T ]: dgA/dxj (see top). */
static void dg_block(const double n[3], double n2, const double eh[3], double s, double l,
                     const double v[3], double D[3][3])
{
    double w[3];
    cross3(n, v, w);
    const double in2 = 1.0 / n2, c = 2.0 * l * in2;
    /* [v]x w' = v x w': rows (0, -v2, v1), (v2, 0, -v0), (-v1, v0, 0) */
    const double V[3][3] = {{0.0, -v[2], v[1]}, {v[2], 0.0, -v[0]}, {-v[1], v[0], 0.0}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            D[i][j] = in2 * (s * n[i] * eh[j] + l * V[i][j] - c * n[i] * w[j]);
}

/* Writes the hinge's Hessian block (12x12 row-major) 2 kappa (g g^T + delta H_theta); g[4][3] is
 * theta's gradient. */
static void hinge_hessian(const hinge_geom *G, const double gA[3], const double gB[3], double sA,
                          double sB, double g[4][3], double two_kappa, double delta, double *H)
{
    const double l = sqrt(G->l2), il2 = 1.0 / G->l2;
    const double eh[3] = {G->e[0] / l, G->e[1] / l, G->e[2] / l};
    double vA0[3], vA1[3], vB0[3];
    for (int i = 0; i < 3; i++) {
        vA0[i] = G->a[i] - G->e[i];
        vA1[i] = -G->a[i];
        vB0[i] = G->e[i] - G->b[i];
    }
    const double me[3] = {-G->e[0], -G->e[1], -G->e[2]};
    double A0[3][3], A1[3][3], A2[3][3], B0[3][3], B1[3][3], B3[3][3];
    dg_block(G->nA, G->lA2, eh, -1.0, l, vA0, A0);
    dg_block(G->nA, G->lA2, eh, 1.0, l, vA1, A1);
    dg_block(G->nA, G->lA2, eh, 0.0, l, G->e, A2);
    dg_block(G->nB, G->lB2, eh, -1.0, l, vB0, B0);
    dg_block(G->nB, G->lB2, eh, 1.0, l, G->b, B1);
    dg_block(G->nB, G->lB2, eh, 0.0, l, me, B3);
    double dsA0[3], dsA1[3], dsB0[3], dsB1[3];
    for (int i = 0; i < 3; i++) {
        dsA1[i] = (G->a[i] - 2.0 * sA * G->e[i]) * il2;
        dsA0[i] = -dsA1[i] - G->e[i] * il2;
        dsB1[i] = (G->b[i] - 2.0 * sB * G->e[i]) * il2;
        dsB0[i] = -dsB1[i] - G->e[i] * il2;
    }
    /* T[i][j]: 3x3 block (i, j) of H_theta for the pairs formed here */
    double T00[3][3], T01[3][3], T11[3][3];
    const double pA = 1.0 - sA, pB = 1.0 - sB;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            T00[i][j] = gA[i] * dsA0[j] - pA * A0[i][j] + gB[i] * dsB0[j] - pB * B0[i][j];
            T01[i][j] = gA[i] * dsA1[j] - pA * A1[i][j] + gB[i] * dsB1[j] - pB * B1[i][j];
            T11[i][j] = -gA[i] * dsA1[j] - sA * A1[i][j] - gB[i] * dsB1[j] - sB * B1[i][j];
        }
    }
    /* upper blocks (r, c), r <= c, of H_theta at Hup[r][c]; (2, 3) is zero */
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double t[4][4];
            t[0][0] = 0.5 * (T00[i][j] + T00[j][i]);
            t[0][1] = T01[i][j];
            t[0][2] = A0[j][i]; /* (0, 2) = (2, 0)^T */
            t[0][3] = B0[j][i];
            t[1][1] = 0.5 * (T11[i][j] + T11[j][i]);
            t[1][2] = A1[j][i];
            t[1][3] = B1[j][i];
            t[2][2] = 0.5 * (A2[i][j] + A2[j][i]);
            t[2][3] = 0.0;
            t[3][3] = 0.5 * (B3[i][j] + B3[j][i]);
            for (int r = 0; r < 4; r++) {
                for (int c = r; c < 4; c++) {
                    const double h = two_kappa * (g[r][i] * g[c][j] + delta * t[r][c]);
                    H[(3 * r + i) * 12 + 3 * c + j] = h;
                    H[(3 * c + j) * 12 + 3 * r + i] = h;
                }
            }
        }
    }
}

/* Projects the 12x12 block H to PSD through the 9x9 translation-free part (see top). */
static void project_hinge(double *H)
{
    /* Hadamard rows: U[I][i] */
    static const double U[4][4] = {{0.5, 0.5, 0.5, 0.5},
                                   {0.5, 0.5, -0.5, -0.5},
                                   {0.5, -0.5, 0.5, -0.5},
                                   {0.5, -0.5, -0.5, 0.5}};
    double R[144], M[81], Mc[81];
    /* R = (U x I3) H */
    for (int I = 0; I < 4; I++)
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 12; c++)
                R[(3 * I + a) * 12 + c] = U[I][0] * H[a * 12 + c] + U[I][1] * H[(3 + a) * 12 + c] +
                                          U[I][2] * H[(6 + a) * 12 + c] + U[I][3] * H[(9 + a) * 12 + c];
    /* M = rows/cols 3..11 of R (U x I3)^T, upper triangle then mirrored (exactly symmetric) */
    for (int r = 0; r < 9; r++)
        for (int J = 1; J < 4; J++)
            for (int b = 0; b < 3; b++) {
                const int c = 3 * (J - 1) + b;
                if (c < r)
                    continue;
                const double *Rr = R + (3 + r) * 12;
                M[r * 9 + c] = U[J][0] * Rr[b] + U[J][1] * Rr[3 + b] + U[J][2] * Rr[6 + b] + U[J][3] * Rr[9 + b];
            }
    for (int r = 0; r < 9; r++)
        for (int c = 0; c < r; c++)
            M[r * 9 + c] = M[c * 9 + r];
    memcpy(Mc, M, sizeof M);
    plume_dense_project_psd(9, M);
    if (memcmp(M, Mc, sizeof M) == 0)
        return; /* already PSD: H stays exactly as computed */
    /* H = (U x I3)^T [0 0; 0 M] (U x I3) (U is symmetric and its own inverse) */
    for (int r = 0; r < 12; r++)
        for (int J = 0; J < 4; J++)
            for (int b = 0; b < 3; b++) {
                /* R[r][(J,b)] = sum_{I >= 1} U[I][r/3] M[(I,a=r%3)][(J,b)] */
                double s = 0.0;
                if (J > 0)
                    for (int I = 1; I < 4; I++)
                        s += U[I][r / 3] * M[(3 * (I - 1) + r % 3) * 9 + 3 * (J - 1) + b];
                R[r * 12 + 3 * J + b] = s;
            }
    for (int r = 0; r < 12; r++)
        for (int c = r; c < 12; c++) {
            const int j = c / 3, b = c % 3;
            double s = 0.0;
            for (int J = 1; J < 4; J++)
                s += R[r * 12 + 3 * J + b] * U[J][j];
            H[r * 12 + c] = H[c * 12 + r] = s;
        }
}

static plume_status bending_eval(void *vctx, int dim, const double *x, double *energy, double *grad,
                                 double *hblocks, int project)
{
    const bend_ctx *ctx = vctx;
    if (!ctx || !x || dim != 3)
        return PLUME_EINVAL;
    double E = 0.0;
    for (plume_index h = 0; h < ctx->nh; h++) {
        const plume_index *v = ctx->stencil + 4 * h;
        const bend_hinge *hg = &ctx->hinge[h];
        hinge_geom G;
        hinge_geometry(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3], &G);
        const double delta = wrap_angle(G.theta - hg->theta0);
        E += hg->kappa * delta * delta;
        if (!grad && !hblocks)
            continue;
        double *H = hblocks ? hblocks + (size_t)h * 144 : NULL;
        if (G.collapsed) {
            /* theta has no derivative at a collapsed triangle: the hinge holds its energy and
             * exerts no force until the triangle opens again (the membrane resists collapse) */
            if (H)
                memset(H, 0, 144 * sizeof *H);
            continue;
        }
        const double l = sqrt(G.l2);
        double gA[3], gB[3], g[4][3];
        const double sA = dot3(G.a, G.e) / G.l2, sB = dot3(G.b, G.e) / G.l2;
        for (int i = 0; i < 3; i++) {
            gA[i] = l * G.nA[i] / G.lA2;
            gB[i] = l * G.nB[i] / G.lB2;
            g[0][i] = -(1.0 - sA) * gA[i] - (1.0 - sB) * gB[i];
            g[1][i] = -sA * gA[i] - sB * gB[i];
            g[2][i] = gA[i];
            g[3][i] = gB[i];
        }
        if (grad) {
            const double f = 2.0 * hg->kappa * delta;
            for (int k = 0; k < 4; k++)
                for (int i = 0; i < 3; i++)
                    grad[3 * v[k] + i] += f * g[k][i];
        }
        if (H) {
            hinge_hessian(&G, gA, gB, sA, sB, g, 2.0 * hg->kappa, delta, H);
            if (project && delta != 0.0 && hg->kappa > 0.0)
                project_hinge(H);
        }
    }
    if (energy)
        *energy += E;
    return PLUME_OK;
}

static plume_status bending_energies(void *vctx, int dim, const double *x, double *e)
{
    const bend_ctx *ctx = vctx;
    if (!ctx || !x || !e || dim != 3)
        return PLUME_EINVAL;
    for (plume_index h = 0; h < ctx->nh; h++) {
        const plume_index *v = ctx->stencil + 4 * h;
        hinge_geom G;
        hinge_geometry(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3], &G);
        const double delta = wrap_angle(G.theta - ctx->hinge[h].theta0);
        e[h] = ctx->hinge[h].kappa * delta * delta;
    }
    return PLUME_OK;
}

static void bending_destroy(void *vctx)
{
    bend_ctx *ctx = vctx;
    if (!ctx)
        return;
    free(ctx->stencil);
    free(ctx->hinge);
    free(ctx);
}

/* 1 if triangle t lists the directed edge i -> j (its vertices in cyclic order) */
static int has_directed_edge(const plume_index *tri, plume_index i, plume_index j)
{
    for (int k = 0; k < 3; k++)
        if (tri[k] == i && tri[(k + 1) % 3] == j)
            return 1;
    return 0;
}

static int tri_has(const plume_index *tri, plume_index v)
{
    return tri[0] == v || tri[1] == v || tri[2] == v;
}

static int material_ok(double D)
{
    return isfinite(D) && D >= 0.0;
}

/* The checks of plume_bending_term_create's inputs that need no allocation (mesh, mats and out
 * not NULL). */
static plume_status check_inputs(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                 const double *rest_x, plume_err *err)
{
    if (mesh->dim != 3)
        return plume_err_set(err, PLUME_EINVAL,
                             "bending: the mesh must be in shell mode (dim 3), got dim %d", mesh->dim);
    if (nmat < 1)
        return plume_err_set(err, PLUME_EINVAL, "bending: nmat must be >= 1 (got %d)", nmat);
    if (mesh->nv < 0 || mesh->nt < 0 || mesh->nh < 0 ||
        (mesh->nt > 0 && (!mesh->X || !mesh->tri || !mesh->barb_dir || !mesh->material)))
        return plume_err_set(err, PLUME_EINVAL, "bending: mesh arrays missing or sizes negative");
    if (mesh->nt > 0 && (!mesh->edges || (mesh->nh > 0 && !mesh->hinges)))
        return plume_err_set(err, PLUME_EINVAL,
                             "bending: mesh topology not built (call plume_mesh_build_topology)");
    for (int i = 0; i < nmat; i++) {
        if (!material_ok(mats[i].D_long))
            return plume_err_set(err, PLUME_EINVAL,
                                 "bending: material %d: D_long must be finite and >= 0 (got %g)", i,
                                 mats[i].D_long);
        if (!material_ok(mats[i].D_trans))
            return plume_err_set(err, PLUME_EINVAL,
                                 "bending: material %d: D_trans must be finite and >= 0 (got %g)", i,
                                 mats[i].D_trans);
    }
    for (plume_index t = 0; t < mesh->nt; t++) {
        if (mesh->material[t] < 0 || mesh->material[t] >= nmat)
            return plume_err_set(err, PLUME_EINVAL,
                                 "bending: triangle %ld: material id %d out of range [0, %d)", (long)t,
                                 mesh->material[t], nmat);
        for (int k = 0; k < 3; k++)
            if (mesh->tri[3 * t + k] < 0 || mesh->tri[3 * t + k] >= mesh->nv)
                return plume_err_set(err, PLUME_EINVAL,
                                     "bending: triangle %ld: vertex id %ld out of range [0, %ld)", (long)t,
                                     (long)mesh->tri[3 * t + k], (long)mesh->nv);
    }
    if (rest_x)
        for (plume_index i = 0; i < 3 * mesh->nv; i++)
            if (!isfinite(rest_x[i]))
                return plume_err_set(err, PLUME_EINVAL,
                                     "bending: rest_x[%ld] (vertex %ld) is not finite (%g)", (long)i,
                                     (long)(i / 3), rest_x[i]);
    return PLUME_OK;
}

/* vertex -> triangles (CSR: the triangles of v are vtri[vstart[v] .. vstart[v + 1])), to find each
 * hinge's two triangles without relying on how the topology orders its arrays. vstart holds nv + 2
 * zeros on entry, vtri room for 3 nt. */
static void vertex_triangles(const plume_mesh *mesh, plume_index *vstart, plume_index *vtri)
{
    for (plume_index t = 0; t < mesh->nt; t++)
        for (int k = 0; k < 3; k++)
            vstart[mesh->tri[3 * t + k] + 2]++;
    for (plume_index v = 0; v < mesh->nv; v++)
        vstart[v + 2] += vstart[v + 1];
    for (plume_index t = 0; t < mesh->nt; t++)
        for (int k = 0; k < 3; k++)
            vtri[vstart[mesh->tri[3 * t + k] + 1]++] = t;
}

/* Hinge h's two triangles (*tA holding the first opposite vertex, *tB the second) and its stencil
 * sv ordered so that (x0, x1, x2) and (x1, x0, x3) are counter-clockwise. */
static plume_status hinge_stencil(const plume_mesh *mesh, const plume_index *vstart, const plume_index *vtri,
                                  plume_index h, plume_index sv[4], plume_index *tA_out, plume_index *tB_out,
                                  plume_err *err)
{
    const plume_index *hv = mesh->hinges + 4 * h;
    for (int k = 0; k < 4; k++)
        if (hv[k] < 0 || hv[k] >= mesh->nv)
            return plume_err_set(err, PLUME_EINVAL, "bending: hinge %ld: vertex id %ld out of range [0, %ld)",
                                 (long)h, (long)hv[k], (long)mesh->nv);
    /* the triangles (hv0, hv1, hv2) and (hv0, hv1, hv3) */
    plume_index tA = -1, tB = -1;
    for (plume_index s = vstart[hv[0]]; s < vstart[hv[0] + 1]; s++) {
        const plume_index *tv = mesh->tri + 3 * vtri[s];
        if (!tri_has(tv, hv[1]))
            continue;
        if (tri_has(tv, hv[2]))
            tA = vtri[s];
        else if (tri_has(tv, hv[3]))
            tB = vtri[s];
    }
    if (tA < 0 || tB < 0)
        return plume_err_set(err, PLUME_EINVAL,
                             "bending: hinge %ld: no triangles (%ld, %ld, %ld) and (%ld, %ld, %ld) in the mesh "
                             "(topology out of date?)",
                             (long)h, (long)hv[0], (long)hv[1], (long)hv[2], (long)hv[0], (long)hv[1], (long)hv[3]);
    const int forward = has_directed_edge(mesh->tri + 3 * tA, hv[0], hv[1]);
    sv[0] = forward ? hv[0] : hv[1];
    sv[1] = forward ? hv[1] : hv[0];
    sv[2] = hv[2];
    sv[3] = hv[3];
    if (!has_directed_edge(mesh->tri + 3 * tB, sv[1], sv[0]))
        return plume_err_set(err, PLUME_EINVAL,
                             "bending: hinge %ld: triangles %ld and %ld are not consistently oriented",
                             (long)h, (long)tA, (long)tB);
    *tA_out = tA, *tB_out = tB;
    return PLUME_OK;
}

/* The stiffness kappa = c D_e |e|^2 / (A1 + A2) of hinge h (stencil sv, triangles tA and tB) from
 * its reference geometry and the barb direction averaged over its two triangles. */
static plume_status hinge_stiffness(const plume_mesh *mesh, const plume_bending_material *mats, plume_index h,
                                    const plume_index sv[4], plume_index tA, plume_index tB, double *kappa,
                                    plume_err *err)
{
    const double *X0 = mesh->X + 2 * sv[0], *X1 = mesh->X + 2 * sv[1];
    const double *X2 = mesh->X + 2 * sv[2], *X3 = mesh->X + 2 * sv[3];
    const double ex = X1[0] - X0[0], ey = X1[1] - X0[1];
    const double ax = X2[0] - X0[0], ay = X2[1] - X0[1];
    const double bx = X3[0] - X0[0], by = X3[1] - X0[1];
    const double detA = ex * ay - ey * ax, detB = bx * ey - by * ex; /* 2 A, both > 0 */
    const double l2 = ex * ex + ey * ey;
    const double sclA = l2 + ax * ax + ay * ay + (ax - ex) * (ax - ex) + (ay - ey) * (ay - ey);
    const double sclB = l2 + bx * bx + by * by + (bx - ex) * (bx - ex) + (by - ey) * (by - ey);
    if (!isfinite(detA) || !isfinite(detB) || !(detA > BENDING_DEGENERATE_REL * sclA) ||
        !(detB > BENDING_DEGENERATE_REL * sclB))
        return plume_err_set(err, PLUME_EINVAL,
                             "bending: hinge %ld: degenerate reference triangle %ld or %ld (areas %g, %g)",
                             (long)h, (long)tA, (long)tB, 0.5 * detA, 0.5 * detB);
    /* barb direction: the two unit directions with matched signs, averaged */
    double d[2] = {0.0, 0.0};
    const plume_index tt[2] = {tA, tB};
    for (int k = 0; k < 2; k++) {
        const double dx = mesh->barb_dir[2 * tt[k]], dy = mesh->barb_dir[2 * tt[k] + 1];
        const double len = hypot(dx, dy);
        if (!isfinite(len) || !(len > 0.0))
            return plume_err_set(err, PLUME_EINVAL,
                                 "bending: triangle %ld: barb direction (%g, %g) cannot be normalised",
                                 (long)tt[k], dx, dy);
        const double sg = (k == 1 && d[0] * dx + d[1] * dy < 0.0) ? -1.0 : 1.0;
        d[0] += sg * dx / len;
        d[1] += sg * dy / len;
    }
    const double dl = hypot(d[0], d[1]); /* >= sqrt 2 */
    const double td = (ex * d[0] + ey * d[1]) / (sqrt(l2) * dl); /* cos of (t, d) = sin phi */
    const double sin2 = td * td, cos2 = 1.0 - sin2;
    const plume_bending_material *mA = &mats[mesh->material[tA]], *mB = &mats[mesh->material[tB]];
    const double Dl = 0.5 * (mA->D_long + mB->D_long), Dt = 0.5 * (mA->D_trans + mB->D_trans);
    const double De = Dl * cos2 + Dt * sin2;
    *kappa = BENDING_C * De * l2 / (0.5 * (detA + detB));
    return PLUME_OK;
}

plume_status plume_bending_term_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                       const double *rest_x, plume_term *out, plume_err *err)
{
    plume_status st = PLUME_OK;
    bend_ctx *ctx = NULL;
    plume_index *vstart = NULL, *vtri = NULL;
    if (out)
        memset(out, 0, sizeof *out);
    if (!mesh || !mats || !out)
        return plume_err_set(err, PLUME_EINVAL, "bending: NULL mesh, materials or output");
    if ((st = check_inputs(mesh, mats, nmat, rest_x, err)) != PLUME_OK)
        return st;

    const plume_index nh = mesh->nh, nv = mesh->nv, nt = mesh->nt;
    ctx = calloc(1, sizeof *ctx);
    vstart = calloc((size_t)(nv + 2), sizeof *vstart);
    vtri = malloc((size_t)(3 * nt + 1) * sizeof *vtri);
    if (!ctx || !vstart || !vtri) {
        st = plume_err_set(err, PLUME_ENOMEM, "bending: out of memory");
        goto cleanup;
    }
    ctx->nh = nh;
    ctx->stencil = malloc((size_t)(4 * nh + 1) * sizeof *ctx->stencil);
    ctx->hinge = malloc((size_t)(nh + 1) * sizeof *ctx->hinge);
    if (!ctx->stencil || !ctx->hinge) {
        st = plume_err_set(err, PLUME_ENOMEM, "bending: out of memory");
        goto cleanup;
    }
    vertex_triangles(mesh, vstart, vtri);

    for (plume_index h = 0; h < nh; h++) {
        plume_index *sv = ctx->stencil + 4 * h, tA = -1, tB = -1;
        if ((st = hinge_stencil(mesh, vstart, vtri, h, sv, &tA, &tB, err)) != PLUME_OK ||
            (st = hinge_stiffness(mesh, mats, h, sv, tA, tB, &ctx->hinge[h].kappa, err)) != PLUME_OK)
            goto cleanup;
        ctx->hinge[h].theta0 = 0.0;
        if (rest_x) {
            hinge_geom G;
            hinge_geometry(rest_x + 3 * sv[0], rest_x + 3 * sv[1], rest_x + 3 * sv[2], rest_x + 3 * sv[3], &G);
            if (G.collapsed) {
                st = plume_err_set(err, PLUME_EINVAL,
                                   "bending: hinge %ld: triangle %ld or %ld is degenerate in rest_x", (long)h,
                                   (long)tA, (long)tB);
                goto cleanup;
            }
            ctx->hinge[h].theta0 = G.theta;
        }
    }

    out->name = "bending";
    out->arity = 4;
    out->nstencil = nh;
    out->stencil = ctx->stencil;
    out->size = sizeof *out;
    out->eval = bending_eval;
    out->energies = bending_energies;
    out->destroy = bending_destroy;
    out->ctx = ctx;
    ctx = NULL;

cleanup:
    bending_destroy(ctx);
    free(vstart);
    free(vtri);
    return st;
}

plume_status plume_plate_moduli_check(const plume_bending_material *mats, int nmat, const char *term, plume_err *err)
{
    for (int i = 0; i < nmat; i++) {
        const plume_bending_material *b = &mats[i];
        const char *names[4] = {"D_long", "D_trans", "D_twist", "D_coupling"};
        const double vals[4] = {b->D_long, b->D_trans, b->D_twist, b->D_coupling};
        for (int f = 0; f < 4; f++)
            if (!(isfinite(vals[f]) && vals[f] >= 0.0))
                return plume_err_set(err, PLUME_EINVAL, "%s: material %d: %s must be finite and >= 0 (got %g)", term, i,
                                     names[f], vals[f]);
        if (b->D_coupling * b->D_coupling > b->D_long * b->D_trans * (1.0 + 1e-12))
            return plume_err_set(err, PLUME_EINVAL,
                                 "%s: material %d: D_coupling (%g) must not exceed sqrt(D_long D_trans) (%g): the plate "
                                 "would not be positive semidefinite",
                                 term, i, b->D_coupling, sqrt(b->D_long * b->D_trans));
    }
    return PLUME_OK;
}
