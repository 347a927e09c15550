/* Tests of midedge bending as a term of a problem (macro/shell/midedge_term.h) and of the problem's
 * extra unknowns it needs (plume_problem_add_unknowns, plume_term.nextra): finite differences of
 * the assembled gradient and Hessian over vertices and edge unknowns with clamped and free edges
 * on a curved state; the re-basing at a step's start (energy and directors unchanged, angles 0);
 * a clamped strip solved by the native Newton and by Ipopt to the same equilibrium, against the
 * linear cantilever (and the shape operator's); the problem's refusals of bad extras. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "test_rng.h"
#include "bend_meshes.h"
#include "plume_tree.h"
#include "../macro/shell/midedge_term.h"

static void mt_dense_from_csc(plume_sparsity sp, const double *values, double *H)
{
    memset(H, 0, (size_t)(sp.n * sp.n) * sizeof *H);
    for (plume_index c = 0; c < sp.n; c++)
        for (plume_index k = sp.colptr[c]; k < sp.colptr[c + 1]; k++)
            H[sp.rowind[k] * sp.n + c] = H[c * sp.n + sp.rowind[k]] = values[k];
}

static double mt_max_abs(const double *a, plume_index n)
{
    double m = 0.0;
    for (plume_index i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* A 1 x 0.5 grid strip at h in shell mode, barbs at 30 degrees, held at x = 0 when `clamp`. */
static plume_mesh *mt_strip(double h, unsigned char **held)
{
    plume_mesh *m = bm_family_mesh(BM_DELAUNAY, h, 1.0, 0.5, 30.0);
    if (!m || !held)
        return m;
    *held = calloc((size_t)m->nv, 1);
    for (plume_index v = 0; *held && v < m->nv; v++)
        (*held)[v] = m->X[2 * v] < 1e-12;
    return m;
}

/* The held vertices as one rigid group (plume_midedge_term_opts.group), malloc'ed; NULL for none. */
static int *held_group(const plume_mesh *m, const unsigned char *held)
{
    int *g = held ? calloc((size_t)m->nv + 1, sizeof *g) : NULL;
    for (plume_index v = 0; g && v < m->nv; v++)
        g[v] = held[v] != 0;
    return g;
}

/* Membrane + midedge bending over m, vertices at x, held vertices fixed; finalised. */
static plume_problem *mt_problem(const plume_mesh *m, const double *x, const unsigned char *held,
                                 const plume_bending_material *bm, plume_midedge_term **term, plume_index *first)
{
    plume_problem *p = NULL;
    plume_err err = {0};
    if (plume_problem_create(m->nv, 3, 1.0, &p, &err) != PLUME_OK)
        return NULL;
    const plume_membrane_material mm = {{1e5, 1e4, 0.3, 2e4}, 1e-2, 0.0, 0};
    plume_term t;
    memcpy(plume_problem_x(p), x, (size_t)(3 * m->nv) * sizeof *x);
    int *group = held_group(m, held);
    const plume_midedge_term_opts o = {NULL, group, NULL};
    if (plume_membrane_term_create(m, 3, &mm, 1, &t, &err) != PLUME_OK || plume_problem_add_term(p, &t, &err) != PLUME_OK ||
        plume_midedge_term_add(p, m, bm, 1, NULL, &o, first, term, &err) != PLUME_OK) {
        fprintf(stderr, "    %s\n", err.msg);
        plume_problem_destroy(&p);
        free(group);
        return NULL;
    }
    free(group);
    for (plume_index v = 0; held && v < m->nv; v++)
        for (int a = 0; held[v] && a < 3; a++)
            plume_problem_fix_dof(p, 3 * v + a, &err);
    if (plume_problem_finalize(p, &err) != PLUME_OK) {
        fprintf(stderr, "    finalize: %s\n", err.msg);
        plume_problem_destroy(&p);
    }
    return p;
}

/* Central differences (step 1e-6) of a finalised problem's objective and exact Hessian over its
 * free unknowns at u (n of them, the last nangle the edge angles); g [n], H [n n] and vals [nnz]
 * are workspaces (g and H keep the analytic gradient and Hessian at u). */
typedef struct {
    double gerr, gs, gerr_angle, gs_angle, herr, hs;
} mt_fd;

static mt_fd mt_fd_errors(plume_problem *p, double *u, plume_index nangle, double *g, double *H, double *vals)
{
    mt_fd r = {0};
    const plume_index n = plume_problem_nfree(p);
    plume_sparsity sp = plume_problem_hessian_pattern(p);
    double *gp = malloc((size_t)n * sizeof *gp), *gm = malloc((size_t)n * sizeof *gm), f = 0.0;
    CHECK(gp && gm && plume_problem_objective(p, u, &f, g) == PLUME_OK);
    CHECK(plume_problem_hessian(p, u, 1.0, NULL, PLUME_HESSIAN_EXACT, vals) == PLUME_OK);
    mt_dense_from_csc(sp, vals, H);
    const double step = 1e-6;
    for (plume_index i = 0; gp && gm && i < n; i++) {
        const double ui = u[i];
        double fp = 0.0, fm = 0.0;
        u[i] = ui + step;
        CHECK(plume_problem_objective(p, u, &fp, gp) == PLUME_OK);
        u[i] = ui - step;
        CHECK(plume_problem_objective(p, u, &fm, gm) == PLUME_OK);
        u[i] = ui;
        const double ge = fabs((fp - fm) / (2.0 * step) - g[i]);
        r.gerr = fmax(r.gerr, ge);
        if (i >= n - nangle) { /* the edge unknowns come last */
            r.gerr_angle = fmax(r.gerr_angle, ge);
            r.gs_angle = fmax(r.gs_angle, fabs(g[i]));
        }
        for (plume_index j = 0; j < n; j++)
            r.herr = fmax(r.herr, fabs((gp[j] - gm[j]) / (2.0 * step) - H[j * n + i]));
    }
    r.gs = mt_max_abs(g, n), r.hs = mt_max_abs(H, n * n);
    free(gp);
    free(gm);
    return r;
}

