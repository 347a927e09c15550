/* plume: narrow-phase contact mathematics (see contact_narrow.h). Each distance type is one of
 * three smooth kernels written in a few "local" difference vectors (x[i] - x[j]); the kernels
 * differentiate in those and scatter() maps the result to the 12 coordinates, so every type shares
 * the same three derivations. */
#include "contact_narrow.h"

#include <math.h>
#include <string.h>

#include "../core/dense.h"
#include "../core/vec3.h"

/* ---- small 3-vector / 3x3 helpers (row-major 3x3) ---------------------------------------- */

/* M = [a]x, the matrix of b -> a x b */
static void skew3(const double a[3], double M[9])
{
    M[0] = 0.0, M[1] = -a[2], M[2] = a[1];
    M[3] = a[2], M[4] = 0.0, M[5] = -a[0];
    M[6] = -a[1], M[7] = a[0], M[8] = 0.0;
}

/* C = A B */
static void mm3(const double A[9], const double B[9], double C[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* C = A^T B */
static void mtm3(const double A[9], const double B[9], double C[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
}

/* block (bi, bj) of an m x m row-major matrix (m = 3 * blocks) from a 3x3 B, and its transpose
 * into (bj, bi) when bi != bj */
static void put_block(double *H, int m, int bi, int bj, const double B[9])
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            H[(3 * bi + a) * m + 3 * bj + b] = B[3 * a + b];
            if (bi != bj)
                H[(3 * bj + b) * m + 3 * bi + a] = B[3 * a + b];
        }
}

static int finite12(const double *x)
{
    for (int i = 0; i < 12; i++)
        if (!isfinite(x[i]))
            return 0;
    return 1;
}

/* ---- local variables and the scatter to the 12 coordinates ------------------------------ */

/* A local variable of a kernel: x[plus] - x[minus] (vertex indices 0..3; minus < 0: none). */
typedef struct {
    int plus, minus;
} lvar;

typedef enum { K_PP, K_PL, K_PLANE } kernel_kind;

/* One distance type: its kernel and the local variables the kernel takes, in order
 * (point–point: r; point–line: r = p - e0, e = e1 - e0; plane: w, e1, e2 with n = e1 x e2). */
typedef struct {
    kernel_kind kind;
    int nv;
    lvar v[3];
} feature;

/* x = (p, t0, t1, t2) */
static const feature pt_features[PLUME_CONTACT_PT_NTYPES] = {
    [PLUME_CONTACT_PT_T0] = {K_PP, 1, {{0, 1}}},
    [PLUME_CONTACT_PT_T1] = {K_PP, 1, {{0, 2}}},
    [PLUME_CONTACT_PT_T2] = {K_PP, 1, {{0, 3}}},
    [PLUME_CONTACT_PT_E01] = {K_PL, 2, {{0, 1}, {2, 1}}},
    [PLUME_CONTACT_PT_E12] = {K_PL, 2, {{0, 2}, {3, 2}}},
    [PLUME_CONTACT_PT_E20] = {K_PL, 2, {{0, 3}, {1, 3}}},
    [PLUME_CONTACT_PT_FACE] = {K_PLANE, 3, {{0, 1}, {2, 1}, {3, 1}}},
};

/* x = (ea0, ea1, eb0, eb1) */
static const feature ee_features[PLUME_CONTACT_EE_NTYPES] = {
    [PLUME_CONTACT_EE_A0B0] = {K_PP, 1, {{0, 2}}},
    [PLUME_CONTACT_EE_A0B1] = {K_PP, 1, {{0, 3}}},
    [PLUME_CONTACT_EE_A1B0] = {K_PP, 1, {{1, 2}}},
    [PLUME_CONTACT_EE_A1B1] = {K_PP, 1, {{1, 3}}},
    [PLUME_CONTACT_EE_A0_EB] = {K_PL, 2, {{0, 2}, {3, 2}}},
    [PLUME_CONTACT_EE_A1_EB] = {K_PL, 2, {{1, 2}, {3, 2}}},
    [PLUME_CONTACT_EE_B0_EA] = {K_PL, 2, {{2, 0}, {1, 0}}},
    [PLUME_CONTACT_EE_B1_EA] = {K_PL, 2, {{3, 0}, {1, 0}}},
    [PLUME_CONTACT_EE_LINES] = {K_PLANE, 3, {{2, 0}, {1, 0}, {3, 2}}},
};

/* g[12] and H[144] (either may be NULL) of a function whose local gradient gl[3 nv] and Hessian
 * Hl[(3 nv)^2] are known: the chain rule through the constant +-1 Jacobian of the local
 * variables. */
static void scatter(int nv, const lvar *v, const double *gl, const double *Hl, double *g, double *H)
{
    const int m = 3 * nv;
    if (g) {
        memset(g, 0, 12 * sizeof *g);
        for (int k = 0; k < nv; k++)
            for (int a = 0; a < 3; a++) {
                g[3 * v[k].plus + a] += gl[3 * k + a];
                if (v[k].minus >= 0)
                    g[3 * v[k].minus + a] -= gl[3 * k + a];
            }
    }
    if (H) {
        memset(H, 0, 144 * sizeof *H);
        for (int k = 0; k < nv; k++) {
            const int vk[2] = {v[k].plus, v[k].minus};
            for (int l = 0; l < nv; l++) {
                const int vl[2] = {v[l].plus, v[l].minus};
                for (int ik = 0; ik < 2; ik++) {
                    if (vk[ik] < 0)
                        continue;
                    for (int il = 0; il < 2; il++) {
                        if (vl[il] < 0)
                            continue;
                        const double sg = (ik == il) ? 1.0 : -1.0;
                        for (int a = 0; a < 3; a++)
                            for (int b = 0; b < 3; b++)
                                H[(3 * vk[ik] + a) * 12 + 3 * vl[il] + b] +=
                                    sg * Hl[(3 * k + a) * m + 3 * l + b];
                    }
                }
            }
        }
    }
}

/* ---- the three kernels ------------------------------------------------------------------ */

/* |r|^2 */
static void kernel_pp(const double r[3], double *d2, double *gl, double *Hl)
{
    *d2 = dot3(r, r);
    if (gl)
        for (int a = 0; a < 3; a++)
            gl[a] = 2.0 * r[a];
    if (Hl)
        for (int a = 0; a < 9; a++)
            Hl[a] = (a % 4 == 0) ? 2.0 : 0.0;
}

/* squared distance of the point r (relative to e0) to the line through 0 along e:
 * s = r.r - (r.e)^2 / e.e in derivative form; the value as |r x e|^2 / e.e, which has no
 * cancellation when the point is near the line. Local variables (r, e). */
static int kernel_pl(const double r[3], const double e[3], double *d2, double *gl, double *Hl)
{
    const double beta = dot3(e, e);
    if (!(beta > 0.0))
        return -1;
    double c[3];
    cross3(r, e, c);
    *d2 = dot3(c, c) / beta;
    if (!gl && !Hl)
        return 0;
    const double k = dot3(r, e) / beta; /* foot of the perpendicular, in units of e */
    double rp[3];                        /* r minus its projection on e */
    for (int a = 0; a < 3; a++)
        rp[a] = r[a] - k * e[a];
    if (gl)
        for (int a = 0; a < 3; a++) {
            gl[a] = 2.0 * rp[a];
            gl[3 + a] = -2.0 * k * rp[a];
        }
    if (Hl) {
        /* d/dr d/dr: 2 I - 2 e e^T / beta
         * d/dr d/de: -2 e r^T / beta - 2 k I + 4 k e e^T / beta
         * d/de d/de: -2 r r^T / beta + 4 k (r e^T + e r^T) / beta + 2 k^2 I - 8 k^2 e e^T / beta */
        double Brr[9], Bre[9], Bee[9];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                const double id = a == b ? 1.0 : 0.0;
                Brr[3 * a + b] = 2.0 * id - 2.0 * e[a] * e[b] / beta;
                Bre[3 * a + b] = -2.0 * e[a] * r[b] / beta - 2.0 * k * id + 4.0 * k * e[a] * e[b] / beta;
                Bee[3 * a + b] = -2.0 * r[a] * r[b] / beta + 4.0 * k * (r[a] * e[b] + e[a] * r[b]) / beta +
                                 2.0 * k * k * id - 8.0 * k * k * e[a] * e[b] / beta;
            }
        put_block(Hl, 6, 0, 0, Brr);
        put_block(Hl, 6, 0, 1, Bre);
        put_block(Hl, 6, 1, 1, Bee);
    }
    return 0;
}

