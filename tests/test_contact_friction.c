/* Lagged friction (lib/contact/contact_friction.h): the mollifier, the pair frames of every contact type
 * (closest points against contact_narrow's distances), finite differences of the pair energy in
 * both regimes, PSD blocks, the Coulomb force of a sliding and a sticking point, the normal force,
 * the term through plume_problem, and the error paths. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact_ref.h"
#include "harness.h"
#include "term_fd.h"
#include "test_rng.h"
#include "../lib/contact/contact_friction.h"
#include "../lib/core/dense.h"
#include "../lib/core/problem.h"

/* max |a| over n entries */
static double max_abs(const double *a, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* tangential displacement u = T^T dx of a 12-vector dx */
static void tangential(const double T[24], const double *dx, double u[2])
{
    u[0] = u[1] = 0.0;
    for (int i = 0; i < 12; i++)
        u[0] += T[2 * i] * dx[i], u[1] += T[2 * i + 1] * dx[i];
}

/* ---- the mollifier -------------------------------------------------------------------------- */

/* Known values, f1 = f0' and f1y = f1 / y, f2y = y (f1/y)' by central differences, continuity of
 * f0, f1, f1y, f2y at eps_u, and bad arguments. */
void test_contact_friction_mollifier(void)
{
    const double eps = 2e-3;
    double f0, f1, f1y, f2y;
    CHECK(plume_friction_mollifier(0.0, eps, &f0, &f1, &f1y, &f2y) == PLUME_OK);
    CHECK_REL(f0, eps / 3.0, 1e-15, 0);
    CHECK(f1 == 0.0 && f2y == 0.0);
    CHECK_REL(f1y, 2.0 / eps, 1e-15, 0);
    CHECK(plume_friction_mollifier(3 * eps, eps, &f0, &f1, &f1y, &f2y) == PLUME_OK);
    CHECK(f0 == 3 * eps && f1 == 1.0);
    CHECK_REL(f1y, 1.0 / (3 * eps), 1e-15, 0);
    CHECK_REL(f2y, -1.0 / (3 * eps), 1e-15, 0);
    /* at the threshold from both sides */
    double a[4], b[4];
    CHECK(plume_friction_mollifier(eps * (1 - 1e-12), eps, a, a + 1, a + 2, a + 3) == PLUME_OK);
    CHECK(plume_friction_mollifier(eps, eps, b, b + 1, b + 2, b + 3) == PLUME_OK);
    CHECK_REL(a[0], b[0], 1e-11, 0);
    CHECK_REL(a[1], b[1], 1e-11, 0);
    CHECK_REL(a[2], b[2], 1e-11, 0);
    CHECK_REL(a[3], b[3], 1e-11, 0);
    /* derivatives in both regimes */
    const double ys[] = {0.1 * eps, 0.5 * eps, 0.9 * eps, 1.5 * eps, 10 * eps};
    double worst = 0.0;
    for (int i = 0; i < 5; i++) {
        const double y = ys[i], h = 1e-4 * eps;
        double p[4], m[4], c[4];
        CHECK(plume_friction_mollifier(y, eps, c, c + 1, c + 2, c + 3) == PLUME_OK);
        CHECK(plume_friction_mollifier(y + h, eps, p, p + 1, p + 2, p + 3) == PLUME_OK);
        CHECK(plume_friction_mollifier(y - h, eps, m, m + 1, m + 2, m + 3) == PLUME_OK);
        const double e1 = fabs((p[0] - m[0]) / (2 * h) - c[1]) / fmax(fabs(c[1]), 1.0);
        const double e2 = fabs(c[2] * y - c[1]) / fmax(fabs(c[1]), 1.0);
        const double e3 = fabs(y * (p[2] - m[2]) / (2 * h) - c[3]) / fabs(c[2]);
        worst = fmax(worst, fmax(e1, fmax(e2, e3)));
        CHECK(c[1] >= 0.0 && c[1] <= 1.0 && c[2] + c[3] >= 0.0);
    }
    fprintf(stderr, "    mollifier derivatives: worst relative FD error %.2e\n", worst);
    CHECK(worst < 1e-7);
    CHECK(plume_friction_mollifier(-1e-9, eps, &f0, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_mollifier(NAN, eps, &f0, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_mollifier(1.0, 0.0, &f0, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_mollifier(1.0, INFINITY, &f0, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_mollifier(1.0, eps, NULL, NULL, NULL, NULL) == PLUME_OK);
}

/* ---- the frames ---------------------------------------------------------------------------- */

/* The frame of x (classified): orthonormal P, weights summing to 0, T = w (x) P, the closest
 * points' separation r = sum w_i x_i of length d and normal to P. Returns the frame's type. */
static int check_frame(int ee, const double x[12], double *worst_d, double *worst_n, double *worst_o)
{
    plume_friction_basis b;
    double d2;
    CHECK(plume_friction_pair_basis(ee, x, &b) == PLUME_OK);
    CHECK((ee ? plume_contact_ee_dist2(x, &d2) : plume_contact_pt_dist2(x, &d2)) == PLUME_OK);
    CHECK(b.is_edge_edge == ee);
    double r[3] = {0, 0, 0}, wsum = 0.0, L = 0.0;
    for (int i = 0; i < 4; i++) {
        wsum += b.w[i];
        for (int k = 0; k < 3; k++)
            r[k] += b.w[i] * x[3 * i + k], L = fmax(L, fabs(x[3 * i + k]));
    }
    CHECK(fabs(wsum) <= 1e-14 * (1 + max_abs(b.w, 4)));
    double o = 0.0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++)
                s += b.P[2 * k + i] * b.P[2 * k + j];
            o = fmax(o, fabs(s - (i == j)));
        }
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < 2; j++)
                CHECK(b.T[2 * (3 * i + k) + j] == b.w[i] * b.P[2 * k + j]);
    const double d = sqrt(d2), rn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    const double n0 = fabs(r[0] * b.P[0] + r[1] * b.P[2] + r[2] * b.P[4]);
    const double n1 = fabs(r[0] * b.P[1] + r[1] * b.P[3] + r[2] * b.P[5]);
    *worst_d = fmax(*worst_d, fabs(rn - d) / L);
    if (d > 1e-6 * L)
        *worst_n = fmax(*worst_n, fmax(n0, n1) / rn);
    *worst_o = fmax(*worst_o, o);
    return b.type;
}

/* 20000 seeded pairs of each kind: every classification type occurs, and check_frame holds; plus
 * the d = 0 fallbacks (a point on a vertex or on an edge's line: the penalty allows it). */
void test_contact_friction_basis(void)
{
    rng64 rng = {0x5eed5eedULL};
    double wd = 0, wn = 0, wo = 0;
    int cpt[PLUME_CONTACT_PT_NTYPES] = {0}, cee[PLUME_CONTACT_EE_NTYPES] = {0};
    for (int it = 0; it < 20000; it++) {
        double x[12];
        rand_vec(&rng, -1, 1, x);
        rand_vec(&rng, -1, 1, x + 3);
        rand_vec(&rng, -1, 1, x + 6);
        rand_vec(&rng, -1, 1, x + 9);
        cpt[check_frame(0, x, &wd, &wn, &wo)]++;
        if (it % 2) { /* near-parallel edges: the endpoint fallbacks and ill-conditioned lines */
            double perp[3];
            rand_unit(&rng, perp);
            const double th = pow(10.0, -urange(&rng, 1, 10)), len = urange(&rng, 0.3, 1.5);
            for (int k = 0; k < 3; k++)
                x[9 + k] = x[6 + k] + len * (x[3 + k] - x[k] + th * perp[k]);
        }
        cee[check_frame(1, x, &wd, &wn, &wo)]++;
    }
    for (int t = 0; t < PLUME_CONTACT_PT_NTYPES; t++)
        CHECK(cpt[t] > 0);
    for (int t = 0; t < PLUME_CONTACT_EE_NTYPES; t++)
        CHECK(cee[t] > 0);
    fprintf(stderr, "    frames: |r| - d <= %.2e L, |P^T r| <= %.2e |r|, |P^T P - I| <= %.2e\n", wd, wn, wo);
    CHECK(wd < 1e-9);
    CHECK(wn < 1e-7); /* near-parallel lines: the normal of two almost parallel edges, ~eps/sin */
    CHECK(wo < 1e-14);

    /* known closest points: face barycentrics, edge parameter, line parameters */
    const double xf[12] = {0.25, 0.3, 0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    plume_friction_basis b;
    CHECK(plume_friction_pair_basis(0, xf, &b) == PLUME_OK && b.type == PLUME_CONTACT_PT_FACE);
    CHECK(fabs(b.coef[0] - 0.25) < 1e-15 && fabs(b.coef[1] - 0.3) < 1e-15);
    CHECK(fabs(b.P[4]) < 1e-15 && fabs(b.P[5]) < 1e-15); /* tangent to the z = 0 plane */
    const double xl[12] = {0, 0, 0, 1, 0, 0, 0.25, -1, 0.2, 0.25, 1, 0.2};
    CHECK(plume_friction_pair_basis(1, xl, &b) == PLUME_OK && b.type == PLUME_CONTACT_EE_LINES);
    CHECK(fabs(b.coef[0] - 0.25) < 1e-15 && fabs(b.coef[1] - 0.5) < 1e-15);
    const double xe[12] = {0.7, -0.2, 0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    CHECK(plume_friction_pair_basis(0, xe, &b) == PLUME_OK && b.type == PLUME_CONTACT_PT_E01);
    CHECK(fabs(b.coef[0] - 0.7) < 1e-15 && b.w[0] == 1.0 && fabs(b.w[1] + 0.3) < 1e-15 && b.w[2] == -0.7);

    /* d = 0: any orthonormal frame of the free directions */
    double x0[12] = {0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (int t = 0; t < PLUME_CONTACT_PT_NTYPES; t++) {
        if (t == PLUME_CONTACT_PT_E01 || t == PLUME_CONTACT_PT_E20) /* p on those edges' lines too */
            x0[0] = t == PLUME_CONTACT_PT_E01 ? 0.4 : 0.0, x0[1] = t == PLUME_CONTACT_PT_E20 ? 0.4 : 0.0;
        else
            x0[0] = x0[1] = 0.0;
        CHECK(plume_friction_pt_basis(x0, (plume_contact_pt_type)t, &b) == PLUME_OK);
        CHECK(isfinite(b.T[0]) && fabs(b.P[0] * b.P[0] + b.P[2] * b.P[2] + b.P[4] * b.P[4] - 1) < 1e-15);
        CHECK(fabs(b.P[1] * b.P[1] + b.P[3] * b.P[3] + b.P[5] * b.P[5] - 1) < 1e-15);
        CHECK(fabs(b.P[0] * b.P[1] + b.P[2] * b.P[3] + b.P[4] * b.P[5]) < 1e-15);
    }
    /* degenerate features: ESINGULAR for the types whose line or plane is undefined */
    const double flat[12] = {0.2, 0.3, 0.1, 0, 0, 0, 1, 0, 0, 2, 0, 0};
    CHECK(plume_friction_pt_basis(flat, PLUME_CONTACT_PT_FACE, &b) == PLUME_ESINGULAR);
    const double par[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 1, 0};
    CHECK(plume_friction_ee_basis(par, PLUME_CONTACT_EE_LINES, &b) == PLUME_ESINGULAR);
    const double zl[12] = {0, 0, 0, 0, 0, 0, 0, 1, 0, 2, 1, 0};
    CHECK(plume_friction_ee_basis(zl, PLUME_CONTACT_EE_B0_EA, &b) == PLUME_ESINGULAR);
    CHECK(plume_friction_ee_basis(zl, PLUME_CONTACT_EE_A0B0, &b) == PLUME_OK);
}

/* ---- finite differences of the pair energy ------------------------------------------------- */

typedef struct {
    const char *name;
    int ee, type;
    double x[12];
} config;

/* lagged configurations of every contact kind (unit scale, separation ~0.1) */
static const config configs[] = {
    {"point-face", 0, PLUME_CONTACT_PT_FACE, {0.25, 0.3, 0.1, 0, 0, 0, 1, 0, 0.05, 0, 1, -0.03}},
    {"point-edge", 0, PLUME_CONTACT_PT_E01, {0.6, -0.2, 0.1, 0, 0, 0, 1, 0, 0, 0.2, 1, 0.1}},
    {"point-edge 12", 0, PLUME_CONTACT_PT_E12, {0.7, 0.7, 0.12, 0, 0, 0, 1, 0, 0, 0, 1, 0}},
    {"point-point", 0, PLUME_CONTACT_PT_T0, {-0.2, -0.3, 0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0}},
    {"point-point t2", 0, PLUME_CONTACT_PT_T2, {-0.1, 1.2, -0.1, 0, 0, 0, 1, 0, 0, 0, 1, 0}},
    {"edge-edge crossing", 1, PLUME_CONTACT_EE_LINES, {0, 0, 0, 1, 0, 0, 0.4, -0.5, 0.1, 0.6, 0.5, 0.12}},
    {"edge-edge nearly parallel", 1, PLUME_CONTACT_EE_LINES, {0, 0, 0, 1, 0, 0, 0, -1e-3, 0.1, 1, 1e-3, 0.1}},
    {"edge-edge sin 2e-6", 1, PLUME_CONTACT_EE_LINES, {0, 0, 0, 1, 0, 0, 0, -1e-6, 0.1, 1, 1e-6, 0.1}},
    {"edge-edge parallel fallback", 1, -1, {0, 0, 0, 1, 0, 0, 0.3, 0.0, 0.1, 1.3, 1e-10, 0.1}},
    {"edge-edge endpoints", 1, PLUME_CONTACT_EE_A1B0, {0, 0, 0, 1, 0, 0, 1.1, 0.1, 0.05, 2, 0.5, 0.3}},
    {"edge-edge endpoint-line", 1, PLUME_CONTACT_EE_B0_EA, {0, 0, 0, 1, 0, 0, 0.5, 0.1, 0.05, 0.7, 0.9, 0.6}},
};

/* central differences of D against g and of g against H, each relative to its largest entry (the
 * gradient's at least mu lambda, the sliding force: at u = 0 the gradient vanishes) */
static void fd_pair(double ml_mu, double lambda, double eps, const double T[24], const double x[12],
                    const double xl[12], double h, double *gerr, double *herr)
{
    double D, g[12], H[144], y[12], gp[12], gm[12], Dp, Dm;
    CHECK(plume_friction_pair_energy(ml_mu, lambda, eps, T, x, xl, &D, g, H) == PLUME_OK);
    double ge = 0.0, he = 0.0;
    for (int i = 0; i < 12; i++) {
        memcpy(y, x, sizeof y);
        y[i] = x[i] + h;
        CHECK(plume_friction_pair_energy(ml_mu, lambda, eps, T, y, xl, &Dp, gp, NULL) == PLUME_OK);
        y[i] = x[i] - h;
        CHECK(plume_friction_pair_energy(ml_mu, lambda, eps, T, y, xl, &Dm, gm, NULL) == PLUME_OK);
        ge = fmax(ge, fabs((Dp - Dm) / (2 * h) - g[i]));
        for (int j = 0; j < 12; j++)
            he = fmax(he, fabs((gp[j] - gm[j]) / (2 * h) - H[12 * j + i]));
    }
    *gerr = ge / fmax(max_abs(g, 12), ml_mu * lambda);
    *herr = he / max_abs(H, 144);
}

/* Every configuration, displaced from its lagged positions by a seeded random 12-vector scaled
 * to |u| = 0 (exactly at the lag), 0.4 eps_u and 0.8 eps_u (sticking), 1.5 eps_u and 20 eps_u
 * (sliding), at two scales (unit scene with eps_u = 1e-3; centimetre scene with IPC's eps_v =
 * 1e-3 m/s, dt = 1e-2: eps_u = 1e-5 m). Relative errors below 1e-6. */
void test_contact_friction_fd(void)
{
    rng64 rng = {0xf12c7};
    const double targets[] = {0.0, 0.4, 0.8, 1.5, 20.0};
    double worst_g[3] = {0, 0, 0}, worst_h[3] = {0, 0, 0}; /* at the lag, sticking, sliding */
    const int nc = (int)(sizeof configs / sizeof configs[0]);
    for (int scale = 0; scale < 2; scale++) {
        const double L = scale ? 1e-2 : 1.0, eps = scale ? 1e-5 : 1e-3;
        for (int c = 0; c < nc; c++) {
            double xl[12];
            for (int i = 0; i < 12; i++)
                xl[i] = L * configs[c].x[i];
            plume_friction_basis b;
            CHECK(plume_friction_pair_basis(configs[c].ee, xl, &b) == PLUME_OK);
            if (configs[c].type >= 0)
                CHECK(b.type == configs[c].type);
            else /* exactly parallel within the threshold: an endpoint–line fallback */
                CHECK(b.type >= PLUME_CONTACT_EE_A0_EB && b.type <= PLUME_CONTACT_EE_B1_EA);
            for (int t = 0; t < 5; t++) {
                double dx[12], u[2], x[12];
                rand_vec(&rng, -1, 1, dx);
                rand_vec(&rng, -1, 1, dx + 3);
                rand_vec(&rng, -1, 1, dx + 6);
                rand_vec(&rng, -1, 1, dx + 9);
                tangential(b.T, dx, u);
                const double s = targets[t] * eps / hypot(u[0], u[1]);
                for (int i = 0; i < 12; i++)
                    x[i] = xl[i] + s * dx[i];
                const double mu = urange(&rng, 0.1, 1.0), lambda = urange(&rng, 0.5, 50.0);
                /* the step: small against eps_u and against the distance to the threshold. At u = 0
                 * the gradient's -|u| u / eps_u^2 part is C^1 only, so the Hessian's central
                 * difference is first order there (error h / (2 eps_u)): a smaller step */
                const double h = targets[t] == 0.0 ? 1e-7 * eps : 1e-4 * eps;
                double ge, he;
                fd_pair(mu, lambda, eps, b.T, x, xl, h, &ge, &he);
                const int r = targets[t] == 0.0 ? 0 : targets[t] < 1.0 ? 1 : 2;
                worst_g[r] = fmax(worst_g[r], ge);
                worst_h[r] = fmax(worst_h[r], he);
                if (!(ge < 1e-6) || !(he < 1e-6))
                    fprintf(stderr, "    FD %s (L %g, |u| = %g eps_u): gradient %.2e, Hessian %.2e\n",
                            configs[c].name, L, targets[t], ge, he);
                CHECK(ge < 1e-6);
                CHECK(he < 1e-6);
            }
        }
    }
    fprintf(stderr,
            "    pair FD, %d configurations x 5 displacements x 2 scales, relative errors of gradient / Hessian: "
            "u = 0 %.2e / %.2e, sticking %.2e / %.2e, sliding %.2e / %.2e\n",
            nc, worst_g[0], worst_h[0], worst_g[1], worst_h[1], worst_g[2], worst_h[2]);
}

/* The term over a small mesh with pairs sharing vertices, through term_fd_check (tests/term_fd.h):
 * three pairs of different kinds, some sticking, some sliding. */
void test_contact_friction_term_fd(void)
{
    /* a triangle (0, 1, 2), a point 3 above it, an edge (4, 5) crossing edge (0, 1) from above */
    double xl[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 0.1, 0.4, -0.5, 0.08, 0.5, 0.5, 0.11};
    plume_friction_opts o;
    plume_friction_opts_default(&o);
    o.mu = 0.5;
    o.eps_v = 1e-3, o.dt = 1.0; /* eps_u = 1e-3 */
    plume_term t;
    plume_friction *f = NULL;
    plume_err err;
    CHECK(plume_friction_term_create(6, &o, &t, &f, &err) == PLUME_OK);
    CHECK(plume_friction_eps_u(f) == 1e-3);
    const plume_friction_pair pairs[3] = {{0, {3, 0, 1, 2}, 2.0}, {1, {0, 1, 4, 5}, 3.0}, {0, {4, 0, 1, 2}, 0.7}};
    CHECK(plume_friction_set_pairs(f, 3, pairs, xl, &err) == PLUME_OK);
    const plume_index *st = NULL;
    plume_index ns = -1;
    int changed = 0;
    CHECK(t.update(t.ctx, 3, xl, &st, &ns, &changed) == PLUME_OK && changed == 1 && ns == 3);
    t.stencil = st, t.nstencil = ns;
    rng64 rng = {77};
    const double amp[2] = {3e-4, 2e-2}; /* mostly sticking; all sliding */
    const char *what[2] = {"friction term, sticking", "friction term, sliding"};
    for (int r = 0; r < 2; r++) {
        double x[18];
        for (int i = 0; i < 18; i++)
            x[i] = xl[i] + amp[r] * urange(&rng, -1, 1);
        term_fd_check(&t, 6, x, 1e-8, 1e-6, what[r]);
    }
    t.destroy(t.ctx);
}

/* ---- PSD blocks ------------------------------------------------------------------------------ */

/* 3000 seeded pairs at random displacements (both regimes): every block's smallest eigenvalue
 * >= -1e-10 of its largest, and the rank is at most 2 (u has two components). */
void test_contact_friction_psd(void)
{
    rng64 rng = {4242};
    double worst = 0.0;
    int stick = 0, slide = 0;
    for (int it = 0; it < 3000; it++) {
        double xl[12], x[12], dx[12], u[2], D, H[144], A[144], lam[12], V[144];
        for (int i = 0; i < 12; i++)
            xl[i] = urange(&rng, -1, 1);
        const int ee = it % 2;
        plume_friction_basis b;
        CHECK(plume_friction_pair_basis(ee, xl, &b) == PLUME_OK);
        for (int i = 0; i < 12; i++)
            dx[i] = urange(&rng, -1, 1);
        tangential(b.T, dx, u);
        const double eps = 1e-3, target = eps * pow(10.0, urange(&rng, -3, 2));
        const double s = target / hypot(u[0], u[1]);
        for (int i = 0; i < 12; i++)
            x[i] = xl[i] + s * dx[i];
        stick += target < eps, slide += target >= eps;
        CHECK(plume_friction_pair_energy(urange(&rng, 0, 1), urange(&rng, 0, 100), eps, b.T, x, xl, &D, NULL, H) ==
              PLUME_OK);
        memcpy(A, H, sizeof A);
        plume_dense_sym_eig(12, A, lam, V);
        const double big = fmax(fabs(lam[0]), fabs(lam[11]));
        if (big > 0) {
            worst = fmin(worst, lam[0] / big);
            CHECK(lam[0] >= -1e-10 * big);
            CHECK(fabs(lam[9]) <= 1e-10 * big);
        }
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < i; j++)
                CHECK(H[12 * i + j] == H[12 * j + i]);
    }
    fprintf(stderr, "    %d sticking and %d sliding blocks: smallest eigenvalue >= %.2e of the largest\n", stick, slide,
            worst);
    CHECK(stick > 500 && slide > 500);
}

/* ---- physics -------------------------------------------------------------------------------- */

/* A point above a triangle's face: sliding far, its friction force -grad_p D has magnitude
 * mu lambda, points against the tangential motion and has no normal component, and the triangle
 * takes the opposite force split by the barycentrics; a small motion sticks with force
 * -mu lambda f1(y)/y u; a translation of the whole pair (any size) costs no force. */
void test_contact_friction_sliding_point(void)
{
    /* tilted triangle so that the normal is not an axis */
    const double xl[12] = {0.3, 0.25, 0.2, 0, 0, 0, 1, 0, 0.3, 0, 1, -0.2};
    plume_friction_basis b;
    CHECK(plume_friction_pair_basis(0, xl, &b) == PLUME_OK && b.type == PLUME_CONTACT_PT_FACE);
    double n[3], e1[3] = {1, 0, 0.3}, e2[3] = {0, 1, -0.2};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; k++)
        n[k] /= nl;
    const double mu = 0.4, lambda = 2.5, eps = 1e-3;
    const double moves[2][3] = {{0.05, -0.02, 0.03}, {2e-4, 3e-4, -1e-4}}; /* sliding; sticking */
    for (int m = 0; m < 2; m++) {
        double x[12], D, g[12], tang[3], dn = 0.0;
        memcpy(x, xl, sizeof x);
        for (int k = 0; k < 3; k++)
            x[k] += moves[m][k], dn += moves[m][k] * n[k];
        for (int k = 0; k < 3; k++)
            tang[k] = moves[m][k] - dn * n[k];
        const double y = sqrt(tang[0] * tang[0] + tang[1] * tang[1] + tang[2] * tang[2]);
        CHECK(plume_friction_pair_energy(mu, lambda, eps, b.T, x, xl, &D, g, NULL) == PLUME_OK);
        double f1y;
        CHECK(plume_friction_mollifier(y, eps, NULL, NULL, &f1y, NULL) == PLUME_OK);
        /* expected force on p: -mu lambda f1y tang (f1y = 1/y when sliding) */
        double fmag = 0.0, fn = 0.0, ferr = 0.0, total[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++) {
            const double fk = -g[k];
            fmag += fk * fk, fn += fk * n[k];
            ferr = fmax(ferr, fabs(fk + mu * lambda * f1y * tang[k]));
            for (int i = 0; i < 4; i++)
                total[k] += -g[3 * i + k];
        }
        fmag = sqrt(fmag);
        if (m == 0) {
            CHECK(y > eps);
            CHECK_REL(fmag, mu * lambda, 1e-13, 0);
        } else {
            CHECK(y < eps);
            CHECK_REL(fmag, mu * lambda * f1y * y, 1e-13, 0);
            CHECK(fmag < mu * lambda);
        }
        CHECK(ferr <= 1e-13 * mu * lambda);
        CHECK(fabs(fn) <= 1e-13 * mu * lambda);
        CHECK(max_abs(total, 3) <= 1e-13 * mu * lambda);
        /* the triangle's vertices: opposite force split by the barycentrics (1 - b1 - b2, b1, b2) */
        const double bary[3] = {1 - b.coef[0] - b.coef[1], b.coef[0], b.coef[1]};
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                CHECK(fabs(g[3 * (i + 1) + k] + bary[i] * g[k]) <= 1e-13 * mu * lambda);
        fprintf(stderr, "    %s: |u| = %.3g eps_u, |force| = %.6g mu lambda, normal part %.1e\n",
                m ? "sticking" : "sliding", y / eps, fmag / (mu * lambda), fn);
    }
    /* rigid translation of all four vertices, large: no tangential relative motion, no force */
    for (int c = 0; c < (int)(sizeof configs / sizeof configs[0]); c++) {
        plume_friction_basis bc;
        CHECK(plume_friction_pair_basis(configs[c].ee, configs[c].x, &bc) == PLUME_OK);
        double x[12], D, g[12];
        const double shift[3] = {0.7, -1.3, 0.45};
        for (int i = 0; i < 12; i++)
            x[i] = configs[c].x[i] + shift[i % 3];
        CHECK(plume_friction_pair_energy(mu, lambda, eps, bc.T, x, configs[c].x, &D, g, NULL) == PLUME_OK);
        CHECK(max_abs(g, 12) <= 1e-11 * mu * lambda);
        CHECK_REL(D, mu * lambda * eps / 3.0, 1e-9, 0); /* f0(0) */
    }
    /* mu = 0 or lambda = 0: nothing */
    double x[12], D = 1, g[12], H[144];
    memcpy(x, xl, sizeof x);
    x[0] += 0.1;
    CHECK(plume_friction_pair_energy(0.0, lambda, eps, b.T, x, xl, &D, g, H) == PLUME_OK);
    CHECK(D == 0.0 && max_abs(g, 12) == 0.0 && max_abs(H, 144) == 0.0);
    CHECK(plume_friction_pair_energy(mu, 0.0, eps, b.T, x, xl, &D, g, H) == PLUME_OK);
    CHECK(D == 0.0 && max_abs(g, 12) == 0.0 && max_abs(H, 144) == 0.0);
}

/* The normal force is the true |dE/dd| of the pair potential: against central differences of
 * plume_contact_pt_energy along the face normal (barrier and penalty), zero at d >= dhat. */
void test_contact_friction_normal_force(void)
{
    for (int model = 0; model < 2; model++) {
        plume_contact_opts o;
        plume_contact_opts_default(&o);
        o.model = model ? PLUME_CONTACT_PENALTY : PLUME_CONTACT_BARRIER;
        o.dhat = 0.1;
        o.stiffness = 7.0;
        const double ds[] = {0.003, 0.02, 0.07, 0.099};
        for (int i = 0; i < 4; i++) {
            const double d = ds[i], h = 1e-7;
            double x[12] = {0.2, 0.3, d, 0, 0, 0, 1, 0, 0, 0, 1, 0}, lam, lam2, Ep, Em;
            CHECK(plume_friction_normal_force(&o, d, &lam) == PLUME_OK);
            CHECK(plume_friction_pair_normal_force(&o, 0, x, &lam2) == PLUME_OK);
            CHECK_REL(lam2, lam, 1e-12, 0);
            x[2] = d + h;
            CHECK(plume_contact_pt_energy(&o, x, &Ep, NULL, NULL, NULL) == PLUME_OK);
            x[2] = d - h;
            CHECK(plume_contact_pt_energy(&o, x, &Em, NULL, NULL, NULL) == PLUME_OK);
            CHECK(lam > 0.0);
            CHECK_REL(lam, -(Ep - Em) / (2 * h), 1e-6, 0);
            if (model)
                CHECK_REL(lam, 7.0 * (0.1 - d), 1e-14, 0);
        }
        double lam = -1;
        CHECK(plume_friction_normal_force(&o, 0.1, &lam) == PLUME_OK && lam == 0.0);
        CHECK(plume_friction_normal_force(&o, 3.0, &lam) == PLUME_OK && lam == 0.0);
        const double xe[12] = {0, 0, 0, 1, 0, 0, 0.5, -0.5, 0.05, 0.5, 0.5, 0.05};
        double le;
        CHECK(plume_friction_pair_normal_force(&o, 1, xe, &le) == PLUME_OK);
        CHECK(plume_friction_normal_force(&o, 0.05, &lam) == PLUME_OK);
        CHECK_REL(le, lam, 1e-12, 0);
    }
    plume_contact_opts o;
    plume_contact_opts_default(&o);
    double lam;
    CHECK(plume_friction_normal_force(&o, 0.0, &lam) == PLUME_ESINGULAR); /* barrier at contact */
    CHECK(plume_friction_normal_force(&o, -1e-3, &lam) == PLUME_EINVAL);
    CHECK(plume_friction_normal_force(&o, NAN, &lam) == PLUME_EINVAL);
    CHECK(plume_friction_normal_force(NULL, 1e-4, &lam) == PLUME_EINVAL);
    CHECK(plume_friction_normal_force(&o, 1e-4, NULL) == PLUME_EINVAL);
    o.dhat = -1;
    CHECK(plume_friction_normal_force(&o, 1e-4, &lam) == PLUME_EINVAL);
    plume_contact_opts_default(&o);
    o.model = PLUME_CONTACT_PENALTY;
    CHECK(plume_friction_normal_force(&o, 0.0, &lam) == PLUME_OK && lam == o.stiffness * o.dhat);
}

/* ---- the term through plume_problem -------------------------------------------------------- */

/* One point–face pair in a problem: set_pairs, then update_terms reports a new pattern once (78
 * upper entries of the 12 x 12 block, besides the diagonal the problem always keeps); objective,
 * gradient and Hessian equal the pair's; central differences of the objective; new lambdas on the
 * same vertices keep the pattern, a different pair list changes it once more. */
void test_contact_friction_problem(void)
{
    plume_problem *p = NULL;
    CHECK(plume_problem_create(5, 3, 1.0, &p, NULL) == PLUME_OK);
    if (!p)
        return;
    plume_friction_opts o;
    plume_friction_opts_default(&o);
    o.mu = 0.6, o.eps_v = 1e-3, o.dt = 0.5; /* eps_u = 5e-4 */
    plume_term t;
    plume_friction *f = NULL;
    plume_err err;
    CHECK(plume_friction_term_create(5, &o, &t, &f, &err) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &t, &err) == PLUME_OK);
    double *x = plume_problem_x(p);
    const double xl[15] = {0.3, 0.2, 0.05, 0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
    memcpy(x, xl, sizeof xl);
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
    CHECK(plume_problem_hessian_pattern(p).nnz == 15); /* the diagonal is always there */
    const plume_friction_pair pair = {0, {0, 1, 2, 3}, 4.0};
    CHECK(plume_friction_set_pairs(f, 1, &pair, xl, &err) == PLUME_OK);
    int changed = 0;
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 1);
    CHECK(plume_problem_hessian_pattern(p).nnz == 78 + 3); /* + vertex 4's diagonal */
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 0);

    /* slide the point and tilt the triangle a little */
    const plume_index n = plume_problem_nfree(p);
    double *u = malloc((size_t)n * sizeof *u), *g = malloc((size_t)n * sizeof *g);
    double *gp = malloc((size_t)n * sizeof *gp), *hv = malloc(81 * sizeof *hv);
    CHECK(n == 15 && u && g && gp && hv);
    if (!u || !g || !gp || !hv)
        goto done;
    plume_problem_gather(p, u);
    u[0] += 0.01, u[1] -= 0.004, u[2] += 0.002, u[7] += 1e-3;
    double F = 0.0;
    CHECK(plume_problem_objective(p, u, &F, g) == PLUME_OK);
    plume_friction_basis b;
    double D, gd[12], H[144];
    CHECK(plume_friction_pair_basis(0, xl, &b) == PLUME_OK);
    CHECK(plume_friction_pair_energy(0.6, 4.0, 5e-4, b.T, u, xl, &D, gd, H) == PLUME_OK);
    CHECK_REL(F, D, 1e-14, 0);
    for (int i = 0; i < 12; i++)
        CHECK_REL(g[i], gd[i], 1e-14, 1e-14);
    for (int i = 12; i < 15; i++)
        CHECK(g[i] == 0.0);
    /* objective FD */
    double err_g = 0.0;
    for (plume_index i = 0; i < n; i++) {
        const double ui = u[i], h = 1e-7;
        double Fp, Fm;
        u[i] = ui + h;
        CHECK(plume_problem_objective(p, u, &Fp, NULL) == PLUME_OK);
        u[i] = ui - h;
        CHECK(plume_problem_objective(p, u, &Fm, NULL) == PLUME_OK);
        u[i] = ui;
        err_g = fmax(err_g, fabs((Fp - Fm) / (2 * h) - g[i]));
    }
    fprintf(stderr, "    problem gradient FD error %.2e of %.2e\n", err_g, max_abs(g, 15));
    CHECK(err_g < 1e-7 * max_abs(g, 15));
    /* Hessian values: the pair's upper triangle (every dof free, pattern sorted by column) */
    CHECK(plume_problem_hessian(p, u, 1.0, NULL, 0, hv) == PLUME_OK);
    plume_sparsity sp = plume_problem_hessian_pattern(p);
    double herr = 0.0;
    for (plume_index c = 0; c < sp.n; c++)
        for (plume_index k = sp.colptr[c]; k < sp.colptr[c + 1]; k++)
            herr = fmax(herr, fabs(hv[k] - (c < 12 ? H[12 * sp.rowind[k] + c] : 0.0)));
    CHECK(herr <= 1e-12 * max_abs(H, 144));

    /* new lagging of the same pair: same pattern, the new lambda counts after the update */
    const plume_friction_pair pair2 = {0, {0, 1, 2, 3}, 8.0};
    CHECK(plume_friction_set_pairs(f, 1, &pair2, xl, &err) == PLUME_OK);
    double F1;
    CHECK(plume_problem_objective(p, u, &F1, NULL) == PLUME_OK && F1 == F); /* not yet */
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 0);
    CHECK(plume_problem_objective(p, u, &F1, NULL) == PLUME_OK);
    CHECK_REL(F1, 2 * F, 1e-14, 0);
    /* a different pair list (here the point 4 too): a new pattern once; then no pair at all */
    const plume_friction_pair two[2] = {{0, {0, 1, 2, 3}, 8.0}, {0, {4, 1, 2, 3}, 1.0}};
    CHECK(plume_friction_set_pairs(f, 2, two, xl, &err) == PLUME_OK);
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 1);
    /* 5 diagonal vertex blocks (6 upper entries each) and 9 coupled vertex pairs (9 each) */
    CHECK(plume_problem_hessian_pattern(p).nnz == 5 * 6 + 9 * 9);
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 0);
    CHECK(plume_friction_set_pairs(f, 0, NULL, xl, &err) == PLUME_OK);
    CHECK(plume_problem_update_terms(p, &changed, &err) == PLUME_OK && changed == 1);
    CHECK(plume_problem_objective(p, u, &F1, g) == PLUME_OK && F1 == 0.0 && max_abs(g, 15) == 0.0);
