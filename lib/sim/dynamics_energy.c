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
    for (int k = 0; k < PLUME_LEDGER_LEVELS; k++) {
        free(l->level_x[k]);
        free(l->level_g[k]);
        l->level_x[k] = l->level_g[k] = NULL;
    }
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
    l->pieces = 0;
    l->started = 1;
    return PLUME_OK;
}

/* Simpson's rule on the piece from xa to xb (grad U ga, gb; U ua, ub there), halved while it and
 * the energies' change disagree: grad U at the midpoint into the level's buffers. A barrier's
 * gradient over a chord that enters its reach needs the halving: the drop test's bounce left
 * 5e-2 to one Simpson piece a step. A gradient that is not its energy's halves down to the last
 * level and keeps its error. Where grad U cannot be evaluated at a midpoint (a contact barrier's
 * domain), the trapezoidal rule, counted. */
static double piece(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in, const double *xa,
                    const double *ga, double ua, const double *xb, const double *gb, double ub, int level)
{
    double *x = plume_problem_x(p), um = 0.0, trap = 0.0;
    for (plume_index i = 0; i < l->ndof; i++)
        trap += 0.5 * (ga[i] + gb[i]) * (xb[i] - xa[i]);
    if (!l->level_x[level]) {
        l->level_x[level] = malloc((size_t)l->ndof * sizeof **l->level_x);
        l->level_g[level] = malloc((size_t)l->ndof * sizeof **l->level_g);
    }
    double *xm = l->level_x[level], *gm = l->level_g[level];
    int ok = xm && gm;
    if (ok) {
        for (plume_index i = 0; i < l->ndof; i++)
            x[i] = xm[i] = 0.5 * (xa[i] + xb[i]);
        ok = potential(p, NULL, in, &um, gm) == PLUME_OK && isfinite(um);
        for (plume_index i = 0; ok && i < l->ndof; i++)
            ok = isfinite(gm[i]);
    }
    if (!ok) {
        l->trapezoid_steps++;
        return trap;
    }
    l->pieces++;
    double S = 0.0;
    for (plume_index i = 0; i < l->ndof; i++)
        S += (ga[i] + 4.0 * gm[i] + gb[i]) / 6.0 * (xb[i] - xa[i]);
    const double dU = ub - ua;
    if (level + 1 == PLUME_LEDGER_LEVELS || l->budget < 2 ||
        fabs(S - dU) <= 1e-4 * (fabs(S) + fabs(dU)) + 1e-12 * (fabs(ua) + fabs(ub)))
        return S;
    l->budget -= 2;
    return piece(l, p, in, xa, ga, ua, xm, gm, um, level + 1) + piece(l, p, in, xm, gm, um, xb, gb, ub, level + 1);
}

/* grad U's integral along the segment from l->seg to the problem's x (the terms in their present
 * state), grad U and U at x into gend and *uend. A segment of no length is 0, gend the segment
 * start's. The problem's x is left as it was. */
static plume_status segment(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in, double *gend,
                            double *uend, double *integral)
{
    double *x = plume_problem_x(p);
    int moved = 0;
    for (plume_index i = 0; i < l->ndof && !moved; i++)
        moved = x[i] != l->seg[i];
    *integral = 0.0;
    if (!moved) {
        memcpy(gend, l->seg_grad, (size_t)l->ndof * sizeof *gend);
        *uend = l->seg_u;
        return PLUME_OK;
    }
    plume_status st = potential(p, NULL, in, uend, gend);
    if (st != PLUME_OK)
        return st;
    memcpy(l->xend, x, (size_t)l->ndof * sizeof *x);
    *integral = piece(l, p, in, l->seg, l->seg_grad, l->seg_u, l->xend, gend, *uend, 0);
    memcpy(x, l->xend, (size_t)l->ndof * sizeof *x);
    return PLUME_OK;
}

void plume_ledger_begin(plume_energy_ledger *l, const double *x0, const double *e0)
{
    memcpy(l->seg, x0, (size_t)l->nd * sizeof *l->seg);
    memcpy(l->seg + l->nd, e0, (size_t)(l->ndof - l->nd) * sizeof *l->seg);
    memcpy(l->seg_grad, l->grad, (size_t)l->ndof * sizeof *l->seg_grad);
    l->seg_u = l->u;
    l->path = 0.0;
    l->budget = PLUME_LEDGER_BUDGET;
}

plume_status plume_ledger_before_commit(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in)
{
    double integral, U;
    plume_status st = segment(l, p, in, l->end, &U, &integral);
    if (st != PLUME_OK)
        return st;
    l->path += integral;
    l->seg_u = U;
    memcpy(l->seg, plume_problem_x(p), (size_t)l->ndof * sizeof *l->seg);
    memcpy(l->seg_grad, l->end, (size_t)l->ndof * sizeof *l->seg_grad);
    return PLUME_OK;
}

plume_status plume_ledger_after_commit(plume_energy_ledger *l, plume_problem *p, const plume_ledger_inertia *in)
{
    return potential(p, NULL, in, &l->seg_u, l->seg_grad);
}

plume_status plume_ledger_step(plume_energy_ledger *l, plume_problem *p, const double *lambda,
                               const plume_ledger_inertia *in, const double *x0, const double *e0, const double *v0,
                               const double *v1, double commits)
{
    double integral, U1, Uend;
    plume_status st = segment(l, p, in, l->end, &Uend, &integral); /* end <- grad U(x') */
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
