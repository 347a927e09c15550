/* The quadratic (6-node) planar membrane element: the law of lib/core/membrane.c
 * (lib/core/internal/membrane_law.h) on straight-sided quadratic triangles.
 *
 * At each of the 6 points of the degree-4 rule, G = F R = sum_a x_a dN_a^T with dN_a the
 * shape-function gradients rotated into the barb frame (precomputed at create, like membrane.c's
 * B = Dm^-1 R). The energy, dpsi/dG and the 4x4 Hessian in G come from the shared law; with
 * `project` each point's 4x4 Hessian is projected to PSD before it is mapped to the nodes (G -> x
 * is linear, and a sum of PSD blocks is PSD). Nothing is allocated after create. */
#include "membrane_p2.h"
#include "internal/membrane_law.h"

#include "dense.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define P2_NODES 6
#define P2_QP 6
#define P2_DOFS (2 * P2_NODES)

/* A mid-edge node further than this fraction of its edge's length from the midpoint is not a
 * mid-edge node (the element assumes straight sides with midpoint nodes). */
#define MEMBRANE_P2_MID_REL 1e-12

/* The symmetric 6-point degree-4 rule (Strang & Fix 1973; Dunavant 1985) in barycentric
 * coordinates: the orbits of (1 - 2a, a, a) with, in closed form,
 * a = (8 - sqrt(10) +- sqrt(38 - 44 sqrt(2/5))) / 18, w = (620 +- sqrt(213125 - 53320 sqrt(10))) / 3720
 * (weights per unit area, summing to 1). */
static const double P2_QL[P2_QP][3] = {
    {0.10810301816807022736, 0.44594849091596488632, 0.44594849091596488632},
    {0.44594849091596488632, 0.10810301816807022736, 0.44594849091596488632},
    {0.44594849091596488632, 0.44594849091596488632, 0.10810301816807022736},
    {0.81684757298045851308, 0.09157621350977074346, 0.09157621350977074346},
    {0.09157621350977074346, 0.81684757298045851308, 0.09157621350977074346},
    {0.09157621350977074346, 0.09157621350977074346, 0.81684757298045851308}};
static const double P2_QW[P2_QP] = {0.2233815896780114657, 0.2233815896780114657, 0.2233815896780114657,
                                    0.10995174365532186764, 0.10995174365532186764, 0.10995174365532186764};

typedef struct {
    double dN[P2_QP][P2_NODES][2]; /* shape-function gradients in the barb frame at each point */
    double wAh[P2_QP];             /* weight times reference area times thickness */
    int mat;
} p2_tri;

typedef struct {
    plume_index nt;
    plume_index *stencil;    /* [6*nt] */
    p2_tri *tri;             /* [nt] */
    plume_membrane_law *mat; /* [nmat] */
} p2_ctx;

/* G at point q of triangle tr, from differences to node 0 so that a large common translation
 * adds no rounding */
static void p2_G(const p2_tri *tr, int q, const double *x, const plume_index *vid, double g[2][3])
{
    const double *x0 = x + 2 * vid[0];
    for (int c = 0; c < 2; c++)
        g[c][0] = g[c][1] = g[c][2] = 0.0;
    for (int a = 1; a < P2_NODES; a++) {
        const double *xa = x + 2 * vid[a], *d = tr->dN[q][a];
        for (int i = 0; i < 2; i++) {
            const double u = xa[i] - x0[i];
            g[0][i] += u * d[0];
            g[1][i] += u * d[1];
        }
    }
}

