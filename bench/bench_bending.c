/* make bench — bending that depends on the mesh: the hinge (macro/shell/bending.c) against the
 * shape-operator term (macro/shell/shape_bending.c) on the five mesh families of tests/bend_meshes.h.
 * Part 1: a 1 x 0.8 patch at h = 1/24 bent into a cylinder of curvature k = 1 (curvature along
 * material x or at 30 degrees to it), barbs at 0, 30, 45, 90 degrees to the curvature; the stored
 * energy over the continuum plate's. Both terms are given the same continuum: the hinge's law
 * D_long c^2 + D_trans s^2 is the orthotropic plate with 2 D_12 + 4 D_66 = D_long + D_trans, so the
 * shape term gets D_coupling = 0, D_twist = (D_long + D_trans) / 4 here (a difference of ratios is
 * then a difference of discretisations, not of plate models). Vane D_long/D_trans = 2500, and
 * isotropic.
 * The shape term is shown twice: "own fit" is each triangle's own 6-point fit alone (the first
 * formulation, which fails the patch test on irregular meshes), "shape" the default with slopes
 * shared across edges (shape_bending.c).
 * The midedge term (macro/shell/midedge_bending.c, one angle per edge) on the same cylinders:
 * "me exact" with every edge's director on the cylinder's normal at the edge's midpoint,
 * "midedge" with the vertices held and every angle relaxed to the energy's minimum (what an
 * equilibrium sees; Newton on the angles alone, below), "me inner" the relaxed energy of the
 * triangles whose vertices lie 0.1 or more from the patch's edge over their continuum energy.
 * A second table sweeps D_trans/D_long from 1 to 1e-3 at the four barb angles; a third follows
 * the error on random Delaunay meshes from h = 1/8 to 1/128.
 * Part 2: one energy + gradient + Hessian evaluation at ~40k triangles, best of 3, exact and
 * projected blocks, and the time of create. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/plume_tree.h"
#include "../tests/bend_meshes.h"

/* The midedge relaxation: Newton on the angles stops at |dE/dtheta|_inf <= ME_GTOL times its
 * value at the exact normals, or after ME_MAXIT iterations. */
#define ME_GTOL 1e-12
#define ME_MAXIT 20
/* "me inner": triangles whose vertices all lie this far (material length) from the patch's edge */
#define ME_INNER 0.1

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef plume_status (*create_fn)(const plume_mesh *, const plume_bending_material *, int, const double *,
                                  plume_term *, plume_err *);

/* the shape-operator term with each triangle's own fit alone (the first formulation) */
static plume_status shape_own_create(const plume_mesh *m, const plume_bending_material *mat, int nmat, const double *rest,
                                     plume_term *out, plume_err *err)
{
    const plume_shape_bending_opts o = {NULL, 1, 0};
    return plume_shape_bending_term_create_opts(m, mat, nmat, rest, &o, out, err);
}

