/* Tests of the assembled problem (lib/core/problem.c), not of single elements: finite-difference checks
 * of the objective gradient, the Lagrangian Hessian on its sparse pattern, the constraint
 * Jacobian triplets and the forces on prescribed dofs, for a membrane mesh with a nonlinear
 * point potential and edge-length constraints, with some dofs prescribed; dropping of fully
 * prescribed constraints; the KKT residual at rest and under a change of units; every error path. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "test_rng.h"
#include "../lib/core/dense.h"
#include "../lib/core/edge_length.h"
#include "../lib/core/membrane.h"
#include "../lib/core/mesh.h"
#include "../lib/core/problem.h"

/* ---- helpers ---------------------------------------------------------------------------- */

/* rng64, urand, urange: tests/test_rng.h */

static double max_abs(const double *a, plume_index n)
{
    double m = 0.0;
    for (plume_index i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* records a failure when err > tol * scale, printing the context */
#define CHECK_ERR(err, tol, scale, what)                                                      \
    do {                                                                                      \
        double e_ = (err), s_ = (scale);                                                      \
        if (!(e_ <= (tol) * s_)) {                                                            \
            plume_test_failures++;                                                            \
            fprintf(stderr, "    CHECK_ERR failed %s:%d: %s: error %.3g > %.3g * %.3g\n",     \
                    __FILE__, __LINE__, what, e_, (double)(tol), s_);                         \
        }                                                                                     \
    } while (0)

/* ---- a nonlinear point potential: k/4 |x_v - a_v|^4 - f_v . x_v (exact derivatives) ------ */

enum { QMAX = 4 };

typedef struct {
    plume_index n;
    plume_index verts[QMAX];
    double k;
    double a[3 * QMAX], f[3 * QMAX];
} quartic_ctx;

static plume_status quartic_eval(void *ctx, int dim, const double *x, double *energy, double *grad,
                                 double *hblocks, int project)
{
    (void)project; /* k (|d|^2 I + 2 d d^T) is PSD already */
    const quartic_ctx *c = ctx;
    for (plume_index s = 0; s < c->n; s++) {
        const double *xv = x + dim * c->verts[s], *a = c->a + 3 * s, *f = c->f + 3 * s;
        double d[3] = {0, 0, 0}, d2 = 0.0;
        for (int q = 0; q < dim; q++) {
            d[q] = xv[q] - a[q];
            d2 += d[q] * d[q];
        }
        if (energy) {
            *energy += 0.25 * c->k * d2 * d2;
            for (int q = 0; q < dim; q++)
                *energy -= f[q] * xv[q];
        }
        if (grad)
            for (int q = 0; q < dim; q++)
                grad[dim * c->verts[s] + q] += c->k * d2 * d[q] - f[q];
        if (hblocks)
            for (int i = 0; i < dim; i++)
                for (int j = 0; j < dim; j++)
                    hblocks[(size_t)s * dim * dim + i * dim + j] = c->k * ((i == j) * d2 + 2.0 * d[i] * d[j]);
    }
    return PLUME_OK;
}

static void quartic_destroy(void *ctx)
{
    free(ctx);
}

/* ---- the test problem ------------------------------------------------------------------- */

/* A 4 x 2 vertex strip (6 triangles) with perturbed reference positions, random barb directions
 * and a membrane term; the point potential on vertices 0 (prescribed), 2 and 7; edge-length
 * constraints on all 13 mesh edges. Vertices 0 and 4 are clamped (so edge 0-4 is entirely
 * prescribed and must be dropped) and vertex 3's x is prescribed. Current positions are a random
 * stretch and rotation of the reference plus noise (and random z in shell mode), or the rest
 * state when at_rest (then the potential is centred on the rest positions and unloaded). Every
 * stiffness is multiplied by `stiff`. The same seed gives the same geometry. */
enum { NCOL = 4, NV = 2 * NCOL, NT = 2 * (NCOL - 1), NE = 3 * (NCOL - 1) + NCOL };

/* prescribed (vertex, axis); axis -1: every axis */
static const plume_index FIXED[3][2] = {{0, -1}, {NCOL, -1}, {3, 0}};
enum { NFIXED_VERT = 2 }; /* fully clamped vertices */

typedef struct {
    plume_problem *p;
    plume_index edges[2 * NE];
    double X[2 * NV];
} strip;

static int strip_build(strip *st, int dim, double stiff, uint64_t seed, int at_rest)
{
    rng64 r = {seed};
    plume_mesh *m = NULL;
    plume_problem *p = NULL;
    quartic_ctx *q = NULL;
    plume_err err;
    int ok = 0;
    memset(st, 0, sizeof *st);
    if (plume_mesh_create(NV, NT, dim, &m, &err) != PLUME_OK)
        return 0;
    for (int row = 0; row < 2; row++)
        for (int c = 0; c < NCOL; c++) {
            plume_index v = row * NCOL + c;
            m->X[2 * v] = c + urange(&r, -0.15, 0.15);
            m->X[2 * v + 1] = row + urange(&r, -0.15, 0.15);
        }
    memcpy(st->X, m->X, sizeof st->X);
    int ne = 0;
    for (int c = 0; c + 1 < NCOL; c++) {
        plume_index v00 = c, v10 = c + 1, v01 = NCOL + c, v11 = NCOL + c + 1;
        const plume_index t[6] = {v00, v10, v11, v00, v11, v01};
        memcpy(m->tri + 6 * c, t, sizeof t);
        const plume_index e[6] = {v00, v10, v01, v11, v00, v11};
        memcpy(st->edges + 2 * ne, e, sizeof e);
        ne += 3;
    }
    for (int c = 0; c < NCOL; c++) {
        st->edges[2 * ne] = c;
        st->edges[2 * ne + 1] = NCOL + c;
        ne++;
    }
    for (plume_index t = 0; t < NT; t++) {
        double a = urange(&r, -3.0, 3.0);
        m->barb_dir[2 * t] = cos(a);
        m->barb_dir[2 * t + 1] = sin(a);
    }
    plume_membrane_material mat = {{300.0, 2.0, 0.4, 1.2}, 0.02, 5.0, 0};
    mat.moduli.E_xx *= stiff, mat.moduli.E_yy *= stiff, mat.moduli.G_xy *= stiff, mat.kappa *= stiff;

    /* current positions x = Q (F X) + noise */
    double phi = urange(&r, -3.0, 3.0), sa = urange(&r, 0.8, 1.2), sb = urange(&r, 0.8, 1.2);
    double sh = urange(&r, -0.2, 0.2), tilt = urange(&r, -0.5, 0.5);
    double x[3 * NV];
    for (plume_index v = 0; v < NV; v++) {
        double X0 = m->X[2 * v], X1 = m->X[2 * v + 1];
        double y0 = sa * X0 + sh * X1, y1 = sb * X1;
        double nz[3] = {urange(&r, -0.1, 0.1), urange(&r, -0.1, 0.1), urange(&r, -0.3, 0.3)};
        if (at_rest) {
            x[dim * v] = X0, x[dim * v + 1] = X1;
            if (dim == 3)
                x[dim * v + 2] = 0.0;
            continue;
        }
        double c0 = cos(phi) * y0 - sin(phi) * y1, c1 = sin(phi) * y0 + cos(phi) * y1;
        if (dim == 2) {
            x[2 * v] = c0 + nz[0], x[2 * v + 1] = c1 + nz[1];
        } else { /* tilt the plane about the first axis */
            x[3 * v] = c0 + nz[0];
            x[3 * v + 1] = cos(tilt) * c1 + nz[1];
            x[3 * v + 2] = sin(tilt) * c1 + nz[2];
        }
    }

    q = calloc(1, sizeof *q);
    if (!q)
        goto cleanup;
    q->n = 3;
    q->verts[0] = 0, q->verts[1] = 2, q->verts[2] = 7;
    q->k = 40.0 * stiff;
    for (int s = 0; s < 3; s++)
        for (int a = 0; a < dim; a++) {
            double xv = x[dim * q->verts[s] + a];
            q->a[3 * s + a] = at_rest ? xv : xv + urange(&r, -0.4, 0.4);
            q->f[3 * s + a] = at_rest ? 0.0 : stiff * urange(&r, -1.0, 1.0);
        }
    plume_term qt = {.size = sizeof(plume_term), .name = "quartic points", .arity = 1, .nstencil = q->n, .stencil = q->verts, .eval = quartic_eval,
                     .destroy = quartic_destroy, .ctx = q};
    plume_term mt;
    plume_constraint ec;
    if (plume_problem_create(NV, dim, 3.0, &p, &err) != PLUME_OK)
        goto cleanup;
    CHECK(plume_membrane_term_create(m, dim, &mat, 1, &mt, &err) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &mt, &err) == PLUME_OK);
    CHECK(plume_problem_add_term(p, &qt, &err) == PLUME_OK);
    q = NULL; /* the problem owns it now */
    CHECK(plume_edge_length_create(st->edges, NE, m->X, NV, &ec, &err) == PLUME_OK);
    CHECK(plume_problem_add_constraint(p, &ec, &err) == PLUME_OK);
    memcpy(plume_problem_x(p), x, (size_t)(dim * NV) * sizeof *x);
    for (int i = 0; i < 3; i++)
        for (int a = 0; a < dim; a++)
            if (FIXED[i][1] < 0 || FIXED[i][1] == a)
                CHECK(plume_problem_fix_dof(p, FIXED[i][0] * dim + a, &err) == PLUME_OK);
    plume_status s = plume_problem_finalize(p, &err);
    CHECK(s == PLUME_OK);
    if (s != PLUME_OK) {
        fprintf(stderr, "    finalize: %s\n", err.msg);
        goto cleanup;
    }
    st->p = p;
    p = NULL;
    ok = 1;
cleanup:
    free(q);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&m);
    return ok;
}