/* Adds wAh * dN^T HG dN to the upper triangle of the 12x12 block H (HG: 4x4, index c*2 + i). */
static void p2_add_block(const double dN[P2_NODES][2], double wAh, const double HG[16], double *H)
{
    double M[4][P2_DOFS]; /* M[p][(b, j)] = sum_d HG[p][(d, j)] dN_b[d] */
    for (int p = 0; p < 4; p++)
        for (int b = 0; b < P2_NODES; b++)
            for (int j = 0; j < 2; j++)
                M[p][2 * b + j] = HG[4 * p + j] * dN[b][0] + HG[4 * p + 2 + j] * dN[b][1];
    for (int a = 0; a < P2_NODES; a++) {
        const double u0 = wAh * dN[a][0], u1 = wAh * dN[a][1];
        for (int i = 0; i < 2; i++) {
            const int r = 2 * a + i;
            for (int s = r; s < P2_DOFS; s++)
                H[r * P2_DOFS + s] += u0 * M[i][s] + u1 * M[2 + i][s];
        }
    }
}

static plume_status p2_eval(void *vctx, int dim, const double *x, double *energy, double *grad,
                            double *hblocks, int project)
{
    const p2_ctx *ctx = vctx;
    if (!ctx || !x || dim != 2)
        return PLUME_EINVAL;
    double E = 0.0;
    for (plume_index t = 0; t < ctx->nt; t++) {
        const p2_tri *tr = &ctx->tri[t];
        const plume_index *vid = ctx->stencil + P2_NODES * t;
        const plume_membrane_law *law = &ctx->mat[tr->mat];
        double *H = hblocks ? hblocks + (size_t)t * P2_DOFS * P2_DOFS : NULL;
        if (H)
            memset(H, 0, sizeof(double) * P2_DOFS * P2_DOFS);
        for (int q = 0; q < P2_QP; q++) {
            double g[2][3], P[2][3], HG[16];
            p2_G(tr, q, x, vid, g);
            const double wAh = tr->wAh[q];
            E += wAh * plume_membrane_law_density_G(law, 2, g, grad ? P : NULL, H ? HG : NULL);
            if (grad) {
                for (int a = 0; a < P2_NODES; a++) {
                    const double *d = tr->dN[q][a];
                    double *ga = grad + 2 * vid[a];
                    for (int i = 0; i < 2; i++)
                        ga[i] += wAh * (d[0] * P[0][i] + d[1] * P[1][i]);
                }
            }
            if (H) {
                if (project)
                    plume_dense_project_psd(4, HG);
                p2_add_block(tr->dN[q], wAh, HG, H);
            }
        }
        if (H) /* mirrored from the upper triangle: exactly symmetric */
            for (int r = 1; r < P2_DOFS; r++)
                for (int s = 0; s < r; s++)
                    H[r * P2_DOFS + s] = H[s * P2_DOFS + r];
    }
    if (energy)
        *energy += E;
    return PLUME_OK;
}

static plume_status p2_energies(void *vctx, int dim, const double *x, double *e)
{
    const p2_ctx *ctx = vctx;
    if (!ctx || !x || !e || dim != 2)
        return PLUME_EINVAL;
    for (plume_index t = 0; t < ctx->nt; t++) {
        const p2_tri *tr = &ctx->tri[t];
        const plume_index *vid = ctx->stencil + P2_NODES * t;
        double s = 0.0;
        for (int q = 0; q < P2_QP; q++) {
            double g[2][3];
            p2_G(tr, q, x, vid, g);
            s += tr->wAh[q] * plume_membrane_law_density_G(&ctx->mat[tr->mat], 2, g, NULL, NULL);
        }
        e[t] = s;
    }
    return PLUME_OK;
}

static void p2_destroy(void *vctx)
{
    p2_ctx *ctx = vctx;
    if (!ctx)
        return;
    free(ctx->stencil);
    free(ctx->tri);
    free(ctx->mat);
    free(ctx);
}

/* Checks triangle t's reference geometry and fills its quadrature data; PLUME_EINVAL naming the
 * triangle otherwise. v: its 6 node ids (in range). */
