/* make bench — bending that depends on the mesh: the hinge (macro/bending.c) against the
 * shape-operator term (macro/shape_bending.c) on the five mesh families of tests/bend_meshes.h.
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
 * Part 2: one energy + gradient + Hessian evaluation at ~40k triangles, best of 3, exact and
 * projected blocks, and the time of create. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/plume_tree.h"
#include "../tests/bend_meshes.h"

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

/* the two tables' titles and column lines; `bench_bending --header` prints them alone (the check
 * of docs/benchmarks.md, scripts/bench-tables.py, compares them with the page) */
static void header_ratios(void)
{
    printf("bending: cylinder k = 1 on a 1 x 0.8 patch, h = 1/24: stored energy / continuum plate energy\n");
    printf("%-18s | curv | mat  | barbs |  hinge  | own fit |  shape\n", "mesh family");
}

static void header_timing(void)
{
    printf("\nbending: one energy + gradient + Hessian evaluation (best of 3), ms\n");
    printf("%-18s | triangles | term  | stencils | create | exact | projected\n", "mesh");
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        header_ratios();
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
    for (int f = 0; f < BM_NFAMILY; f++)
        for (int ic = 0; ic < 2; ic++)
            for (int im = 0; im < 2; im++)
                for (int ib = 0; ib < 4; ib++) {
                    if (im == 1 && ib > 0)
                        continue; /* isotropic: the barb angle does not matter */
                    const double rh = ratio(plume_bending_term_create, f, h, curvs[ic], barbs[ib], mats[im], k);
                    const double ro = ratio(shape_own_create, f, h, curvs[ic], barbs[ib], mats[im], k);
                    const double rs = ratio(plume_shape_bending_term_create, f, h, curvs[ic], barbs[ib], mats[im], k);
                    printf("%-18s | %4g | %-4s | %5g | %7.4f | %7.4f | %7.4f\n", bm_family_name[f], curvs[ic],
                           mname[im], barbs[ib], rh, ro, rs);
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
            printf("%-18s | %9ld | %-5s | %8ld | %6.1f | %5.1f | %9.1f\n", bm_family_name[fams[i]], (long)m->nt, tn[j],
                   ns, 1e3 * cs, 1e3 * te, 1e3 * tp);
        }
        plume_mesh_destroy(&m);
    }
    return 0;
}