/* Dense symmetric matrix from the upper-triangle CSC values. */
static void dense_from_csc(plume_sparsity sp, const double *values, double *H)
{
    memset(H, 0, (size_t)(sp.n * sp.n) * sizeof *H);
    for (plume_index c = 0; c < sp.n; c++)
        for (plume_index k = sp.colptr[c]; k < sp.colptr[c + 1]; k++)
            H[sp.rowind[k] * sp.n + c] = H[c * sp.n + sp.rowind[k]] = values[k];
}

/* r <- grad f(u) + J(u)^T lambda on the free dofs (jval: workspace of the Jacobian's nnz). */
static int lagrangian_gradient(plume_problem *p, const double *u, const double *lambda, double *r,
                               double *jval)
{
    double f;
    plume_index jnnz;
    const plume_index *rows, *cols;
    plume_problem_jacobian_pattern(p, &jnnz, &rows, &cols);
    if (plume_problem_objective(p, u, &f, r) != PLUME_OK || plume_problem_jacobian(p, u, jval) != PLUME_OK)
        return 0;
    for (plume_index k = 0; k < jnnz; k++)
        r[cols[k]] += jval[k] * lambda[rows[k]];
    return 1;
}

/* f + lambda . g at the problem's current x (u = NULL: x as it is) */
static double lagrangian_at_x(plume_problem *p, const double *lambda, double *g)
{
    double f = NAN;
    CHECK(plume_problem_objective(p, NULL, &f, NULL) == PLUME_OK);
    CHECK(plume_problem_constraints(p, NULL, g, NULL) == PLUME_OK);
    for (plume_index c = 0; c < plume_problem_ncons(p); c++)
        f += lambda[c] * g[c];
    return f;
}

