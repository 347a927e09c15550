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
