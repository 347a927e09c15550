/* One linear solve with the native solver's Newton/KKT matrix and a right-hand side given by the
 * caller (lib/solve/predict.h): the tangent predictor's solve. It borrows the solver's
 * factorisation and workspaces between solves (every solve starts afresh: plume_newton_solve
 * resets the chord state, the trust-region shift and the refinement tolerance). */
#include <string.h>

#include "internal/newton_state.h"
#include "predict.h"

plume_status plume_newton_linear_step(plume_newton *s, const double *u, const double *lambda, const double *r,
                                      const double *c, double *du, double *lambda_out)
{
    if (!s || !u || !r || !du || (s->m > 0 && (!lambda || !c)))
        return PLUME_EINVAL;
    plume_index n = s->n, m = s->m;
    plume_status st = PLUME_OK;
    if (m > 0 && (st = plume_problem_jacobian(s->p, u, s->jval)) != PLUME_OK)
        return st;
    memcpy(s->grad, r, (size_t)n * sizeof *s->grad);
    if (m > 0)
        memcpy(s->g, c, (size_t)m * sizeof *s->g);
    const double sigma = s->tr_sigma, rtol = s->refine_rtol;
    s->tr_sigma = 0.0;
    s->refine_rtol = 1e-12; /* a predictor is worth its digits: refinement passes cost solves, not factorisations */
    s->factor_valid = 0;    /* this factorisation is not of a solve's iterate */
    double step_max = 0.0;
    st = plume_newton_direction(s, u, lambda, &step_max);
    s->tr_sigma = sigma;
    s->refine_rtol = rtol;
    if (st != PLUME_OK)
        return st;
    memcpy(du, s->sol, (size_t)n * sizeof *du);
    if (m > 0 && lambda_out)
        memcpy(lambda_out, s->sol + n, (size_t)m * sizeof *lambda_out);
    return PLUME_OK;
}