void test_midedge_term_problem_fd(void)
{
    unsigned char *held = NULL;
    plume_mesh *m = mt_strip(0.25, &held);
    CHECK(m && held);
    if (!m || !held)
        return;
    double *x = malloc((size_t)(3 * m->nv) * sizeof *x);
    bm_map_cylinder(m, 20.0, 1.5, x);
    rng64 s = {17};
    for (plume_index v = 0; v < m->nv; v++)
        for (int a = 0; a < 3 && !held[v]; a++)
            x[3 * v + a] += 0.01 * (2.0 * urand(&s) - 1.0);
    const plume_bending_material bm = {1e-3, 2e-4, 0.0, 5e-5};
    plume_midedge_term *mt = NULL;
    plume_index first = -1;
    plume_problem *p = mt_problem(m, x, held, &bm, &mt, &first);
    CHECK(p && mt && first == 3 * m->nv);
    if (!p) {
        free(x);
        free(held);
        plume_mesh_destroy(&m);
        return;
    }
    CHECK(plume_problem_ndof(p) == 3 * m->nv + m->ne);
    /* the held edges' unknowns are prescribed: nfree counts the others */
    plume_index nheld_v = 0, nheld_e = 0;
    for (plume_index v = 0; v < m->nv; v++)
        nheld_v += held[v];
    for (plume_index e = 0; e < m->ne; e++)
        nheld_e += held[m->edges[2 * e]] && held[m->edges[2 * e + 1]];
    CHECK(nheld_e > 0);
    const plume_index n = plume_problem_nfree(p);
    CHECK(n == 3 * (m->nv - nheld_v) + m->ne - nheld_e);
    /* the start angles are the mean normals', the held ones too (the clamp is on one line: no
     * frame), and those are fixed */
    const double *xp = plume_problem_x(p);
    for (plume_index e = 0; e < m->ne; e++)
        if (held[m->edges[2 * e]] && held[m->edges[2 * e + 1]])
            CHECK(isfinite(xp[first + e]) && plume_problem_is_fixed(p, first + e));
    /* perturb the angles too, then finite differences on the free unknowns */
    double *u = malloc((size_t)n * sizeof *u), *g = malloc((size_t)n * sizeof *g);
    double *H = malloc((size_t)(n * n) * sizeof *H);
    plume_sparsity sp = plume_problem_hessian_pattern(p);
    double *vals = malloc((size_t)sp.nnz * sizeof *vals);
    plume_problem_gather(p, u);
    for (plume_index i = 0; i < n; i++)
        u[i] += 1e-3 * (2.0 * urand(&s) - 1.0);
    mt_fd fd = mt_fd_errors(p, u, n - (m->ne - nheld_e), g, H, vals);
    fprintf(stderr, "    %ld free unknowns (%ld edges): gradient error %.2e of %.2e (angles %.2e of %.2e), Hessian %.2e of %.2e\n",
            (long)n, (long)(m->ne - nheld_e), fd.gerr, fd.gs, fd.gerr_angle, fd.gs_angle, fd.herr, fd.hs);
    CHECK(fd.gerr <= 1e-7 * fd.gs && fd.gerr_angle <= 1e-6 * fd.gs_angle && fd.gs_angle > 1e-6 * fd.gs);
    CHECK(fd.herr <= 1e-6 * fd.hs);
    const double hs = fd.hs;
    /* the projected Hessian of the bending blocks is PSD: the whole projected matrix has no
     * negative pivot (a dense Cholesky of it plus a tiny shift) */
    CHECK(plume_problem_hessian(p, u, 1.0, NULL, PLUME_HESSIAN_PROJECTED, vals) == PLUME_OK);
    mt_dense_from_csc(sp, vals, H);
    int pd = 1;
    for (plume_index k = 0; k < n && pd; k++) {
        H[k * n + k] += 1e-12 * hs;
        double d = H[k * n + k];
        for (plume_index j = 0; j < k; j++)
            d -= H[k * n + j] * H[k * n + j];
        if (!(d > 0.0)) {
            pd = 0;
            break;
        }
        H[k * n + k] = sqrt(d);
        for (plume_index i = k + 1; i < n; i++) {
            double q = H[i * n + k];
            for (plume_index j = 0; j < k; j++)
                q -= H[i * n + j] * H[k * n + j];
            H[i * n + k] = q / H[k * n + k];
        }
    }
    CHECK(pd);
    free(u);
    free(g);
    free(H);
    free(vals);
    plume_problem_destroy(&p);
    free(x);
    free(held);
    plume_mesh_destroy(&m);
}

/* Held edges anchored to their group: the strip turned rigidly (50 degrees about (1, 1, 0) / sqrt 2)
 * stores no energy, as the rest does, whether held on a patch (x <= 0.25, two columns, off one
 * line: the held edges' rest directors carried by the group's frame) or on one line (no frame: the
 * held edges keep the directors they start with); finite differences on the free unknowns of the
 * turned, perturbed strip; bad anchors are refused, naming the edge. */
