/* plume (private, not installed): the membrane material law of lib/core/membrane.h as the elements use
 * it, shared by the linear (lib/core/membrane.c) and quadratic (lib/core/membrane_p2.c) triangles: the
 * energy density per unit volume of G = F R (F in the barb frame), its gradient and its Hessian in
 * closed form. Static inline so each element loop keeps it inlined. */
#ifndef PLUME_INTERNAL_MEMBRANE_LAW_H
#define PLUME_INTERNAL_MEMBRANE_LAW_H

#include <float.h>
#include <math.h>

#include "../membrane.h"
#include "../vec3.h"

/* Below this area ratio the current triangle is collapsed and the second derivative of J, which
 * divides by J, is dropped; the first derivative (a unit normal) stays well defined down to 0. */
#define MEMBRANE_J_TINY 1e-14

/* A reference triangle whose doubled area is below this fraction of its squared edge lengths is
 * degenerate up to rounding (collinear points computed in floating point): Dm^-1 would be noise.
 * Both elements reject their reference triangles by this one test. */
#define MEMBRANE_DEGENERATE_REL (64.0 * DBL_EPSILON)

/* A material as the element uses it: the plane-stress tensor C in the barb frame (Voigt order E11,
 * E22, 2E12; docs/design.md, membrane energy). An orthotropic material has C13 = C23 = 0; a
 * monoclinic one (a cell with inclined barbules, docs/monoclinic-vane.md) couples the normal
 * strains and the shear through them. */
typedef struct {
    double C11, C12, C22, C33, C13, C23;
    double kappa; /* compression coefficient (Pa) */
    int log_barrier;
} plume_membrane_law;

/* The law of a material; C (row-major 3x3, or NULL) replaces the tensor of its moduli. */
static inline void plume_membrane_law_set_tensor(const plume_membrane_material *mat, const double *C,
                                                 plume_membrane_law *m)
{
    double Co[9];
    if (!C) {
        plume_membrane_stiffness(mat, Co);
        C = Co;
    }
    m->C11 = C[0];
    m->C12 = C[1];
    m->C13 = C[2];
    m->C22 = C[4];
    m->C23 = C[5];
    m->C33 = C[8];
    m->kappa = mat->kappa;
    m->log_barrier = mat->log_barrier;
}

static inline void plume_membrane_law_set(const plume_membrane_material *mat, plume_membrane_law *m)
{
    plume_membrane_law_set_tensor(mat, NULL, m);
}

/* Density per unit volume psi(G) (without h) for the columns g[0], g[1] of G (3-vectors, z = 0 in
 * planar mode). P (if non-NULL): dpsi/dg_c. HG (if non-NULL): Hessian, (2 dim)^2 row-major, the
 * entry G[i][c] having index c*dim + i.
 *
 * With e = (E11, E22, 2E12) and s = C e, a unit change of G[i][c] changes e by
 * v_(0,i) = (g0_i, 0, g1_i), v_(1,i) = (0, g1_i, g0_i), so the Hessian blocks (dim x dim) are
 *   H00 = C11 g0 g0^T + C13 (g0 g1^T + g1 g0^T) + C33 g1 g1^T + s0 I,
 *   H11 = C22 g1 g1^T + C23 (g1 g0^T + g0 g1^T) + C33 g0 g0^T + s1 I,
 *   H01 = C12 g0 g1^T + C13 g0 g0^T + C23 g1 g1^T + C33 g1 g0^T + s2 I
 *   (v_a . C v_b plus the geometric term S : e_a^T e_b, S = [[s0, s2], [s2, s1]] the second
 *   Piola-Kirchhoff stress in the barb frame).
 * For J = |n|, n = g0 x g1, n^ = n/J: dJ/dg0 = g1 x n^, dJ/dg1 = n^ x g0 and
 *   d2J = (dn_a . dn_b - dJ_a dJ_b) / J + n^ . (e_i x e_j) [mixed columns only], with
 *   dn_(0,i) . dn_(0,j) = d_ij |g1|^2 - g1_i g1_j,  dn_(1,i) . dn_(1,j) = d_ij |g0|^2 - g0_i g0_j,
 *   dn_(0,i) . dn_(1,j) = g0_i g1_j - d_ij g0.g1.
 * g is read only; it is not const-qualified because C11 does not convert double (*)[3] to
 * const double (*)[3] implicitly. */
static inline double plume_membrane_law_density_G(const plume_membrane_law *m, const int dim, double g[2][3],
                                                  double P[2][3], double *HG)
{
    const double *g0 = g[0], *g1 = g[1];
    const double c11 = dot3(g0, g0), c22 = dot3(g1, g1), c12 = dot3(g0, g1);
    const double e0 = 0.5 * (c11 - 1.0), e1 = 0.5 * (c22 - 1.0), e2 = c12;
    const double s0 = m->C11 * e0 + m->C12 * e1 + m->C13 * e2, s1 = m->C12 * e0 + m->C22 * e1 + m->C23 * e2,
                 s2 = m->C13 * e0 + m->C23 * e1 + m->C33 * e2;
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
    } else if (comp) {
        const double t = (1.0 - J) / 6.0;
        psi += m->kappa / 12.0 * t * t * t;
        dpc = -m->kappa * t * t * (1.0 / 24.0); /* d psi_c / dJ */
        ddpc = m->kappa * t * (1.0 / 72.0);     /* d2 psi_c / dJ2 */
    }
    if (comp && J > 0.0) { /* the unit normal and dJ/dg0, dJ/dg1 */
        const double iJ = 1.0 / J;
        for (int k = 0; k < 3; k++)
            nh[k] = n[k] * iJ;
        cross3(g1, nh, dJ0);
        cross3(nh, g0, dJ1);
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
                const double x01 = g0[i] * g1[j] + g1[i] * g0[j];
                double h00 = m->C11 * g0[i] * g0[j] + m->C13 * x01 + m->C33 * g1[i] * g1[j] + s0 * dij;
                double h11 = m->C22 * g1[i] * g1[j] + m->C23 * x01 + m->C33 * g0[i] * g0[j] + s1 * dij;
                double h01 = m->C12 * g0[i] * g1[j] + m->C13 * g0[i] * g0[j] + m->C23 * g1[i] * g1[j] +
                             m->C33 * g1[i] * g0[j] + s2 * dij;
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

#endif
