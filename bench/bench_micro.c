/* make bench (second part) — the cost of the microscale: a homogenisation (small-strain tensor,
 * then tensor + cell curves) and micro against macro traction runs of the same scenario, with
 * element counts, times and their ratio. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../tests/plume_tree.h"
#include "../micro/cell_linear.h"
#include "../micro/homogenize.h"
#include "../micro/layout.h"
#include "../micro/micro_model.h"

static void homogenisation_row(const char *name, const plume_layout *l)
{
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    plume_homog_result r;
    plume_err err = {{0}};
    o.strain_max = 0.0;
    double t0 = plume_wall_seconds();
    if (plume_homogenize(l, &o, &r, &err) != PLUME_OK) {
        printf("%-28s | failed: %s\n", name, err.msg);
        return;
    }
    double t_tensor = plume_wall_seconds() - t0;
    plume_homog_result_free(&r);
    o.strain_max = 0.05;
    o.steps = 10;
    t0 = plume_wall_seconds();
    if (plume_homogenize(l, &o, &r, &err) != PLUME_OK) {
        printf("%-28s | curves failed: %s\n", name, err.msg);
        return;
    }
    double t_all = plume_wall_seconds() - t0;
    printf("%-28s | %8ld | %10.2f | %12.2f | %8d | E_yy %.5g, G_xy %.5g Pa\n", name, (long)r.elements, 1e3 * t_tensor,
           1e3 * t_all, r.newton_iterations, r.moduli.E_yy, r.moduli.G_xy);
    plume_homog_result_free(&r);
}

/* one traction run; returns seconds, fills stress and elements */
static double micro_run(const plume_layout *l, double *stress, long *elements)
{
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_err err = {{0}};
    double s = NAN;
    if (plume_micro_specimen(l, 1.0, 1.3, 45.0, &mesh, &p, &err) != PLUME_OK)
        return NAN;
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = 5, o.progress = 0;
    plume_traction_result r;
    if (plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_OK && r.converged) {
        *stress = r.curve.stress[r.curve.n - 1];
        s = r.seconds;
    }
    plume_traction_result_free(&r);
    *elements = (long)mesh->nt;
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return s;
}

static double macro_run(const plume_ortho *m, double edge, double *stress, long *elements)
{
    plume_vane v;
    plume_vane_default(&v);
    v.moduli = *m;
    v.h = 1.0;
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_err err = {{0}};
    double s = NAN;
    if (plume_patch_mesh(1.0, 1.3, 45.0, edge, PLUME_PATCH_ALIGNED, 2, &mesh, &err) != PLUME_OK ||
        plume_problem_create(mesh->nv, 2, 1.3, &p, &err) != PLUME_OK || plume_vane_add(p, mesh, &v, &barbs, &nb, &err) != PLUME_OK)
        return NAN;
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = 5, o.progress = 0;
    plume_traction_result r;
    if (plume_traction_run(mesh, p, barbs, nb, &o, &r, &err) == PLUME_OK && r.converged) {
        *stress = r.curve.stress[r.curve.n - 1];
        s = r.seconds;
    }
    plume_traction_result_free(&r);
    *elements = (long)mesh->nt;
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return s;
}

/* E_yy of the explicit-barbule cell's exact tensor at order and e_rel; seconds and elements out */
static double barbule_cell(int order, double e_rel, double *seconds, long *elements)
{
    plume_layout l;
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES, l.ratio = 1.0, l.phi = 0.3, l.barbule_width = 1e-4, l.barbule_spacing = 8e-4;
    l.order = order, l.e_rel = e_rel;
    plume_membrane_material mats[2];
    plume_layout_materials(&l, mats);
    plume_cell *c = NULL;
    plume_err err = {{0}};
    double C[9], t0 = plume_wall_seconds(), E = NAN;
    plume_ortho m;
    if (plume_cell_mesh(&l, &c, &err) == PLUME_OK && plume_cell_linear_tensor(c, mats, 2, l.h, C, NULL, &err) == PLUME_OK &&
        plume_ortho_from_tensor(C, &m, &err) == PLUME_OK)
        E = m.E_yy;
    *seconds = plume_wall_seconds() - t0;
    *elements = c ? (long)plume_cell_elements(c) : 0;
    plume_cell_destroy(&c);
    return E;
}