/* squared distance of w to the plane through 0 spanned by e1, e2: s = (w.n)^2 / n.n, n = e1 x e2
 * (point–plane with w = p - t0, or line–line with w = eb0 - ea0). Local variables (w, e1, e2). */
static int kernel_plane(const double w[3], const double e1[3], const double e2[3], double *d2,
                        double *gl, double *Hl)
{
    double n[3];
    cross3(e1, e2, n);
    const double N = dot3(n, n);
    if (!(N > 0.0))
        return -1;
    /* w.n computed after removing from w its component along the longer of e1, e2 (orthogonal
     * to n, so w.n is unchanged in exact arithmetic): for a thin triangle or nearly parallel
     * lines the rounding error of n tilts it along that direction by ~eps/sin, and w's large
     * component there would turn that tilt into an error ~ |w| eps / sin in the distance. */
    const double *ev = dot3(e1, e1) >= dot3(e2, e2) ? e1 : e2;
    const double kv = dot3(w, ev) / dot3(ev, ev);
    double wp[3];
    for (int a = 0; a < 3; a++)
        wp[a] = w[a] - kv * ev[a];
    const double q = dot3(wp, n);
    *d2 = q * q / N;
    if (!gl && !Hl)
        return 0;

    /* s as phi(w, n): d phi/dw = 2 q n / N, d phi/dn = gn = (2q/N) (w - (q/N) n) */
    const double qn = q / N;
    double gn[3];
    for (int a = 0; a < 3; a++)
        gn[a] = 2.0 * qn * (w[a] - qn * n[a]);
    if (gl) {
        double t1[3], t2[3];
        cross3(e2, gn, t1); /* dn = de1 x e2 + e1 x de2, so d s/de1 = e2 x gn */
        cross3(gn, e1, t2); /*                           and d s/de2 = gn x e1 */
        for (int a = 0; a < 3; a++) {
            gl[a] = 2.0 * qn * n[a];
            gl[3 + a] = t1[a];
            gl[6 + a] = t2[a];
        }
    }
    if (Hl) {
        /* Hessian of phi in (w, n), then through the bilinear n(e1, e2): with A1 = -[e2]x and
         * A2 = [e1]x (dn = A1 de1 + A2 de2) the (e_i, e_j) block is A_i^T Pnn A_j, plus the
         * second variation gn . (2 de1 x de2), i.e. -[gn]x in the (e1, e2) block. */
        double Pww[9], Pwn[9], Pnn[9];
        const double iN = 1.0 / N;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                const double id = a == b ? 1.0 : 0.0;
                Pww[3 * a + b] = 2.0 * iN * n[a] * n[b];
                Pwn[3 * a + b] = 2.0 * iN * (n[a] * w[b] + q * id) - 4.0 * qn * iN * n[a] * n[b];
                Pnn[3 * a + b] = 2.0 * iN * w[a] * w[b] - 4.0 * qn * iN * (w[a] * n[b] + n[a] * w[b]) -
                                 2.0 * qn * qn * id + 8.0 * qn * qn * iN * n[a] * n[b];
            }
        double A1[9], A2[9], T[9], B[9], S[9];
        skew3(e2, A1);
        for (int a = 0; a < 9; a++)
            A1[a] = -A1[a];
        skew3(e1, A2);
        put_block(Hl, 9, 0, 0, Pww);
        mm3(Pwn, A1, B);
        put_block(Hl, 9, 0, 1, B);
        mm3(Pwn, A2, B);
        put_block(Hl, 9, 0, 2, B);
        mm3(Pnn, A1, T);
        mtm3(A1, T, B);
        put_block(Hl, 9, 1, 1, B);
        mm3(Pnn, A2, T);
        mtm3(A2, T, B);
        put_block(Hl, 9, 2, 2, B);
        mtm3(A1, T, B); /* T = Pnn A2 still */
        skew3(gn, S);
        for (int a = 0; a < 9; a++)
            B[a] -= S[a];
        put_block(Hl, 9, 1, 2, B);
    }
    return 0;
}