void test_midedge_term_anchored(void)
{
    const double ang = 50.0 * BM_PI / 180.0, c = cos(ang), sn = sin(ang), a = sqrt(0.5);
    /* Rodrigues: R = c I + sn [k]x + (1 - c) k k^T, k = (a, a, 0) */
    const double R[3][3] = {{c + (1 - c) * a * a, (1 - c) * a * a, sn * a},
                            {(1 - c) * a * a, c + (1 - c) * a * a, -sn * a},
                            {-sn * a, sn * a, c}};
    const plume_bending_material bm = {1e-3, 2e-4, 0.0, 5e-5};
    double energy[2] = {0.0, 0.0};
    for (int patch = 0; patch < 2; patch++) {
        unsigned char *held = NULL;
        plume_mesh *m = mt_strip(0.25, &held);
        CHECK(m && held);
        if (!m || !held)
            return;
        for (plume_index v = 0; v < m->nv; v++)
            held[v] = m->X[2 * v] < (patch ? 0.3 : 1e-12);
        double *x = malloc((size_t)(3 * m->nv) * sizeof *x);
        for (plume_index v = 0; v < m->nv; v++)
            for (int i = 0; i < 3; i++)
                x[3 * v + i] = R[i][0] * m->X[2 * v] + R[i][1] * m->X[2 * v + 1] + 0.1 * i;
        plume_midedge_term *mt = NULL;
        plume_index first = -1;
        plume_problem *p = mt_problem(m, x, held, &bm, &mt, &first);
        CHECK(p && mt);
        if (p && mt) {
            CHECK(plume_midedge_term_group_anchored(mt, 1) == patch && !plume_midedge_term_group_anchored(mt, 2));
            const plume_index n = plume_problem_nfree(p);
            double *u = malloc((size_t)n * sizeof *u), *g = malloc((size_t)n * sizeof *g);
            double *H = malloc((size_t)(n * n) * sizeof *H);
            double *vals = malloc((size_t)plume_problem_hessian_pattern(p).nnz * sizeof *vals);
            plume_problem_gather(p, u);
            CHECK(plume_problem_objective(p, u, &energy[patch], g) == PLUME_OK);
            if (patch) {
                plume_index nheld_e = 0;
                for (plume_index e = 0; e < m->ne; e++)
                    nheld_e += held[m->edges[2 * e]] && held[m->edges[2 * e + 1]];
                rng64 r = {5};
                for (plume_index i = 0; i < n; i++)
                    u[i] += 2e-2 * (2.0 * urand(&r) - 1.0);
                mt_fd fd = mt_fd_errors(p, u, m->ne - nheld_e, g, H, vals);
                fprintf(stderr, "    turned, anchored: %ld free unknowns, gradient error %.2e of %.2e (angles %.2e of %.2e), "
                        "Hessian %.2e of %.2e\n", (long)n, fd.gerr, fd.gs, fd.gerr_angle, fd.gs_angle, fd.herr, fd.hs);
                CHECK(fd.gerr <= 1e-7 * fd.gs && fd.gerr_angle <= 1e-6 * fd.gs_angle && fd.herr <= 1e-6 * fd.hs);
            }
            free(u);
            free(g);
            free(H);
            free(vals);
        }
        plume_problem_destroy(&p);
        free(x);
        free(held);
        plume_mesh_destroy(&m);
    }
    /* membrane and bending at a rigid turn: the scale is a unit curvature over the strip, D A */
    fprintf(stderr, "    the strip turned 50 degrees: energy %.2e (held patch, anchored), %.2e (held on one line)\n",
            energy[1], energy[0]);
    CHECK(fabs(energy[1]) < 1e-12 * bm.D_long * 0.5 && fabs(energy[0]) < 1e-12 * bm.D_long * 0.5);
    /* bad anchors: out of range, and three on one line */
    plume_mesh *m = mt_strip(0.25, NULL);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_index *anchor = malloc((size_t)(3 * m->ne) * sizeof *anchor);
    for (plume_index i = 0; i < 3 * m->ne; i++)
        anchor[i] = -1;
    plume_midedge_bending *b = NULL;
    plume_err err = {{0}};
    anchor[0] = 0, anchor[1] = 1, anchor[2] = m->nv;
    plume_midedge_bending_opts o = {NULL, anchor};
    CHECK(plume_midedge_bending_create_opts(m, &bm, 1, NULL, &o, &b, &err) == PLUME_EINVAL && !b &&
          strstr(err.msg, "edge 0") && strstr(err.msg, "out of range"));
    fprintf(stderr, "    %s\n", err.msg);
    plume_index col[3] = {-1, -1, -1}, k = 0; /* three vertices at x = 0 */
    for (plume_index v = 0; v < m->nv && k < 3; v++)
        if (m->X[2 * v] < 1e-12)
            col[k++] = v;
    anchor[0] = col[0], anchor[1] = col[1], anchor[2] = col[2];
    CHECK(plume_midedge_bending_create_opts(m, &bm, 1, NULL, &o, &b, &err) == PLUME_EINVAL && !b &&
          strstr(err.msg, "one line"));
    fprintf(stderr, "    %s\n", err.msg);
    free(anchor);
    plume_mesh_destroy(&m);
}

/* The linear deflection at x = 0.5 of the half [0, 0.5] x [0, 0.25] of a plate strip clamped at
 * both ends x = 0 and 1 under pressure q (nu = 0): held at x = 0, its x = 0.5 vertices holding x,
 * their edges on the symmetry plane (sym) or not (NULL: a free end that only keeps x). */