/* The tables' titles and column lines (a table with a reference line has its title and its columns
 * apart); `bench_micro --header` prints them alone (the check of docs/benchmarks.md,
 * scripts/bench-tables.py, compares them with the page). */
static void header_homogenisation(void)
{
    printf("\nplume bench (micro): homogenisation of a periodic cell (tensor: exact linear cell problem;\n"
           "curves: uniaxial stress along and across the barbs and shear with free normal stresses to 5%%,\n"
           "10 steps each)\n");
    printf("%-28s | %8s | %10s | %12s | %8s |\n", "layout", "elements", "tensor ms", "+ curves ms", "Newton it");
}

static void header_barbule_title(void)
{
    printf("\nExplicit-barbule cell, E_yy of the exact small-strain tensor: linear (P1, the paper's) against\n"
           "quadratic (P2) triangles on the same meshes; error against P2 at e-bar 1/128\n");
}

static void header_barbule_columns(void)
{
    printf("%8s | %8s | %10s %8s %9s | %10s %8s %9s | %s\n", "e-bar", "elements", "P1 E_yy", "error", "ms", "P2 E_yy",
           "error", "ms", "P1 error / P2 error");
}

static void header_specimen_title(void)
{
    printf("\nFigure 10 specimen (strips, contrast 1e-6, d-bar_B 0.086, tilted 45 deg, 5 %% in 5 steps): linear\n"
           "(the paper's) against quadratic triangles; error against quadratic at e-bar 0.725\n");
}

static void header_specimen_columns(void)
{
    printf("%5s %6s | %8s %9s %9s %8s\n", "order", "e-bar", "elements", "seconds", "stress", "error");
}

static void header_micro_macro(void)
{
    printf("\nMicro (resolved barbs, Figure 10 setting) against macro (homogenised moduli, barbs inextensible,\n"
           "aligned mesh, edge 0.02) on the same tilted 45 deg traction to 5%% strain in 5 steps:\n");
    printf("%7s %5s %s | %9s %9s | %9s %9s | %8s | %s\n", "d-bar_B", "e-bar", "  ", "micro el", "micro s", "macro el", "macro s",
           "micro/ma", "stress micro vs macro");
}

/* The explicit-barbule cell (data/layout_barbules.json) under refinement, linear against quadratic
 * elements: E_yy's error against the quadratic result at e-bar 1/128. The corners where barbules
 * meet barbs make every order converge at about h^1, unevenly (the meshes are not nested): on
 * 2026-11-27 P2 gave 1.8445, 1.8399, 1.8368, 1.8355e7 Pa at e-bar 1/32 .. 1/256 (541k elements),
 * so the reference is about 0.07 % above the limit. */
static void barbule_cell_table(void)
{
    header_barbule_title();
    double t;
    long n;
    double limit = barbule_cell(2, 0.0078125, &t, &n);
    printf("reference %.6g Pa (%ld elements, %.2f s)\n", limit, n, t);
    header_barbule_columns();
    const double e[5] = {0.5, 0.25, 0.125, 0.0625, 0.03125};
    for (int k = 0; k < 5; k++) {
        double t1, t2;
        long n1, n2;
        double e1 = barbule_cell(1, e[k], &t1, &n1), e2 = barbule_cell(2, e[k], &t2, &n2);
        double r1 = (e1 - limit) / limit, r2 = (e2 - limit) / limit;
        printf("%8.4g | %8ld | %10.5g %7.2f%% %9.2f | %10.5g %7.2f%% %9.2f | %.1f\n", e[k], n1, e1, 100.0 * r1, 1e3 * t1, e2,
               100.0 * r2, 1e3 * t2, r1 / r2);
    }
    for (int k = 0; k < 2; k++) { /* what P1 needs for the 1 % P2 gets by default */
        double e1 = k == 0 ? 0.015625 : 0.0078125, t1;
        long n1;
        double v = barbule_cell(1, e1, &t1, &n1);
        printf("%8.4g | %8ld | %10.5g %7.2f%% %9.2f |\n", e1, n1, v, 100.0 * (v - limit) / limit, 1e3 * t1);
    }
}

/* Figure 10's tilted specimen at d-bar_B 0.086: linear against quadratic elements, cost against
 * error, the error against the quadratic run at e-bar 0.725 (within 0.05 % of its own limit). */