/* energy / continuum for one term, NAN on failure */
static double ratio(create_fn create, int family, double h, double curv, double barb, const plume_bending_material *mat,
                    double k)
{
    plume_mesh *m = bm_family_mesh(family, h, 1.0, 0.8, curv + barb);
    if (!m)
        return NAN;
    plume_term t;
    double r = NAN, E = 0.0;
    if (create(m, mat, 1, NULL, &t, NULL) == PLUME_OK) {
        bm_map_cylinder(m, curv, k, m->x);
        if (t.eval(t.ctx, 3, m->x, &E, NULL, NULL, 0) == PLUME_OK)
            r = E / (bm_continuum_density(mat, k, barb) * plume_mesh_total_area(m));
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
    return r;
}

/* best of 3 of one eval with energy, gradient and blocks; *create_s the creation time */
static double time_eval(create_fn create, const plume_mesh *m, const plume_bending_material *mat, int project,
                        double *create_s, long *nstencil)
{
    plume_term t;
    double t0 = now();
    if (create(m, mat, 1, NULL, &t, NULL) != PLUME_OK)
        return NAN;
    *create_s = now() - t0;
    *nstencil = (long)t.nstencil;
    const size_t kk = (size_t)(3 * t.arity) * (size_t)(3 * t.arity);
    double *g = calloc((size_t)(3 * m->nv), sizeof *g), *H = malloc(sizeof(double) * kk * (size_t)(t.nstencil + 1));
    double best = NAN;
    if (g && H)
        for (int rep = 0; rep < 3; rep++) {
            double E = 0.0;
            t0 = now();
            const plume_status st = t.eval(t.ctx, 3, m->x, &E, g, H, project);
            const double s = now() - t0;
            if (st == PLUME_OK && !(s >= best))
                best = s;
        }
    free(g);
    free(H);
    t.destroy(t.ctx);
    return best;
}

/* ---- the midedge term ---------------------------------------------------------------------- */

/* Newton on the edge angles with the vertices held: the angles' Hessian (rows and columns 9..11
 * of each triangle's block, coupling the three edges of a face) in CSC (upper triangle),
 * factorised by plume's CHOLMOD wrapper; analysed once. */
typedef struct {
    plume_index ne, nt, nnz;
    plume_index *colptr, *rowind, *map; /* map [9 nt]: value of slots (a, c) of face t, -1 below the diagonal */
    double *vals, *blocks, *g, *rhs, *dz, *trial;
    plume_chol *chol;
} me_newton;

static int cmp_long(const void *a, const void *b)
{
    const long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

static void me_newton_free(me_newton *w)
{
    free(w->colptr), free(w->rowind), free(w->map), free(w->vals), free(w->blocks);
    free(w->g), free(w->rhs), free(w->dz), free(w->trial);
    plume_chol_destroy(&w->chol);
    memset(w, 0, sizeof *w);
}

/* The pattern, its map from the faces' blocks and the analysis. 0, or -1 (w freed). */
static int me_newton_init(const plume_midedge_bending *b, me_newton *w)
{
    memset(w, 0, sizeof *w);
    const plume_index ne = plume_midedge_bending_nedge(b), nt = plume_midedge_bending_nface(b);
    const plume_index *fe = plume_midedge_bending_face_edges(b);
    w->ne = ne, w->nt = nt;
    long *key = malloc(sizeof(long) * 9 * (size_t)nt);
    w->colptr = calloc((size_t)ne + 1, sizeof(plume_index));
    w->map = malloc(sizeof(plume_index) * 9 * (size_t)nt);
    w->blocks = malloc(sizeof(double) * 144 * (size_t)nt);
    w->g = malloc(sizeof(double) * (size_t)ne), w->rhs = malloc(sizeof(double) * (size_t)ne);
    w->dz = malloc(sizeof(double) * (size_t)ne), w->trial = malloc(sizeof(double) * (size_t)ne);
    if (!key || !w->colptr || !w->map || !w->blocks || !w->g || !w->rhs || !w->dz || !w->trial)
        goto fail;
    long nk = 0; /* key = column ne + row, row <= column */
    for (plume_index t = 0; t < nt; t++)
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                if (fe[3 * t + a] <= fe[3 * t + c])
                    key[nk++] = (long)fe[3 * t + c] * ne + fe[3 * t + a];
    qsort(key, (size_t)nk, sizeof *key, cmp_long);
    long nu = 0;
    for (long i = 0; i < nk; i++)
        if (i == 0 || key[i] != key[i - 1])
            key[nu++] = key[i];
    w->nnz = nu;
    w->rowind = malloc(sizeof(plume_index) * (size_t)nu), w->vals = malloc(sizeof(double) * (size_t)nu);
    if (!w->rowind || !w->vals)
        goto fail;
    for (long i = 0; i < nu; i++) {
        w->rowind[i] = key[i] % ne;
        w->colptr[key[i] / ne + 1]++;
    }
    for (plume_index j = 0; j < ne; j++)
        w->colptr[j + 1] += w->colptr[j];
    for (plume_index t = 0; t < nt; t++)
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) {
                const plume_index i = fe[3 * t + a], j = fe[3 * t + c];
                w->map[9 * t + 3 * a + c] = -1;
                if (i > j)
                    continue;
                const long want = (long)j * ne + i, *hit = bsearch(&want, key, (size_t)nu, sizeof *key, cmp_long);
                w->map[9 * t + 3 * a + c] = (plume_index)(hit - key);
            }
    free(key);
    key = NULL;
    if (plume_chol_create(ne, w->colptr, w->rowind, 0, &w->chol, NULL) != PLUME_OK)
        goto fail;
    return 0;
fail:
    free(key);
    me_newton_free(w);
    return -1;
}

/* The angles' Hessian from w->blocks, factorised. PLUME_OK or the factorisation's status. */
static plume_status me_newton_factor(me_newton *w)
{
    memset(w->vals, 0, sizeof(double) * (size_t)w->nnz);
    for (plume_index t = 0; t < w->nt; t++)
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                if (w->map[9 * t + 3 * a + c] >= 0)
                    w->vals[w->map[9 * t + 3 * a + c]] += w->blocks[144 * (size_t)t + 12 * (9 + a) + 9 + c];
    return plume_chol_factor(w->chol, w->vals, 0.0);
}

static double max_abs(const double *a, plume_index n)
{
    double m = 0.0;
    for (plume_index i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* Minimises the energy over every angle at the vertices x from theta (overwritten): Newton with
 * the exact angle blocks (the Gauss-Newton ones if those are not positive definite) and a
 * backtracking on the energy. The iterations, or -1 on a failure; *E the final energy, *gratio
 * the final |dE/dtheta|_inf over the first one. */
static int me_relax(const plume_midedge_bending *b, const double *x, double *theta, me_newton *w, double *E,
                    double *gratio)
{
    const plume_index ne = w->ne;
    double g0 = 0.0;
    for (int it = 0;; it++) {
        double En = 0.0;
        memset(w->g, 0, sizeof(double) * (size_t)ne);
        if (plume_midedge_bending_eval(b, x, theta, &En, NULL, w->g, w->blocks, 0, NULL) != PLUME_OK)
            return -1;
        const double gn = max_abs(w->g, ne);
        if (it == 0)
            g0 = gn;
        *E = En, *gratio = g0 > 0.0 ? gn / g0 : 0.0;
        if (gn <= ME_GTOL * g0 || it == ME_MAXIT)
            return it;
        if (me_newton_factor(w) != PLUME_OK &&
            (plume_midedge_bending_eval(b, x, theta, NULL, NULL, NULL, w->blocks, 1, NULL) != PLUME_OK ||
             me_newton_factor(w) != PLUME_OK))
            return -1;
        for (plume_index i = 0; i < ne; i++)
            w->rhs[i] = -w->g[i];
        if (plume_chol_solve(w->chol, w->rhs, w->dz) != PLUME_OK)
            return -1;
        double step = 1.0;
        int ls = 0;
        for (; ls < 40; ls++, step *= 0.5) {
            double Et = 0.0;
            for (plume_index i = 0; i < ne; i++)
                w->trial[i] = theta[i] + step * w->dz[i];
            if (plume_midedge_bending_eval(b, x, w->trial, &Et, NULL, NULL, NULL, 0, NULL) == PLUME_OK &&
                Et <= En + 1e-13 * fabs(En))
                break;
        }
        if (ls == 40)
            return it; /* no decrease left: at the minimum to rounding */
        memcpy(theta, w->trial, sizeof(double) * (size_t)ne);
    }
}

/* Triangle t's energy at (x, theta): the face kernel with each director as its own reference
 * vector and angle 0 (the director of such a frame is the reference vector itself). */
static double me_face_energy(const plume_mesh *m, const plume_midedge_bending *b, const double *x,
                             const double *theta, plume_index t)
{
    const plume_index *fe = plume_midedge_bending_face_edges(b);
    double xv[9], d[3][3], E = NAN;
    const double th[3] = {0.0, 0.0, 0.0}, *r0[3] = {d[0], d[1], d[2]};
    for (int k = 0; k < 3; k++) {
        memcpy(xv + 3 * k, x + 3 * m->tri[3 * t + k], 3 * sizeof(double));
        plume_midedge_bending_director(b, x, theta, fe[3 * t + k], d[k]);
    }
    if (plume_midedge_face_eval(plume_midedge_bending_face(b, t), xv, th, r0, &E, NULL, NULL, 0) != 0)
        return NAN;
    return E;
}

/* Material distance of point P to the segment AB. */
static double seg_dist(const double *P, const double *A, const double *B)
{
    const double ab[2] = {B[0] - A[0], B[1] - A[1]}, ap[2] = {P[0] - A[0], P[1] - A[1]};
    double s = (ab[0] * ap[0] + ab[1] * ap[1]) / (ab[0] * ab[0] + ab[1] * ab[1]);
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    return hypot(ap[0] - s * ab[0], ap[1] - s * ab[1]);
}

/* [nv] 1 where the vertex lies ME_INNER or more from every boundary edge (material space). */
static unsigned char *inner_vertices(const plume_mesh *m)
{
    unsigned char *in = malloc((size_t)m->nv);
    if (!in)
        return NULL;
    for (plume_index v = 0; v < m->nv; v++) {
        double dmin = INFINITY;
        for (plume_index e = 0; e < m->ne; e++)
            if (m->edge_tri[2 * e + 1] < 0)
                dmin = fmin(dmin, seg_dist(m->X + 2 * v, m->X + 2 * m->edges[2 * e], m->X + 2 * m->edges[2 * e + 1]));
        in[v] = dmin >= ME_INNER - 1e-12;
    }
    return in;
}

/* The midedge term's ratios on one cylinder (NAN where something failed) */
typedef struct {
    double exact, relaxed, inner; /* energy / continuum: exact normals, relaxed, relaxed inner triangles */
    int iters;                    /* Newton iterations of the relaxation (-1: failed) */
    double gratio;                /* its final |dE/dtheta|_inf over the first */
    long nt;
} me_result;

static me_result me_ratios(int family, double h, double curv, double barb, const plume_bending_material *mat, double k)
{
    me_result r = {NAN, NAN, NAN, -1, NAN, 0};
    plume_mesh *m = bm_family_mesh(family, h, 1.0, 0.8, curv + barb);
    if (!m)
        return r;
    r.nt = (long)m->nt;
    plume_midedge_bending *b = NULL;
    double *theta = malloc(sizeof(double) * (size_t)m->ne);
    unsigned char *in = inner_vertices(m);
    me_newton w;
    if (theta && in && plume_midedge_bending_create(m, mat, 1, NULL, &b, NULL) == PLUME_OK && me_newton_init(b, &w) == 0) {
        bm_map_cylinder(m, curv, k, m->x);
        for (plume_index e = 0; e < m->ne; e++) {
            double nu[3];
            bm_cylinder_normal(m, e, curv, k, nu);
            theta[e] = plume_midedge_bending_angle_of(b, m->x, e, nu);
        }
        const double dens = bm_continuum_density(mat, k, barb), Ec = dens * plume_mesh_total_area(m);
        double E = 0.0;
        if (plume_midedge_bending_eval(b, m->x, theta, &E, NULL, NULL, NULL, 0, NULL) == PLUME_OK)
            r.exact = E / Ec;
        r.iters = me_relax(b, m->x, theta, &w, &E, &r.gratio);
        if (r.iters >= 0) {
            r.relaxed = E / Ec;
            double Ein = 0.0, Ain = 0.0;
            for (plume_index t = 0; t < m->nt; t++) {
                const plume_index *v = m->tri + 3 * t;
                if (!in[v[0]] || !in[v[1]] || !in[v[2]])
                    continue;
                const double *P0 = m->X + 2 * v[0], *P1 = m->X + 2 * v[1], *P2 = m->X + 2 * v[2];
                Ain += 0.5 * fabs((P1[0] - P0[0]) * (P2[1] - P0[1]) - (P1[1] - P0[1]) * (P2[0] - P0[0]));
                Ein += me_face_energy(m, b, m->x, theta, t);
            }
            r.inner = Ein / (dens * Ain);
        }
        me_newton_free(&w);
    }
    plume_midedge_bending_destroy(&b);
    free(theta);
    free(in);
    plume_mesh_destroy(&m);
    return r;
}

/* the worst relaxation of a table, printed under it */
typedef struct {
    int cases, failed, maxit;
    double worst_g;
} me_tally;

static void tally(me_tally *t, const me_result *r)
{
    t->cases++;
    if (r->iters < 0) {
        t->failed++;
        return;
    }
    t->maxit = r->iters > t->maxit ? r->iters : t->maxit;
    t->worst_g = fmax(t->worst_g, r->gratio);
}

static void print_tally(const me_tally *t)
{
    printf("midedge relaxation (Newton on the angles, vertices held): %d cases, %d failed, at most %d iterations, "
           "final |dE/dtheta| at most %.1e of the first\n",
           t->cases, t->failed, t->maxit, t->worst_g);
}

/* best of 3 of one midedge eval with energy, both gradients and every block, angles on the
 * cylinder's normals (curvature 20 degrees, k = 1, as the mesh is bent); *create_s its creation */
static double time_midedge(const plume_mesh *m, const plume_bending_material *mat, int project, double *create_s)
{
    plume_midedge_bending *b = NULL;
    double t0 = now();
    if (plume_midedge_bending_create(m, mat, 1, NULL, &b, NULL) != PLUME_OK)
        return NAN;
    *create_s = now() - t0;
    double *th = malloc(sizeof(double) * (size_t)m->ne), *gt = calloc((size_t)m->ne, sizeof(double));
    double *g = calloc((size_t)(3 * m->nv), sizeof *g), *H = malloc(sizeof(double) * 144 * (size_t)m->nt);
    double best = NAN;
    if (th && gt && g && H) {
        for (plume_index e = 0; e < m->ne; e++) {
            double nu[3];
            bm_cylinder_normal(m, e, 20.0, 1.0, nu);
            th[e] = plume_midedge_bending_angle_of(b, m->x, e, nu);
        }
        for (int rep = 0; rep < 3; rep++) {
            double E = 0.0;
            t0 = now();
            const plume_status st = plume_midedge_bending_eval(b, m->x, th, &E, g, gt, H, project, NULL);
            const double s = now() - t0;
            if (st == PLUME_OK && !(s >= best))
                best = s;
        }
    }
    free(th), free(gt), free(g), free(H);
    plume_midedge_bending_destroy(&b);
    return best;
}

/* the two tables' titles and column lines; `bench_bending --header` prints them alone (the check
 * of docs/benchmarks.md, scripts/bench-tables.py, compares them with the page) */
static void header_ratios(void)
{
    printf("bending: cylinder k = 1 on a 1 x 0.8 patch, h = 1/24: stored energy / continuum plate energy\n");
    printf("%-18s | curv | mat  | barbs |  hinge  | own fit |  shape  | midedge | me exact | me inner\n", "mesh family");
}

static void header_sweep(void)
{
    printf("\nbending: the same cylinders, D_long = 1, D_trans from 1 to 1e-3, D_coupling 0, "
           "D_twist (D_long + D_trans) / 4: stored energy / continuum\n");
    printf("%-18s | curv | Dt/Dl | barbs |  hinge  |  shape  | midedge | me exact | me inner\n", "mesh family");
}

static void header_conv(void)
{
    printf("\nbending: random Delaunay, curvature along x, h from 1/8 to 1/128: |energy / continuum - 1|\n");
    printf("   h    | triangles | mat  | barbs |  shape   | midedge  | me exact | me inner | Newton it\n");
}

static void header_timing(void)
{
    printf("\nbending: one energy + gradient + Hessian evaluation (best of 3), ms\n");
    printf("%-18s | triangles | term    | stencils | create | exact | projected\n", "mesh");
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        header_ratios();
        header_sweep();
        header_conv();
        header_timing();
        return 0;
    }
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    const plume_bending_material vane = {2.5e-4, 1e-7, (2.5e-4 + 1e-7) / 4.0, 0.0};
    const plume_bending_material iso = {1.0, 1.0, 0.5, 0.0};
    const plume_bending_material *mats[2] = {&vane, &iso};
    const char *mname[2] = {"vane", "iso"};
    const double barbs[4] = {0.0, 30.0, 45.0, 90.0}, curvs[2] = {0.0, 30.0};
    const double h = 1.0 / 24, k = 1.0;

    header_ratios();
    me_tally tl = {0, 0, 0, 0.0};
    for (int f = 0; f < BM_NFAMILY; f++)
        for (int ic = 0; ic < 2; ic++)
            for (int im = 0; im < 2; im++)
                for (int ib = 0; ib < 4; ib++) {
                    if (im == 1 && ib > 0)
                        continue; /* isotropic: the barb angle does not matter */
                    const double rh = ratio(plume_bending_term_create, f, h, curvs[ic], barbs[ib], mats[im], k);
                    const double ro = ratio(shape_own_create, f, h, curvs[ic], barbs[ib], mats[im], k);
                    const double rs = ratio(plume_shape_bending_term_create, f, h, curvs[ic], barbs[ib], mats[im], k);
                    const me_result me = me_ratios(f, h, curvs[ic], barbs[ib], mats[im], k);
                    tally(&tl, &me);
                    printf("%-18s | %4g | %-4s | %5g | %7.4f | %7.4f | %7.4f | %7.4f | %8.4f | %8.4f\n", bm_family_name[f],
                           curvs[ic], mname[im], barbs[ib], rh, ro, rs, me.relaxed, me.exact, me.inner);
                }
    print_tally(&tl);

    /* D_trans/D_long from 1 to 1e-3 on the right grid and the random Delaunay mesh */
    header_sweep();
    tl = (me_tally){0, 0, 0, 0.0};
    const int sweep_fams[2] = {BM_RIGHT, BM_DELAUNAY};
    const double dts[4] = {1.0, 1e-1, 1e-2, 1e-3};
    for (int fi = 0; fi < 2; fi++)
        for (int ic = 0; ic < 2; ic++)
            for (int id = 0; id < 4; id++)
                for (int ib = 0; ib < 4; ib++) {
                    if (id == 0 && ib > 0)
                        continue; /* isotropic */
                    const plume_bending_material mat = {1.0, dts[id], (1.0 + dts[id]) / 4.0, 0.0};
                    const int f = sweep_fams[fi];
                    const double rh = ratio(plume_bending_term_create, f, h, curvs[ic], barbs[ib], &mat, k);
                    const double rs = ratio(plume_shape_bending_term_create, f, h, curvs[ic], barbs[ib], &mat, k);
                    const me_result me = me_ratios(f, h, curvs[ic], barbs[ib], &mat, k);
                    tally(&tl, &me);
                    printf("%-18s | %4g | %5g | %5g | %7.4f | %7.4f | %7.4f | %8.4f | %8.4f\n", bm_family_name[f],
                           curvs[ic], dts[id], barbs[ib], rh, rs, me.relaxed, me.exact, me.inner);
                }
    print_tally(&tl);

    /* convergence on the random Delaunay family */
    header_conv();
    const int hs[5] = {8, 16, 32, 64, 128};
    for (int ih = 0; ih < 5; ih++)
        for (int im = 0; im < 2; im++)
            for (int ib = 0; ib < 4; ib++) {
                if ((im == 1 && ib > 0) || ib == 1)
                    continue; /* vane at 0, 45, 90 degrees; isotropic */
                const double hh = 1.0 / hs[ih];
                const double rs = ratio(plume_shape_bending_term_create, BM_DELAUNAY, hh, 0.0, barbs[ib], mats[im], k);
                const me_result me = me_ratios(BM_DELAUNAY, hh, 0.0, barbs[ib], mats[im], k);
                printf("  1/%-3d | %9ld | %-4s | %5g | %8.2e | %8.2e | %8.2e | %8.2e | %9d\n", hs[ih], me.nt, mname[im],
                       barbs[ib], fabs(rs - 1.0), fabs(me.relaxed - 1.0), fabs(me.exact - 1.0), fabs(me.inner - 1.0),
                       me.iters);
            }

    /* ~40k triangles: the right grid at h = 1/158 (158 x 126 cells) and a Delaunay mesh */
    header_timing();
    const int fams[2] = {BM_RIGHT, BM_DELAUNAY};
    for (int i = 0; i < 2; i++) {
        plume_mesh *m = bm_family_mesh(fams[i], 1.0 / 158, 1.0, 0.8, 30.0);
        if (!m) {
            printf("%-18s | mesh failed\n", bm_family_name[fams[i]]);
            continue;
        }
        bm_map_cylinder(m, 20.0, 1.0, m->x);
        const create_fn fn[3] = {plume_bending_term_create, shape_own_create, plume_shape_bending_term_create};
        const char *tn[3] = {"hinge", "own", "shape"};
        for (int j = 0; j < 3; j++) {
            double cs = NAN;
            long ns = 0;
            const double te = time_eval(fn[j], m, &vane, 0, &cs, &ns);
            const double tp = time_eval(fn[j], m, &vane, 1, &cs, &ns);
            printf("%-18s | %9ld | %-7s | %8ld | %6.1f | %5.1f | %9.1f\n", bm_family_name[fams[i]], (long)m->nt, tn[j],
                   ns, 1e3 * cs, 1e3 * te, 1e3 * tp);
        }
        double cs = NAN;
        const double te = time_midedge(m, &vane, 0, &cs), tp = time_midedge(m, &vane, 1, &cs);
        printf("%-18s | %9ld | %-7s | %8ld | %6.1f | %5.1f | %9.1f\n", bm_family_name[fams[i]], (long)m->nt, "midedge",
               (long)m->nt, 1e3 * cs, 1e3 * te, 1e3 * tp);
        plume_mesh_destroy(&m);
    }
    return 0;
}