static double half_strip_deflection(const plume_mesh *m, const unsigned char *sym, double D, double q, int *iterations)
{
    plume_problem *p = NULL;
    plume_err err = {0};
    const plume_bending_material bm = {D, D, 0.5 * D, 0.0};
    const plume_membrane_material mm = {{1e6, 1e6, 0.0, 5e5}, 1e-2, 0.0, 0};
    unsigned char *held = calloc((size_t)m->nv + 1, 1);
    double *f = calloc(3 * (size_t)m->nv + 1, sizeof *f);
    plume_index *ids = malloc(((size_t)m->nv + 1) * sizeof *ids);
    double w = NAN;
    if (!held || !f || !ids || plume_problem_create(m->nv, 3, 1.0, &p, &err) != PLUME_OK)
        goto done;
    for (plume_index v = 0; v < m->nv; v++) {
        held[v] = m->X[2 * v] < 1e-12;
        ids[v] = v;
        double *x = plume_problem_x(p) + 3 * v;
        x[0] = m->X[2 * v], x[1] = m->X[2 * v + 1], x[2] = 0.0;
    }
    for (plume_index t = 0; t < m->nt; t++) { /* q times a third of each triangle's area to its vertices */
        const plume_index *v = m->tri + 3 * t;
        const double *a = m->X + 2 * v[0], *b = m->X + 2 * v[1], *c = m->X + 2 * v[2];
        const double area = 0.5 * fabs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
        for (int k = 0; k < 3; k++)
            f[3 * v[k] + 2] += q * area / 3.0;
    }
    int *group = held_group(m, held);
    const plume_midedge_term_opts o = {NULL, group, sym};
    plume_term t;
    plume_index first;
    int ok = plume_membrane_term_create(m, 3, &mm, 1, &t, &err) == PLUME_OK && plume_problem_add_term(p, &t, &err) == PLUME_OK &&
             plume_midedge_term_add(p, m, &bm, 1, NULL, &o, &first, NULL, &err) == PLUME_OK &&
             plume_load_term_create(ids, m->nv, 3, f, &t, &err) == PLUME_OK && plume_problem_add_term(p, &t, &err) == PLUME_OK;
    free(group);
    for (plume_index v = 0; ok && v < m->nv; v++) {
        for (int a = 0; held[v] && a < 3; a++)
            plume_problem_fix_dof(p, 3 * v + a, &err);
        if (m->X[2 * v] > 0.5 - 1e-12)
            plume_problem_fix_dof(p, 3 * v, &err);
    }
    plume_solver *sv = NULL;
    if (!ok || plume_problem_finalize(p, &err) != PLUME_OK ||
        plume_solver_create(PLUME_SOLVER_NEWTON, p, NULL, &sv, &err) != PLUME_OK) {
        fprintf(stderr, "    %s\n", err.msg);
        goto done;
    }
    const plume_index n = plume_problem_nfree(p);
    double *u = malloc(((size_t)n + 1) * sizeof *u);
    plume_solve_report rep;
    memset(&rep, 0, sizeof rep);
    plume_problem_gather(p, u);
    if (u && plume_solver_solve(sv, u, NULL, &rep) == PLUME_OK && rep.converged) {
        double sum = 0.0;
        int count = 0;
        for (plume_index v = 0; v < m->nv; v++)
            if (m->X[2 * v] > 0.5 - 1e-12)
                sum += plume_problem_x(p)[3 * v + 2], count++;
        w = sum / count;
        *iterations = rep.iterations;
    }
    free(u);
    plume_solver_destroy(&sv);
done:
    plume_problem_destroy(&p);
    free(held), free(f), free(ids);
    return w;
}

/* Symmetry: half a clamped-clamped strip under pressure, its cut x = 0.5 a symmetry plane, deflects
 * there as the whole strip does at its middle (q L^4 / (384 D)), converging as h falls; with the
 * cut's angles free (the plane only holding x) it is a cantilever of half the length (q (L/2)^4 /
 * (8 D), three times more); a rest that is not symmetric at the plane is refused, naming it. */
void test_midedge_term_symmetry(void)
{
    const double D = 1e-3, q = 1e-5, w_ref = q / (384.0 * D);
    double err_prev = INFINITY;
    for (int hi = 0; hi < 2; hi++) {
        plume_mesh *m = bm_family_mesh(BM_DELAUNAY, hi ? 1.0 / 32.0 : 1.0 / 16.0, 0.5, 0.25, 0.0);
        CHECK(m != NULL);
        if (!m)
            return;
        unsigned char *sym = calloc((size_t)m->nv + 1, 1);
        for (plume_index v = 0; sym && v < m->nv; v++)
            sym[v] = m->X[2 * v] > 0.5 - 1e-12 ? 1 : 0;
        int it_sym = 0, it_free = 0;
        const double w_sym = half_strip_deflection(m, sym, D, q, &it_sym);
        const double w_free = hi ? NAN : half_strip_deflection(m, NULL, D, q, &it_free);
        const double e = fabs(w_sym / w_ref - 1.0);
        fprintf(stderr, "    h = 1/%d: deflection at the plane %.6e, %.4f of q L^4 / (384 D) (%d iterations)%s", hi ? 32 : 16,
                w_sym, w_sym / w_ref, it_sym, hi ? "\n" : "");
        if (!hi)
            fprintf(stderr, "; the plane's angles free: %.4f of it (half-length cantilever: 3)\n", w_free / w_ref);
        CHECK(e < 6e-2 && e < 0.5 * err_prev); /* second order: 4.4e-2, 1.1e-2 */
        if (!hi)
            CHECK(w_free > 2.5 * w_ref);
        err_prev = e;
        if (hi) { /* a curved rest meets the plane x = 0.5 at a slope: refused */
            double *rest = malloc(3 * (size_t)m->nv * sizeof *rest);
            bm_map_cylinder(m, 0.0, 1.0, rest);
            plume_problem *p = NULL;
            plume_err err = {0};
            const plume_bending_material bm = {D, D, 0.5 * D, 0.0};
            const plume_midedge_term_opts o = {NULL, NULL, sym};
            plume_index first;
            CHECK(rest && plume_problem_create(m->nv, 3, 1.0, &p, &err) == PLUME_OK);
            if (rest && p) {
                memcpy(plume_problem_x(p), rest, 3 * (size_t)m->nv * sizeof *rest);
                CHECK(plume_midedge_term_add(p, m, &bm, 1, rest, &o, &first, NULL, &err) == PLUME_EINVAL &&
                      strstr(err.msg, "symmetry plane normal to x"));
                fprintf(stderr, "    %s\n", err.msg);
            }
            plume_problem_destroy(&p);
            free(rest);
        }
        free(sym);
        plume_mesh_destroy(&m);
    }
}

