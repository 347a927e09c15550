/* The face kernel of the midedge bending term (midedge_bending.h): one triangle's energy, gradient
 * and Hessian in its 9 vertex coordinates and 3 edge angles. Morley's triangle on the current
 * face (docs/theory-bending-midedge.md has the derivation, the patch test and the choices).
 *
 * The director. Edge e = (a, b) (mesh->edges, a < b) carries an angle theta_e and a reference
 * vector r0_e (unit, perpendicular to the edge when it was set). With t the current unit edge
 * vector,
 *     d = cos(theta) (r0 - (r0 . t) t) + sin(theta) (t x r0),
 * both parts perpendicular to t and of equal length sqrt(1 - (r0 . t)^2): d is a director of the
 * edge (a normal of the surface at its midpoint), |d| times a unit one. Nothing but the edge's own
 * vertices enters, so a triangle reads the director of each of its edges from its own vertices
 * and the angle: that is what keeps the stencil at 3 vertices + 3 angles. The frame degenerates
 * only when the edge turns onto r0; plume_midedge_bending_lag re-bases r0 before that can happen.
 *
 * The slope. In triangle T (vertices x0, x1, x2, normal n), slot k is the edge opposite x_k with
 * outward unit material normal N_k. The surface at the edge's midpoint has the tangent plane
 * perpendicular to d; its tangent along N_k, written g_k + s n with g_k = F N_k the triangle's
 * own image of N_k (in T's plane), is perpendicular to d when
 *     s_k = -(g_k . d) / (n . d),
 * the slope of the surface above T's plane across edge k, per unit material length. It is
 * homogeneous of degree 0 in d, so |d| never matters. By the divergence theorem on T
 * (cell_plate.c's Morley operator, with T's vertices at height 0 above T's plane),
 *     A II = sum_k l_k s_k N_k N_k^T,
 * and kappa = (k11, k22, k12) in the barb frame is B s with B constant per triangle: the energy
 * 1/2 (s - s0)^T K (s - s0), K = A B^T Dv B.
 *
 * Derivatives. s = phi(n, g, d) = -P / Q with P = g . d, Q = n . d; n depends on the three
 * vertices, g linearly on them, d on the edge's two vertices and theta. Then
 *     grad s = J^T grad phi,   Hess s = J^T Hess phi J + Hess n[phi_n] + Hess d[phi_d],
 * J the Jacobian of z = (n, g, d) and Hess v[u] the Hessian of u . v for fixed u. The unit-vector
 * Hessians come from one formula: for f(V) = u . V / |V|, with v = V / |V|,
 *     Hess f = (-(u v^T + v u^T) - (u . v)(I - 3 v v^T)) / |V|^2,
 * applied to n = N / |N| (N = e1 x e2 is bilinear: it adds p . (de1 x de2), p = grad_N f) and
 * to t = E / |E|. The face's Hessian is sum K_kl grad s_k grad s_l^T + sum f_k Hess s_k, with
 * f = K (s - s0); projected, the first sum alone (Gauss-Newton, PSD since K is). Hess n[u] is
 * linear in u and the same triangle's for all three slopes, so it is added once, for
 * u = sum f_k phi_n,k, instead of once a slope (its 9x9x9 products are the kernel's largest).
 *
 * No allocation: everything lives on the stack. */
#include "midedge_bending.h"
#include "../../lib/core/vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A current triangle with |N|^2 <= this * |e1|^2 |e2|^2 has no normal. */
#define MIDEDGE_COLLAPSED_REL 1e-28

/* Coefficients of e1 = x1 - x0 and e2 = x2 - x0 on the vertices. */
static const double S1[3] = {-1.0, 1.0, 0.0}, S2[3] = {-1.0, 0.0, 1.0};

static void skew(const double v[3], double S[3][3])
{
    S[0][0] = 0.0, S[0][1] = -v[2], S[0][2] = v[1];
    S[1][0] = v[2], S[1][1] = 0.0, S[1][2] = -v[0];
    S[2][0] = -v[1], S[2][1] = v[0], S[2][2] = 0.0;
}