static void specimen_table(void)
{
    header_specimen_title();
    plume_layout l;
    plume_layout_default(&l);
    l.d_B = 0.086 * 1.3, l.h = 1.0;
    double ref = NAN;
    long nref = 0;
    l.order = 2, l.e_rel = 0.725;
    double tref = micro_run(&l, &ref, &nref);
    printf("reference %.6g Pa (%ld elements, %.2f s)\n", ref, nref / 4, tref);
    header_specimen_columns();
    const double e[3] = {2.9, 1.45, 0.725};
    for (int o = 1; o <= 2; o++)
        for (int k = 0; k < (o == 1 ? 3 : 2); k++) {
            double s = NAN;
            long nm = 0;
            l.order = o, l.e_rel = e[k];
            double tm = micro_run(&l, &s, &nm);
            printf("%5d %6.3g | %8ld %9.3f %9.5g %7.2f%%\n", o, e[k], o == 2 ? nm / 4 : nm, tm, s, 100.0 * (s - ref) / ref);
        }
    l.order = 2, l.e_rel = 0.0;
    double s = NAN;
    long nm = 0;
    double tm = micro_run(&l, &s, &nm);
    printf("%5d %6s | %8ld %9.3f %9.5g %7.2f%%   (the default: automatic edge %.3g w_B)\n", 2, "auto", nm / 4, tm, s,
           100.0 * (s - ref) / ref, plume_layout_element_edge(&l, PLUME_MESH_SPECIMEN) / plume_layout_barb_width(&l));
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--header")) {
        header_homogenisation();
        header_barbule_title();
        header_barbule_columns();
        header_specimen_title();
        header_specimen_columns();
        header_micro_macro();
        return 0;
    }
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    header_homogenisation();
    plume_layout l;
    const double erel[3] = {1.0, 0.5, 0.25};
    for (int k = 0; k < 3; k++) {
        plume_layout_default(&l);
        l.e_rel = erel[k];
        char name[64];
        snprintf(name, sizeof name, "strips, e-bar %.2g", erel[k]);
        homogenisation_row(name, &l);
    }
    plume_layout_default(&l);
    homogenisation_row("strips, automatic", &l);
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES;
    l.ratio = 1.0;
    l.phi = 0.3;
    l.barbule_width = 1e-4;
    l.barbule_spacing = 8e-4;
    l.order = 1, l.e_rel = 0.5;
    homogenisation_row("explicit barbules, P1 0.5", &l);
    l.order = 2, l.e_rel = 0.0;
    homogenisation_row("explicit barbules, P2 auto", &l);
    barbule_cell_table();
    specimen_table();

    header_micro_macro();
    plume_layout_default(&l);
    plume_homog_opts ho;
    plume_homog_opts_default(&ho);
    ho.strain_max = 0.0;
    plume_homog_result hr;
    plume_err err = {{0}};
    if (plume_homogenize(&l, &ho, &hr, &err) != PLUME_OK) {
        printf("homogenisation failed: %s\n", err.msg);
        return 1;
    }
    double sM = NAN;
    long nM = 0;
    double tM = macro_run(&hr.moduli, 0.02, &sM, &nM);
    const double dB[3] = {0.086, 0.043, 0.0215};
    for (int k = 0; k < 3; k++)
        for (int o = 1; o <= 2; o++) {
            plume_layout_default(&l);
            l.d_B = dB[k] * 1.3;
            l.order = o;
            l.e_rel = o == 1 ? 2.9 : 0.0; /* the paper's compromise; the automatic edge */
            l.h = 1.0;
            double sm = NAN;
            long nm = 0;
            double tm = micro_run(&l, &sm, &nm);
            printf("%7.4f %5.2g %s | %9ld %9.3f | %9ld %9.3f | %8.1f | %.5g vs %.5g Pa (%+.1f%%)\n", dB[k],
                   plume_layout_element_edge(&l, PLUME_MESH_SPECIMEN) / plume_layout_barb_width(&l), o == 1 ? "P1" : "P2",
                   o == 2 ? nm / 4 : nm, tm, nM, tM, tm / tM, sm, sM, 100.0 * (sm - sM) / sM);
        }
    plume_homog_result_free(&hr);
    return 0;
}