void test_midedge_term_rebase(void)
{
    plume_mesh *m = mt_strip(0.2, NULL);
    CHECK(m != NULL);
    if (!m)
        return;
    double *x = malloc((size_t)(3 * m->nv) * sizeof *x);
    bm_map_cylinder(m, 60.0, 2.0, x);
    const plume_bending_material bm = {1e-3, 1e-3, 0.0, 0.0};
    plume_midedge_term *mt = NULL;
    plume_index first = -1;
    plume_problem *p = mt_problem(m, x, NULL, &bm, &mt, &first);
    CHECK(p != NULL);
    if (!p) {
        free(x);
        plume_mesh_destroy(&m);
        return;
    }
    double *xp = plume_problem_x(p);
    rng64 s = {5};
    for (plume_index e = 0; e < m->ne; e++)
        xp[first + e] += 0.05 * (2.0 * urand(&s) - 1.0);
    double *d0 = malloc((size_t)(3 * m->ne) * sizeof *d0), *d1 = malloc((size_t)(3 * m->ne) * sizeof *d1);
    double f0 = 0.0, f1 = 0.0;
    plume_midedge_term_directors(mt, xp, d0);
    CHECK(plume_problem_objective(p, NULL, &f0, NULL) == PLUME_OK);
    CHECK(plume_problem_rebases(p) == 1);
    CHECK(plume_problem_rebase_terms(p) == PLUME_OK);
    CHECK(plume_problem_objective(p, NULL, &f1, NULL) == PLUME_OK);
    plume_midedge_term_directors(mt, xp, d1);
    double dd = 0.0;
    for (plume_index i = 0; i < 3 * m->ne; i++)
        dd = fmax(dd, fabs(d1[i] - d0[i]));
    CHECK(mt_max_abs(xp + first, m->ne) == 0.0);
    fprintf(stderr, "    re-basing: energy %.15g -> %.15g, directors moved %.1e\n", f0, f1, dd);
    CHECK_REL(f1, f0, 1e-12, 0.0);
    CHECK(dd < 1e-14);
    free(d0);
    free(d1);
    free(x);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&m);
}

/* A cantilever strip (length 1, width 0.5) clamped at x = 0 under a small tip force solved by
 * Newton and by Ipopt: the same equilibrium, and the linear beam's tip deflection F L^3 / (3 D b)
 * (isotropic plate, nu = 0, barbs along the strip; a plate strip under plane strain deflects
 * 1/(1-nu^2) more, 1 here). */