enum { NFMAX = 3 * NV, NCMAX = NE };

/* ---- finite-difference checks ----------------------------------------------------------- */

/* Sizes, free-dof map, pattern structure and dropped constraints. */
void test_problem_structure(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        strip st;
        if (!strip_build(&st, dim, 1.0, 0x1234567890abcdefULL + (uint64_t)dim, 0))
            continue;
        plume_problem *p = st.p;
        CHECK(plume_problem_dim(p) == dim && plume_problem_nvert(p) == NV);
        CHECK(plume_problem_nfree(p) == dim * NV - NFIXED_VERT * dim - 1);
        CHECK(plume_problem_length_scale(p) == 3.0);
        /* edge 0-4 joins two clamped vertices: dropped; every other edge kept */
        CHECK(plume_problem_ncons(p) == NE - 1);
        for (int a = 0; a < dim; a++)
            CHECK(plume_problem_is_fixed(p, a) && plume_problem_is_fixed(p, NCOL * dim + a));
        CHECK(plume_problem_is_fixed(p, 3 * dim));
        CHECK(!plume_problem_is_fixed(p, 3 * dim + 1) && !plume_problem_is_fixed(p, dim * NV - 1));

        /* gather / scatter: free dofs in increasing dof order */
        double u[NFMAX], x0[3 * NV];
        memcpy(x0, plume_problem_x(p), (size_t)(dim * NV) * sizeof *x0);
        plume_problem_gather(p, u);
        plume_index i = 0;
        for (plume_index d = 0; d < dim * NV; d++)
            if (!plume_problem_is_fixed(p, d))
                CHECK(u[i++] == x0[d]);
        u[0] += 1.0;
        plume_problem_scatter(p, u);
        CHECK(plume_problem_x(p)[dim] == x0[dim] + 1.0); /* first free dof: vertex 1's x */
        u[0] -= 1.0;
        plume_problem_scatter(p, u);

        /* Hessian pattern: upper triangle, sorted, diagonal present */
        plume_sparsity sp = plume_problem_hessian_pattern(p);
        CHECK(sp.n == plume_problem_nfree(p) && sp.colptr[0] == 0 && sp.colptr[sp.n] == sp.nnz);
        int sorted = 1, diag = 1;
        for (plume_index c = 0; c < sp.n; c++) {
            for (plume_index k = sp.colptr[c]; k < sp.colptr[c + 1]; k++)
                sorted &= sp.rowind[k] <= c && (k == sp.colptr[c] || sp.rowind[k - 1] < sp.rowind[k]);
            diag &= sp.colptr[c + 1] > sp.colptr[c] && sp.rowind[sp.colptr[c + 1] - 1] == c;
        }
        CHECK(sorted && diag);

        /* Jacobian triplets: in range, one per (row, free dof), every kept row present */
        plume_index jnnz;
        const plume_index *rows, *cols;
        plume_problem_jacobian_pattern(p, &jnnz, &rows, &cols);
        int inrange = 1, rowseen[NCMAX] = {0};
        for (plume_index k = 0; k < jnnz; k++) {
            inrange &= rows[k] >= 0 && rows[k] < plume_problem_ncons(p) && cols[k] >= 0 && cols[k] < sp.n;
            if (inrange)
                rowseen[rows[k]]++;
            for (plume_index l = 0; l < k && inrange; l++)
                CHECK(rows[l] != rows[k] || cols[l] != cols[k]);
        }
        CHECK(inrange);
        /* 2 dim coordinates per kept edge, minus the prescribed ones: clamped vertex 0 in edges
         * 0-1 and 0-5, clamped vertex 4 in edge 4-5, vertex 3's x in edges 2-3 and 3-7 */
        CHECK(jnnz == (NE - 1) * 2 * dim - 3 * dim - 2);
        for (plume_index c = 0; c < plume_problem_ncons(p); c++)
            CHECK(rowseen[c] > 0);
        plume_problem_destroy(&st.p);
    }
}

