/* make bench — the vane with hooks, micro against macro (docs/monoclinic-vane.md, "A cohesive zone
 * with the cell's energy"): data/layout_hooks.json's cell at barb spacings 1, 0.5 and 0.25 mm (the
 * barbules scaled with the spacing, the hook's strength with the barbule spacing), a 4 x 5.2 mm
 * specimen pulled at 45 deg to 0.8 % in 40 steps. The resolved specimen (every barb, barbule and
 * hook) against the macro vane C: the hooked cell's tensor, one split line per barb spacing a
 * thousand times stiffer than the cell across it, brittle (letting go at the strength) and
 * cohesive (the cell's separation energy under a softening branch, plume_split_stiff_law). Peak
 * stress, dissipated energy, Newton iterations and time side by side, and the macro figures over
 * the resolved ones. --quick: 1 mm only. --header: the table's title and columns. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/hooked_vane.h"
#include "../tests/plume_tree.h"

#define LX 4e-3
#define LY 5.2e-3

typedef struct {
    int converged, iterations;
    double peak, dissipated, balance, seconds;
} run_figures;

static double wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void traction_opts(plume_traction_opts *o, plume_solver_opts *so, int max_iter)
{
    plume_traction_opts_default(o);
    o->lx = LX, o->ly = LY, o->h = 1e-4, o->strain_max = 0.008, o->steps = 40, o->progress = 0;
    plume_solver_opts_default(so);
    so->max_iter = max_iter;
    o->solver_opts = so;
}

static void take(const plume_traction_result *r, double t0, run_figures *f)
{
    f->converged = r->converged, f->iterations = r->newton_iterations;
    f->peak = r->peak_stress, f->dissipated = r->dissipated_energy, f->balance = r->energy_balance_error;
    f->seconds = wall() - t0;
}

static run_figures resolved(double d_B)
{
    run_figures f = {0, 0, NAN, NAN, NAN, NAN};
    plume_layout l;
    hooked_layout(d_B, &l);
    plume_traction_opts o;
    plume_solver_opts so;
    traction_opts(&o, &so, 100);
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_traction_result r;
    const double t0 = wall();
    if (plume_micro_specimen(&l, LX, LY, 45.0, &mesh, &p, &err) == PLUME_OK &&
        plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_OK) {
        take(&r, t0, &f);
        plume_traction_result_free(&r);
    } else {
        fprintf(stderr, "bench_unzip: resolved, d_B %g mm: %s\n", 1e3 * d_B, err.msg);
    }
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return f;
}

/* vane C (tests/hooked_vane.h); cohesive: the lines keep the cell's energy (and a cap of 1000
 * Newton iterations a solve, which the solves at fixed grips where whole lines snap need at 1 mm) */
static run_figures vane_c(double d_B, int cohesive)
{
    run_figures f = {0, 0, NAN, NAN, NAN, NAN};
    plume_layout l;
    hooked_layout(d_B, &l);
    plume_traction_opts o;
    plume_solver_opts so;
    traction_opts(&o, &so, cohesive ? 1000 : 100);
    plume_err err = {{0}};
    plume_traction_result r;
    const double t0 = wall();
    if (hooked_vane_c(&l, LX, LY, cohesive, &o, &r, &err) == PLUME_OK) {
        take(&r, t0, &f);
        plume_traction_result_free(&r);
    } else {
        fprintf(stderr, "bench_unzip: vane C, d_B %g mm: %s\n", 1e3 * d_B, err.msg);
    }
    return f;
}

static void header(void)
{
    printf("plume bench: layout_hooks.json's cell at barb spacing d_B, 4 x 5.2 mm pulled at 45 deg to 0.8 %% in 40 "
           "steps: the resolved specimen against vane C (hooked tensor, stiff lines), brittle and cohesive\n");
    printf("     |            resolved |              C, brittle lines |             C, cohesive lines | "
           "cohesive/resolved\n");
    printf(" d_B |  peak     D      s  |  peak     D     it      s     |  peak     D     it      s     |  peak      D\n");
    printf("  mm |   kPa    nJ         |   kPa    nJ                   |   kPa    nJ                   |\n");
}

static void cell(const run_figures *f, int iterations)
{
    if (iterations)
        printf(" %6.2f %6.1f %6d %6.1f%s |", 1e-3 * f->peak, 1e9 * f->dissipated, f->iterations, f->seconds,
               f->converged ? " " : "*");
    else
        printf(" %6.2f %6.1f %6.1f%s |", 1e-3 * f->peak, 1e9 * f->dissipated, f->seconds, f->converged ? " " : "*");
}

int main(int argc, char **argv)
{
    plume_openmp_serial();
    if (argc > 1 && strcmp(argv[1], "--header") == 0) {
        header();
        return 0;
    }
    const int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    const double spacings[3] = {1e-3, 5e-4, 2.5e-4};
    header();
    double worst = 0.0;
    for (int k = 0; k < (quick ? 1 : 3); k++) {
        const run_figures m = resolved(spacings[k]), b = vane_c(spacings[k], 0), c = vane_c(spacings[k], 1);
        printf(" %4.2f|", 1e3 * spacings[k]);
        cell(&m, 0);
        cell(&b, 1);
        cell(&c, 1);
        printf(" %+6.1f%% %+6.1f%%\n", 100.0 * (c.peak / m.peak - 1.0), 100.0 * (c.dissipated / m.dissipated - 1.0));
        worst = fmax(worst, fmax(fabs(m.balance), fmax(fabs(b.balance), fabs(c.balance))));
    }
    printf("(D: the dissipated energy; it: Newton iterations; s: seconds, the cell's homogenisation included for "
           "vane C; * not converged; the largest energy balance error %.1e)\n", worst);
    return 0;
}
