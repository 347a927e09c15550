/* Paper Figure 6 as an assertion: the penalty model's conditioning grows with the stiffness
 * ratio, the constrained model's does not. */
#include <math.h>

#include "harness.h"
#include "../lib/core/membrane.h"
#include "../lib/core/mesh.h"
#include "../drivers/stability.h"
#include <stdlib.h>
#include <string.h>

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
        CHECK(plume_stability_compression(kappa[k], 0, 0.3, 30, &jmin[k], &jmax[k], &conv[k], &it[k], &err) == PLUME_OK);
        fprintf(stderr, "    kappa %g: J in [%.3f, %.3f], converged %d, %d iterations\n", kappa[k], jmin[k], jmax[k], conv[k],
                it[k]);
        CHECK(conv[k]);
    }
    CHECK(jmin[0] < 0.0 && jmax[0] > 1.0); /* collapse: inverted elements let others stretch */
    CHECK(jmin[1] > 0.3);                   /* the compression term keeps every element open */
}

/* The log-barrier compression term: gradient and Hessian against central differences on a
 * compressed pair of triangles (J < 1). */
void test_stability_log_barrier_fd(void)
{
    plume_mesh *m = NULL;
    CHECK(plume_mesh_create(4, 2, 2, &m, NULL) == PLUME_OK);
    const double X[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    const plume_index tri[6] = {0, 1, 2, 0, 2, 3};
    memcpy(m->X, X, sizeof X);
    memcpy(m->tri, tri, sizeof tri);
    const double x0[8] = {0.02, -0.01, 0.71, 0.03, 0.66, 0.58, -0.03, 0.62}; /* J about 0.4 */
    plume_membrane_material mat = {{3.0, 1.0, 0.2, 0.7}, 0.1, 50.0, 1};
    plume_term t;
    plume_err err = {{0}};
    CHECK(plume_membrane_term_create(m, 2, &mat, 1, &t, &err) == PLUME_OK);
    double x[8], g[8] = {0}, H[72], e0 = 0.0;
    memcpy(x, x0, sizeof x);
    CHECK(t.eval(t.ctx, 2, x, &e0, g, H, 0) == PLUME_OK);
    double h = 1e-6, gmax = 0.0, gerr = 0.0, herr = 0.0, hmax = 0.0;
    for (int i = 0; i < 8; i++) {
        double ep = 0.0, em = 0.0, gp[8] = {0}, gm[8] = {0};
        x[i] = x0[i] + h;
        t.eval(t.ctx, 2, x, &ep, gp, NULL, 0);
        x[i] = x0[i] - h;
        t.eval(t.ctx, 2, x, &em, gm, NULL, 0);
        x[i] = x0[i];
        gerr = fmax(gerr, fabs((ep - em) / (2 * h) - g[i]));
        gmax = fmax(gmax, fabs(g[i]));
        /* assembled Hessian column i from the two triangle blocks */
        for (int j = 0; j < 8; j++) {
            double Hij = 0.0;
            for (int s = 0; s < 2; s++)
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++)
                        for (int ca = 0; ca < 2; ca++)
                            for (int cb = 0; cb < 2; cb++)
                                if (2 * tri[3 * s + a] + ca == j && 2 * tri[3 * s + b] + cb == i)
                                    Hij += H[36 * s + (2 * a + ca) * 6 + 2 * b + cb];
            herr = fmax(herr, fabs((gp[j] - gm[j]) / (2 * h) - Hij));
            hmax = fmax(hmax, fabs(Hij));
        }
    }
    CHECK(gerr <= 1e-6 * gmax);
    CHECK(herr <= 1e-5 * hmax);
    t.destroy(t.ctx);
    plume_mesh_destroy(&m);
}

/* Supplementary §8: with a log barrier in place of the cubic term, the compressed strip keeps its
 * elements open too; the study reports whether the solver converges and at what cost. */
void test_stability_log_barrier_compression(void)
{
    plume_err err = {{0}};
    double jmin = 0, jmax = 0;
    int conv = 0, it = 0;
    CHECK(plume_stability_compression(1000.0, 1, 0.3, 30, &jmin, &jmax, &conv, &it, &err) == PLUME_OK);
    fprintf(stderr, "    log barrier: J in [%.3f, %.3f], converged %d, %d iterations\n", jmin, jmax, conv, it);
    CHECK(!conv || jmin > 0.0); /* converged states never collapse: the barrier is infinite at J = 0 */
}
