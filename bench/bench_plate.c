/* make bench — the cost of the bending moduli: the periodic plate cell (micro/cell_plate.h, Morley
 * triangles) against the membrane cell (micro/cell_linear.h) on the same cell meshes, each timed as
 * the best of three runs, side by side with their ratio. Then both scales in bending
 * (macro/plate_bending.h) down to the finest barb spacing, lx/16: the resolved strip specimen
 * against the plate with the cell's D, the figures of docs/bending-homogenisation.md (the lx/16
 * specimens have 2.3e5 triangles and take up to 12.5 GB and 35-50 s of CPU each). The cylinders
 * use the edge moments ("edge"); the twist is run under both the edge moments' corner forces and
 * the uniform-curvature loads ("unif", each barb gripped), whose last column is the interior
 * residual of the uniform state (0 for the edge moments). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/plume_tree.h"
#include "../micro/cell_linear.h"
#include "../micro/cell_plate.h"
#include "../micro/layout.h"

#define REPS 3

static void row(const char *name, const plume_layout *l)
{
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    plume_cell *c = NULL;
    plume_err err = {{0}};
    if (plume_cell_mesh(l, &c, &err) != PLUME_OK) {
        printf("%-30s | mesh failed: %s\n", name, err.msg);
        return;
    }
    double tm = INFINITY, tp = INFINITY, C[9], D[9];
    plume_cell_plate_info info = {0, 0, 0};
    for (int r = 0; r < REPS; r++) {
        double t0 = plume_wall_seconds();
        if (plume_cell_linear_tensor(c, mats, 2, l->h, C, NULL, &err) != PLUME_OK) {
            printf("%-30s | membrane failed: %s\n", name, err.msg);
            break;
        }
        double t1 = plume_wall_seconds();
        if (plume_cell_plate_tensor(c, mats, 2, D, &info, &err) != PLUME_OK) {
            printf("%-30s | plate failed: %s\n", name, err.msg);
            break;
        }
        double t2 = plume_wall_seconds();
        tm = fmin(tm, t1 - t0), tp = fmin(tp, t2 - t1);
    }
    if (isfinite(tm) && isfinite(tp))
        printf("%-30s | %9ld | %9ld | %9ld | %10.2f | %10.2f | %6.2f | %.5g %.5g %.5g\n", name,
               (long)plume_cell_elements(c), (long)c->mesh->nv * 2, (long)info.dofs, 1e3 * tm, 1e3 * tp, tp / tm, D[0],
               D[4], D[8]);
    plume_cell_destroy(&c);
}

/* One load of both scales in bending (linear plate, one step): the resolved specimen of l and the
 * plate with the cell's D (edge lx/20), the same edge moments. */
static void both_scales(const plume_layout *l, double lx, double ly, double angle, plume_bend_load load,
                        plume_bend_loading loading)
{
    plume_err err = {{0}};
    plume_cell *cell = NULL;
    double D[9], moment, predicted, s[2] = {NAN, NAN}, cpu = NAN, resid = 0.0;
    long nt = 0;
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    if (plume_cell_mesh(l, &cell, &err) != PLUME_OK || plume_cell_plate_tensor(cell, mats, 2, D, NULL, &err) != PLUME_OK ||
        plume_bend_expected(D, angle, load, 0.01, &moment, &predicted, &err) != PLUME_OK) {
        plume_cell_destroy(&cell);
        printf("  failed: %s\n", err.msg);
        return;
    }
    plume_cell_destroy(&cell);
    plume_bending_material phases[2], hom = {D[0], D[4], D[8], D[1]};
    plume_plate_of_membrane(&mats[0], &phases[0]);
    plume_plate_of_membrane(&mats[1], &phases[1]);
    for (int scale = 0; scale < 2; scale++) {
        plume_mesh *planar = NULL, *mesh = NULL;
        plume_problem *p = NULL;
        const clock_t c0 = clock();
        plume_status st = scale == 0 ? plume_specimen_mesh(l, lx, ly, angle, &planar, &err) : PLUME_OK;
        if (st == PLUME_OK)
            st = scale == 0 ? plume_shell_specimen(planar, mats, phases, 2, &mesh, &p, &err)
                            : plume_plate_specimen(lx, ly, angle, lx / 20, &mats[0], &hom, &mesh, &p, &err);
        if (st == PLUME_OK) {
            plume_bend_opts o;
            plume_bend_opts_default(&o);
            o.load = load, o.loading = loading, o.lx = lx, o.ly = ly, o.moment = moment, o.steps = 1;
            o.solver = PLUME_SOLVER_LINEARIZED;
            o.phases = scale == 0 ? phases : &hom, o.nphases = scale == 0 ? 2 : 1;
            plume_bend_result r;
            if ((st = plume_bend_run(mesh, p, &o, &r, &err)) == PLUME_OK) {
                s[scale] = r.converged ? r.stiffness : NAN;
                if (scale == 0)
                    resid = r.load_residual;
                plume_bend_result_free(&r);
            }
            if (scale == 0)
                nt = (long)mesh->nt, cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
        }
        if (st != PLUME_OK)
            printf("  failed: %s\n", err.msg);
        plume_problem_destroy(&p);
        plume_mesh_destroy(&mesh);
        plume_mesh_destroy(&planar);
    }
    printf("%-8s | %-8s %3.0f %-5s | %9ld | %12.6g | %12.6g | %+8.2f %% | %+9.1e | %7.1f | %.1e\n", "",
           plume_bend_load_name(load), angle, loading == PLUME_BEND_UNIFORM_CURVATURE ? "unif" : "edge", nt, s[0], s[1],
           100.0 * (s[0] / s[1] - 1.0), s[1] / predicted - 1.0, cpu, resid);
    fflush(stdout);
}