static plume_status eval_feature(const feature *f, const double *x, double *d2, double *g, double *H)
{
    double y[9], gl[9], Hl[81];
    for (int k = 0; k < f->nv; k++)
        for (int a = 0; a < 3; a++)
            y[3 * k + a] = x[3 * f->v[k].plus + a] - (f->v[k].minus >= 0 ? x[3 * f->v[k].minus + a] : 0.0);
    double *glp = g ? gl : NULL, *Hlp = H ? Hl : NULL;
    int rc = 0;
    switch (f->kind) {
    case K_PP:
        kernel_pp(y, d2, glp, Hlp);
        break;
    case K_PL:
        rc = kernel_pl(y, y + 3, d2, glp, Hlp);
        break;
    case K_PLANE:
        rc = kernel_plane(y, y + 3, y + 6, d2, glp, Hlp);
        break;
    }
    if (rc)
        return PLUME_ESINGULAR;
    scatter(f->nv, f->v, glp, Hlp, g, H);
    return PLUME_OK;
}

plume_status plume_contact_pt_distance2(const double x[12], plume_contact_pt_type type, double *d2,
                                        double *g, double *H)
{
    if (!x || !d2 || (int)type < 0 || type >= PLUME_CONTACT_PT_NTYPES || !finite12(x))
        return PLUME_EINVAL;
    return eval_feature(&pt_features[type], x, d2, g, H);
}

