/* plume example: macroscale moduli fitted to traction curves (include/plume/fit.h). The target is
 * the macro model's own curve at 60 degrees with G_xy = 1 Pa; the fit starts three times too low
 * and recovers it, as apps/fit does with measured curves.
 * Build against the installed library:
 *   cc -std=c11 fit.c $(pkg-config --cflags --libs plume) -lm -o fit */
#include <math.h>
#include <stdio.h>

#include <plume/plume.h>

int main(void)
{
    plume_openmp_serial();
    plume_err err = {{0}};
    const double angle = 60.0, lx = 1.0, ly = 1.3;
    plume_macro_model model = {.lx = lx, .ly = ly, .h = 1.0, .edge = plume_traction_default_edge(lx, ly),
                               .mesh = PLUME_PATCH_ALIGNED, .constraint = 1, .kappa = 0.0, .strain_max = 0.05,
                               .steps = 5, .ncurves = 1, .angles = &angle, .solver = PLUME_SOLVER_NEWTON};
    const plume_ortho truth = {.E_xx = 1e4, .E_yy = 1.0, .nu_xy = 0.0, .G_xy = 1.0};
    plume_curve target = {0};
    if (plume_macro_model_curve(&model, &truth, 0, &target, &err) != PLUME_OK) {
        fprintf(stderr, "fit: %s\n", err.msg);
        return 1;
    }
    plume_ortho start = truth, found;
    start.G_xy = truth.G_xy / 3.0;
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    o.free_mask = PLUME_FIT_GXY;
    plume_fit_report rep;
    plume_status st = plume_fit_moduli(plume_macro_model_curve, &model, &target, 1, &start, &o, &found, &rep, &err);
    plume_curve_free(&target);
    if (st != PLUME_OK) {
        fprintf(stderr, "fit: %s\n", err.msg);
        return 1;
    }
    printf("G_xy from %g Pa to %.6g Pa (target %g) in %d evaluations, misfit %.2g, stop: %s\n", start.G_xy, found.G_xy,
           truth.G_xy, rep.evaluations, rep.residual, rep.stop);
    const int ok = fabs(found.G_xy - truth.G_xy) < 1e-4 * truth.G_xy;
    printf("fit example: %s\n", ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}