/* the two tables' titles and column lines; `bench_plate --header` prints them alone (the check
 * of docs/benchmarks.md, scripts/bench-tables.py, compares them with the page) */
static void header_cell(void)
{
    printf("\nplume bench (bending): the plate cell (Morley, exact bending tensor) against the membrane cell\n"
           "(exact small-strain tensor) on the same cell; best of %d; plate/membrane is the cost ratio\n", REPS);
    printf("%-30s | %9s | %9s | %9s | %10s | %10s | %6s | %s\n", "layout", "elements", "2 nodes", "plate dofs",
           "membr. ms", "plate ms", "ratio", "D_long D_trans D_twist (N m)");
}

static void header_both_scales(void)
{
    printf("\nplume bench (bending, both scales): strips phi 0.3, barbs 1.5e-4 m thick, a matrix 20 times softer\n"
           "and 5e-5 m thick, 10 x 20 mm specimen, curvature 0.01 1/m, linear plate; edge moments (edge) or\n"
           "uniform-curvature loads (unif); the micro specimen at the default element edge (phase-aware\n"
           "stencils); micro - macro is the size effect; residual: interior forces of the uniform state\n");
    printf("%-8s | %-18s | %9s | %12s | %12s | %10s | %9s | %7s | %s\n", "d_B", "load", "triangles", "micro N m",
           "macro N m", "micro-macro", "macro-th.", "cpu s", "residual");
}

/* bench_plate [both [E_REL [N_MAX]]]: "both" runs the both-scales part alone, on an element edge of
 * E_REL barb widths (default: the layout's) down to d_B = lx / N_MAX (default 16). */
int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        header_cell();
        header_both_scales();
        return 0;
    }
    plume_openmp_serial();
    const int both_only = argc > 1 && strcmp(argv[1], "both") == 0;
    const double e_rel = argc > 2 ? atof(argv[2]) : -1.0;
    const int n_max = argc > 3 ? atoi(argv[3]) : 16;
    if (!both_only) {
    header_cell();
    plume_layout l;
    plume_layout_default(&l);
    row("strips, automatic (P2)", &l);
    l.e_rel = 0.25;
    row("strips, e-bar 0.25 (P2)", &l);
    l.order = 1;
    row("strips, e-bar 0.25 (P1)", &l);
    const double e[3] = {0.2, 0.1, 0.05};
    for (int k = 0; k < 3; k++) {
        plume_layout_default(&l);
        l.kind = PLUME_LAYOUT_BARBULES, l.ratio = 1.0, l.phi = 0.3, l.barbule_width = 1e-4, l.barbule_spacing = 8e-4;
        l.order = 1, l.e_rel = e[k];
        char name[64];
        snprintf(name, sizeof name, "barbules, e-bar %.2g (P1)", e[k]);
        row(name, &l);
    }
    l.order = 2, l.e_rel = 0.0;
    row("barbules, automatic (P2)", &l);
    }

    header_both_scales();
    plume_layout b;
    plume_layout_default(&b);
    b.phi = 0.3, b.ratio = 0.05, b.h = 1e-4, b.h_barb = 1.5e-4, b.h_barbule = 5e-5, b.order = 1;
    if (e_rel > 0.0)
        b.e_rel = e_rel;
    const double lx = 0.01, ly = 0.02;
    for (int n = 4; n <= n_max; n *= 2) {
        b.d_B = lx / n;
        printf("lx/%-5d |\n", n);
        both_scales(&b, lx, ly, 0.0, PLUME_BEND_CYLINDER, PLUME_BEND_EDGE_MOMENTS);
        both_scales(&b, lx, ly, 45.0, PLUME_BEND_CYLINDER, PLUME_BEND_EDGE_MOMENTS);
        both_scales(&b, lx, ly, 90.0, PLUME_BEND_CYLINDER, PLUME_BEND_EDGE_MOMENTS);
        both_scales(&b, lx, ly, 0.0, PLUME_BEND_TWIST, PLUME_BEND_EDGE_MOMENTS);
        both_scales(&b, lx, ly, 0.0, PLUME_BEND_TWIST, PLUME_BEND_UNIFORM_CURVATURE);
    }
    return 0;
}
