#include "homogenize.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/membrane.h"
#include "../lib/core/opts.h"
#include "../lib/solve/options.h"
#include "../lib/io/progress.h"
#include "cell_linear.h"
#include "periodic.h"

void plume_homog_opts_default_sized(plume_homog_opts *o, size_t size)
{
    static const plume_homog_opts full = {.size = sizeof full,
                                          .strain_max = 0.05,
                                          .steps = 10,
                                          .convergence = 1};
    plume_opts_give(o, size, &full, sizeof full);
}

void plume_homog_result_free(plume_homog_result *r)
{
    if (!r)
        return;
    plume_curve_free(&r->uniaxial_x);
    plume_curve_free(&r->uniaxial_y);
    plume_curve_free(&r->shear);
}

/* A periodic cell problem: the membrane over the cell wrapped periodically, non-master vertices
 * and one anchor vertex fixed, a native solver, and the state of the last solve. */
typedef struct {
    const plume_cell *cell;
    plume_problem *p;
    plume_solver *s;
    plume_periodic *per;
    double *u, *grad;
    double Fprev[4];
    double h;
    double lateral_tol; /* relative free stress accepted as zero in the stress-controlled tests */
    double stress_floor; /* absolute free stress (Pa) accepted as zero: round-off of the stiff phase */
    int iterations;
} cell_solver;

static void cell_solver_free(cell_solver *c)
{
    plume_solver_destroy(&c->s);
    plume_problem_destroy(&c->p);
    free(c->u);
    free(c->grad);
}

static plume_status cell_solver_init(cell_solver *c, const plume_cell *cell, const plume_membrane_material *mats,
                                     int nmat, double h_ref, const plume_solver_opts *so, plume_err *err)
{
    memset(c, 0, sizeof *c);
    c->cell = cell;
    c->h = h_ref; /* nominal stresses are the membrane's over the reference thickness */
    c->Fprev[0] = c->Fprev[3] = 1.0;
    const plume_mesh *m = cell->mesh;
    plume_term membrane, wrapped;
    plume_status st = plume_micro_membrane_term(m, cell->order == 2 ? &cell->quad : NULL, mats, nmat, &membrane, err);
    if (st != PLUME_OK)
        return st;
    if ((st = plume_periodic_term_create(cell, &membrane, &c->per, &wrapped, err)) != PLUME_OK)
        return st;
    if ((st = plume_problem_create(m->nv, 2, fmax(cell->a, cell->b), &c->p, err)) != PLUME_OK) {
        wrapped.destroy(wrapped.ctx);
        return st;
    }
    if ((st = plume_problem_add_term(c->p, &wrapped, err)) != PLUME_OK)
        return st;
    plume_periodic_hold(cell, c->p, err);
    if ((st = plume_problem_finalize(c->p, err)) != PLUME_OK)
        return st;
    plume_err why;
    if ((st = plume_solver_create(PLUME_SOLVER_NEWTON, c->p, so, &c->s, &why)) != PLUME_OK)
        return plume_err_set(err, st, "homogenize: cannot create the cell solver: %s", why.msg);
    plume_index n = plume_problem_nfree(c->p);
    c->u = malloc((size_t)n * sizeof *c->u);
    c->grad = malloc((size_t)n * sizeof *c->grad);
    if (!c->u || !c->grad)
        return PLUME_ENOMEM;
    return PLUME_OK;
}

/* Solves the cell at macroscopic gradient F (predictor: the previous fluctuation on the new
 * affine map) and returns the average first Piola stress over the thickness (Pa). */
static plume_status cell_solve(cell_solver *c, const double F[4], double P[4], const char *what, plume_err *err)
{
    const plume_mesh *m = c->cell->mesh;
    double *x = plume_problem_x(c->p);
    const double *G = c->Fprev;
    for (plume_index v = 0; v < m->nv; v++) {
        if (c->cell->master[v] != v)
            continue;
        const double *X = m->X + 2 * v;
        double wx = x[2 * v] - (G[0] * X[0] + G[1] * X[1]), wy = x[2 * v + 1] - (G[2] * X[0] + G[3] * X[1]);
        x[2 * v] = F[0] * X[0] + F[1] * X[1] + wx;
        x[2 * v + 1] = F[2] * X[0] + F[3] * X[1] + wy;
    }
    memcpy(c->Fprev, F, sizeof c->Fprev);
    plume_periodic_set_macro(c->per, F);
    plume_problem_gather(c->p, c->u);
    plume_solve_report rep;
    plume_status st = plume_solver_solve(c->s, c->u, NULL, &rep);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "homogenize: %s: solver error (%s)", what, plume_strerror(st));
    c->iterations += rep.iterations;
    if (!rep.converged)
        return plume_err_set(err, PLUME_EINFEASIBLE, "homogenize: %s: the cell did not converge (%s after %d iterations)",
                             what, plume_reason_name(rep.reason), rep.iterations);
    double f;
    if ((st = plume_problem_objective(c->p, c->u, &f, c->grad)) != PLUME_OK)
        return st;
    plume_periodic_average_stress(c->per, P);
    for (int k = 0; k < 4; k++)
        P[k] /= c->h;
    return PLUME_OK;
}