static plume_status p2_tri_setup(const double *X, const plume_index *v, const double bd[2], double h,
                                 plume_index t, p2_tri *tr, plume_err *err)
{
    const double *X0 = X + 2 * v[0], *X1 = X + 2 * v[1], *X2 = X + 2 * v[2];
    const double d00 = X1[0] - X0[0], d01 = X2[0] - X0[0]; /* Dm = [X1-X0, X2-X0] */
    const double d10 = X1[1] - X0[1], d11 = X2[1] - X0[1];
    const double det = d00 * d11 - d01 * d10;
    const double area = 0.5 * fabs(det);
    const double scale = d00 * d00 + d10 * d10 + d01 * d01 + d11 * d11 + (d01 - d00) * (d01 - d00) +
                         (d11 - d10) * (d11 - d10);
    if (!isfinite(area) || !isfinite(scale) || !(fabs(det) > MEMBRANE_DEGENERATE_REL * scale))
        return plume_err_set(err, PLUME_EINVAL,
                             "membrane_p2: triangle %ld: degenerate reference triangle (area %g)", (long)t, area);
    for (int e = 0; e < 3; e++) {
        /* a midpoint computed in floating point far from the origin is off by the rounding of
         * the coordinates, whatever the edge length: that much is allowed too */
        const double *A = X + 2 * v[e], *B = X + 2 * v[(e + 1) % 3], *M = X + 2 * v[3 + e];
        const double len = hypot(B[0] - A[0], B[1] - A[1]);
        const double off = hypot(M[0] - 0.5 * (A[0] + B[0]), M[1] - 0.5 * (A[1] + B[1]));
        const double ulp = 4.0 * DBL_EPSILON * fmax(fmax(fabs(A[0]), fabs(A[1])), fmax(fabs(B[0]), fabs(B[1])));
        if (!(off <= MEMBRANE_P2_MID_REL * len + ulp))
            return plume_err_set(err, PLUME_EINVAL,
                                 "membrane_p2: triangle %ld: node %ld (position %d) is not the midpoint of edge "
                                 "(%ld, %ld): off by %g for an edge of length %g",
                                 (long)t, (long)v[3 + e], 3 + e, (long)v[e], (long)v[(e + 1) % 3], off, len);
    }
    double dx = bd[0], dy = bd[1];
    const double blen = hypot(dx, dy);
    if (!isfinite(blen) || !(blen > 0.0))
        return plume_err_set(err, PLUME_EINVAL,
                             "membrane_p2: triangle %ld: barb direction (%g, %g) cannot be normalised", (long)t,
                             dx, dy);
    dx /= blen;
    dy /= blen;
    /* the barycentric gradients in the barb frame: rows of B = Dm^-1 R for L1, L2, R = [d, d_perp] */
    const double i00 = d11 / det, i01 = -d01 / det, i10 = -d10 / det, i11 = d00 / det;
    double W[3][2];
    W[1][0] = i00 * dx + i01 * dy;
    W[1][1] = -i00 * dy + i01 * dx;
    W[2][0] = i10 * dx + i11 * dy;
    W[2][1] = -i10 * dy + i11 * dx;
    W[0][0] = -(W[1][0] + W[2][0]);
    W[0][1] = -(W[1][1] + W[2][1]);
    for (int q = 0; q < P2_QP; q++) {
        const double *L = P2_QL[q];
        for (int c = 0; c < 2; c++) {
            /* corners L_i (2 L_i - 1), mid-edge nodes 4 L_i L_j */
            double s = 0.0;
            for (int a = 1; a < 3; a++)
                s += tr->dN[q][a][c] = (4.0 * L[a] - 1.0) * W[a][c];
            s += tr->dN[q][3][c] = 4.0 * (L[0] * W[1][c] + L[1] * W[0][c]);
            s += tr->dN[q][4][c] = 4.0 * (L[1] * W[2][c] + L[2] * W[1][c]);
            s += tr->dN[q][5][c] = 4.0 * (L[2] * W[0][c] + L[0] * W[2][c]);
            tr->dN[q][0][c] = -s; /* = (4 L_0 - 1) W_0: the gradients sum to zero exactly */
        }
        tr->wAh[q] = P2_QW[q] * area * h;
    }
    return PLUME_OK;
}