void test_midedge_term_cantilever_solvers(void)
{
    unsigned char *held = NULL;
    plume_mesh *m = mt_strip(1.0 / 16.0, &held);
    CHECK(m && held);
    if (!m || !held)
        return;
    for (plume_index t = 0; t < m->nt; t++)
        m->barb_dir[2 * t] = 1.0, m->barb_dir[2 * t + 1] = 0.0;
    const double D = 1e-3, F = 1e-6, b = 0.5;
    const plume_bending_material bm = {D, D, 0.5 * D, 0.0}; /* D_long, D_trans, D_twist, D_coupling: nu = 0 */
    double tip[3] = {0.0, 0.0, 0.0};
    for (int solver = 0; solver < 3; solver++) { /* newton, ipopt, newton with the shape operator */
        plume_midedge_term *mt = NULL;
        plume_index first = -1;
        plume_problem *p = NULL;
        plume_err err = {0};
        double *x = malloc((size_t)(3 * m->nv) * sizeof *x);
        for (plume_index v = 0; v < m->nv; v++)
            x[3 * v] = m->X[2 * v], x[3 * v + 1] = m->X[2 * v + 1], x[3 * v + 2] = 0.0;
        /* the membrane, stiff, keeps the strip inextensible; the tip force spread over the tip edge */
        CHECK(plume_problem_create(m->nv, 3, 1.0, &p, &err) == PLUME_OK);
        memcpy(plume_problem_x(p), x, (size_t)(3 * m->nv) * sizeof *x);
        const plume_membrane_material mm = {{1e6, 1e6, 0.0, 5e5}, 1e-2, 0.0, 0};
        plume_term t;
        CHECK(plume_membrane_term_create(m, 3, &mm, 1, &t, &err) == PLUME_OK && plume_problem_add_term(p, &t, &err) == PLUME_OK);
        int *group = held_group(m, held);
        const plume_midedge_term_opts o = {NULL, group, NULL};
        const plume_shape_bending_opts so = {held, 0, 0};
        if (solver < 2)
            CHECK(plume_midedge_term_add(p, m, &bm, 1, NULL, &o, &first, &mt, &err) == PLUME_OK);
        else
            CHECK(plume_shape_bending_term_create_opts(m, &bm, 1, NULL, &so, &t, &err) == PLUME_OK &&
                  plume_problem_add_term(p, &t, &err) == PLUME_OK);
        free(group);
        plume_index ntip = 0;
        for (plume_index v = 0; v < m->nv; v++)
            ntip += m->X[2 * v] > 1.0 - 1e-12;
        plume_index *ids = malloc((size_t)ntip * sizeof *ids);
        double *f = malloc((size_t)(3 * ntip) * sizeof *f);
        ntip = 0;
        for (plume_index v = 0; v < m->nv; v++)
            if (m->X[2 * v] > 1.0 - 1e-12)
                ids[ntip++] = v;
        /* trapezoid weights along the tip edge */
        for (plume_index i = 0; i < ntip; i++)
            f[3 * i] = f[3 * i + 1] = 0.0, f[3 * i + 2] = F / (double)(ntip - 1) * ((m->X[2 * ids[i] + 1] < 1e-12 || m->X[2 * ids[i] + 1] > b - 1e-12) ? 0.5 : 1.0);
        CHECK(plume_load_term_create(ids, ntip, 3, f, &t, &err) == PLUME_OK && plume_problem_add_term(p, &t, &err) == PLUME_OK);
        for (plume_index v = 0; v < m->nv; v++)
            for (int a = 0; held[v] && a < 3; a++)
                plume_problem_fix_dof(p, 3 * v + a, &err);
        CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
        plume_solver *sv = NULL;
        CHECK(plume_solver_create(solver == 1 ? PLUME_SOLVER_IPOPT : PLUME_SOLVER_NEWTON, p, NULL, &sv, &err) == PLUME_OK);
        const plume_index n = plume_problem_nfree(p);
        double *u = malloc((size_t)n * sizeof *u);
        plume_problem_gather(p, u);
        plume_solve_report rep;
        memset(&rep, 0, sizeof rep);
        CHECK(sv && plume_solver_solve(sv, u, NULL, &rep) == PLUME_OK);
        CHECK(rep.converged);
        double w = 0.0;
        for (plume_index i = 0; i < ntip; i++)
            w += plume_problem_x(p)[3 * ids[i] + 2] / (double)ntip;
        tip[solver] = w;
        fprintf(stderr, "    %s: %s in %d iterations, tip deflection %.6e\n", solver == 1 ? "ipopt" : solver ? "shape operator" : "newton",
                plume_reason_name(rep.reason), rep.iterations, w);
        plume_solver_destroy(&sv);
        plume_problem_destroy(&p);
        free(u);
        free(ids);
        free(f);
        free(x);
    }
    const double w_beam = F * 1.0 / (3.0 * D * b);
    fprintf(stderr, "    linear beam: %.6e (newton %.4f of it)\n", w_beam, tip[0] / w_beam);
    CHECK_REL(tip[1], tip[0], 1e-6, 0.0);
    CHECK_REL(tip[0], w_beam, 5e-3, 0.0);
    CHECK_REL(tip[2], w_beam, 1e-2, 0.0);
    free(held);
    plume_mesh_destroy(&m);
}

static plume_status mt_noop_eval(void *ctx, int dim, const double *x, double *energy, double *grad, double *hblocks,
                                 int project)
{
    (void)ctx, (void)dim, (void)x, (void)energy, (void)grad, (void)hblocks, (void)project;
    return PLUME_OK;
}

void test_midedge_term_bad_extras(void)
{
    plume_problem *p = NULL;
    plume_err err = {0};
    CHECK(plume_problem_create(3, 3, 1.0, &p, &err) == PLUME_OK);
    plume_index first = -1;
    CHECK(plume_problem_add_unknowns(p, 0, &first, &err) == PLUME_EINVAL && strstr(err.msg, "at least 1"));
    CHECK(plume_problem_add_unknowns(p, 2, &first, &err) == PLUME_OK && first == 9 && plume_problem_ndof(p) == 11);
    static const plume_index st[3] = {0, 1, 2}, ex_bad[1] = {3}, ex_ok[1] = {10};
    plume_term t = {.size = sizeof(plume_term), .name = "x", .arity = 3, .nstencil = 1, .stencil = st, .eval = mt_noop_eval,
                    .nextra = 1};
    CHECK(plume_problem_add_term(p, &t, &err) == PLUME_EINVAL && strstr(err.msg, "extra array"));
    t.extra = ex_bad;
    CHECK(plume_problem_add_term(p, &t, &err) == PLUME_OK);
    CHECK(plume_problem_finalize(p, &err) == PLUME_EINVAL && strstr(err.msg, "extra unknown out of [9, 11)"));
    plume_problem_destroy(&p);
    CHECK(plume_problem_create(3, 3, 1.0, &p, &err) == PLUME_OK);
    CHECK(plume_problem_add_unknowns(p, 2, &first, &err) == PLUME_OK);
    t.extra = ex_ok;
    CHECK(plume_problem_add_term(p, &t, &err) == PLUME_OK);
    CHECK(plume_problem_fix_dof(p, 9, &err) == PLUME_OK);
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK && plume_problem_nfree(p) == 10);
    CHECK(plume_problem_add_unknowns(p, 1, &first, &err) == PLUME_EINVAL && strstr(err.msg, "before plume_problem_finalize"));
    plume_problem_destroy(&p);
}