plume_status plume_ortho_from_tensor(const double C[9], plume_ortho *m, plume_err *err)
{
    if (!C || !m)
        return plume_err_set(err, PLUME_EINVAL, "moduli from a tensor: the tensor and the output are required");
    double det = C[0] * (C[4] * C[8] - C[5] * C[7]) - C[1] * (C[3] * C[8] - C[5] * C[6]) +
                 C[2] * (C[3] * C[7] - C[4] * C[6]);
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return plume_err_set(err, PLUME_ESINGULAR,
                             "moduli from a tensor: the tensor is singular or not finite (determinant %g): a phase "
                             "with no stiffness?", det);
    double S11 = (C[4] * C[8] - C[5] * C[7]) / det, S22 = (C[0] * C[8] - C[2] * C[6]) / det;
    double S33 = (C[0] * C[4] - C[1] * C[3]) / det, S12 = -(C[1] * C[8] - C[2] * C[7]) / det;
    m->E_xx = 1.0 / S11;
    m->E_yy = 1.0 / S22;
    m->G_xy = 1.0 / S33;
    m->nu_xy = -S12 / S11;
    if (!(m->E_xx > 0 && m->E_yy > 0 && m->G_xy > 0))
        return plume_err_set(err, PLUME_ESINGULAR,
                             "moduli from a tensor: the tensor is not positive definite (E_xx %g, E_yy %g, G_xy %g)",
                             m->E_xx, m->E_yy, m->G_xy);
    return PLUME_OK;
}

/* The convergence estimate (plume_homog_result): the tensor of the cell meshed at twice the element
 * edge, or half of it when the layout refuses the coarser mesh. */
static plume_status refinement_estimate(const plume_layout *l, const plume_membrane_material *mats,
                                        plume_homog_result *r, plume_err *err)
{
    plume_layout lc;
    plume_layout_refinement(l, PLUME_MESH_CELL, &lc);
    plume_cell *cell = NULL;
    double C[9], D[9];
    plume_status st = plume_cell_mesh(&lc, &cell, err);
    if (st == PLUME_OK)
        st = plume_cell_linear_tensor(cell, mats, 2, l->h, C, NULL, err);
    if (st == PLUME_OK && plume_cell_plate_tensor(cell, mats, 2, D, NULL, err) == PLUME_OK) {
        r->bending_change = 0.0;
        for (int k = 0; k < 3; k++)
            r->bending_change = fmax(r->bending_change, fabs(r->D[4 * k] - D[4 * k]) / r->D[4 * k]);
    }
    plume_cell_destroy(&cell);
    plume_ortho m;
    if (st != PLUME_OK || plume_ortho_from_tensor(C, &m, err) != PLUME_OK) {
        /* no estimate is not a failure of the homogenisation itself */
        r->refinement_change = -1.0;
        return PLUME_OK;
    }
    r->refinement_edge = plume_layout_element_edge(&lc, PLUME_MESH_CELL);
    double change = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            change = fmax(change, fabs(r->C[3 * i + j] - C[3 * i + j]) / sqrt(r->C[4 * i] * r->C[4 * j]));
    const double a[4] = {r->moduli.E_xx, r->moduli.E_yy, r->moduli.nu_xy, r->moduli.G_xy};
    const double b[4] = {m.E_xx, m.E_yy, m.nu_xy, m.G_xy};
    for (int k = 0; k < 4; k++) {
        r->moduli_change[k] = fabs(a[k] - b[k]) / fmax(fabs(a[k]), DBL_MIN);
        if (k != 2) /* a small nu_xy's relative change says little: the tensor's measure covers it */
            change = fmax(change, r->moduli_change[k]);
    }
    r->refinement_change = change;
    return PLUME_OK;
}

