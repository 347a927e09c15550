/* Tests of the shape-operator bending term (macro/shape_bending.c): exactness for quadratic
 * surfaces on irregular meshes, finite differences of the gradient and Hessian at large random
 * deformations (several barb angles, curved rest shapes), rigid-motion invariance, the PSD
 * Gauss-Newton blocks, the stencil on boundaries, every input error, and the acceptance
 * test: cylinders on five mesh families against the continuum orthotropic plate energy. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "term_fd.h"
#include "test_rng.h"
#include "bend_meshes.h"
#include "../lib/core/dense.h"
#include "../lib/core/mesh.h"
#include "../macro/shape_bending.h"
#include "plume_tree.h"

/* The vane of supplementary Table 3 (a), D_long/D_trans = 2500; twist by Huber's rule. */
static const plume_bending_material SB_VANE = {2.5e-4, 1e-7, 0.0, 0.0};

static double sb_energy(const plume_term *t, const double *x)
{
    double E = 0.0;
    if (t->eval(t->ctx, 3, x, &E, NULL, NULL, 0) != PLUME_OK)
        return NAN;
    return E;
}

/* ---- exactness --------------------------------------------------------------------------------- */

/* A quadratic surface x(X) = (X, Y, 1/2 X^T H X) in every triangle: its II pulled back to the
 * material is (n . e_z) H with n the chord normal; for small H the energy is the plate's up to
 * (n . e_z)^2 = 1 - O(|H| h)^2. A direct check of the fit: on a random Delaunay mesh, a surface
 * z = quadratic, with a tiny amplitude (linear regime), stores A/2 k^T Dv k to 1e-6. */
void test_shape_bending_quadratic_exact(void)
{
    const plume_bending_material mat = {3.0, 0.7, 0.4, 0.2};
    const double barb = 27.0 * BM_PI / 180.0;
    for (int fam = 0; fam < BM_NFAMILY; fam++) {
        plume_mesh *m = bm_family_mesh(fam, 0.25, 1.0, 0.75, 27.0);
        CHECK(m != NULL);
        if (!m)
            continue;
        plume_term t;
        plume_err err;
        CHECK(plume_shape_bending_term_create(m, &mat, 1, NULL, &t, &err) == PLUME_OK);
        const double eps = 1e-6, H[3] = {0.8, -0.5, 0.3}; /* H11, H22, H12 */
        for (plume_index v = 0; v < m->nv; v++) {
            const double X = m->X[2 * v], Y = m->X[2 * v + 1];
            m->x[3 * v + 2] = eps * 0.5 * (H[0] * X * X + H[1] * Y * Y + 2.0 * H[2] * X * Y) + 0.3 * X - 0.1 * Y;
        }
        /* curvature in the barb frame */
        const double c = cos(barb), s = sin(barb);
        const double k11 = eps * (H[0] * c * c + H[1] * s * s + 2.0 * H[2] * c * s);
        const double k22 = eps * (H[0] * s * s + H[1] * c * c - 2.0 * H[2] * c * s);
        const double k12 = eps * ((H[1] - H[0]) * c * s + H[2] * (c * c - s * s));
        const double dens = 0.5 * (mat.D_long * k11 * k11 + mat.D_trans * k22 * k22 + 2.0 * mat.D_coupling * k11 * k22 +
                                   4.0 * mat.D_twist * k12 * k12);
        /* the tilt 0.3 X - 0.1 Y changes the metric: the heights are measured along the tilted
         * normal, II = H / sqrt(1 + 0.1): remove that factor */
        const double tilt = 1.0 / (1.0 + 0.09 + 0.01);
        const double E = sb_energy(&t, m->x);
        CHECK_REL(E, dens * tilt * plume_mesh_total_area(m), 1e-6, 0.0);
        t.destroy(t.ctx);
        plume_mesh_destroy(&m);
    }
}

/* ---- derivatives ------------------------------------------------------------------------------- */

/* Random large deformations (a cylinder of curvature up to 2.5 on a patch of size ~1 plus noise
 * of 10 % of the patch) of small meshes of every family, barbs at several angles, two materials,
 * flat and curved (noisy) rest shapes. */
void test_shape_bending_fd_random(void)
{
    rng64 r = {0x5eedf00dULL};
    const plume_bending_material mats[2] = {{2.0, 0.3, 0.0, 0.1}, {0.5, 1.5, 0.35, 0.6}};
    for (int trial = 0; trial < 8; trial++) {
        const int fam = trial % BM_NFAMILY;
        const double barb = 25.0 * trial;
        plume_mesh *m = bm_family_mesh(fam, 0.25, 0.75, 0.5, barb);
        CHECK(m != NULL);
        if (!m)
            return;
        for (plume_index q = 0; q < m->nt; q++)
            m->material[q] = (int)(q % 2);
        double *rest = NULL;
        if (trial >= 4) {
            rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
            CHECK(rest != NULL);
            if (!rest)
                break;
            bm_map_cylinder(m, 17.0 * trial, 1.5, rest);
            for (plume_index i = 0; i < 3 * m->nv; i++)
                rest[i] += urange(&r, -0.04, 0.04);
        }
        plume_term t;
        plume_err err;
        CHECK(plume_shape_bending_term_create(m, mats, 2, rest, &t, &err) == PLUME_OK);
        bm_map_cylinder(m, urange(&r, 0.0, 180.0), urange(&r, -2.5, 2.5), m->x);
        for (plume_index i = 0; i < 3 * m->nv; i++)
            m->x[i] += urange(&r, -0.1, 0.1);
        char what[96];
        snprintf(what, sizeof what, "%s, barbs %g%s", bm_family_name[fam], barb, rest ? ", curved rest" : "");
        term_fd_check(&t, m->nv, m->x, 1e-6, 2e-7, what);
        t.destroy(t.ctx);
        free(rest);
        plume_mesh_destroy(&m);
    }
}

/* The phase-aware stencils (opts.phase_aware: no fit spans two materials) change which vertices a
 * triangle's fit uses, not the energy's form: gradient and Hessian against finite differences on
 * meshes split into two materials (the resolved-specimen case), flat and curved rest. */