/* Gradient of f against central differences of f. */
void test_problem_fd_gradient(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int trial = 0; trial < 3; trial++) {
            strip st;
            if (!strip_build(&st, dim, 1.0, 0x9e3779b97f4a7c15ULL * (uint64_t)(3 * dim + trial + 1), 0))
                continue;
            plume_problem *p = st.p;
            plume_index n = plume_problem_nfree(p);
            double u[NFMAX], grad[NFMAX], fd[NFMAX], f, fp, fm;
            const double h = 1e-6;
            plume_problem_gather(p, u);
            CHECK(plume_problem_objective(p, u, &f, grad) == PLUME_OK);
            for (plume_index i = 0; i < n; i++) {
                double ui = u[i];
                u[i] = ui + h;
                CHECK(plume_problem_objective(p, u, &fp, NULL) == PLUME_OK);
                u[i] = ui - h;
                CHECK(plume_problem_objective(p, u, &fm, NULL) == PLUME_OK);
                u[i] = ui;
                fd[i] = (fp - fm) / (2.0 * h);
            }
            double e = 0.0;
            for (plume_index i = 0; i < n; i++)
                e = fmax(e, fabs(fd[i] - grad[i]));
            CHECK(max_abs(grad, n) > 1e-3); /* a loaded, deformed state: the check has teeth */
            CHECK_ERR(e, 1e-7, max_abs(grad, n), dim == 2 ? "gradient 2d" : "gradient 3d");
            /* with or without the gradient, the same energy; x follows u */
            double f2;
            CHECK(plume_problem_objective(p, u, &f2, NULL) == PLUME_OK && f2 == f);
            plume_problem_destroy(&st.p);
        }
}

/* Hessian of the Lagrangian (obj_factor 1, random lambda) against central differences of
 * grad f + J^T lambda; obj_factor scaling; the projected Hessian is PSD. */
void test_problem_fd_hessian(void)
{
    rng64 r = {0x5151515151515151ULL};
    for (int dim = 2; dim <= 3; dim++)
        for (int trial = 0; trial < 3; trial++) {
            strip st;
            if (!strip_build(&st, dim, 1.0, 0xabcdef0123456789ULL ^ (uint64_t)(10 * dim + trial), 0))
                continue;
            plume_problem *p = st.p;
            plume_sparsity sp = plume_problem_hessian_pattern(p);
            plume_index n = sp.n, m = plume_problem_ncons(p), jnnz;
            const plume_index *rows, *cols;
            plume_problem_jacobian_pattern(p, &jnnz, &rows, &cols);
            double *values = malloc((size_t)sp.nnz * sizeof *values);
            double *v2 = malloc((size_t)sp.nnz * sizeof *v2);
            double *jval = malloc((size_t)(jnnz + 1) * sizeof *jval);
            double H[NFMAX * NFMAX], FD[NFMAX * NFMAX], u[NFMAX], lam[NCMAX], rp[NFMAX], rm[NFMAX];
            if (!values || !v2 || !jval) {
                CHECK(!"out of memory");
                goto next;
            }
            for (plume_index c = 0; c < m; c++)
                lam[c] = urange(&r, -20.0, 20.0);
            plume_problem_gather(p, u);
            CHECK(plume_problem_hessian(p, u, 1.0, lam, 0, values) == PLUME_OK);
            dense_from_csc(sp, values, H);
            const double h = 1e-6;
            for (plume_index j = 0; j < n; j++) {
                double uj = u[j];
                u[j] = uj + h;
                CHECK(lagrangian_gradient(p, u, lam, rp, jval));
                u[j] = uj - h;
                CHECK(lagrangian_gradient(p, u, lam, rm, jval));
                u[j] = uj;
                for (plume_index i = 0; i < n; i++)
                    FD[i * n + j] = (rp[i] - rm[i]) / (2.0 * h);
            }
            /* compares every entry, so one outside the pattern would show as a mismatch */
            double e = 0.0;
            for (plume_index i = 0; i < n * n; i++)
                e = fmax(e, fabs(FD[i] - H[i]));
            CHECK_ERR(e, 1e-6, max_abs(H, n * n), dim == 2 ? "Lagrangian Hessian 2d" : "Lagrangian Hessian 3d");

            /* obj_factor scales the energy part only; lambda = NULL drops the constraint part */
            double Hf[NFMAX * NFMAX], Hs[NFMAX * NFMAX], Hl[NFMAX * NFMAX];
            CHECK(plume_problem_hessian(p, u, 1.0, NULL, 0, v2) == PLUME_OK);
            dense_from_csc(sp, v2, Hf);
            CHECK(plume_problem_hessian(p, u, 2.5, lam, 0, v2) == PLUME_OK);
            dense_from_csc(sp, v2, Hs);
            double es = 0.0;
            for (plume_index i = 0; i < n * n; i++) {
                Hl[i] = H[i] - Hf[i];
                es = fmax(es, fabs(Hs[i] - (2.5 * Hf[i] + Hl[i])));
            }
            CHECK_ERR(es, 1e-13, max_abs(H, n * n), "obj_factor");
            CHECK(max_abs(Hl, n * n) > 1.0); /* the constraint part is there */

            /* projected per block: the sum of PSD blocks is PSD */
            double evals[NFMAX], evecs[NFMAX * NFMAX];
            CHECK(plume_problem_hessian(p, u, 1.0, lam, 1, v2) == PLUME_OK);
            dense_from_csc(sp, v2, Hs);
            double hmax = max_abs(Hs, n * n);
            plume_dense_sym_eig((int)n, Hs, evals, evecs);
            CHECK(evals[0] >= -1e-12 * hmax);
        next:
            free(values);
            free(v2);
            free(jval);
            plume_problem_destroy(&st.p);
        }
}