plume_status plume_contact_ee_distance2(const double x[12], plume_contact_ee_type type, double *d2,
                                        double *g, double *H)
{
    if (!x || !d2 || (int)type < 0 || type >= PLUME_CONTACT_EE_NTYPES || !finite12(x))
        return PLUME_EINVAL;
    return eval_feature(&ee_features[type], x, d2, g, H);
}

/* ---- classification --------------------------------------------------------------------- */

/* Nearest point of the segment (a, b) to p: returns 0 (endpoint a), 1 (endpoint b) or 2 (interior)
 * and the squared distance. A zero-length segment is its endpoint a. */
static int segment_region(const double p[3], const double a[3], const double b[3], double *d2)
{
    double e[3], r[3];
    sub3(b, a, e);
    sub3(p, a, r);
    const double beta = dot3(e, e), t = dot3(r, e);
    if (!(beta > 0.0) || t <= 0.0) {
        *d2 = dot3(r, r);
        return 0;
    }
    if (t >= beta) {
        double s[3];
        sub3(p, b, s);
        *d2 = dot3(s, s);
        return 1;
    }
    double c[3];
    cross3(r, e, c);
    *d2 = dot3(c, c) / beta;
    return 2;
}

plume_status plume_contact_pt_classify(const double x[12], plume_contact_pt_type *type)
{
    if (!x || !type || !finite12(x))
        return PLUME_EINVAL;
    const double *p = x, *a = x + 3, *b = x + 6, *c = x + 9;
    double ab[3], ac[3], bc[3], n[3];
    sub3(b, a, ab);
    sub3(c, a, ac);
    sub3(c, b, bc);
    cross3(ab, ac, n);
    double L2 = dot3(ab, ab);
    if (dot3(ac, ac) > L2)
        L2 = dot3(ac, ac);
    if (dot3(bc, bc) > L2)
        L2 = dot3(bc, bc);
    if (!(dot3(n, n) > PLUME_CONTACT_PARALLEL_SIN2 * L2 * L2)) {
        /* flat triangle: it is (to within its width) the union of its three segments */
        static const plume_contact_pt_type vert[3] = {PLUME_CONTACT_PT_T0, PLUME_CONTACT_PT_T1,
                                                      PLUME_CONTACT_PT_T2};
        static const plume_contact_pt_type edge[3] = {PLUME_CONTACT_PT_E01, PLUME_CONTACT_PT_E12,
                                                      PLUME_CONTACT_PT_E20};
        double best = INFINITY;
        for (int i = 0; i < 3; i++) {
            const int j = (i + 1) % 3;
            double d2;
            const int r = segment_region(p, x + 3 + 3 * i, x + 3 + 3 * j, &d2);
            if (d2 < best) {
                best = d2;
                *type = r == 2 ? edge[i] : vert[r == 0 ? i : j];
            }
        }
        return PLUME_OK;
    }
    /* Voronoi regions by signs of dot products (Ericson, Real-Time Collision Detection, 2005, §5.1):
     * vertices first, then edges, then the face; each test is exact in exact arithmetic and
     * the regions' boundaries are where the neighbouring formulas agree. */
    double ap[3], bp[3], cp[3];
    sub3(p, a, ap);
    sub3(p, b, bp);
    sub3(p, c, cp);
    const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        *type = PLUME_CONTACT_PT_T0;
        return PLUME_OK;
    }
    const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        *type = PLUME_CONTACT_PT_T1;
        return PLUME_OK;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        *type = PLUME_CONTACT_PT_E01;
        return PLUME_OK;
    }
    const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        *type = PLUME_CONTACT_PT_T2;
        return PLUME_OK;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        *type = PLUME_CONTACT_PT_E20;
        return PLUME_OK;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        *type = PLUME_CONTACT_PT_E12;
        return PLUME_OK;
    }
    *type = PLUME_CONTACT_PT_FACE;
    return PLUME_OK;
}