void test_shape_bending_fd_phase_aware(void)
{
    rng64 r = {0xba5eba11ULL};
    const plume_bending_material mats[2] = {{2.0, 0.3, 0.0, 0.1}, {0.05, 0.02, 0.0, 0.01}};
    int trials_changed = 0; /* trials whose stencils the option changed: it is exercised */
    for (int trial = 0; trial < 4; trial++) {
        const int fam = trial % BM_NFAMILY;
        plume_mesh *m = bm_family_mesh(fam, 0.125, 0.75, 0.5, 30.0 * trial);
        CHECK(m != NULL);
        if (!m)
            return;
        for (plume_index q = 0; q < m->nt; q++) { /* two halves across x */
            const plume_index *v = m->tri + 3 * q;
            m->material[q] = m->X[2 * v[0]] + m->X[2 * v[1]] + m->X[2 * v[2]] < 3.0 * 0.375;
        }
        double *rest = NULL;
        if (trial >= 2) {
            rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
            CHECK(rest != NULL);
            if (!rest)
                break;
            bm_map_cylinder(m, 20.0 * trial, 1.5, rest);
        }
        plume_shape_bending_opts o = {0};
        o.phase_aware = 1;
        plume_term t;
        plume_err err;
        CHECK(plume_shape_bending_term_create_opts(m, mats, 2, rest, &o, &t, &err) == PLUME_OK);
        plume_term plain; /* the option must change some stencils here, or this tests nothing new */
        CHECK(plume_shape_bending_term_create(m, mats, 2, rest, &plain, &err) == PLUME_OK);
        long changed = plain.arity != t.arity; /* a wider stencil somewhere */
        for (plume_index k = 0; !changed && k < (plume_index)t.arity * t.nstencil; k++)
            changed += t.stencil[k] != plain.stencil[k];
        trials_changed += changed > 0;
        plain.destroy(plain.ctx);
        bm_map_cylinder(m, urange(&r, 0.0, 180.0), urange(&r, -2.5, 2.5), m->x);
        for (plume_index i = 0; i < 3 * m->nv; i++)
            m->x[i] += urange(&r, -0.1, 0.1);
        char what[96];
        snprintf(what, sizeof what, "phase-aware, %s%s", bm_family_name[fam], rest ? ", curved rest" : "");
        term_fd_check(&t, m->nv, m->x, 1e-6, 2e-7, what);
        t.destroy(t.ctx);
        free(rest);
        plume_mesh_destroy(&m);
    }
    CHECK(trials_changed >= 3);
}

/* ---- clamped edges (mirror ghosts) ------------------------------------------------------------ */

/* Marks the vertices with u . X within 1e-9 of its minimum (one straight side of the patch);
 * returns their number. */
static plume_index sb_clamp_side(const plume_mesh *m, const double u[2], unsigned char *clamped)
{
    double lo = INFINITY;
    for (plume_index v = 0; v < m->nv; v++)
        lo = fmin(lo, u[0] * m->X[2 * v] + u[1] * m->X[2 * v + 1]);
    plume_index n = 0;
    for (plume_index v = 0; v < m->nv; v++) {
        clamped[v] = u[0] * m->X[2 * v] + u[1] * m->X[2 * v + 1] <= lo + 1e-9;
        n += clamped[v];
    }
    return n;
}

/* The direction across the patch's first side, per family (BM_RIGHT45 is turned by 45 degrees). */
static void sb_side_normal(int fam, double u[2])
{
    u[0] = fam == BM_RIGHT45 ? sqrt(0.5) : 1.0;
    u[1] = fam == BM_RIGHT45 ? sqrt(0.5) : 0.0;
}

/* Exactness with a clamped side: the quadratic surfaces that leave the side with zero slope are
 * w = a (u . X - c)^2; every triangle, the mirrored ones included, stores A/2 k^T Dv k with
 * II = 2 a u u^T, on every family. The same clamped term's derivatives by central differences
 * at large random deformations (clamped vertices moved too: the mirror is a fixed plane, the
 * chain rule through it is exact), with a flat and a curved rest, one side or the whole boundary
 * clamped (corner triangles then have two mirrored slots). */
void test_shape_bending_clamped_edges(void)
{
    const plume_bending_material mat = {3.0, 0.7, 0.4, 0.2};
    const double barb = 27.0 * BM_PI / 180.0, c = cos(barb), s = sin(barb);
    rng64 r = {0xc1a3bULL};
    for (int fam = 0; fam < BM_NFAMILY; fam++) {
        plume_mesh *m = bm_family_mesh(fam, 0.25, 1.0, 0.75, 27.0);
        CHECK(m != NULL);
        if (!m)
            continue;
        unsigned char *cl = calloc((size_t)m->nv, 1);
        double *rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
        CHECK(cl && rest);
        if (!cl || !rest) {
            free(cl);
            free(rest);
            plume_mesh_destroy(&m);
            continue;
        }
        double u[2];
        sb_side_normal(fam, u);
        const plume_index ncl = sb_clamp_side(m, u, cl);
        CHECK(ncl >= 3);
        plume_term t;
        plume_err err;
        CHECK(plume_shape_bending_term_create_opts(m, &mat, 1, NULL, &(plume_shape_bending_opts){cl, 0, 0}, &t, &err) == PLUME_OK);
        double lo = INFINITY;
        for (plume_index v = 0; v < m->nv; v++)
            lo = fmin(lo, u[0] * m->X[2 * v] + u[1] * m->X[2 * v + 1]);
        const double eps = 1e-6, a = 0.9;
        for (plume_index v = 0; v < m->nv; v++) {
            const double xi = u[0] * m->X[2 * v] + u[1] * m->X[2 * v + 1] - lo;
            m->x[3 * v + 2] = eps * a * xi * xi;
        }
        const double ud = u[0] * c + u[1] * s, up = -u[0] * s + u[1] * c;
        const double k11 = 2.0 * eps * a * ud * ud, k22 = 2.0 * eps * a * up * up, k12 = 2.0 * eps * a * ud * up;
        const double dens = 0.5 * (mat.D_long * k11 * k11 + mat.D_trans * k22 * k22 + 2.0 * mat.D_coupling * k11 * k22 +
                                   4.0 * mat.D_twist * k12 * k12);
        CHECK_REL(sb_energy(&t, m->x), dens * plume_mesh_total_area(m), 1e-6, 0.0);
        /* the unclamped term is exact for it too; a surface with slope at the side is not
         * admissible: the mirrored triangles see a kink there and store more than the plate */
        for (plume_index v = 0; v < m->nv; v++)
            m->x[3 * v + 2] = eps * 0.3 * (u[0] * m->X[2 * v] + u[1] * m->X[2 * v + 1] - lo);
        CHECK(sb_energy(&t, m->x) > 0.0);
        t.destroy(t.ctx);

        for (int variant = 0; variant < 2; variant++) {
            if (variant == 1) /* the whole boundary */
                for (plume_index e = 0; e < m->ne; e++)
                    if (m->edge_tri[2 * e + 1] < 0)
                        cl[m->edges[2 * e]] = cl[m->edges[2 * e + 1]] = 1;
            bm_map_cylinder(m, 20.0 + 35.0 * fam, 0.8, rest);
            for (plume_index i = 0; i < 3 * m->nv; i++)
                rest[i] += urange(&r, -0.03, 0.03);
            for (int curved = 0; curved < 2; curved++) {
                CHECK(plume_shape_bending_term_create_opts(m, &mat, 1, curved ? rest : NULL, &(plume_shape_bending_opts){cl, 0, 0}, &t, &err) ==
                      PLUME_OK);
                bm_map_cylinder(m, urange(&r, 0.0, 180.0), urange(&r, -2.0, 2.0), m->x);
                for (plume_index i = 0; i < 3 * m->nv; i++)
                    m->x[i] += urange(&r, -0.08, 0.08);
                char what[96];
                snprintf(what, sizeof what, "%s, clamped %s%s", bm_family_name[fam], variant ? "boundary" : "side",
                         curved ? ", curved rest" : "");
                term_fd_check(&t, m->nv, m->x, 1e-6, 2e-7, what);
                t.destroy(t.ctx);
            }
        }
        /* a rest shape that gives a clamped edge no mirror plane: an error naming it */
        if (fam == 0) {
            memset(rest, 0, sizeof(double) * 3 * (size_t)m->nv);
            CHECK(plume_shape_bending_term_create_opts(m, &mat, 1, rest, &(plume_shape_bending_opts){cl, 0, 0}, &t,
                                                       &err) == PLUME_EINVAL);
            CHECK(strstr(err.msg, "clamped edge") && strstr(err.msg, "mirror plane"));
        }
        free(cl);
        free(rest);
        plume_mesh_destroy(&m);
    }
}