/* Jacobian triplets against central differences of g. */
void test_problem_fd_jacobian(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        strip st;
        if (!strip_build(&st, dim, 1.0, 0x0f0f0f0f12345678ULL + (uint64_t)dim, 0))
            continue;
        plume_problem *p = st.p;
        plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p), jnnz;
        const plume_index *rows, *cols;
        plume_problem_jacobian_pattern(p, &jnnz, &rows, &cols);
        double jval[2 * 3 * NE], J[NCMAX * NFMAX], FD[NCMAX * NFMAX], u[NFMAX], gp[NCMAX], gm[NCMAX];
        double g[NCMAX], viol;
        plume_problem_gather(p, u);
        CHECK(plume_problem_jacobian(p, u, jval) == PLUME_OK);
        memset(J, 0, sizeof J);
        for (plume_index k = 0; k < jnnz; k++)
            J[rows[k] * n + cols[k]] += jval[k];
        const double h = 1e-6;
        for (plume_index j = 0; j < n; j++) {
            double uj = u[j];
            u[j] = uj + h;
            CHECK(plume_problem_constraints(p, u, gp, NULL) == PLUME_OK);
            u[j] = uj - h;
            CHECK(plume_problem_constraints(p, u, gm, NULL) == PLUME_OK);
            u[j] = uj;
            for (plume_index c = 0; c < m; c++)
                FD[c * n + j] = (gp[c] - gm[c]) / (2.0 * h);
        }
        double e = 0.0;
        for (plume_index i = 0; i < m * n; i++)
            e = fmax(e, fabs(FD[i] - J[i]));
        CHECK_ERR(e, 1e-8, max_abs(J, m * n), dim == 2 ? "Jacobian 2d" : "Jacobian 3d");

        /* g and the relative violation: max |g_c| / L_c^2 over the kept rows */
        CHECK(plume_problem_constraints(p, u, g, &viol) == PLUME_OK);
        double vmax = 0.0;
        plume_index c = 0;
        for (int e2 = 0; e2 < NE; e2++) {
            plume_index a = st.edges[2 * e2], b = st.edges[2 * e2 + 1];
            if (a == 0 && b == NCOL)
                continue; /* the dropped edge */
            const double *x = plume_problem_x(p);
            double l2 = 0.0, L2 = 0.0;
            for (int k = 0; k < dim; k++)
                l2 += (x[dim * a + k] - x[dim * b + k]) * (x[dim * a + k] - x[dim * b + k]);
            for (int k = 0; k < 2; k++)
                L2 += (st.X[2 * a + k] - st.X[2 * b + k]) * (st.X[2 * a + k] - st.X[2 * b + k]);
            CHECK_REL(g[c], l2 - L2, 1e-12, L2);
            vmax = fmax(vmax, fabs(l2 - L2) / L2);
            c++;
        }
        CHECK(c == m);
        CHECK_REL(viol, vmax, 1e-12, 1e-12);
        plume_problem_destroy(&st.p);
    }
}

/* plume_problem_forces = grad f + J^T lambda on every dof, the prescribed ones included, against
 * central differences of f + lambda.g with respect to each coordinate of plume_problem_x. */