/* Hessian of u . V / |V| in V (see the top), v = V / |V|, len = |V|. */
static void unit_hessian(const double u[3], const double v[3], double len, double H[3][3])
{
    const double uv = dot3(u, v), s = 1.0 / (len * len);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            H[i][j] = s * (-(u[i] * v[j] + v[i] * u[j]) - uv * ((i == j) - 3.0 * v[i] * v[j]));
}

/* The triangle's current normal and its Jacobian: Jn[a] = dn/dx_a (3x3). -1 if collapsed. */
typedef struct {
    double e1[3], e2[3], N[3], L, n[3];
    double JN[3][3][3], Jn[3][3][3];
} face_geom;

static int face_geometry(const double xv[9], face_geom *G)
{
    sub3(xv + 3, xv, G->e1);
    sub3(xv + 6, xv, G->e2);
    cross3(G->e1, G->e2, G->N);
    const double L2 = dot3(G->N, G->N);
    if (!(L2 > MIDEDGE_COLLAPSED_REL * dot3(G->e1, G->e1) * dot3(G->e2, G->e2)) || !isfinite(L2))
        return -1;
    G->L = sqrt(L2);
    for (int i = 0; i < 3; i++)
        G->n[i] = G->N[i] / G->L;
    double A1[3][3], A2[3][3]; /* dN/de1 = -[e2]x, dN/de2 = [e1]x */
    skew(G->e2, A1);
    skew(G->e1, A2);
    for (int a = 0; a < 3; a++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                G->JN[a][i][j] = -S1[a] * A1[i][j] + S2[a] * A2[i][j];
    for (int a = 0; a < 3; a++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double s = 0.0;
                for (int m = 0; m < 3; m++)
                    s += ((i == m) - G->n[i] * G->n[m]) * G->JN[a][m][j];
                G->Jn[a][i][j] = s / G->L;
            }
    return 0;
}

/* An edge's director at angle th: d, its derivative in th (dd), and what its Hessian needs. */
typedef struct {
    double t[3], len, rt, c, s;
    double av[3], bv[3], d[3], dd[3];
    double Jt[3][3]; /* dt/dE */
    double JdE[3][3]; /* dd/dE */
} edge_dir;

static int edge_director(const double E[3], double th, const double r0[3], edge_dir *D)
{
    D->len = sqrt(dot3(E, E));
    if (!(D->len > 0.0))
        return -1;
    for (int i = 0; i < 3; i++)
        D->t[i] = E[i] / D->len;
    D->rt = dot3(D->t, r0);
    D->c = cos(th), D->s = sin(th);
    for (int i = 0; i < 3; i++)
        D->av[i] = r0[i] - D->rt * D->t[i];
    cross3(D->t, r0, D->bv);
    if (!(sqrt(dot3(D->av, D->av)) >= MIDEDGE_MIN_FRAME))
        return -1;
    for (int i = 0; i < 3; i++) {
        D->d[i] = D->c * D->av[i] + D->s * D->bv[i];
        D->dd[i] = -D->s * D->av[i] + D->c * D->bv[i];
    }
    double R[3][3], Dt[3][3];
    skew(r0, R);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            D->Jt[i][j] = ((i == j) - D->t[i] * D->t[j]) / D->len;
            /* da/dt = -t r0^T - (r0 . t) I, db/dt = -[r0]x */
            Dt[i][j] = D->c * (-D->t[i] * r0[j] - D->rt * (i == j)) - D->s * R[i][j];
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int m = 0; m < 3; m++)
                s += Dt[i][m] * D->Jt[m][j];
            D->JdE[i][j] = s;
        }
    return 0;
}

/* Adds Hess n[u] (the Hessian of u . n in the three vertices) to the 9x9 vertex part of a 12x12
 * block H: through N = e1 x e2 with the unit-vector Hessian, plus N's bilinear part
 * p . (de1 x de2), p the gradient of u . n in N. */