/* ---- the patch test ------------------------------------------------------------------------------ */

/* A surface of constant curvature (small amplitude: the linear plate) is the exact solution of
 * pure bending, so the discrete equilibrium must hold at every vertex away from the boundary:
 * the energy's gradient there is zero. A per-triangle fit exact for quadratics is not enough for
 * that (the own fit alone leaves forces of the order of the boundary moments inside an irregular
 * mesh, so its equilibria converge to a wrong, softer answer); the shared edge slopes make the
 * discrete total curvature a boundary sum and the forces vanish. Both are measured: the default
 * term must pass on every family, the own fit must fail on the random Delaunay mesh (else this
 * test could not see the difference). */
static double sb_patch_residual(int fam, int own_only)
{
    const plume_bending_material mat = {2.0, 0.6, 0.3, 0.2};
    const double h = 0.0625;
    plume_mesh *m = bm_family_mesh(fam, h, 1.0, 0.75, 33.0);
    if (!m)
        return NAN;
    double res = NAN;
    const long n = 3 * (long)m->nv;
    double *g = calloc((size_t)n, sizeof *g);
    unsigned char *bnd = calloc((size_t)m->nv, 1);
    plume_term t;
    const plume_shape_bending_opts o = {NULL, own_only, 0};
    if (!g || !bnd || plume_shape_bending_term_create_opts(m, &mat, 1, NULL, &o, &t, NULL) != PLUME_OK)
        goto done;
    const double eps = 1e-7;
    for (plume_index v = 0; v < m->nv; v++) {
        const double X = m->X[2 * v], Y = m->X[2 * v + 1];
        m->x[3 * v + 2] = eps * 0.5 * (0.8 * X * X - 0.5 * Y * Y + 0.6 * X * Y);
    }
    if (t.eval(t.ctx, 3, m->x, NULL, g, NULL, 0) == PLUME_OK) {
        for (plume_index e = 0; e < m->ne; e++)
            if (m->edge_tri[2 * e + 1] < 0)
                bnd[m->edges[2 * e]] = bnd[m->edges[2 * e + 1]] = 1;
        double gin = 0.0, gall = 0.0;
        for (plume_index v = 0; v < m->nv; v++) {
            double dmin = INFINITY;
            for (plume_index b = 0; b < m->nv; b++)
                if (bnd[b])
                    dmin = fmin(dmin, hypot(m->X[2 * v] - m->X[2 * b], m->X[2 * v + 1] - m->X[2 * b + 1]));
            gall = fmax(gall, fabs(g[3 * v + 2]));
            if (dmin > 5.0 * h)
                gin = fmax(gin, fabs(g[3 * v + 2]));
        }
        res = gall > 0.0 ? gin / gall : NAN;
    }
    t.destroy(t.ctx);
done:
    free(g);
    free(bnd);
    plume_mesh_destroy(&m);
    return res;
}

void test_shape_bending_patch_test(void)
{
    for (int fam = 0; fam < BM_NFAMILY; fam++) {
        const double avg = sb_patch_residual(fam, 0), own = sb_patch_residual(fam, 1);
        fprintf(stderr, "    %-20s interior force / boundary force: edge-averaged %.1e, own fit %.1e\n",
                bm_family_name[fam], avg, own);
        CHECK(avg <= 1e-6);
        if (fam == BM_DELAUNAY)
            CHECK(own >= 1e-3);
    }
}

/* ---- invariance, projection ---------------------------------------------------------------------- */