static plume_status check_opts(const plume_homog_opts *o, plume_err *err)
{
    if (!(o->strain_max >= 0.0 && o->strain_max < 1.0))
        return plume_err_set(err, PLUME_EINVAL, "homogenize: plume_homog_opts.strain_max must be in [0, 1) (got %g)", o->strain_max);
    if (o->strain_max > 0.0 && o->steps < 1)
        return plume_err_set(err, PLUME_EINVAL, "homogenize: plume_homog_opts.steps must be >= 1 (got %d)", o->steps);
    return PLUME_OK;
}

static plume_status alloc_curve(plume_curve *cv, int n)
{
    cv->n = n;
    cv->strain = calloc((size_t)n, sizeof(double));
    cv->stress = calloc((size_t)n, sizeof(double));
    cv->wbar = calloc((size_t)n, sizeof(double));
    cv->iterations = calloc((size_t)n, sizeof(double));
    cv->seconds = calloc((size_t)n, sizeof(double));
    return cv->strain && cv->stress && cv->wbar && cv->iterations && cv->seconds ? PLUME_OK : PLUME_ENOMEM;
}

/* o->on_state with the cell's current state: masters from the last solve, periodic images
 * x_master + Fbar (X_v - X_master) (the problem holds them at rest). */
static plume_status report_state(cell_solver *c, const plume_homog_opts *o, int load_case, int step, double strain,
                                 plume_err *err)
{
    if (!o->on_state)
        return PLUME_OK;
    const plume_cell *cell = c->cell;
    const plume_mesh *m = cell->mesh;
    const double *x = plume_problem_x(c->p), *F = c->Fprev;
    double *xs = malloc((size_t)(2 * m->nv + 1) * sizeof *xs);
    if (!xs)
        return plume_err_set(err, PLUME_ENOMEM, "homogenize: out of memory");
    for (plume_index v = 0; v < m->nv; v++) {
        const double *xm = x + 2 * cell->master[v], *sh = cell->shift + 2 * v;
        if (step == 0) /* the rest state */
            xs[2 * v] = m->X[2 * v], xs[2 * v + 1] = m->X[2 * v + 1];
        else
            xs[2 * v] = xm[0] + F[0] * sh[0] + F[1] * sh[1], xs[2 * v + 1] = xm[1] + F[2] * sh[0] + F[3] * sh[1];
    }
    plume_status st = o->on_state(o->on_state_user, load_case, step, strain, cell, xs);
    free(xs);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "homogenize: writing load case %d, step %d failed (%s)", load_case, step,
                             plume_strerror(st));
    return PLUME_OK;
}

/* The three load cases of the cell curves, each a stress-controlled test: one component of F
 * driven, two found so that their conjugate nominal stresses vanish, and the fourth held at zero to
 * remove the rigid rotation. Holding the shear (or, in shear, the stretches) fixed instead measures
 * C22 - C12^2 / C11 (or C66), not the compliance's 1/S22 (1/S66): for inclined barbules, whose
 * normal stresses and shear are strongly coupled (C26 / sqrt(C22 C66) = 0.95 for
 * data/layout_barbules.json), that was 11 times E_yy and G_xy. The rotation is fixed so that the
 * loaded fibre keeps its direction: uniaxial x F = [1+e g; 0 c] (P22 = P12 = 0), uniaxial y
 * F = [c 0; g 1+e] (P11 = P21 = 0), each then a Cauchy stress along the load; shear F = [a g; 0 c]
 * (P11 = P22 = 0). Indices: F and P row-major, free[] into F (and P), voigt[] their rows in C. */
typedef struct {
    int drive, free[2];     /* components of F (and of P) */
    int voigt_drive, voigt_free[2]; /* their Voigt indices (0: 11, 1: 22, 2: 12) */
    int wbar;               /* free[] entry whose strain is the curve's wbar, -1: none */
    const char *what;
} load_case;

static const load_case LOAD_CASES[3] = {
    {0, {3, 1}, 0, {1, 2}, 0, "uniaxial x at strain"},
    {3, {0, 2}, 1, {0, 2}, 0, "uniaxial y at strain"},
    {1, {0, 3}, 2, {0, 1}, -1, "shear at gamma"},
};

/* 2x2 solve J d = r, J row-major; 0 if singular */
static int solve2(const double J[4], const double r[2], double d[2])
{
    double det = J[0] * J[3] - J[1] * J[2];
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return 0;
    d[0] = (J[3] * r[0] - J[1] * r[1]) / det;
    d[1] = (J[0] * r[1] - J[2] * r[0]) / det;
    return 1;
}