void test_problem_fd_forces(void)
{
    rng64 r = {0x7a7a7a7a01010101ULL};
    for (int dim = 2; dim <= 3; dim++) {
        strip st;
        if (!strip_build(&st, dim, 1.0, 0x2468ace013579bdfULL + (uint64_t)dim, 0))
            continue;
        plume_problem *p = st.p;
        plume_index ndof = dim * NV, m = plume_problem_ncons(p), n = plume_problem_nfree(p);
        double lam[NCMAX], force[3 * NV], force0[3 * NV], g[NCMAX], fd[3 * NV];
        for (plume_index c = 0; c < m; c++)
            lam[c] = urange(&r, -20.0, 20.0);
        CHECK(plume_problem_forces(p, lam, force) == PLUME_OK);
        CHECK(plume_problem_forces(p, NULL, force0) == PLUME_OK);
        double *x = plume_problem_x(p);
        const double h = 1e-6;
        for (plume_index d = 0; d < ndof; d++) {
            double xd = x[d];
            x[d] = xd + h;
            double lp = lagrangian_at_x(p, lam, g);
            x[d] = xd - h;
            double lm = lagrangian_at_x(p, lam, g);
            x[d] = xd;
            fd[d] = (lp - lm) / (2.0 * h);
        }
        double e = 0.0, efix = 0.0, fixmax = 0.0;
        for (plume_index d = 0; d < ndof; d++) {
            e = fmax(e, fabs(fd[d] - force[d]));
            if (plume_problem_is_fixed(p, d)) {
                efix = fmax(efix, fabs(fd[d] - force[d]));
                fixmax = fmax(fixmax, fabs(force[d]));
            }
        }
        CHECK(fixmax > 1e-2); /* reactions on the supports are really there */
        CHECK_ERR(e, 1e-7, max_abs(force, ndof), dim == 2 ? "forces 2d" : "forces 3d");
        CHECK_ERR(efix, 1e-7, fixmax, "forces on prescribed dofs");

        /* on the free dofs: the objective's gradient (+ J^T lambda); force scale = max |grad f| */
        double u[NFMAX], grad[NFMAX], f;
        plume_problem_gather(p, u);
        CHECK(plume_problem_objective(p, u, &f, grad) == PLUME_OK);
        plume_index i = 0;
        for (plume_index d = 0; d < ndof; d++)
            if (!plume_problem_is_fixed(p, d)) {
                CHECK(grad[i] == force0[d]);
                i++;
            }
        CHECK(i == n);
        CHECK(plume_problem_force_scale(p) == max_abs(force0, ndof));
        plume_problem_destroy(&st.p);
    }
}

/* ---- KKT residual ----------------------------------------------------------------------- */

/* 0 at rest (nothing loaded, nothing deformed), and unchanged when every stiffness, load and
 * multiplier is multiplied by 1e6 (a change of units must not change convergence). The membrane
 * strip at rest has round-off gradients (F = Ds Dm^-1 is not exactly I); the point potential at
 * its centre has exactly zero ones. */
void test_problem_kkt_residual(void)
{
    rng64 r = {0x0123012301230123ULL};
    {
        plume_problem *p = NULL;
        quartic_ctx *q = calloc(1, sizeof *q);
        const plume_index edge[2] = {0, 1};
        const double X[4] = {0.1, 0.2, 0.7, -0.3};
        plume_constraint ec;
        CHECK(q && plume_problem_create(2, 2, 1.0, &p, NULL) == PLUME_OK);
        if (!q || !p) {
            free(q);
            plume_problem_destroy(&p);
            return;
        }
        q->n = 2, q->verts[0] = 0, q->verts[1] = 1, q->k = 1e6;
        q->a[0] = X[0], q->a[1] = X[1], q->a[3] = X[2], q->a[4] = X[3];
        plume_term qt = {.size = sizeof(plume_term), .name = "quartic points", .arity = 1, .nstencil = q->n, .stencil = q->verts, .eval = quartic_eval,
                     .destroy = quartic_destroy, .ctx = q};
        CHECK(plume_problem_add_term(p, &qt, NULL) == PLUME_OK);
        CHECK(plume_edge_length_create(edge, 1, X, 2, &ec, NULL) == PLUME_OK);
        CHECK(plume_problem_add_constraint(p, &ec, NULL) == PLUME_OK);
        CHECK(plume_problem_fix_dof(p, 0, NULL) == PLUME_OK && plume_problem_fix_dof(p, 1, NULL) == PLUME_OK);
        memcpy(plume_problem_x(p), X, sizeof X);
        CHECK(plume_problem_finalize(p, NULL) == PLUME_OK);
        double u[2] = {X[2], X[3]}, zero = 0.0, rr = -1.0;
        CHECK(plume_problem_kkt_residual(p, u, &zero, &rr) == PLUME_OK && rr == 0.0);
        CHECK(plume_problem_kkt_residual(p, u, NULL, &rr) == PLUME_OK && rr == 0.0);
        plume_problem_destroy(&p);
    }
    for (int dim = 2; dim <= 3; dim++) {
        double res[2], lam[2][NCMAX], u[NFMAX];
        for (int k = 0; k < NCMAX; k++)
            lam[0][k] = urange(&r, -20.0, 20.0), lam[1][k] = 1e6 * lam[0][k];
        for (int scaled = 0; scaled < 2; scaled++) {
            double stiff = scaled ? 1e6 : 1.0, zero[NCMAX] = {0}, rr = -1.0;
            strip st;
            /* at rest, with lambda = 0 and lambda = NULL */
            if (strip_build(&st, dim, stiff, 0x4242424242424242ULL, 1)) {
                plume_problem_gather(st.p, u);
                CHECK(plume_problem_kkt_residual(st.p, u, zero, &rr) == PLUME_OK && rr <= 1e-9);
                if (!(rr <= 1e-9))
                    fprintf(stderr, "    at rest (dim %d, stiffness x%g): residual %.3g, force scale %.3g\n",
                            dim, stiff, rr, plume_problem_force_scale(st.p));
                CHECK(plume_problem_kkt_residual(st.p, u, NULL, &rr) == PLUME_OK && rr <= 1e-9);
                plume_problem_destroy(&st.p);
            }
            /* deformed and loaded, random multipliers */
            res[scaled] = NAN;
            if (strip_build(&st, dim, stiff, 0x4242424242424242ULL, 0)) {
                plume_problem_gather(st.p, u);
                CHECK(plume_problem_kkt_residual(st.p, u, lam[scaled], &res[scaled]) == PLUME_OK);
                plume_problem_destroy(&st.p);
            }
        }
        CHECK(res[0] > 1e-3 && res[0] <= 2.0); /* |g + J^T l| <= 2 max(|g|, |J^T l|) */
        if (!(res[0] > 1e-3 && res[0] <= 2.0))
            fprintf(stderr, "    deformed (dim %d): residual %.3g\n", dim, res[0]);
        CHECK_REL(res[1], res[0], 1e-12, 1e-12);
    }
}