void test_shape_bending_rigid_invariance(void)
{
    rng64 r = {0x77aaULL};
    const plume_bending_material mat = {1.2, 0.1, 0.0, 0.05};
    plume_mesh *m = bm_family_mesh(BM_DELAUNAY, 0.25, 1.0, 0.75, 35.0);
    CHECK(m != NULL);
    if (!m)
        return;
    const long n = 3 * (long)m->nv;
    double *rest = malloc(sizeof(double) * (size_t)n), *y = malloc(sizeof(double) * (size_t)n);
    double *g = calloc((size_t)n, sizeof *g), *gy = calloc((size_t)n, sizeof *gy);
    plume_term t;
    CHECK(rest && y && g && gy);
    if (!rest || !y || !g || !gy)
        goto done;
    bm_map_cylinder(m, 80.0, 0.7, rest);
    CHECK(plume_shape_bending_term_create(m, &mat, 1, rest, &t, NULL) == PLUME_OK);
    const int ka = 3 * t.arity;
    const size_t kk = (size_t)ka * (size_t)ka;
    double *H = malloc(sizeof(double) * kk * (size_t)t.nstencil), *Hy = malloc(sizeof(double) * kk * (size_t)t.nstencil);
    CHECK(H && Hy);
    if (H && Hy) {
        bm_map_cylinder(m, 20.0, -1.9, m->x);
        for (long i = 0; i < n; i++)
            m->x[i] += urange(&r, -0.1, 0.1);
        double Q[3][3];
        bm_rigid_motion(m->nv, m->x, Q, y);
        double E = 0.0, Ey = 0.0;
        CHECK(t.eval(t.ctx, 3, m->x, &E, g, H, 0) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, y, &Ey, gy, Hy, 0) == PLUME_OK);
        CHECK(E > 0.0);
        CHECK_REL(Ey, E, 1e-11, 0.0);
        const double gs = term_max_abs(g, n);
        double gerr = 0.0;
        for (plume_index v = 0; v < m->nv; v++)
            for (int i = 0; i < 3; i++) {
                const double Rg = Q[i][0] * g[3 * v] + Q[i][1] * g[3 * v + 1] + Q[i][2] * g[3 * v + 2];
                gerr = fmax(gerr, fabs(gy[3 * v + i] - Rg));
            }
        CHECK(gerr <= 1e-10 * gs);
        double herr = 0.0, hs = 0.0;
        for (plume_index st = 0; st < t.nstencil; st++) {
            const double *h = H + kk * st, *hy = Hy + kk * st;
            hs = fmax(hs, term_max_abs(h, (long)kk));
            for (int a = 0; a < t.arity; a++)
                for (int b = 0; b < t.arity; b++)
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++) {
                            double v = 0.0;
                            for (int p = 0; p < 3; p++)
                                for (int q = 0; q < 3; q++)
                                    v += Q[i][p] * h[(3 * a + p) * ka + 3 * b + q] * Q[j][q];
                            herr = fmax(herr, fabs(hy[(3 * a + i) * ka + 3 * b + j] - v));
                        }
        }
        CHECK(herr <= 1e-10 * hs);
        /* the energy's gradient is orthogonal to the six rigid modes (net force and torque 0) */
        double F[3] = {0, 0, 0}, T[3] = {0, 0, 0};
        for (plume_index v = 0; v < m->nv; v++) {
            double tq[3];
            const double *xv = m->x + 3 * v, *gv = g + 3 * v;
            tq[0] = xv[1] * gv[2] - xv[2] * gv[1];
            tq[1] = xv[2] * gv[0] - xv[0] * gv[2];
            tq[2] = xv[0] * gv[1] - xv[1] * gv[0];
            for (int i = 0; i < 3; i++)
                F[i] += gv[i], T[i] += tq[i];
        }
        CHECK(term_max_abs(F, 3) <= 1e-11 * gs * (double)m->nv);
        CHECK(term_max_abs(T, 3) <= 1e-11 * gs * (double)m->nv);
    }
    free(H);
    free(Hy);
    t.destroy(t.ctx);
done:
    free(rest);
    free(y);
    free(g);
    free(gy);
    plume_mesh_destroy(&m);
}

static double sb_min_eig(const double *B, int k, double *scale)
{
    double *A = malloc(sizeof(double) * (size_t)(2 * k * k + k)), mn = 0.0;
    *scale = term_max_abs(B, (long)k * k);
    if (!A)
        return -INFINITY;
    double *V = A + k * k, *lam = V + k * k;
    memcpy(A, B, sizeof(double) * (size_t)(k * k));
    plume_dense_sym_eig(k, A, lam, V);
    mn = lam[0];
    for (int i = 1; i < k; i++)
        mn = fmin(mn, lam[i]);
    free(A);
    return mn;
}

/* project = 1: the Gauss-Newton blocks, PSD and exactly symmetric; the exact blocks are
 * indefinite somewhere at a large deformation; at the rest shape both are the same. */
void test_shape_bending_projection(void)
{
    rng64 r = {0xabcdef02ULL};
    const plume_bending_material mat = {2.0, 0.5, 0.0, 0.0};
    plume_mesh *m = bm_family_mesh(BM_EQUI_ACROSS, 0.25, 1.0, 0.75, 70.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_term t;
    CHECK(plume_shape_bending_term_create(m, &mat, 1, NULL, &t, NULL) == PLUME_OK);
    const int ka = 3 * t.arity;
    const size_t kk = (size_t)ka * (size_t)ka, nb = kk * (size_t)t.nstencil;
    double *H = malloc(sizeof(double) * nb), *P = malloc(sizeof(double) * nb);
    CHECK(H && P);
    if (H && P) {
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, 0) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, P, 1) == PLUME_OK);
        CHECK(memcmp(H, P, sizeof(double) * nb) == 0);
        int indefinite = 0;
        for (int trial = 0; trial < 4; trial++) {
            bm_map_cylinder(m, urange(&r, 0.0, 180.0), urange(&r, -3.0, 3.0), m->x);
            for (plume_index i = 0; i < 3 * m->nv; i++)
                m->x[i] += urange(&r, -0.1, 0.1);
            CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, 0) == PLUME_OK);
            CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, P, 1) == PLUME_OK);
            for (plume_index s = 0; s < t.nstencil; s++) {
                const double *h = H + kk * s, *p = P + kk * s;
                double sh, sp;
                indefinite += sb_min_eig(h, ka, &sh) < -1e-9 * sh;
                CHECK(sb_min_eig(p, ka, &sp) >= -1e-12 * sp);
                for (int i = 0; i < ka; i++)
                    for (int j = 0; j < ka; j++)
                        CHECK(p[i * ka + j] == p[j * ka + i] && h[i * ka + j] == h[j * ka + i]);
                /* translations are in the null space of both */
                for (int i = 0; i < ka; i++)
                    for (int c = 0; c < 3; c++) {
                        double s6 = 0.0, t6 = 0.0;
                        for (int v = 0; v < t.arity; v++)
                            s6 += p[i * ka + 3 * v + c], t6 += h[i * ka + 3 * v + c];
                        CHECK(fabs(s6) <= 1e-12 * sp && fabs(t6) <= 1e-12 * sh);
                    }
            }
        }
        CHECK(indefinite > 0);
    }
    free(H);
    free(P);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* ---- stencil, interface, collapse, errors -------------------------------------------------------- */