static void add_normal_hessian(const face_geom *G, const double u[3], double *H)
{
    double Hf[3][3], p[3], M12[3][3];
    const double un = dot3(u, G->n);
    unit_hessian(u, G->n, G->L, Hf);
    for (int i = 0; i < 3; i++)
        p[i] = (u[i] - un * G->n[i]) / G->L;
    skew(p, M12);
    /* the upper triangle, mirrored, so that H stays exactly symmetric */
    for (int r = 0; r < 9; r++)
        for (int c = r; c < 9; c++) {
            const int a = r / 3, i = r % 3, b = c / 3, j = c % 3;
            double v = 0.0;
            for (int m = 0; m < 3; m++)
                for (int q = 0; q < 3; q++)
                    v += G->JN[a][m][i] * Hf[m][q] * G->JN[b][q][j];
            /* p . (de1 x de2) = de1^T (-[p]x) de2 */
            v += -S1[a] * S2[b] * M12[i][j] - S2[a] * S1[b] * M12[j][i];
            H[12 * r + c] += v;
            if (c != r)
                H[12 * c + r] += v;
        }
}

/* Slot k's slope, and its gradient gs[12] and Hessian Hs[144] (when non-NULL) in the face's
 * variables (x0, x1, x2, th_0, th_1, th_2); the caller zeroes gs and Hs. Hs leaves out the
 * normal's part Hess n[phi_n], written to un: it is linear in phi_n, so the face adds it once
 * for the weighted sum of its three slopes (add_normal_hessian), not three times. */