/* ---- error paths ------------------------------------------------------------------------ */

/* A term / constraint set that does nothing, counting how often its ctx is destroyed. */
typedef struct {
    plume_index stencil[2];
    double scale[1];
    int destroyed;
} dummy_ctx;

static plume_status dummy_eval(void *ctx, int dim, const double *x, double *energy, double *grad,
                               double *hblocks, int project)
{
    (void)ctx, (void)dim, (void)x, (void)energy, (void)grad, (void)hblocks, (void)project;
    return PLUME_OK;
}

static plume_status dummy_geval(void *ctx, int dim, const double *x, double *g, double *jac)
{
    (void)ctx, (void)dim, (void)x, (void)g, (void)jac;
    return PLUME_OK;
}

static plume_status dummy_hess(void *ctx, int dim, const double *x, const double *lambda, double *hblocks,
                               int project)
{
    (void)ctx, (void)dim, (void)x, (void)lambda, (void)hblocks, (void)project;
    return PLUME_OK;
}

static void dummy_destroy(void *ctx)
{
    ((dummy_ctx *)ctx)->destroyed++;
}

static plume_term dummy_term(dummy_ctx *c, const char *name)
{
    plume_term t = {.size = sizeof(plume_term), .name = name, .arity = 2, .nstencil = 1, .stencil = c->stencil, .eval = dummy_eval,
                    .destroy = dummy_destroy, .ctx = c};
    return t;
}

static plume_constraint dummy_constraint(dummy_ctx *c, const char *name)
{
    c->scale[0] = 1.0;
    plume_constraint k = {sizeof(plume_constraint), name, 2, 1, c->stencil, c->scale, dummy_geval, dummy_hess,
                          dummy_destroy, c, 0};
    return k;
}