void test_shape_bending_stencil(void)
{
    plume_mesh *m = bm_family_mesh(BM_RIGHT, 0.25, 1.0, 1.0, 0.0);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_term t;
    plume_err err;
    /* the own fit alone: six distinct vertices, the natural ones inside */
    const plume_shape_bending_opts own = {NULL, 1, 0};
    CHECK(plume_shape_bending_term_create_opts(m, &SB_VANE, 1, NULL, &own, &t, &err) == PLUME_OK);
    CHECK(strcmp(t.name, "shape bending") == 0);
    CHECK(t.arity == 6 && t.nstencil == m->nt);
    for (plume_index q = 0; q < m->nt; q++) {
        const plume_index *s = t.stencil + 6 * q, *tv = m->tri + 3 * q;
        CHECK(s[0] == tv[0] && s[1] == tv[1] && s[2] == tv[2]);
        /* six distinct vertices; an interior edge's neighbour vertex is kept */
        for (int a = 0; a < 6; a++)
            for (int b = a + 1; b < 6; b++)
                CHECK(s[a] != s[b]);
        for (int k = 0; k < 3; k++) {
            const plume_index a = tv[(k + 1) % 3], b = tv[(k + 2) % 3];
            for (plume_index u = 0; u < m->nt; u++) {
                const plume_index *uv = m->tri + 3 * u;
                int ha = 0, hb = 0;
                for (int j = 0; j < 3; j++)
                    ha |= uv[j] == a, hb |= uv[j] == b;
                if (u != q && ha && hb)
                    for (int j = 0; j < 3; j++)
                        if (uv[j] != a && uv[j] != b)
                            CHECK(s[3 + k] == uv[j]);
            }
        }
    }
    t.destroy(t.ctx);
    /* the default (edge-averaged) term: T's vertices first, its own points and its neighbours'
     * in the row, no vertex twice (padding repeats the first) */
    CHECK(plume_shape_bending_term_create(m, &SB_VANE, 1, NULL, &t, &err) == PLUME_OK);
    CHECK(t.arity > 6 && t.arity <= 24 && t.nstencil == m->nt);
    int widest = 0;
    for (plume_index q = 0; q < m->nt; q++) {
        const plume_index *s = t.stencil + (size_t)t.arity * q, *tv = m->tri + 3 * q;
        CHECK(s[0] == tv[0] && s[1] == tv[1] && s[2] == tv[2]);
        int nreal = t.arity, distinct = 1;
        while (nreal > 1 && s[nreal - 1] == s[0])
            nreal--;
        for (int a = 0; a < nreal; a++)
            for (int b = a + 1; b < nreal; b++)
                distinct &= s[a] != s[b];
        CHECK(distinct && nreal >= 6);
        widest = nreal > widest ? nreal : widest;
    }
    CHECK(widest == t.arity);
    /* energy and gradient are added; blocks are overwritten; all optional */
    bm_map_cylinder(m, 30.0, 1.0, m->x);
    const long n = 3 * (long)m->nv;
    double *g = calloc((size_t)n, sizeof *g), *g2 = calloc((size_t)n, sizeof *g2);
    const size_t kk = (size_t)(9 * t.arity * t.arity);
    double *H = malloc(sizeof(double) * kk * (size_t)t.nstencil);
    CHECK(g && g2 && H);
    if (g && g2 && H) {
        double E = 0.0, E2 = 10.0;
        CHECK(t.eval(t.ctx, 3, m->x, &E, g, NULL, 0) == PLUME_OK);
        for (long i = 0; i < n; i++)
            g2[i] = 1.0;
        for (size_t i = 0; i < kk * (size_t)t.nstencil; i++)
            H[i] = NAN;
        CHECK(t.eval(t.ctx, 3, m->x, &E2, g2, H, 0) == PLUME_OK);
        CHECK(E > 0.0);
        CHECK_REL(E2, 10.0 + E, 1e-14, 0.0);
        for (long i = 0; i < n; i++)
            CHECK_REL(g2[i], 1.0 + g[i], 1e-14, 1.0);
        for (size_t i = 0; i < kk * (size_t)t.nstencil; i++)
            CHECK(isfinite(H[i]));
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, NULL, 0) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, 1) == PLUME_OK);
        CHECK(t.eval(t.ctx, 2, m->x, &E, NULL, NULL, 0) == PLUME_EINVAL);
        CHECK(t.eval(t.ctx, 3, NULL, &E, NULL, NULL, 0) == PLUME_EINVAL);
        /* hess_range: the blocks of any range as eval writes them, bit for bit, exact and projected;
         * the stencils are padded with their first vertex */
        CHECK(t.hess_range != NULL && t.padded == 1);
        double *R = malloc(sizeof(double) * kk * 7);
        for (int pj = 0; pj < 2 && t.hess_range && R; pj++) {
            CHECK(t.eval(t.ctx, 3, m->x, NULL, NULL, H, pj) == PLUME_OK);
            for (plume_index first = 0; first < t.nstencil; first += 7) {
                const plume_index cnt = t.nstencil - first < 7 ? t.nstencil - first : 7;
                CHECK(t.hess_range(t.ctx, 3, m->x, first, cnt, R, pj) == PLUME_OK);
                CHECK(memcmp(R, H + kk * (size_t)first, sizeof(double) * kk * (size_t)cnt) == 0);
            }
        }
        if (t.hess_range && R) {
            CHECK(t.hess_range(t.ctx, 3, m->x, t.nstencil - 1, 2, R, 0) == PLUME_EINVAL);
            CHECK(t.hess_range(t.ctx, 3, m->x, -1, 1, R, 0) == PLUME_EINVAL);
            CHECK(t.hess_range(t.ctx, 2, m->x, 0, 1, R, 0) == PLUME_EINVAL);
            CHECK(t.hess_range(t.ctx, 3, m->x, 0, 1, NULL, 0) == PLUME_EINVAL);
        }
        free(R);
        /* a collapsed current triangle: PLUME_ESINGULAR (a trial point the line search rejects), not NaN */
        const plume_index *tv = m->tri;
        for (int i = 0; i < 3; i++)
            m->x[3 * tv[2] + i] = 0.5 * (m->x[3 * tv[0] + i] + m->x[3 * tv[1] + i]);
        E = 0.0;
        CHECK(t.eval(t.ctx, 3, m->x, &E, NULL, NULL, 0) == PLUME_ESINGULAR);
        CHECK(t.eval(t.ctx, 3, m->x, NULL, g, H, 1) == PLUME_ESINGULAR);
        for (int i = 0; i < 3; i++)
            m->x[3 * tv[1] + i] = m->x[3 * tv[0] + i];
        CHECK(t.eval(t.ctx, 3, m->x, &E, NULL, NULL, 0) == PLUME_ESINGULAR);
    }
    free(g);
    free(g2);
    free(H);
    t.destroy(t.ctx);
    t.destroy(NULL);
    plume_mesh_destroy(&m);
}