done:
    free(u);
    free(g);
    free(gp);
    free(hv);
    plume_problem_destroy(&p);
}

/* ---- errors --------------------------------------------------------------------------------- */

/* Every error path names itself: options, NULLs, vertices out of range or repeated, bad normal
 * forces, non-finite positions; a failed set_pairs changes nothing. */
void test_contact_friction_bad_inputs(void)
{
    plume_friction_opts o;
    plume_friction_opts_default(&o);
    CHECK(o.mu == 0.3 && o.eps_v == 1e-3 && o.dt == 1e-2);
    plume_term t;
    plume_friction *f = NULL;
    plume_err err;
    const double bad_mu[] = {-0.1, NAN, INFINITY};
    for (int i = 0; i < 3; i++) {
        plume_friction_opts b = o;
        b.mu = bad_mu[i];
        err.msg[0] = 0;
        CHECK(plume_friction_term_create(4, &b, &t, &f, &err) == PLUME_EINVAL && f == NULL && err.msg[0]);
        CHECK(strstr(err.msg, "mu") != NULL);
    }
    plume_friction_opts b = o;
    b.eps_v = 0;
    CHECK(plume_friction_term_create(4, &b, &t, &f, &err) == PLUME_EINVAL);
    b = o, b.dt = -1;
    CHECK(plume_friction_term_create(4, &b, &t, &f, &err) == PLUME_EINVAL);
    b = o, b.dt = 1e-200, b.eps_v = 1e-200; /* eps_u underflows */
    CHECK(plume_friction_term_create(4, &b, &t, &f, &err) == PLUME_EINVAL);
    CHECK(plume_friction_term_create(0, &o, &t, &f, &err) == PLUME_EINVAL);
    CHECK(plume_friction_term_create(4, NULL, &t, &f, &err) == PLUME_EINVAL);
    CHECK(plume_friction_term_create(4, &o, NULL, &f, &err) == PLUME_EINVAL);
    b = o, b.mu = 0.0; /* allowed: costs nothing */
    CHECK(plume_friction_term_create(4, &b, &t, NULL, NULL) == PLUME_OK);
    t.destroy(t.ctx);

    CHECK(plume_friction_term_create(5, &o, &t, &f, &err) == PLUME_OK && f);
    const double xl[15] = {0.3, 0.2, 0.05, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.3, 0.04};
    const plume_friction_pair good = {0, {0, 1, 2, 3}, 1.0};
    CHECK(plume_friction_set_pairs(f, 1, &good, xl, &err) == PLUME_OK);
    const plume_index *st;
    plume_index ns;
    int changed;
    CHECK(t.update(t.ctx, 3, xl, &st, &ns, &changed) == PLUME_OK && changed == 1 && ns == 1);
    struct {
        plume_friction_pair pr;
        const char *needle;
    } bad[] = {
        {{0, {0, 1, 2, 5}, 1.0}, "out of range"},  {{0, {-1, 1, 2, 3}, 1.0}, "out of range"},
        {{1, {0, 1, 1, 3}, 1.0}, "repeated"},      {{0, {0, 1, 2, 3}, -1.0}, "normal force"},
        {{0, {0, 1, 2, 3}, NAN}, "normal force"},  {{0, {0, 1, 2, 3}, INFINITY}, "normal force"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const plume_friction_pair two[2] = {good, bad[i].pr};
        err.msg[0] = 0;
        CHECK(plume_friction_set_pairs(f, 2, two, xl, &err) == PLUME_EINVAL);
        CHECK(strstr(err.msg, bad[i].needle) != NULL && strstr(err.msg, "pair 1") != NULL);
    }
    double xnan[15];
    memcpy(xnan, xl, sizeof xnan);
    xnan[10] = NAN;
    err.msg[0] = 0;
    CHECK(plume_friction_set_pairs(f, 1, &good, xnan, &err) == PLUME_EINVAL && strstr(err.msg, "non-finite"));
    CHECK(plume_friction_set_pairs(NULL, 1, &good, xl, &err) == PLUME_EINVAL && err.msg[0]);
    CHECK(plume_friction_set_pairs(f, 1, &good, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_friction_set_pairs(f, 1, NULL, xl, &err) == PLUME_EINVAL);
    CHECK(plume_friction_set_pairs(f, -1, &good, xl, &err) == PLUME_EINVAL);
    /* the failures changed nothing: no pending pairs, same energy */
    CHECK(t.update(t.ctx, 3, xl, &st, &ns, &changed) == PLUME_OK && changed == 0 && ns == 1);
    double x[15], E = 0.0, grad[15] = {0};
    memcpy(x, xl, sizeof x);
    x[0] += 0.1;
    CHECK(t.eval(t.ctx, 3, x, &E, grad, NULL, 0) == PLUME_OK);
    CHECK_REL(E, 0.3 * 1.0 * 0.1, 1e-12, 0); /* sliding: mu lambda |u| */
    CHECK(t.eval(t.ctx, 2, x, &E, grad, NULL, 0) == PLUME_EINVAL);
    x[1] = NAN;
    CHECK(t.eval(t.ctx, 3, x, &E, grad, NULL, 0) == PLUME_EINVAL);
    CHECK(t.update(t.ctx, 2, xl, &st, &ns, &changed) == PLUME_EINVAL);
    t.destroy(t.ctx);

    /* the pair functions */
    plume_friction_basis fb;
    const double xp[12] = {0.3, 0.2, 0.05, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    double xn[12];
    memcpy(xn, xp, sizeof xn);
    xn[4] = INFINITY;
    CHECK(plume_friction_pt_basis(NULL, PLUME_CONTACT_PT_FACE, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_pt_basis(xp, PLUME_CONTACT_PT_FACE, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pt_basis(xn, PLUME_CONTACT_PT_FACE, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_pt_basis(xp, PLUME_CONTACT_PT_NTYPES, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_pt_basis(xp, (plume_contact_pt_type)-1, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_ee_basis(xp, PLUME_CONTACT_EE_NTYPES, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_pair_basis(0, xn, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_pair_basis(1, NULL, &fb) == PLUME_EINVAL);
    CHECK(plume_friction_pair_basis(0, xp, &fb) == PLUME_OK);
    double D, g[12];
    CHECK(plume_friction_pair_energy(-0.1, 1, 1e-3, fb.T, xp, xp, &D, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_energy(0.1, -1, 1e-3, fb.T, xp, xp, &D, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_energy(0.1, 1, 0.0, fb.T, xp, xp, &D, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_energy(0.1, 1, 1e-3, NULL, xp, xp, &D, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_energy(0.1, 1, 1e-3, fb.T, xn, xp, &D, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_energy(0.1, 1, 1e-3, fb.T, xp, xn, &D, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_energy(0.1, 1, 1e-3, fb.T, xp, xp, NULL, g, NULL) == PLUME_EINVAL);
    CHECK(plume_friction_pair_normal_force(NULL, 0, xp, &D) == PLUME_EINVAL);
    CHECK(plume_friction_pair_normal_force(NULL, 0, NULL, &D) == PLUME_EINVAL);
}