plume_status plume_membrane_p2_term_create(const double *X, plume_index nnodes, const plume_index *tri6,
                                           plume_index nt, const int *material, const double *barb_dir,
                                           const plume_membrane_material *mats, int nmat, plume_term *out,
                                           plume_err *err)
{
    plume_status st = PLUME_OK;
    p2_ctx *ctx = NULL;
    if (out)
        memset(out, 0, sizeof *out);
    if (!mats || !out)
        return plume_err_set(err, PLUME_EINVAL, "membrane_p2: NULL materials or output");
    if (nnodes < 0 || nt < 0)
        return plume_err_set(err, PLUME_EINVAL, "membrane_p2: negative sizes (nnodes %ld, nt %ld)", (long)nnodes,
                             (long)nt);
    if (nt > 0 && (!X || !tri6 || !material || !barb_dir))
        return plume_err_set(err, PLUME_EINVAL, "membrane_p2: NULL positions, triangles, material ids or barb "
                                                "directions");
    if (nmat < 1)
        return plume_err_set(err, PLUME_EINVAL, "membrane_p2: nmat must be >= 1 (got %d)", nmat);
    for (int i = 0; i < nmat; i++) {
        plume_err e;
        if (plume_membrane_material_check(&mats[i], &e) != PLUME_OK)
            return plume_err_set(err, PLUME_EINVAL, "membrane_p2: material %d: %s", i, e.msg);
    }

    ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return plume_err_set(err, PLUME_ENOMEM, "membrane_p2: out of memory");
    ctx->nt = nt;
    ctx->stencil = malloc((size_t)(P2_NODES * nt + 1) * sizeof *ctx->stencil);
    ctx->tri = malloc((size_t)(nt + 1) * sizeof *ctx->tri);
    ctx->mat = malloc((size_t)nmat * sizeof *ctx->mat);
    if (!ctx->stencil || !ctx->tri || !ctx->mat) {
        st = plume_err_set(err, PLUME_ENOMEM, "membrane_p2: out of memory");
        goto cleanup;
    }
    for (int i = 0; i < nmat; i++)
        plume_membrane_law_set(&mats[i], &ctx->mat[i]);

    for (plume_index t = 0; t < nt; t++) {
        const plume_index *v = tri6 + P2_NODES * t;
        for (int l = 0; l < P2_NODES; l++) {
            if (v[l] < 0 || v[l] >= nnodes) {
                st = plume_err_set(err, PLUME_EINVAL,
                                   "membrane_p2: triangle %ld: node id %ld (position %d) out of range [0, %ld)",
                                   (long)t, (long)v[l], l, (long)nnodes);
                goto cleanup;
            }
            ctx->stencil[P2_NODES * t + l] = v[l];
        }
        const int mid = material[t];
        if (mid < 0 || mid >= nmat) {
            st = plume_err_set(err, PLUME_EINVAL, "membrane_p2: triangle %ld: material id %d out of range [0, %d)",
                               (long)t, mid, nmat);
            goto cleanup;
        }
        st = p2_tri_setup(X, v, barb_dir + 2 * t, mats[mid].h, t, &ctx->tri[t], err);
        if (st != PLUME_OK)
            goto cleanup;
        ctx->tri[t].mat = mid;
    }

    out->name = "membrane_p2";
    out->arity = P2_NODES;
    out->nstencil = nt;
    out->stencil = ctx->stencil;
    out->size = sizeof *out;
    out->eval = p2_eval;
    out->energies = p2_energies;
    out->destroy = p2_destroy;
    out->ctx = ctx;
    return PLUME_OK;

cleanup:
    p2_destroy(ctx);
    return st;
}