plume_status plume_contact_ee_classify(const double x[12], plume_contact_ee_type *type)
{
    if (!x || !type || !finite12(x))
        return PLUME_EINVAL;
    const double *a0 = x, *a1 = x + 3, *b0 = x + 6, *b1 = x + 9;
    double u[3], v[3], w[3], n[3];
    sub3(a1, a0, u);
    sub3(b1, b0, v);
    sub3(a0, b0, w);
    cross3(u, v, n);
    const double a = dot3(u, u), b = dot3(u, v), c = dot3(v, v), d = dot3(u, w), e = dot3(v, w);
    /* |u x v|^2 rather than ac - b^2: no cancellation when the edges are nearly parallel */
    const double D = dot3(n, n);
    if (!(D > PLUME_CONTACT_PARALLEL_SIN2 * a * c)) {
        /* parallel (or a zero-length edge): the nearest of the four endpoint–segment pairs */
        static const plume_contact_ee_type cand[4][3] = {
            {PLUME_CONTACT_EE_A0B0, PLUME_CONTACT_EE_A0B1, PLUME_CONTACT_EE_A0_EB},
            {PLUME_CONTACT_EE_A1B0, PLUME_CONTACT_EE_A1B1, PLUME_CONTACT_EE_A1_EB},
            {PLUME_CONTACT_EE_A0B0, PLUME_CONTACT_EE_A1B0, PLUME_CONTACT_EE_B0_EA},
            {PLUME_CONTACT_EE_A0B1, PLUME_CONTACT_EE_A1B1, PLUME_CONTACT_EE_B1_EA},
        };
        const double *pts[4] = {a0, a1, b0, b1};
        double best = INFINITY;
        for (int i = 0; i < 4; i++) {
            double d2;
            const int r = i < 2 ? segment_region(pts[i], b0, b1, &d2) : segment_region(pts[i], a0, a1, &d2);
            if (d2 < best) {
                best = d2;
                *type = cand[i][r];
            }
        }
        return PLUME_OK;
    }
    /* Minimiser of the convex quadratic |w + s u - t v|^2 on [0,1]^2 (Ericson 2005, §5.1): s of
     * the lines' closest points clamped, t optimal for that s, and s re-optimised when t is
     * clamped. Regions: 0 endpoint 0, 1 endpoint 1, 2 interior. */
    int ra, rb;
    const double sn = b * e - c * d;
    double s;
    if (sn <= 0.0)
        s = 0.0, ra = 0;
    else if (sn >= D)
        s = 1.0, ra = 1;
    else
        s = sn / D, ra = 2;
    const double tn = b * s + e;
    if (tn <= 0.0) {
        rb = 0;
        ra = -d <= 0.0 ? 0 : (-d >= a ? 1 : 2);
    } else if (tn >= c) {
        rb = 1;
        ra = b - d <= 0.0 ? 0 : (b - d >= a ? 1 : 2);
    } else {
        rb = 2;
    }
    static const plume_contact_ee_type map[3][3] = {
        /* ra \ rb:  eb0                   eb1                    interior of b */
        {PLUME_CONTACT_EE_A0B0, PLUME_CONTACT_EE_A0B1, PLUME_CONTACT_EE_A0_EB},
        {PLUME_CONTACT_EE_A1B0, PLUME_CONTACT_EE_A1B1, PLUME_CONTACT_EE_A1_EB},
        {PLUME_CONTACT_EE_B0_EA, PLUME_CONTACT_EE_B1_EA, PLUME_CONTACT_EE_LINES},
    };
    *type = map[ra][rb];
    return PLUME_OK;
}

