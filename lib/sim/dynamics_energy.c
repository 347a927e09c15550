/* The energy ledger of the implicit Euler stepper (dynamics_energy.h has the derivation). */
#include "dynamics_energy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

plume_status plume_ledger_alloc(plume_energy_ledger *l, plume_index nv, plume_index ndof)
{
    memset(l, 0, sizeof *l);
    l->nd = 3 * nv;
    l->ndof = ndof;
    l->grad = calloc((size_t)ndof, sizeof *l->grad); /* the forces cover every unknown */
    l->force = calloc((size_t)ndof, sizeof *l->force);
    l->mid = calloc((size_t)ndof, sizeof *l->mid);
    l->xend = calloc((size_t)ndof, sizeof *l->xend);
    l->end = calloc((size_t)ndof, sizeof *l->end);
    l->seg = calloc((size_t)ndof, sizeof *l->seg);
    l->seg_grad = calloc((size_t)ndof, sizeof *l->seg_grad);
    return l->grad && l->force && l->mid && l->xend && l->end && l->seg && l->seg_grad ? PLUME_OK : PLUME_ENOMEM;
}

void plume_ledger_free(plume_energy_ledger *l)
{
    free(l->grad);
    free(l->force);
    free(l->mid);
    free(l->xend);
    free(l->end);
    free(l->seg);
    free(l->seg_grad);
    l->grad = l->force = l->mid = l->xend = l->end = l->seg = l->seg_grad = NULL;
}

/* U and grad U (into grad) at the problem's x: the problem's energy and forces less the inertia's
 * quadratic part (gravity stays: the inertia term carries it); with lambda (not NULL) the
 * constraints' forces J^T lambda are added to grad U */
static plume_status potential(plume_problem *p, const double *lambda, const plume_ledger_inertia *in, double *U,
                              double *grad)
{
    double f = 0.0;
    plume_status st = plume_problem_energy_forces(p, lambda && plume_problem_ncons(p) ? lambda : NULL, &f, grad);
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

plume_status plume_ledger_start(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in,
                                const double *v)
{
    plume_status st = potential(p, NULL, in, &l->u0, l->grad);
    if (st != PLUME_OK)
        return st;
    l->u = l->u0;
    l->ke = l->ke0 = kinetic(in, v);
    l->work = l->gross_work = l->numerical = l->commits = l->peak_change = 0.0;
    l->trapezoid_steps = 0;
    l->started = 1;
    return PLUME_OK;
}

/* Simpson's integral of grad U along the segment from l->seg to the problem's x (the terms in their
 * present state), grad U at x into gend; the trapezoidal rule where grad U cannot be evaluated at the
 * midpoint (counted). A segment of no length is 0, gend the segment start's. The problem's x is
 * left as it was. */
static plume_status segment(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in, double *gend,
                            double *integral)
{
    double *x = plume_problem_x(p), U;
    int moved = 0;
    for (plume_index i = 0; i < l->ndof && !moved; i++)
        moved = x[i] != l->seg[i];
    *integral = 0.0;
    if (!moved) {
        memcpy(gend, l->seg_grad, (size_t)l->ndof * sizeof *gend);
        return PLUME_OK;
    }
    memcpy(l->xend, x, (size_t)l->ndof * sizeof *x);
    for (plume_index i = 0; i < l->ndof; i++)
        x[i] = 0.5 * (l->seg[i] + l->xend[i]);
    int simpson = potential(p, NULL, in, &U, l->mid) == PLUME_OK && isfinite(U);
    for (plume_index i = 0; simpson && i < l->ndof; i++)
        simpson = isfinite(l->mid[i]);
    memcpy(x, l->xend, (size_t)l->ndof * sizeof *x);
    plume_status st = potential(p, NULL, in, &U, gend);
    if (st != PLUME_OK)
        return st;
    double sum = 0.0;
    for (plume_index i = 0; i < l->ndof; i++)
        sum += (simpson ? (l->seg_grad[i] + 4.0 * l->mid[i] + gend[i]) / 6.0 : 0.5 * (l->seg_grad[i] + gend[i])) *
               (x[i] - l->seg[i]);
    *integral = sum;
    l->trapezoid_steps += !simpson;
    return PLUME_OK;
}

void plume_ledger_begin(plume_energy_ledger *l, const double *x0, const double *e0)
{
    memcpy(l->seg, x0, (size_t)l->nd * sizeof *l->seg);
    memcpy(l->seg + l->nd, e0, (size_t)(l->ndof - l->nd) * sizeof *l->seg);
    memcpy(l->seg_grad, l->grad, (size_t)l->ndof * sizeof *l->seg_grad);
    l->path = 0.0;
}

plume_status plume_ledger_before_commit(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in)
{
    double integral;
    plume_status st = segment(l, p, in, l->end, &integral);
    if (st != PLUME_OK)
        return st;
    l->path += integral;
    memcpy(l->seg, plume_problem_x(p), (size_t)l->ndof * sizeof *l->seg);
    memcpy(l->seg_grad, l->end, (size_t)l->ndof * sizeof *l->seg_grad);
    return PLUME_OK;
}

plume_status plume_ledger_after_commit(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in)
{
    double U;
    return potential(p, NULL, in, &U, l->seg_grad);
}

plume_status plume_ledger_step(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                               const plume_ledger_inertia *in, const double *x0, const double *e0, const double *v0,
                               const double *v1, double commits)
{
    double integral, U1;
    plume_status st = segment(l, p, in, l->end, &integral); /* end <- grad U(x') */
    if (st == PLUME_OK) /* force <- grad U(x') + J^T lambda, the last evaluation */
        st = potential(p, lambda, in, &U1, l->force);
    if (st != PLUME_OK)
        return st;
    l->path += integral;
    const double *x1 = plume_problem_x(p);
    double work = 0.0, jump = 0.0, curvature = -l->path;
    for (plume_index i = 0; i < l->ndof; i++) {
        const double dx = x1[i] - (i < l->nd ? x0[i] : e0[i - l->nd]);
        /* the step's forces along its chord, less grad U's integral along the step's segments: the
         * constraints' forces are the multipliers' at x', whose work along the chord is the
         * method's too */
        curvature += l->force[i] * dx;
        if (i >= l->nd)
            continue; /* the extras carry no mass and no handle */
        const double dv = v1[i] - v0[i];
        if (plume_problem_is_fixed(p, i)) /* the handle supplies what the inertia and the potential take */
            work += (l->force[i] + in->mass[i / 3] * in->inv_dt2 * (x1[i] - in->xt[i])) * dx;
        jump += 0.5 * in->mass[i / 3] * dv * dv;
    }
    l->work += work;
    l->gross_work += fabs(work);
    l->numerical += jump + curvature;
    l->commits += commits;
    l->u = U1;
    l->ke = kinetic(in, v1);
    l->peak_change = fmax(l->peak_change, fabs(l->ke - l->ke0) + fabs(l->u - l->u0));
    double *t = l->grad;
    l->grad = l->end, l->end = t;
    return PLUME_OK;
}

double plume_ledger_error(const plume_energy_ledger *l)
{
    const double scale = fmax(l->gross_work, l->peak_change);
    if (!(scale > 0.0))
        return 0.0;
    return (l->work - (l->ke - l->ke0) - (l->u - l->u0) - l->numerical - l->commits) / scale;
}