void test_problem_errors(void)
{
    plume_problem *p = (plume_problem *)&p; /* not NULL: create must reset it on failure */
    plume_err err;
    double f, v[4];

    /* create */
    CHECK(plume_problem_create(0, 2, 1.0, &p, &err) == PLUME_EINVAL && p == NULL);
    CHECK(plume_problem_create(3, 1, 1.0, &p, &err) == PLUME_EINVAL && p == NULL);
    CHECK(plume_problem_create(3, 4, 1.0, &p, &err) == PLUME_EINVAL && p == NULL);
    CHECK(plume_problem_create(3, 2, 0.0, &p, &err) == PLUME_EINVAL && p == NULL);
    CHECK(plume_problem_create(3, 2, NAN, &p, &err) == PLUME_EINVAL && p == NULL);
    CHECK(plume_problem_create(3, 2, INFINITY, &p, &err) == PLUME_EINVAL && p == NULL);
    CHECK(strstr(err.msg, "length scale inf") != NULL); /* the message says what was given */
    CHECK(plume_problem_create(3, 2, 1.0, NULL, &err) == PLUME_EINVAL);
    plume_problem_destroy(NULL);
    plume_problem_destroy(&p);

    /* fix_dof range; evaluations before finalize; add after finalize (ctx destroyed once) */
    dummy_ctx a = {{0, 1}, {0}, 0}, b = {{1, 2}, {0}, 0}, c = {{0, 2}, {0}, 0}, d = {{0, 1}, {0}, 0};
    CHECK(plume_problem_create(3, 2, 1.0, &p, &err) == PLUME_OK);
    if (!p)
        return;
    CHECK(plume_problem_fix_dof(p, -1, &err) == PLUME_EINVAL);
    CHECK(plume_problem_fix_dof(p, 6, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "dof 6 out of [0, 6) (vertex 3, component 0)") != NULL);
    CHECK(plume_problem_fix_dof(p, 5, &err) == PLUME_OK && plume_problem_is_fixed(p, 5));
    CHECK(plume_problem_fix_dof(p, 5, &err) == PLUME_OK); /* twice is harmless */
    CHECK(plume_problem_fix_dof(NULL, 0, &err) == PLUME_EINVAL);
    CHECK(plume_problem_add_term(p, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_problem_add_constraint(p, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_problem_objective(p, NULL, &f, NULL) == PLUME_EINVAL);
    CHECK(plume_problem_hessian(p, NULL, 1.0, NULL, 0, v) == PLUME_EINVAL);
    CHECK(plume_problem_constraints(p, NULL, v, NULL) == PLUME_EINVAL);
    CHECK(plume_problem_jacobian(p, NULL, v) == PLUME_EINVAL);
    CHECK(plume_problem_forces(p, NULL, v) == PLUME_EINVAL);
    CHECK(plume_problem_kkt_residual(p, NULL, NULL, &f) == PLUME_EINVAL);
    /* a term without eval is refused, and its ctx freed */
    plume_term bad = dummy_term(&d, "no eval");
    bad.eval = NULL;
    CHECK(plume_problem_add_term(p, &bad, &err) == PLUME_EINVAL && d.destroyed == 1);
    CHECK(strstr(err.msg, "needs eval") != NULL);
    plume_term ta = dummy_term(&a, "a");
    plume_constraint cb = dummy_constraint(&b, "b");
    CHECK(plume_problem_add_term(p, &ta, &err) == PLUME_OK);
    CHECK(plume_problem_add_constraint(p, &cb, &err) == PLUME_OK);
    err.msg[0] = '\0';
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
    CHECK(plume_problem_nfree(p) == 5 && plume_problem_ncons(p) == 1);
    CHECK(plume_problem_finalize(p, &err) == PLUME_EINVAL); /* twice */
    plume_term tc = dummy_term(&c, "late term");
    CHECK(plume_problem_add_term(p, &tc, &err) == PLUME_EINVAL && c.destroyed == 1);
    CHECK(strstr(err.msg, "before plume_problem_finalize") != NULL);
    plume_constraint cc = dummy_constraint(&c, "late constraint");
    CHECK(plume_problem_add_constraint(p, &cc, &err) == PLUME_EINVAL && c.destroyed == 2);
    CHECK(plume_problem_fix_dof(p, 0, &err) == PLUME_EINVAL && !plume_problem_is_fixed(p, 0));
    CHECK(plume_problem_objective(p, NULL, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_problem_hessian(p, NULL, 1.0, NULL, 0, NULL) == PLUME_EINVAL);
    CHECK(plume_problem_jacobian(p, NULL, NULL) == PLUME_EINVAL); /* jnnz > 0 */
    CHECK(plume_problem_forces(p, NULL, NULL) == PLUME_EINVAL);
    CHECK(plume_problem_kkt_residual(p, NULL, NULL, NULL) == PLUME_EINVAL);
    plume_problem_destroy(&p);
    CHECK(p == NULL && a.destroyed == 1 && b.destroyed == 1 && c.destroyed == 2);

    /* a term with a vertex out of range: finalize fails naming the term */
    for (int which = 0; which < 3; which++) {
        dummy_ctx e = {{0, which == 0 ? 3 : which == 1 ? -1 : 1}, {0}, 0};
        CHECK(plume_problem_create(3, 2, 1.0, &p, &err) == PLUME_OK);
        if (!p)
            return;
        plume_status st;
        if (which < 2) {
            plume_term te = dummy_term(&e, "bent spring #7");
            CHECK(plume_problem_add_term(p, &te, &err) == PLUME_OK);
        } else { /* the same for a constraint set (edge_length checks its own input) */
            e.stencil[1] = 5;
            plume_constraint ce = dummy_constraint(&e, "tied pair #3");
            CHECK(plume_problem_add_constraint(p, &ce, &err) == PLUME_OK);
        }
        err.msg[0] = '\0';
        st = plume_problem_finalize(p, &err);
        CHECK(st == PLUME_EINVAL);
        CHECK(strstr(err.msg, which < 2 ? "bent spring #7" : "tied pair #3") != NULL);
        if (st == PLUME_EINVAL && !strstr(err.msg, "#"))
            fprintf(stderr, "    message: '%s'\n", err.msg);
        CHECK(plume_problem_finalize(p, NULL) != PLUME_OK); /* still broken, no crash, no leak */
        plume_problem_destroy(&p);
        CHECK(e.destroyed == 1);
    }

    /* every dof prescribed: nothing to solve for */
    CHECK(plume_problem_create(2, 3, 1.0, &p, &err) == PLUME_OK);
    if (!p)
        return;
    for (plume_index dof = 0; dof < 6; dof++)
        CHECK(plume_problem_fix_dof(p, dof, &err) == PLUME_OK);
    err.msg[0] = '\0';
    CHECK(plume_problem_finalize(p, &err) == PLUME_EINVAL && err.msg[0] != '\0');
    CHECK(plume_problem_finalize(p, NULL) == PLUME_EINVAL);
    plume_problem_destroy(&p);
}