/* The strip of data/shell/strip_scene.json (clamped by a handle, inextensible barbs, sagging under
 * gravity) run for 10 steps with each bending model: midedge converges every step and ends within
 * 2 % of the shape operator's tip. A midedge run of 3 frames restarted for 2 more ends on the
 * straight run's last frame bit for bit, its edge unknowns and frames too (the frames file stores
 * them). */
static int mt_run_strip(const char *model, const char *dir, long frames, const char *restart, double tip[3],
                        plume_err *err)
{
    plume_scene *s = NULL;
    char set[128];
    snprintf(set, sizeof set, "{\"bending_model\": \"%s\"}", model);
    if (plume_scene_load("../data/shell/strip_scene.json", &s, err) != PLUME_OK ||
        plume_scene_set(s, set, err) != PLUME_OK) {
        plume_scene_destroy(&s);
        return -1;
    }
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.output_dir = dir;
    o.frames = frames; /* output_every 2: two steps a frame */
    o.restart = restart;
    plume_run *r = NULL;
    plume_status st = plume_run_create(s, &o, &r, err);
    if (st == PLUME_OK)
        st = plume_run_to_end(r, err);
    plume_run_report rep;
    if (st == PLUME_OK) {
        plume_run_get_report(r, &rep);
        const double *x = plume_run_positions(r);
        const plume_mesh *m = plume_scene_mesh(s);
        plume_index far = 0; /* the free end's corner */
        for (plume_index v = 0; v < m->nv; v++)
            if (m->X[2 * v] + m->X[2 * v + 1] > m->X[2 * far] + m->X[2 * far + 1])
                far = v;
        memcpy(tip, x + 3 * far, 3 * sizeof *tip);
        fprintf(stderr, "    %s: %ld steps, %ld iterations, converged %d, tip (%.6f, %.6f, %.6f)\n", model,
                (long)rep.steps, (long)rep.iterations, rep.converged, tip[0], tip[1], tip[2]);
        st = rep.converged ? PLUME_OK : PLUME_EINVAL;
    }
    plume_run_destroy(&r);
    plume_scene_destroy(&s);
    return st == PLUME_OK ? 0 : -1;
}

/* 1 when array `name` of frame k is the same, bit for bit, in files a and b (n values) */
static int mt_same_array(const char *a, const char *b, long k, const char *name, plume_index n)
{
    double *va = malloc((size_t)n * sizeof *va), *vb = malloc((size_t)n * sizeof *vb);
    int same = va && vb && plume_frames_read_array(a, k, name, va, n, NULL) == PLUME_OK &&
               plume_frames_read_array(b, k, name, vb, n, NULL) == PLUME_OK && memcmp(va, vb, (size_t)n * sizeof *va) == 0;
    free(va);
    free(vb);
    return same;
}

void test_midedge_term_dynamic_scene(void)
{
    char dir[64] = "/tmp/plume-midedge-XXXXXX", out[128], a[160], b[160];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_err err = {{0}};
    double ts[3], tm[3], th[3];
    snprintf(out, sizeof out, "%s/shape", dir);
    CHECK(mt_run_strip("shape_operator", out, 5, NULL, ts, &err) == 0);
    snprintf(out, sizeof out, "%s/midedge", dir);
    CHECK(mt_run_strip("midedge", out, 5, NULL, tm, &err) == 0);
    const double sag_s = -ts[2], sag_m = -tm[2];
    fprintf(stderr, "    sag: shape operator %.6f, midedge %.6f (%.2f %%)\n", sag_s, sag_m, 100.0 * (sag_m - sag_s) / sag_s);
    CHECK(sag_s > 1e-3);
    CHECK_REL(sag_m, sag_s, 2e-2, 0.0);
    snprintf(out, sizeof out, "%s/midedge/frame_00005.vtu", dir);
    CHECK(access(out, R_OK) == 0);
    /* 3 frames, then 2 more from the frames file: the straight run's last frame */
    snprintf(out, sizeof out, "%s/half", dir);
    CHECK(mt_run_strip("midedge", out, 3, NULL, th, &err) == 0);
    snprintf(a, sizeof a, "%s/half/frames.h5", dir);
    CHECK(mt_run_strip("midedge", out, 2, a, th, &err) == 0);
    snprintf(b, sizeof b, "%s/midedge/frames.h5", dir);
    plume_frame fa = {0}, fb = {0};
    CHECK(plume_frames_read(a, 5, &fa, &err) == PLUME_OK && plume_frames_read(b, 5, &fb, &err) == PLUME_OK);
    const int same_x = fa.x && fb.x && fa.nv == fb.nv && memcmp(fa.x, fb.x, 3 * (size_t)fa.nv * sizeof *fa.x) == 0 &&
                       memcmp(fa.v, fb.v, 3 * (size_t)fa.nv * sizeof *fa.v) == 0 && fa.t == fb.t;
    plume_scene *s = NULL;
    CHECK(plume_scene_load("../data/shell/strip_scene.json", &s, &err) == PLUME_OK);
    const plume_index ne = s ? plume_scene_mesh(s)->ne : 0;
    const int same_e = mt_same_array(a, b, 5, "edge_angles", ne) && mt_same_array(a, b, 5, "edge_frames", 3 * ne);
    fprintf(stderr, "    restart after 3 frames, 2 more: positions and velocities %s, edge unknowns and frames %s\n",
            same_x ? "bit for bit" : "DIFFER", same_e ? "bit for bit" : "DIFFER");
    CHECK(same_x && same_e && ne > 0);
    /* a frames file without the edge arrays (a shape-operator run's) is refused, naming them */
    snprintf(a, sizeof a, "%s/shape/frames.h5", dir);
    snprintf(out, sizeof out, "%s/again", dir);
    CHECK(mt_run_strip("midedge", out, 1, a, th, &err) != 0);
    fprintf(stderr, "    %s\n", err.msg);
    CHECK(strstr(err.msg, "restart") && strstr(err.msg, "edge_"));
    plume_frame_free(&fa);
    plume_frame_free(&fb);
    plume_scene_destroy(&s);
    snprintf(out, sizeof out, "rm -rf '%s'", dir);
    CHECK(system(out) == 0);
}