/* One curve of load case `lc` (0 uniaxial x, 1 uniaxial y, 2 shear). The free components are found
 * by Broyden's method on the two stresses, from the linear tensor C (Pa) as the Jacobian and the
 * linear response as the first predictor: each step starts from the previous step's solution plus
 * its rate, so that near-linear curves take one or two cell solves a step. */
static plume_status stress_controlled_curve(cell_solver *c, int lc, const double C[9], const plume_homog_opts *o,
                                            plume_curve *cv, plume_err *err)
{
    plume_status st = alloc_curve(cv, o->steps + 1);
    if (st != PLUME_OK)
        return st;
    const load_case *L = &LOAD_CASES[lc];
    const double de = o->strain_max / o->steps;
    double J[4], z[2] = {0.0, 0.0}, rate[2], rhs[2];
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 2; j++)
            J[2 * i + j] = C[3 * L->voigt_free[i] + L->voigt_free[j]];
        rhs[i] = -C[3 * L->voigt_free[i] + L->voigt_drive];
    }
    if (!solve2(J, rhs, rate))
        return plume_err_set(err, PLUME_ESINGULAR, "homogenize: %s: the tensor's free block is singular", L->what);
    char what[64];
    if ((st = report_state(c, o, lc, 0, 0.0, err)) != PLUME_OK)
        return st;
    for (int k = 1; k <= o->steps; k++) {
        double eps = de * k, t0 = plume_wall_seconds();
        int it0 = c->iterations;
        double zk[2] = {z[0] + rate[0] * de, z[1] + rate[1] * de}, F[4], P[4], r[2] = {0, 0}, dz[2] = {0, 0};
        double drive = 0.0;
        snprintf(what, sizeof what, "%s %g", L->what, eps);
        int done = 0;
        for (int s = 0;; s++) {
            memcpy(F, (const double[4]){1.0, 0.0, 0.0, 1.0}, sizeof F);
            F[L->drive] += eps;
            for (int i = 0; i < 2; i++)
                F[L->free[i]] += zk[i];
            if ((st = cell_solve(c, F, P, what, err)) != PLUME_OK)
                return st;
            double rn[2] = {P[L->free[0]], P[L->free[1]]};
            if (s > 0) { /* Broyden's update from the last change */
                double dr[2] = {rn[0] - r[0], rn[1] - r[1]}, dd = dz[0] * dz[0] + dz[1] * dz[1];
                for (int i = 0; i < 2; i++) {
                    double u = dr[i] - (J[2 * i] * dz[0] + J[2 * i + 1] * dz[1]);
                    for (int j = 0; j < 2; j++)
                        J[2 * i + j] += u * dz[j] / dd;
                }
            }
            r[0] = rn[0], r[1] = rn[1];
            drive = fabs(P[L->drive]);
            double tol = fmax(c->lateral_tol * drive, c->stress_floor);
            if (fabs(r[0]) <= tol && fabs(r[1]) <= tol) {
                done = 1;
                break;
            }
            double mr[2] = {-r[0], -r[1]};
            if (s == 20 || !solve2(J, mr, dz))
                break;
            if (fabs(dz[0]) + fabs(dz[1]) <= 1e-14) { /* stalled at round-off: accept within 10 tol */
                done = fabs(r[0]) <= 10.0 * tol && fabs(r[1]) <= 10.0 * tol;
                break;
            }
            zk[0] += dz[0], zk[1] += dz[1];
        }
        if (!done)
            return plume_err_set(err, PLUME_EINFEASIBLE, "homogenize: %s: the free stresses did not vanish (%g, %g of %g)",
                                 what, r[0], r[1], drive);
        /* the state of the last solve is the accepted one */
        rate[0] = (zk[0] - z[0]) / de, rate[1] = (zk[1] - z[1]) / de;
        z[0] = zk[0], z[1] = zk[1];
        cv->strain[k] = eps;
        cv->stress[k] = P[L->drive];
        cv->wbar[k] = L->wbar >= 0 ? z[L->wbar] : 0.0;
        cv->iterations[k] = c->iterations - it0;
        cv->seconds[k] = plume_wall_seconds() - t0;
        if ((st = report_state(c, o, lc, k, eps, err)) != PLUME_OK)
            return st;
    }
    return PLUME_OK;
}