plume_status plume_contact_pt_dist2(const double x[12], double *d2)
{
    plume_contact_pt_type t;
    plume_status st = plume_contact_pt_classify(x, &t);
    if (st == PLUME_OK && !d2)
        st = PLUME_EINVAL;
    return st ? st : eval_feature(&pt_features[t], x, d2, NULL, NULL);
}

plume_status plume_contact_ee_dist2(const double x[12], double *d2)
{
    plume_contact_ee_type t;
    plume_status st = plume_contact_ee_classify(x, &t);
    if (st == PLUME_OK && !d2)
        st = PLUME_EINVAL;
    return st ? st : eval_feature(&ee_features[t], x, d2, NULL, NULL);
}

/* ---- edge–edge mollifier ---------------------------------------------------------------- */

plume_status plume_contact_ee_mollifier_threshold(const double xrest[12], double *eps_x)
{
    if (!xrest || !eps_x || !finite12(xrest))
        return PLUME_EINVAL;
    double u[3], v[3];
    sub3(xrest + 3, xrest, u);
    sub3(xrest + 9, xrest + 6, v);
    *eps_x = PLUME_CONTACT_MOLLIFIER_SCALE * dot3(u, u) * dot3(v, v);
    return PLUME_OK;
}

plume_status plume_contact_ee_mollifier(const double x[12], double eps_x, double *m, double *g,
                                        double *H)
{
    if (!x || !m || !finite12(x) || !isfinite(eps_x) || !(eps_x > 0.0))
        return PLUME_EINVAL;
    double u[3], v[3], n[3];
    sub3(x + 3, x, u);
    sub3(x + 9, x + 6, v);
    cross3(u, v, n);
    const double c = dot3(n, n);
    if (c >= eps_x) {
        *m = 1.0;
        if (g)
            memset(g, 0, 12 * sizeof *g);
        if (H)
            memset(H, 0, 144 * sizeof *H);
        return PLUME_OK;
    }
    const double r = c / eps_x;
    *m = (2.0 - r) * r;
    if (!g && !H)
        return PLUME_OK;
    const double m1 = 2.0 / eps_x * (1.0 - r), m2 = -2.0 / (eps_x * eps_x);
    /* c = |u x v|^2: dc/du = 2 v x n, dc/dv = 2 n x u (no cancellation near parallel) */
    double gc[6], gl[6], Hl[36];
    cross3(v, n, gc);
    cross3(n, u, gc + 3);
    for (int a = 0; a < 6; a++)
        gc[a] *= 2.0;
    for (int a = 0; a < 6; a++)
        gl[a] = m1 * gc[a];
    if (H) {
        /* Lagrange form c = |u|^2 |v|^2 - (u.v)^2 for the second derivatives */
        const double uu = dot3(u, u), vv = dot3(v, v), uv = dot3(u, v);
        double Buu[9], Bvv[9], Buv[9];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                const double id = a == b ? 1.0 : 0.0;
                Buu[3 * a + b] = 2.0 * vv * id - 2.0 * v[a] * v[b];
                Bvv[3 * a + b] = 2.0 * uu * id - 2.0 * u[a] * u[b];
                Buv[3 * a + b] = 4.0 * u[a] * v[b] - 2.0 * v[a] * u[b] - 2.0 * uv * id;
            }
        put_block(Hl, 6, 0, 0, Buu);
        put_block(Hl, 6, 0, 1, Buv);
        put_block(Hl, 6, 1, 1, Bvv);
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++)
                Hl[6 * i + j] = m1 * Hl[6 * i + j] + m2 * gc[i] * gc[j];
    }
    static const lvar mv[2] = {{1, 0}, {3, 2}};
    scatter(2, mv, gl, H ? Hl : NULL, g, H);
    return PLUME_OK;
}