/* The scene's refusals around midedge: a bending model it does not know names the three it does,
 * and the fields without a run (plume_scene_fields: no edge angles to read) say where they come
 * from; neither changes the scene. A run's fields (plume_run_fields) give the bending energy. */
void test_midedge_term_scene_bad_inputs(void)
{
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load("../data/shell/strip_scene.json", &s, &err) == PLUME_OK);
    if (!s)
        return;
    CHECK(plume_scene_set(s, "{\"bending_model\": \"morley\"}", &err) == PLUME_EINVAL);
    fprintf(stderr, "    %s\n", err.msg);
    CHECK(strstr(err.msg, "bending_model") && strstr(err.msg, "\"midedge\""));
    char *desc = NULL;
    CHECK(plume_scene_describe(s, &desc, &err) == PLUME_OK && desc && strstr(desc, "shape_operator"));
    plume_free(desc);
    CHECK(plume_scene_set(s, "{\"bending_model\": \"midedge\"}", &err) == PLUME_OK);
    plume_fields *f = NULL;
    CHECK(plume_scene_fields(s, &f, &err) == PLUME_EINVAL && !f);
    fprintf(stderr, "    %s\n", err.msg);
    CHECK(strstr(err.msg, "midedge") && strstr(err.msg, "plume_run_fields"));
    /* a run's fields: the bending energy density of a sagging strip, from the run's edge angles */
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.frames = 2;
    plume_run *r = NULL;
    CHECK(plume_run_create(s, &o, &r, &err) == PLUME_OK && plume_run_to_end(r, &err) == PLUME_OK);
    CHECK(plume_run_fields(r, &f, &err) == PLUME_OK && f);
    plume_field_values fv;
    const plume_index nt = plume_scene_mesh(s)->nt;
    double *psi = malloc((size_t)nt * sizeof *psi), worst = 0.0, total = 0.0;
    CHECK(f && psi && plume_fields_compute(f, plume_run_positions(r), &fv, &err) == PLUME_OK &&
          plume_field_values_select(&fv, "bending_energy", psi, &err) == PLUME_OK);
    for (plume_index t = 0; psi && t < nt; t++) {
        worst = isfinite(psi[t]) && psi[t] >= 0.0 ? worst : 1.0;
        total += psi[t];
    }
    fprintf(stderr, "    run fields: bending energy density summed over %ld triangles %.3e J/m^2\n", (long)nt, total);
    CHECK(worst == 0.0 && total > 0.0);
    /* the operator's curvature: its plate energy is the energy density (flat rest), and the strip
     * bends along its barbs */
    const plume_mesh *sm = plume_scene_mesh(s);
    double eworst = 0.0, kbb = 0.0, ktt = 0.0;
    CHECK(fv.curvature != NULL);
    for (plume_index t = 0; fv.curvature && psi && t < nt; t++) {
        const double *kp = fv.curvature + 3 * t;
        const plume_bending_material *bm = &s->mats[sm->material[t]].bending;
        const double D66 = bm->D_twist > 0.0 ? bm->D_twist : 0.5 * (sqrt(bm->D_long * bm->D_trans) - bm->D_coupling);
        const double w = 0.5 * (bm->D_long * kp[0] * kp[0] + 2.0 * bm->D_coupling * kp[0] * kp[1] + bm->D_trans * kp[1] * kp[1] +
                                4.0 * D66 * kp[2] * kp[2]);
        eworst = fmax(eworst, fabs(w - psi[t]));
        kbb = fmax(kbb, fabs(kp[0])), ktt = fmax(ktt, fabs(kp[1]));
    }
    fprintf(stderr, "    run fields: curvature along the barbs up to %.3f 1/m, across %.3f; plate energy of the curvature "
            "against the density %.1e of %.1e\n", kbb, ktt, eworst, mt_max_abs(psi, nt));
    CHECK(kbb > 1.0 && ktt < 0.5 * kbb && eworst < 1e-9 * mt_max_abs(psi, nt));
    double *kb = malloc((size_t)nt * sizeof *kb);
    CHECK(kb && plume_field_values_select(&fv, "curvature_bb", kb, &err) == PLUME_OK && kb[0] == fv.curvature[0]);
    free(kb);
    free(psi);
    plume_fields_destroy(&f);
    plume_run_destroy(&r);
    /* the other models' fields have no operator curvature */
    CHECK(plume_scene_set(s, "{\"bending_model\": \"shape_operator\"}", &err) == PLUME_OK &&
          plume_scene_fields(s, &f, &err) == PLUME_OK && f &&
          plume_fields_compute(f, sm->x, &fv, &err) == PLUME_OK && fv.curvature == NULL);
    plume_fields_destroy(&f);
    CHECK(plume_run_fields(NULL, &f, &err) == PLUME_EINVAL && !f);
    plume_scene_destroy(&s);
}