plume_status plume_homogenize(const plume_layout *l, const plume_homog_opts *given, plume_homog_result *r,
                              plume_err *err)
{
    if (!l || !given || !r)
        return plume_err_set(err, PLUME_EINVAL, "homogenize: invalid arguments");
    memset(r, 0, sizeof *r);
    plume_homog_opts full; /* the caller's options over this library's defaults */
    const plume_homog_opts *o = &full;
    plume_solver_opts so;
    plume_homog_opts_default(&full);
    if (plume_opts_take(&full, sizeof full, given, "plume_homog_opts", err) != PLUME_OK ||
        plume_solver_opts_take(&so, full.solver_opts, err) != PLUME_OK)
        return PLUME_EINVAL;
    double t0 = plume_wall_seconds();
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK || (st = check_opts(o, err)) != PLUME_OK)
        return st;
    plume_cell *cell = NULL;
    if ((st = plume_cell_mesh(l, &cell, err)) != PLUME_OK)
        return st;
    r->elements = plume_cell_elements(cell);
    r->order = cell->order;
    r->element_edge = plume_layout_element_edge(l, PLUME_MESH_CELL);
    r->vertices = cell->mesh->nv;
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    cell_solver c;
    /* Round-off of the stiff phase's Green strain (1e-16 E_b) is what a residual can reach; on
     * the soft phase's stresses (ratio E_b strain) that is 1e-16 / (ratio strain) relative, so
     * no tighter tolerance can be met at high contrast; with a margin of 100 for the sums over
     * elements: 1e-5 at ratio 1e-6 and 0.1% strain steps. */
    double contrast = fmin(l->ratio, 1.0 / l->ratio), step = o->steps > 0 ? o->strain_max / o->steps : 1.0;
    double lateral_tol = fmax(1e-10, 1e-14 / (contrast * fmax(step, 1e-12)));
    so.tol_kkt = fmax(so.tol_kkt, lateral_tol);
    if ((st = cell_solver_init(&c, cell, mats, 2, l->h, &so, err)) != PLUME_OK)
        goto done;
    c.lateral_tol = 10.0 * lateral_tol;
    /* The free stresses are sums of the stiff phase's stresses, whose round-off (1e-16 E h / h_ref
     * per element, some 1e-15 summed) does not shrink with the strain: at small drives (strains of
     * 1e-6, a soft direction) no relative tolerance can be met below it. Margin 100. */
    c.stress_floor = 0.0;
    for (int k = 0; k < 2; k++)
        c.stress_floor = fmax(c.stress_floor, 1e-13 * fmax(mats[k].moduli.E_xx, mats[k].moduli.E_yy) * mats[k].h / l->h);
    int lin_iterations = 0;
    if ((st = plume_cell_linear_tensor(cell, mats, 2, l->h, r->C, &lin_iterations, err)) != PLUME_OK)
        goto done;
    c.iterations += lin_iterations;
    if (plume_ortho_from_tensor(r->C, &r->moduli, err) != PLUME_OK) {
        st = plume_err_set(err, PLUME_ESINGULAR, "homogenize: the effective tensor is not positive definite");
        goto done;
    }
    r->coupling = fmax(fabs(r->C[2]), fabs(r->C[5])) / sqrt(r->C[0] * r->C[4]);
    plume_cell_plate_info pinfo;
    if ((st = plume_cell_plate_tensor(cell, mats, 2, r->D, &pinfo, err)) != PLUME_OK)
        goto done;
    plume_plate_moduli_from_tensor(r->D, &r->bending);
    r->plate_dofs = pinfo.dofs;
    r->bending_change = -1.0;
    r->refinement_change = -1.0;
    for (int k = 0; k < 4; k++)
        r->moduli_change[k] = -1.0;
    if (o->convergence && (st = refinement_estimate(l, mats, r, err)) != PLUME_OK)
        goto done;
    if (o->strain_max > 0.0) {
        /* back to the rest state between load cases */
        double I[4] = {1, 0, 0, 1}, P[4];
        for (int lc = 0; lc < 3 && st == PLUME_OK; lc++)
            if ((st = stress_controlled_curve(&c, lc, r->C, o, lc == 0   ? &r->uniaxial_x
                                                               : lc == 1 ? &r->uniaxial_y
                                                                         : &r->shear,
                                              err)) == PLUME_OK &&
                lc < 2)
                st = cell_solve(&c, I, P, "unloading", err);
        if (st != PLUME_OK)
            goto done;
    }
done:
    r->newton_iterations = c.iterations;
    cell_solver_free(&c);
    plume_cell_destroy(&cell);
    r->seconds = plume_wall_seconds() - t0;
    if (st != PLUME_OK)
        plume_homog_result_free(r);
    return st;
}