/* ---- scalar potentials ------------------------------------------------------------------ */

plume_status plume_contact_barrier(double d, double dhat, double *b, double *db, double *d2b)
{
    if (!b || !isfinite(dhat) || !(dhat > 0.0))
        return PLUME_EINVAL;
    double v = 0.0, v1 = 0.0, v2 = 0.0;
    plume_status st = PLUME_OK;
    if (!(d > 0.0)) {
        v = INFINITY;
        st = PLUME_ESINGULAR;
    } else if (d < dhat) {
        const double r = d - dhat, L = log(d / dhat);
        v = -r * r * L;
        v1 = -2.0 * r * L - r * r / d;
        v2 = -2.0 * L - 4.0 * r / d + r * r / (d * d);
    }
    *b = v;
    if (db)
        *db = v1;
    if (d2b)
        *d2b = v2;
    return st;
}

plume_status plume_contact_penalty(double d, double dhat, double *p, double *dp, double *d2p)
{
    if (!p || !isfinite(dhat) || !(dhat > 0.0) || !(d >= 0.0) || !isfinite(d))
        return PLUME_EINVAL;
    double v = 0.0, v1 = 0.0, v2 = 0.0;
    if (d < dhat) {
        v = 0.5 * (dhat - d) * (dhat - d);
        v1 = d - dhat;
        v2 = 1.0;
    }
    *p = v;
    if (dp)
        *dp = v1;
    if (d2p)
        *d2p = v2;
    return PLUME_OK;
}

void plume_contact_opts_default(plume_contact_opts *o)
{
    if (!o)
        return;
    o->model = PLUME_CONTACT_BARRIER;
    o->dhat = 1e-3;
    o->stiffness = 1.0;
    o->project_psd = PLUME_CONTACT_PROJECT_GAUSS_NEWTON;
}

static int opts_ok(const plume_contact_opts *o)
{
    return o && (o->model == PLUME_CONTACT_BARRIER || o->model == PLUME_CONTACT_PENALTY) && o->project_psd >= 0 &&
           o->project_psd <= PLUME_CONTACT_PROJECT_GAUSS_NEWTON &&
           isfinite(o->dhat) && o->dhat > 0.0 && isfinite(o->stiffness) && o->stiffness >= 0.0;
}

static void zero_out(double *g, double *H)
{
    if (g)
        memset(g, 0, 12 * sizeof *g);
    if (H)
        memset(H, 0, 144 * sizeof *H);
}

/* E = k phi(d) of a pair at squared distance d2 (< dhat^2) with the derivatives gs, Hs of d2.
 * Through d = sqrt(d2): with gd = grad d = gs / (2d),
 *   grad E = phi'(d) gd,   hess E = (phi'(d) / (2d)) Hs + (phi''(d) - phi'(d)/d) gd gd^T.
 * Written with gd rather than as E_ss gs gs^T, where E_ss grows like 1/d^4 (barrier) while
 * |gs|^2 shrinks like d^2: no factor larger than 1/d^2 (barrier) or 1/d (penalty) is ever formed
 * as d -> 0 (measured: 3e-16 relative error at d = 1e-14 dhat, test_contact_narrow_small_distance). */
static plume_status compose(const plume_contact_opts *o, double d2, const double *gs,
                            const double *Hs, double *E, double *g, double *H)
{
    const double d = sqrt(d2);
    double f, f1, f2;
    plume_status st = o->model == PLUME_CONTACT_BARRIER ? plume_contact_barrier(d, o->dhat, &f, &f1, &f2)
                                                        : plume_contact_penalty(d, o->dhat, &f, &f1, &f2);
    if (st != PLUME_OK) {
        *E = f;
        zero_out(g, H);
        return st;
    }
    *E = o->stiffness * f;
    if (!(d > 0.0) || (!g && !H)) { /* penalty at d = 0: not differentiable there */
        zero_out(g, H);
        return PLUME_OK;
    }
    f1 *= o->stiffness;
    f2 *= o->stiffness;
    double gd[12];
    for (int i = 0; i < 12; i++)
        gd[i] = gs[i] / (2.0 * d);
    if (g)
        for (int i = 0; i < 12; i++)
            g[i] = f1 * gd[i];
    if (H && o->project_psd == PLUME_CONTACT_PROJECT_GAUSS_NEWTON) { /* phi'' grad d grad d^T */
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++)
                H[12 * i + j] = f2 * gd[i] * gd[j];
    } else if (H) {
        const double a = f1 / (2.0 * d), c = f2 - f1 / d;
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++)
                H[12 * i + j] = a * Hs[12 * i + j] + c * gd[i] * gd[j];
    }
    return PLUME_OK;
}