static int sb_create_fails(const plume_mesh *m, const plume_bending_material *mats, int nmat, const double *rest,
                           const char *needle)
{
    plume_term t;
    memset(&t, 0xff, sizeof t);
    plume_err err;
    err.msg[0] = '\0';
    plume_status st = plume_shape_bending_term_create(m, mats, nmat, rest, &t, &err);
    int ok = st == PLUME_EINVAL && strstr(err.msg, needle) != NULL && t.ctx == NULL && t.eval == NULL;
    if (!ok)
        fprintf(stderr, "    expected EINVAL with \"%s\", got %d: \"%s\"\n", needle, (int)st, err.msg);
    if (plume_shape_bending_term_create(m, mats, nmat, rest, &t, NULL) != PLUME_EINVAL)
        ok = 0;
    return ok;
}

/* a mesh of the given vertices and triangles, topology built */
static plume_mesh *sb_small_mesh(int nv, const double *X, int nt, const plume_index *tri, int dim)
{
    plume_mesh *m = NULL;
    if (plume_mesh_create(nv, nt, dim, &m, NULL) != PLUME_OK)
        return NULL;
    memcpy(m->X, X, sizeof(double) * 2 * (size_t)nv);
    memcpy(m->tri, tri, sizeof(plume_index) * 3 * (size_t)nt);
    if (plume_mesh_build_topology(m, NULL) != PLUME_OK) {
        plume_mesh_destroy(&m);
        return NULL;
    }
    plume_mesh_reset_current(m);
    return m;
}

/* A fan of k triangles round one vertex (a rim of slightly varying radius, so no six stencil
 * points share a conic): no triangle has a natural stencil (its rim edge is on the boundary), so
 * each searches its 1-ring, which holds every vertex. The search tries a bounded set of
 * candidates spread round T (the unbounded search cost about k^4: 2.3 s at k = 100, 32 s at
 * k = 150 and 200); the fit stays exact for a quadratic surface at k = 12, 100 and 400 (the
 * nearest candidates alone lie along the rim and found no stencil at k = 100). */
void test_shape_bending_fan(void)
{
    const plume_bending_material mat = {3.0, 0.7, 0.4, 0.2};
    const int ks[3] = {12, 100, 400};
    for (int c = 0; c < 3; c++) {
        const int k = ks[c];
        double *X = malloc(sizeof(double) * 2 * (size_t)(k + 1));
        plume_index *tri = malloc(sizeof(plume_index) * 3 * (size_t)k);
        CHECK(X && tri);
        if (!X || !tri) {
            free(X);
            free(tri);
            return;
        }
        X[0] = X[1] = 0.0;
        for (int i = 0; i < k; i++) {
            const double a = 2.0 * BM_PI * i / k, r = 1.0 + 0.05 * sin(7.0 * a) + 0.03 * cos(3.0 * a);
            X[2 * (i + 1)] = r * cos(a);
            X[2 * (i + 1) + 1] = r * sin(a);
            tri[3 * i] = 0;
            tri[3 * i + 1] = i + 1;
            tri[3 * i + 2] = (i + 1) % k + 1;
        }
        plume_mesh *m = sb_small_mesh(k + 1, X, k, tri, 3);
        free(X);
        free(tri);
        CHECK(m != NULL);
        if (!m)
            return;
        plume_term t;
        plume_err err;
        const plume_status st = plume_shape_bending_term_create(m, &mat, 1, NULL, &t, &err);
        CHECK(st == PLUME_OK);
        if (st != PLUME_OK) {
            fprintf(stderr, "    fan of %d: %s\n", k, err.msg);
            plume_mesh_destroy(&m);
            continue;
        }
        const double eps = 1e-6, H[3] = {0.8, -0.5, 0.3};
        for (plume_index v = 0; v < m->nv; v++) {
            const double x = m->X[2 * v], y = m->X[2 * v + 1];
            m->x[3 * v + 2] = eps * 0.5 * (H[0] * x * x + H[1] * y * y + 2.0 * H[2] * x * y);
        }
        /* the barbs run along material x (barb_dir 0) */
        const double dens = 0.5 * eps * eps *
                            (mat.D_long * H[0] * H[0] + mat.D_trans * H[1] * H[1] + 2.0 * mat.D_coupling * H[0] * H[1] +
                             4.0 * mat.D_twist * H[2] * H[2]);
        CHECK_REL(sb_energy(&t, m->x), dens * plume_mesh_total_area(m), 1e-6, 0.0);
        t.destroy(t.ctx);
        plume_mesh_destroy(&m);
    }
}

