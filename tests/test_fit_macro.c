/* The paper's protocol end to end: macroscale traction curves made with known moduli are given
 * to the fitter (NLopt) with the macroscale traction model, which must recover the moduli. */
#include <stdlib.h>

#include "harness.h"
#include "plume_tree.h"
#include "../macro/traction_model.h"
#include "../micro/fit.h"

void test_fit_macro_recovers_moduli(void)
{
    const double angles[2] = {45.0, 90.0};
    plume_macro_model mm = {1.0, 1.3, 1.0, 0.15, PLUME_PATCH_ALIGNED, 1, 0.0, 0.05, 3, 2, angles, PLUME_SOLVER_NEWTON};
    const plume_ortho truth = {1e4, 1.3, 0.0, 0.7};
    plume_curve targets[2] = {{0}};
    plume_err err = {{0}};
    for (int i = 0; i < 2; i++)
        CHECK(plume_macro_model_curve(&mm, &truth, i, &targets[i], &err) == PLUME_OK);
    const plume_ortho start = {1e4, 1.0, 0.0, 1.0};
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    o.xtol_rel = 1e-8;
    plume_ortho fit;
    plume_fit_report rep;
    CHECK(plume_fit_moduli(plume_macro_model_curve, &mm, targets, 2, &start, &o, &fit, &rep, &err) == PLUME_OK);
    fprintf(stderr, "    fit: E_yy %.8g (true 1.3), G_xy %.8g (true 0.7), %d evaluations, residual %.2g, %s\n",
            fit.E_yy, fit.G_xy, rep.evaluations, rep.residual, rep.stop);
    CHECK_REL(fit.E_yy, truth.E_yy, 1e-5, 0.0);
    CHECK_REL(fit.G_xy, truth.G_xy, 1e-5, 0.0);
    CHECK(fit.E_xx == truth.E_xx); /* not free: the barbs are inextensible */
    CHECK(rep.residual < 1e-6);
    for (int i = 0; i < 2; i++)
        plume_curve_free(&targets[i]);
}
