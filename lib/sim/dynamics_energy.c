/* The energy ledger of the implicit Euler stepper (dynamics_energy.h has the derivation). */
#include "dynamics_energy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

plume_status plume_ledger_alloc(plume_energy_ledger *l, plume_index nv, plume_index ndof)
{
    memset(l, 0, sizeof *l);
    l->nd = 3 * nv;
    l->grad = calloc((size_t)ndof, sizeof *l->grad); /* the forces cover every unknown */
    l->force = calloc((size_t)ndof, sizeof *l->force);
    return l->grad && l->force ? PLUME_OK : PLUME_ENOMEM;
}

void plume_ledger_free(plume_energy_ledger *l)
{
    free(l->grad);
    free(l->force);
    l->grad = l->force = NULL;
}

/* U and grad U (into grad) at the problem's x: the problem's energy and forces less the inertia's
 * quadratic part (gravity stays: the inertia term carries it) */
static plume_status potential(plume_problem *p, const double *lambda, const plume_ledger_inertia *in, double *U,
                              double *grad)
{
    double f = 0.0;
    plume_status st = plume_problem_energy_forces(p, plume_problem_ncons(p) ? lambda : NULL, &f, grad);
    if (st != PLUME_OK)
        return st;
    const double *x = plume_problem_x(p);
    double q = 0.0;
    for (plume_index v = 0; v < in->nv; v++)
        for (int a = 0; a < 3; a++) {
            const double d = x[3 * v + a] - in->xt[3 * v + a], k = in->mass[v] * in->inv_dt2;
            q += 0.5 * k * d * d;
            grad[3 * v + a] -= k * d;
        }
    *U = f - q;
    return PLUME_OK;
}

static double kinetic(const plume_ledger_inertia *in, const double *v)
{
    double ke = 0.0;
    for (plume_index i = 0; i < in->nv; i++)
        ke += 0.5 * in->mass[i] * (v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2]);
    return ke;
}

plume_status plume_ledger_start(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                                const plume_ledger_inertia *in, const double *v)
{
    plume_status st = potential(p, lambda, in, &l->u0, l->grad);
    if (st != PLUME_OK)
        return st;
    l->u = l->u0;
    l->ke = l->ke0 = kinetic(in, v);
    l->work = l->gross_work = l->numerical = l->commits = l->peak_change = 0.0;
    l->started = 1;
    return PLUME_OK;
}

plume_status plume_ledger_step(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                               const plume_ledger_inertia *in, const double *x0, const double *v0, const double *v1,
                               double commits)
{
    double U1;
    plume_status st = potential(p, lambda, in, &U1, l->force); /* force <- grad U(x') */
    if (st != PLUME_OK)
        return st;
    const double *x1 = plume_problem_x(p);
    double work = 0.0, jump = 0.0, curvature = 0.0;
    for (plume_index i = 0; i < l->nd; i++) {
        const double dx = x1[i] - x0[i], dv = v1[i] - v0[i];
        if (plume_problem_is_fixed(p, i)) /* the handle supplies what the inertia and the potential take */
            work += (l->force[i] + in->mass[i / 3] * in->inv_dt2 * (x1[i] - in->xt[i])) * dx;
        jump += 0.5 * in->mass[i / 3] * dv * dv;
        curvature += 0.5 * (l->force[i] - l->grad[i]) * dx;
    }
    l->work += work;
    l->gross_work += fabs(work);
    l->numerical += jump + curvature;
    l->commits += commits;
    l->u = U1;
    l->ke = kinetic(in, v1);
    l->peak_change = fmax(l->peak_change, fabs(l->ke - l->ke0) + fabs(l->u - l->u0));
    double *t = l->grad;
    l->grad = l->force, l->force = t;
    return PLUME_OK;
}

double plume_ledger_error(const plume_energy_ledger *l)
{
    const double scale = fmax(l->gross_work, l->peak_change);
    if (!(scale > 0.0))
        return 0.0;
    return (l->work - (l->ke - l->ke0) - (l->u - l->u0) - l->numerical - l->commits) / scale;
}