/* The pair's squared distance d2 through its classified feature f. *near = 0 when d >= dhat:
 * then E and the outputs g, H are zeroed and nothing else is computed; otherwise gs (and Hs when
 * H is wanted) receive the derivatives of d2 when g or H is wanted. */
static plume_status near_feature(const feature *f, const plume_contact_opts *o, const double *x, double *d2,
                                 double *gs, double *Hs, double *E, double *g, double *H, int *near)
{
    plume_status st = eval_feature(f, x, d2, NULL, NULL);
    *near = 0;
    if (st)
        return st;
    if (*d2 >= o->dhat * o->dhat) {
        *E = 0.0;
        zero_out(g, H);
        return PLUME_OK;
    }
    *near = 1;
    return (g || H) ? eval_feature(f, x, d2, gs, H ? Hs : NULL) : PLUME_OK;
}

plume_status plume_contact_pt_energy(const plume_contact_opts *o, const double x[12], double *E,
                                     double *g, double *H, plume_contact_pt_type *type)
{
    if (!opts_ok(o) || !x || !E)
        return PLUME_EINVAL;
    plume_contact_pt_type t;
    plume_status st = plume_contact_pt_classify(x, &t);
    if (st)
        return st;
    if (type)
        *type = t;
    double d2, gs[12], Hs[144];
    int near;
    if ((st = near_feature(&pt_features[t], o, x, &d2, gs, Hs, E, g, H, &near)) || !near)
        return st;
    st = compose(o, d2, (g || H) ? gs : NULL, H ? Hs : NULL, E, g, H);
    if (st == PLUME_OK && H && o->project_psd == PLUME_CONTACT_PROJECT_EIGEN)
        plume_dense_project_psd(12, H);
    return st;
}

plume_status plume_contact_ee_energy(const plume_contact_opts *o, const double x[12], double eps_x,
                                     double *E, double *g, double *H, plume_contact_ee_type *type)
{
    if (!opts_ok(o) || !x || !E || !isfinite(eps_x) || eps_x < 0.0)
        return PLUME_EINVAL;
    plume_contact_ee_type t;
    plume_status st = plume_contact_ee_classify(x, &t);
    if (st)
        return st;
    if (type)
        *type = t;
    double d2, gs[12], Hs[144];
    int near;
    if ((st = near_feature(&ee_features[t], o, x, &d2, gs, Hs, E, g, H, &near)) || !near)
        return st;
    if (eps_x == 0.0) { /* unmollified */
        st = compose(o, d2, (g || H) ? gs : NULL, H ? Hs : NULL, E, g, H);
        if (o->project_psd == PLUME_CONTACT_PROJECT_GAUSS_NEWTON)
            return st; /* PSD as composed */
        goto project;
    }
    /* E = m Eb: the product rule needs both gradients whenever H is wanted */
    const int need = g || H;
    double Eb, gb[12], Hb[144], m, gm[12], Hm[144];
    if ((st = compose(o, d2, need ? gs : NULL, H ? Hs : NULL, &Eb, need ? gb : NULL, H ? Hb : NULL))) {
        *E = Eb;
        zero_out(g, H);
        return st;
    }
    if ((st = plume_contact_ee_mollifier(x, eps_x, &m, need ? gm : NULL, H ? Hm : NULL)))
        return st;
    *E = m * Eb;
    if (H)
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++)
                H[12 * i + j] = m * Hb[12 * i + j] + Eb * Hm[12 * i + j] + gm[i] * gb[j] + gb[i] * gm[j];
    if (g)
        for (int i = 0; i < 12; i++)
            g[i] = m * gb[i] + Eb * gm[i];
project:
    if (st == PLUME_OK && H && o->project_psd)
        plume_dense_project_psd(12, H);
    return st;
}