void test_shape_bending_bad_inputs(void)
{
    plume_bending_material mats[2] = {{1.0, 0.5, 0.0, 0.0}, {2.0, 0.1, 0.2, 0.1}};
    plume_mesh *m = bm_family_mesh(BM_RIGHT, 0.5, 1.0, 1.0, 0.0);
    CHECK(m != NULL);
    if (!m)
        return;
    CHECK(sb_create_fails(NULL, mats, 2, NULL, "NULL"));
    CHECK(sb_create_fails(m, NULL, 2, NULL, "NULL"));
    CHECK(plume_shape_bending_term_create(m, mats, 2, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(sb_create_fails(m, mats, 0, NULL, "nmat"));

    /* every stiffness field: negative, NaN, infinite */
    double *fields[4] = {&mats[1].D_long, &mats[1].D_trans, &mats[1].D_twist, &mats[1].D_coupling};
    const char *names[4] = {"material 1: D_long", "material 1: D_trans", "material 1: D_twist",
                            "material 1: D_coupling"};
    const double bad[3] = {-1.0, NAN, INFINITY};
    for (int f = 0; f < 4; f++) {
        const double keep = *fields[f];
        for (int b = 0; b < 3; b++) {
            *fields[f] = bad[b];
            CHECK(sb_create_fails(m, mats, 2, NULL, names[f]));
        }
        *fields[f] = keep;
    }
    mats[0].D_coupling = -1e-300;
    CHECK(sb_create_fails(m, mats, 2, NULL, "material 0: D_coupling must be finite and >= 0 (got -1e-300)"));
    /* coupling beyond sqrt(D_long D_trans): not positive semidefinite */
    mats[0].D_coupling = 0.8;
    CHECK(sb_create_fails(m, mats, 2, NULL, "material 0: D_coupling (0.8) must not exceed"));
    mats[0].D_coupling = 0.0;
    /* zero stiffness is allowed */
    const plume_bending_material zero = {0.0, 0.0, 0.0, 0.0};
    plume_term t;
    CHECK(plume_shape_bending_term_create(m, &zero, 1, NULL, &t, NULL) == PLUME_OK);
    bm_map_cylinder(m, 10.0, 1.0, m->x);
    CHECK(sb_energy(&t, m->x) == 0.0);
    plume_mesh_reset_current(m);
    t.destroy(t.ctx);

    /* material id out of range, both ways */
    m->material[3] = 2;
    CHECK(sb_create_fails(m, mats, 2, NULL, "triangle 3: material id 2 out of range [0, 2)"));
    m->material[3] = -1;
    CHECK(sb_create_fails(m, mats, 2, NULL, "material id -1"));
    m->material[3] = 1;
    CHECK(sb_create_fails(m, mats, 1, NULL, "material id 1 out of range [0, 1)"));
    m->material[3] = 0;

    /* barb direction */
    m->barb_dir[2] = 0.0;
    m->barb_dir[3] = 0.0;
    CHECK(sb_create_fails(m, mats, 2, NULL, "triangle 1: barb direction"));
    m->barb_dir[2] = NAN;
    CHECK(sb_create_fails(m, mats, 2, NULL, "barb direction"));
    m->barb_dir[2] = 1.0;

    /* rest shape: NaN, collapsed */
    double *rest = malloc(sizeof(double) * 3 * (size_t)m->nv);
    CHECK(rest != NULL);
    if (rest) {
        memcpy(rest, m->x, sizeof(double) * 3 * (size_t)m->nv);
        rest[3 * 4 + 2] = NAN;
        CHECK(sb_create_fails(m, mats, 2, rest, "rest_x[14] (vertex 4) is not finite"));
        memset(rest, 0, sizeof(double) * 3 * (size_t)m->nv);
        CHECK(sb_create_fails(m, mats, 2, rest, "degenerate in rest_x"));
        free(rest);
    }

    /* a degenerate reference triangle (collinear up to rounding): build the topology on a good
     * shape, then flatten it */
    {
        const double X[10] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0, 1.5, 0.5};
        const plume_index tri[9] = {0, 1, 2, 1, 0, 3, 1, 4, 2};
        plume_mesh *d = sb_small_mesh(5, X, 3, tri, 3);
        CHECK(d != NULL);
        if (d) {
            d->X[5] = 1e-17;
            CHECK(sb_create_fails(d, mats, 2, NULL, "degenerate reference triangle"));
            plume_mesh_destroy(&d);
        }
    }

    /* too few vertices for any well-conditioned stencil: one triangle, two triangles */
    {
        const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0};
        const plume_index tri[6] = {0, 1, 2, 1, 0, 3};
        plume_mesh *one = sb_small_mesh(3, X, 1, tri, 3), *two = sb_small_mesh(4, X, 2, tri, 3);
        CHECK(one && two);
        if (one)
            CHECK(sb_create_fails(one, mats, 2, NULL, "triangle 0: no well-conditioned 6-vertex stencil"));
        if (two)
            CHECK(sb_create_fails(two, mats, 2, NULL, "no well-conditioned 6-vertex stencil"));
        plume_mesh_destroy(&one);
        plume_mesh_destroy(&two);
    }

    /* topology not built */
    {
        plume_mesh *raw = NULL;
        CHECK(plume_mesh_create(4, 2, 3, &raw, NULL) == PLUME_OK);
        if (raw) {
            const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0};
            const plume_index tri[6] = {0, 1, 2, 1, 0, 3};
            memcpy(raw->X, X, sizeof X);
            memcpy(raw->tri, tri, sizeof tri);
            CHECK(sb_create_fails(raw, mats, 2, NULL, "topology not built"));
            plume_mesh_destroy(&raw);
        }
    }

    /* planar mode */
    {
        const double X[8] = {0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0};
        const plume_index tri[6] = {0, 1, 2, 1, 0, 3};
        plume_mesh *flat = sb_small_mesh(4, X, 2, tri, 2);
        CHECK(flat != NULL);
        if (flat)
            CHECK(sb_create_fails(flat, mats, 2, NULL, "got dim 2"));
        plume_mesh_destroy(&flat);
    }

    CHECK(plume_shape_bending_term_create(m, mats, 2, NULL, &t, NULL) == PLUME_OK);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* ---- cylinders on five mesh families (the acceptance test) -------------------------------- */

/* Energy / continuum energy of a Lx x Ly patch at spacing h bent into a cylinder of curvature k
 * (curvature along material x), barbs at barb_deg to the curvature direction. */
