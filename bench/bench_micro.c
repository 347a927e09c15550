/* make bench (second part) — the cost of the microscale: a homogenisation (small-strain tensor,
 * then tensor + cell curves) and micro against macro traction runs of the same scenario, with
 * element counts, times and their ratio. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/plume.h"
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
        plume_problem_create(mesh->nv, 2, 1.3, &p) != PLUME_OK || plume_vane_add(p, mesh, &v, &barbs, &nb, &err) != PLUME_OK)
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

int main(void)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    printf("\nplume bench (micro): homogenisation of a periodic cell (tensor: exact linear cell problem;\n"
           "curves: uniaxial along and across the barbs and simple shear to 5%%, 10 steps each)\n");
    printf("%-28s | %8s | %10s | %12s | %8s |\n", "layout", "elements", "tensor ms", "+ curves ms", "Newton it");
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
    l.kind = PLUME_LAYOUT_BARBULES;
    l.ratio = 1.0;
    l.phi = 0.3;
    l.barbule_width = 1e-4;
    l.barbule_spacing = 8e-4;
    l.e_rel = 0.5;
    homogenisation_row("explicit barbules, e-bar 0.5", &l);

    printf("\nMicro (resolved barbs, Figure 10 setting) against macro (homogenised moduli, barbs inextensible,\n"
           "aligned mesh, edge 0.02) on the same tilted 45 deg traction to 5%% strain in 5 steps:\n");
    printf("%7s %5s | %9s %9s | %9s %9s | %8s | %s\n", "d-bar_B", "e-bar", "micro el", "micro s", "macro el", "macro s",
           "micro/ma", "stress micro vs macro");
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
    const double dB[3] = {0.086, 0.043, 0.0215}, e[3] = {2.9, 2.9, 2.9};
    for (int k = 0; k < 3; k++) {
        plume_layout_default(&l);
        l.d_B = dB[k] * 1.3;
        l.e_rel = e[k];
        l.h = 1.0;
        double sm = NAN;
        long nm = 0;
        double tm = micro_run(&l, &sm, &nm);
        printf("%7.4f %5.2g | %9ld %9.3f | %9ld %9.3f | %8.1f | %.5g vs %.5g Pa (%+.1f%%)\n", dB[k], e[k], nm, tm, nM,
               tM, tm / tM, sm, sM, 100.0 * (sm - sM) / sM);
    }
    plume_homog_result_free(&hr);
    return 0;
}