static int slot_slope(const plume_midedge_face *f, const double xv[9], const face_geom *G, int k, double th,
                      const double r0[3], double *sk, double *gs, double *Hs, double un[3])
{
    const int va = (k + 1) % 3, vb = (k + 2) % 3;
    double ec[3] = {0.0, 0.0, 0.0}; /* E = sigma (x_vb - x_va) */
    ec[va] = -f->sigma[k], ec[vb] = f->sigma[k];
    double E[3];
    for (int i = 0; i < 3; i++)
        E[i] = f->sigma[k] * (xv[3 * vb + i] - xv[3 * va + i]);
    edge_dir D;
    if (edge_director(E, th, r0, &D) != 0)
        return -1;
    double g[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            g[i] += f->c[k][j] * xv[3 * j + i];
    const double P = dot3(g, D.d), Q = dot3(G->n, D.d);
    if (!(Q >= MIDEDGE_MIN_COS * sqrt(dot3(D.av, D.av))))
        return -1;
    const double s = -P / Q;
    *sk = s;
    if (!gs)
        return 0;
    /* grad phi in z = (n, g, d) */
    double phi[9];
    for (int i = 0; i < 3; i++) {
        phi[i] = -s * D.d[i] / Q;
        phi[3 + i] = -D.d[i] / Q;
        phi[6 + i] = -(g[i] + s * G->n[i]) / Q;
    }
    /* J: 9 rows (z) x 10 columns (x0, x1, x2, th) */
    double J[9][10];
    memset(J, 0, sizeof J);
    for (int a = 0; a < 3; a++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                J[i][3 * a + j] = G->Jn[a][i][j];
                J[3 + i][3 * a + j] = (i == j) * f->c[k][a];
                J[6 + i][3 * a + j] = ec[a] * D.JdE[i][j];
            }
    for (int i = 0; i < 3; i++)
        J[6 + i][9] = D.dd[i];
    double gl[10];
    for (int c = 0; c < 10; c++) {
        double v = 0.0;
        for (int r = 0; r < 9; r++)
            v += phi[r] * J[r][c];
        gl[c] = v;
    }
    for (int c = 0; c < 9; c++)
        gs[c] = gl[c];
    gs[9 + k] = gl[9];
    if (!Hs)
        return 0;
    for (int i = 0; i < 3; i++)
        un[i] = phi[i];
    /* Hess phi: -P_ab/Q + (P_a Q_b + P_b Q_a)/Q^2 - s Q_ab/Q + 2 s Q_a Q_b/Q^2, with
     * grad P = (0, d, g), grad Q = (d, 0, n), P_ab = I on (g, d), Q_ab = I on (n, d). Its image
     * J^T Hess phi J is taken term by term, never as a 9x9 matrix: with jp = J^T grad P and
     * jq = J^T grad Q, the rank-one parts are (jp jq^T + jq jp^T + 2 s jq jq^T) / Q^2, and the
     * identity blocks give -(M + M^T), M = W^T J_d with W = (J_g + s J_n) / Q (J_n, J_g, J_d the
     * rows of J for n, g and d). */
    double Pa[9], Qa[9], jp[10], jq[10], W[3][10], Hl[10][10];
    for (int i = 0; i < 3; i++) {
        Pa[i] = 0.0, Pa[3 + i] = D.d[i], Pa[6 + i] = g[i];
        Qa[i] = D.d[i], Qa[3 + i] = 0.0, Qa[6 + i] = G->n[i];
    }
    for (int c = 0; c < 10; c++) {
        double vp = 0.0, vq = 0.0;
        for (int r = 0; r < 9; r++)
            vp += Pa[r] * J[r][c], vq += Qa[r] * J[r][c];
        jp[c] = vp, jq[c] = vq;
        for (int i = 0; i < 3; i++)
            W[i][c] = (J[3 + i][c] + s * J[i][c]) / Q;
    }
    const double q2 = 1.0 / (Q * Q);
    for (int a = 0; a < 10; a++)
        for (int b = a; b < 10; b++) {
            double v = q2 * (jp[a] * jq[b] + jq[a] * jp[b] + 2.0 * s * jq[a] * jq[b]);
            for (int i = 0; i < 3; i++)
                v -= W[i][a] * J[6 + i][b] + W[i][b] * J[6 + i][a];
            Hl[a][b] = Hl[b][a] = v;
        }
    /* Hess d[phi_d] in (E, th), then onto the edge's vertices */
    {
        const double *u = phi + 6;
        const double tu = dot3(D.t, u), ud = dot3(u, D.d);
        double rxu[3], pt[3], ptth[3], Htt[3][3], HE[3][3], Hu[3][3];
        cross3(r0, u, rxu);
        for (int i = 0; i < 3; i++) {
            const double base = -r0[i] * tu - D.rt * u[i];
            pt[i] = D.c * base + D.s * rxu[i];    /* d(u . d)/dt */
            ptth[i] = -D.s * base + D.c * rxu[i]; /* its derivative in th */
        }
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                Htt[i][j] = -D.c * (r0[i] * u[j] + u[i] * r0[j]);
        unit_hessian(pt, D.t, D.len, Hu);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double v = 0.0;
                for (int m = 0; m < 3; m++)
                    for (int q = 0; q < 3; q++)
                        v += D.Jt[m][i] * Htt[m][q] * D.Jt[q][j];
                HE[i][j] = v + Hu[i][j];
            }
        double HEth[3];
        for (int i = 0; i < 3; i++) {
            double v = 0.0;
            for (int m = 0; m < 3; m++)
                v += D.Jt[m][i] * ptth[m];
            HEth[i] = v;
        }
        for (int a = 0; a < 3; a++) {
            if (ec[a] == 0.0)
                continue;
            for (int i = 0; i < 3; i++) {
                for (int b = 0; b < 3; b++)
                    for (int j = 0; j < 3; j++)
                        Hl[3 * a + i][3 * b + j] += ec[a] * ec[b] * HE[i][j];
                Hl[3 * a + i][9] += ec[a] * HEth[i];
                Hl[9][3 * a + i] += ec[a] * HEth[i];
            }
        }
        Hl[9][9] += -ud;
    }
    const int map[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9 + k};
    for (int a = 0; a < 10; a++)
        for (int b = 0; b < 10; b++)
            Hs[12 * map[a] + map[b]] = Hl[a][b];
    return 0;
}