static double sb_cylinder_ratio(int family, double h, double curv_deg, double barb_deg,
                                const plume_bending_material *mat, double k)
{
    plume_mesh *m = bm_family_mesh(family, h, 1.0, 0.8, curv_deg + barb_deg);
    if (!m)
        return NAN;
    plume_term t;
    double ratio = NAN;
    if (plume_shape_bending_term_create(m, mat, 1, NULL, &t, NULL) == PLUME_OK) {
        bm_map_cylinder(m, curv_deg, k, m->x);
        ratio = sb_energy(&t, m->x) / (bm_continuum_density(mat, k, barb_deg) * plume_mesh_total_area(m));
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
    return ratio;
}

/* Within 2 % at every resolution and |error| shrinking at h = 1/12, 1/24, 1/48 (an error already
 * below 1e-9 counts as converged), for barbs at 0, 30, 45, 90 degrees to the curvature, vane and
 * isotropic, the curvature along material x and at 30 degrees to it (on the right grid: the
 * hinge's +160 % case). */
static void sb_cylinder_family(int family)
{
    static const plume_bending_material iso = {1.0, 1.0, 0.0, 0.3};
    const plume_bending_material *mats[2] = {&SB_VANE, &iso};
    const char *mname[2] = {"vane", "iso"};
    const double barbs[4] = {0.0, 30.0, 45.0, 90.0}, curvs[2] = {0.0, 30.0};
    /* (on 1/8, 1/16, 1/32 the Delaunay family's vane at 90 degrees, curvature at 30, went
     * 0.9995, 0.9989, 0.9997: the O(h^2) metric deficit and the positive pollution of the stiff
     * direction cancel on the coarsest mesh; every mesh is a new random draw) */
    const double hs[3] = {1.0 / 12, 1.0 / 24, 1.0 / 48};
    for (int ic = 0; ic < 2; ic++)
        for (int im = 0; im < 2; im++)
            for (int ib = 0; ib < 4; ib++) {
                double r[3];
                for (int l = 0; l < 3; l++)
                    r[l] = sb_cylinder_ratio(family, hs[l], curvs[ic], barbs[ib], mats[im], 1.0);
                fprintf(stderr, "    %-18s curv %2g %-4s barbs %2g: E/E_plate h=1/12 %.4f  1/24 %.4f  1/48 %.4f\n",
                        bm_family_name[family], curvs[ic], mname[im], barbs[ib], r[0], r[1], r[2]);
                CHECK(isfinite(r[0]) && isfinite(r[1]) && isfinite(r[2]));
                for (int l = 0; l < 3; l++)
                    CHECK(fabs(r[l] - 1.0) < 0.02);
                for (int l = 1; l < 3; l++)
                    CHECK(fabs(r[l] - 1.0) < fabs(r[l - 1] - 1.0) || fabs(r[l] - 1.0) < 1e-9);
            }
}

void test_shape_bending_cylinder_right(void)
{
    sb_cylinder_family(BM_RIGHT);
}

void test_shape_bending_cylinder_right45(void)
{
    sb_cylinder_family(BM_RIGHT45);
}

void test_shape_bending_cylinder_equi_along(void)
{
    sb_cylinder_family(BM_EQUI_ALONG);
}

void test_shape_bending_cylinder_equi_across(void)
{
    sb_cylinder_family(BM_EQUI_ACROSS);
}

void test_shape_bending_cylinder_delaunay(void)
{
    sb_cylinder_family(BM_DELAUNAY);
}

/* ---- phases ------------------------------------------------------------------------------------ */

/* A resolved strip laminate bent across its strips: barbs along x (the layout's specimen mesh at
 * 90 degrees, strip boundaries on mesh edges), a deflection w(y) whose curvature is k_i in phase
 * i with D_i k_i the same in both (the laminate's uniform moment), C1 across the interfaces. The
 * phase-aware stencils fit each triangle within its own phase, where w is one quadratic, so the
 * term stores the exact sum of A/2 D_i k_i^2. The stencils that reach across the interface smear
 * the jump (a stiff barb triangle takes some of the matrix's curvature) and store more. */
void test_shape_bending_phase_aware_laminate(void)
{
    plume_layout l;
    plume_layout_default(&l);
    l.phi = 0.3, l.ratio = 0.05, l.h = 1e-4, l.h_barb = 1.5e-4, l.h_barbule = 5e-5, l.order = 1;
    const double lx = 0.01, ly = 0.01;
    l.d_B = ly / 4;
    plume_mesh *planar = NULL, *mesh = NULL;
    plume_problem *p = NULL;
    plume_err err = {{0}};
    plume_membrane_material mats[2];
    plume_bending_material ph[2];
    plume_layout_materials(&l, mats);
    plume_plate_of_membrane(&mats[0], &ph[0]);
    plume_plate_of_membrane(&mats[1], &ph[1]);
    CHECK(plume_specimen_mesh(&l, lx, ly, 90.0, &planar, &err) == PLUME_OK);
    CHECK(planar && plume_shell_specimen(planar, mats, ph, 2, &mesh, &p, &err) == PLUME_OK);
    if (!mesh) {
        plume_mesh_destroy(&planar);
        return;
    }
    /* the phases along y: barb k covers y in ly/2 + k d_B +- w_B/2 (micro/specimen_mesh.c) */
    const double wB = l.phi * l.d_B, eps = 1e-3, kB = eps * ph[1].D_trans / ph[0].D_trans, kM = eps;
#define LAM_BARB(y) (fabs(remainder((y) - 0.5 * ly, l.d_B)) < 0.5 * wB)
    int consistent = 1;
    for (plume_index t = 0; t < mesh->nt; t++) {
        const plume_index *v = mesh->tri + 3 * t;
        const double yc = (mesh->X[2 * v[0] + 1] + mesh->X[2 * v[1] + 1] + mesh->X[2 * v[2] + 1]) / 3.0;
        consistent &= (mesh->material[t] == 0) == LAM_BARB(yc);
    }
    CHECK(consistent);
    /* w(y) = int_0^y int_0^s k: exact on each piece, breakpoints at the interfaces */
    double *x = malloc((size_t)(3 * mesh->nv) * sizeof *x);
    for (plume_index v = 0; v < mesh->nv; v++) {
        const double Y = mesh->X[2 * v + 1];
        double y = 0.0, w = 0.0, s = 0.0;
        while (y < Y) {
            const double k = LAM_BARB(y + 1e-12 * ly) ? kB : kM;
            /* the next interface above y */
            double next = Y;
            for (int j = -8; j <= 8; j++)
                for (int side = -1; side <= 1; side += 2) {
                    const double yi = 0.5 * ly + j * l.d_B + side * 0.5 * wB;
                    if (yi > y + 1e-12 * ly && yi < next)
                        next = yi;
                }
            const double d = next - y;
            w += s * d + 0.5 * k * d * d;
            s += k * d;
            y = next;
        }
        x[3 * v] = mesh->X[2 * v], x[3 * v + 1] = Y, x[3 * v + 2] = w;
    }
    double expect = 0.0;
    for (plume_index t = 0; t < mesh->nt; t++) {
        const double k = mesh->material[t] == 0 ? kB : kM;
        expect += 0.5 * plume_mesh_ref_area(mesh, t) * ph[mesh->material[t]].D_trans * k * k;
    }
#undef LAM_BARB
    for (int aware = 0; aware < 2; aware++) {
        plume_term t;
        const plume_shape_bending_opts o = {NULL, 0, aware};
        CHECK(plume_shape_bending_term_create_opts(mesh, ph, 2, NULL, &o, &t, &err) == PLUME_OK);
        const double E = sb_energy(&t, x);
        fprintf(stderr, "    %s stencils: energy / laminate's %.8f (%ld triangles)\n", aware ? "phase-aware" : "plain",
                E / expect, (long)mesh->nt);
        if (aware)
            CHECK_REL(E, expect, 1e-6, 0.0);
        else
            CHECK(E > 1.02 * expect);
        t.destroy(t.ctx);
    }
    free(x);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    plume_mesh_destroy(&planar);
}
