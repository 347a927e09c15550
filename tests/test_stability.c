/* Paper Figure 6 as an assertion: the penalty model's conditioning grows with the stiffness
 * ratio, the constrained model's does not. */
#include <math.h>

#include "harness.h"
#include "../macro/stability.h"

void test_stability_penalty_conditioning(void)
{
    double pen[3], con[3];
    const double ratio[3] = {1.0, 1e2, 1e4};
    plume_err err = {{0}};
    for (int k = 0; k < 3; k++) {
        CHECK(plume_stability_condition(ratio[k], 0.1, 0, &pen[k], &err) == PLUME_OK);
        CHECK(plume_stability_condition(ratio[k], 0.1, 1, &con[k], &err) == PLUME_OK);
        fprintf(stderr, "    E_xx/E_yy %g: condition estimate penalty %.3g, constrained %.3g\n", ratio[k], pen[k], con[k]);
    }
    CHECK(pen[1] > 3.0 * pen[0] && pen[2] > 30.0 * pen[1]); /* grows about linearly with the ratio */
    CHECK_REL(con[2], con[0], 1e-12, 0.0);                  /* independent of the ratio */
    CHECK(plume_stability_condition(0.5, 0.1, 0, &pen[0], &err) == PLUME_EINVAL);
}

/* Supplementary Figure 7 as an assertion: compressed to 30% of its length, a plain St Venant-
 * Kirchhoff strip collapses (some elements invert, others stretch); with the compression term
 * every element stays open. Both runs converge. */
void test_stability_compression_collapse(void)
{
    plume_err err = {{0}};
    double jmin[2], jmax[2];
    int conv[2], it[2];
    const double kappa[2] = {0.0, 1000.0};
    for (int k = 0; k < 2; k++) {
        CHECK(plume_stability_compression(kappa[k], 0.3, 30, &jmin[k], &jmax[k], &conv[k], &it[k], &err) == PLUME_OK);
        fprintf(stderr, "    kappa %g: J in [%.3f, %.3f], converged %d, %d iterations\n", kappa[k], jmin[k], jmax[k], conv[k],
                it[k]);
        CHECK(conv[k]);
    }
    CHECK(jmin[0] < 0.0 && jmax[0] > 1.0); /* collapse: inverted elements let others stretch */
    CHECK(jmin[1] > 0.3);                   /* the compression term keeps every element open */
}