int plume_midedge_director(const double E[3], double th, const double r0[3], double d[3])
{
    edge_dir D;
    if (edge_director(E, th, r0, &D) != 0)
        return -1;
    const double a = sqrt(dot3(D.av, D.av));
    for (int i = 0; i < 3; i++)
        d[i] = D.d[i] / a;
    return 0;
}

double plume_midedge_angle(const double E[3], const double r0[3], const double d[3])
{
    /* av and bv have the same length, so their dot products with d give the angle directly */
    const double len = sqrt(dot3(E, E));
    double t[3], bv[3], av[3];
    for (int i = 0; i < 3; i++)
        t[i] = E[i] / len;
    const double rt = dot3(t, r0);
    for (int i = 0; i < 3; i++)
        av[i] = r0[i] - rt * t[i];
    cross3(t, r0, bv);
    return atan2(dot3(d, bv), dot3(d, av));
}

int plume_midedge_face_slope(const plume_midedge_face *f, const double xv[9], int k, double th, const double r0[3],
                             double *s)
{
    face_geom G;
    if (k < 0 || k > 2 || face_geometry(xv, &G) != 0)
        return -1;
    return slot_slope(f, xv, &G, k, th, r0, s, NULL, NULL, NULL);
}

int plume_midedge_face_eval(const plume_midedge_face *f, const double xv[9], const double th[3],
                            const double *const r0[3], double *E, double g[12], double H[144], int project)
{
    face_geom G;
    if (face_geometry(xv, &G) != 0)
        return -1;
    const int need_grad = g || H, need_hs = H && !project;
    double s[3], gs[3][12], Hs[3][144], un[3][3];
    for (int k = 0; k < 3; k++) {
        if (need_grad)
            memset(gs[k], 0, sizeof gs[k]);
        if (need_hs)
            memset(Hs[k], 0, sizeof Hs[k]);
        if (slot_slope(f, xv, &G, k, th[k], r0[k], &s[k], need_grad ? gs[k] : NULL, need_hs ? Hs[k] : NULL, un[k]) != 0)
            return -1;
    }
    double r[3], fk[3];
    for (int k = 0; k < 3; k++)
        r[k] = s[k] - f->s0[k];
    for (int k = 0; k < 3; k++)
        fk[k] = f->K[3 * k] * r[0] + f->K[3 * k + 1] * r[1] + f->K[3 * k + 2] * r[2];
    if (E)
        *E = 0.5 * (r[0] * fk[0] + r[1] * fk[1] + r[2] * fk[2]);
    if (g)
        for (int c = 0; c < 12; c++)
            g[c] = fk[0] * gs[0][c] + fk[1] * gs[1][c] + fk[2] * gs[2][c];
    if (H) {
        double KJ[3][12];
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 12; c++)
                KJ[k][c] = f->K[3 * k] * gs[0][c] + f->K[3 * k + 1] * gs[1][c] + f->K[3 * k + 2] * gs[2][c];
        for (int a = 0; a < 12; a++)
            for (int b = a; b < 12; b++) {
                double v = gs[0][a] * KJ[0][b] + gs[1][a] * KJ[1][b] + gs[2][a] * KJ[2][b];
                if (need_hs)
                    v += fk[0] * Hs[0][12 * a + b] + fk[1] * Hs[1][12 * a + b] + fk[2] * Hs[2][12 * a + b];
                H[12 * a + b] = H[12 * b + a] = v;
            }
        if (need_hs) {
            double u[3];
            for (int i = 0; i < 3; i++)
                u[i] = fk[0] * un[0][i] + fk[1] * un[1][i] + fk[2] * un[2][i];
            add_normal_hessian(&G, u, H);
        }
    }
    return 0;
}
