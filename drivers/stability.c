#include "stability.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/solve/cholesky.h"
#include "../lib/core/membrane.h"
#include "../lib/core/problem.h"
#include "../lib/solve/solver.h"
#include "../macro/shell/patch_mesh.h"
#include "../macro/shell/vane.h"

/* a sample with both grips clamped (bottom at rest, top at `delta` along y), finalised */
static plume_status clamped_sample(double angle, double edge, const plume_vane *v, plume_mesh **mesh, plume_problem **p,
                                   plume_err *err)
{
    plume_status st = plume_patch_mesh(1.0, 1.3, angle, edge, PLUME_PATCH_ALIGNED, 2, mesh, err);
    if (st != PLUME_OK)
        return st;
    if ((st = plume_problem_create((*mesh)->nv, 2, 1.3, p, err)) != PLUME_OK ||
        (st = plume_vane_add(*p, *mesh, v, NULL, NULL, err)) != PLUME_OK)
        return st;
    double *x = plume_problem_x(*p);
    for (plume_index i = 0; i < (*mesh)->nv; i++) {
        x[2 * i] = (*mesh)->X[2 * i];
        x[2 * i + 1] = (*mesh)->X[2 * i + 1];
        double Y = (*mesh)->X[2 * i + 1];
        if (Y < 1e-12 || Y > 1.3 - 1e-12)
            plume_problem_fix_dof(*p, 2 * i, err), plume_problem_fix_dof(*p, 2 * i + 1, err);
    }
    return plume_problem_finalize(*p, err);
}

plume_status plume_stability_condition(double ratio, double edge, int constraint, double *cond, plume_err *err)
{
    if (!(ratio >= 1.0) || !(edge > 0.0) || !cond)
        return plume_err_set(err, PLUME_EINVAL, "stability: ratio must be >= 1 and edge > 0");
    plume_vane v;
    plume_vane_default(&v);
    v.moduli.E_xx = constraint ? 1.0 : ratio; /* the constraint removes the stiff mode */
    v.constraint = 0;
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_chol *c = NULL;
    double *values = NULL;
    plume_status st = clamped_sample(45.0, edge, &v, &mesh, &p, err);
    if (st == PLUME_OK) {
        plume_sparsity s = plume_problem_hessian_pattern(p);
        values = malloc((size_t)s.nnz * sizeof *values);
        if (!values)
            st = PLUME_ENOMEM;
        else if ((st = plume_problem_hessian(p, NULL, 1.0, NULL, 0, values)) == PLUME_OK &&
                 (st = plume_chol_create(s.n, s.colptr, s.rowind, 0, &c, err)) == PLUME_OK &&
                 (st = plume_chol_factor(c, values, 0.0)) == PLUME_OK) {
            double r = plume_chol_rcond(c);
            *cond = r > 0.0 ? 1.0 / r : INFINITY;
        }
    }
    free(values);
    plume_chol_destroy(&c);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return st;
}

plume_status plume_stability_compression(double kappa, int log_barrier, double lambda_end, int steps, double *min_J,
                                         double *max_J, int *converged, int *iterations, plume_err *err)
{
    if (!(kappa >= 0.0) || !(lambda_end > 0.0 && lambda_end < 1.0) || steps < 1 || !min_J || !max_J || !converged ||
        !iterations)
        return plume_err_set(err, PLUME_EINVAL, "stability: kappa >= 0, lambda_end in (0, 1), steps >= 1");
    plume_mesh *m = NULL;
    plume_problem *p = NULL;
    plume_solver *s = NULL;
    double *u = NULL;
    plume_membrane_material mat = {.moduli = {1.0, 1.0, 0.0, 0.5}, .h = 1.0, .kappa = kappa, .log_barrier = log_barrier};
    plume_term t;
    plume_status st = plume_patch_mesh(0.05, 1.0, 0.0, 0.05, PLUME_PATCH_ALIGNED, 2, &m, err);
    if (st == PLUME_OK && (st = plume_problem_create(m->nv, 2, 1.0, &p, err)) == PLUME_OK &&
        (st = plume_membrane_term_create(m, 2, &mat, 1, &t, err)) == PLUME_OK)
        st = plume_problem_add_term(p, &t, err);
    double *x = st == PLUME_OK ? plume_problem_x(p) : NULL;
    for (plume_index i = 0; st == PLUME_OK && i < m->nv; i++) {
        x[2 * i] = m->X[2 * i];
        x[2 * i + 1] = m->X[2 * i + 1];
        if (m->X[2 * i + 1] < 1e-12 || m->X[2 * i + 1] > 1.0 - 1e-12)
            plume_problem_fix_dof(p, 2 * i, err), plume_problem_fix_dof(p, 2 * i + 1, err);
    }
    plume_solver_opts o;
    plume_solver_opts_default(&o);
    o.max_iter = 300;
    if (st == PLUME_OK && (st = plume_problem_finalize(p, err)) == PLUME_OK)
        st = plume_solver_create(PLUME_SOLVER_NEWTON, p, &o, &s, err);
    if (st == PLUME_OK && !(u = malloc((size_t)plume_problem_nfree(p) * sizeof *u)))
        st = PLUME_ENOMEM;
    *converged = 1;
    *iterations = 0;
    for (int k = 1; k <= steps && st == PLUME_OK; k++) {
        double lam = 1.0 - (1.0 - lambda_end) * k / steps, prev = 1.0 - (1.0 - lambda_end) * (k - 1) / steps;
        for (plume_index i = 0; i < m->nv; i++) {
            x[2 * i + 1] *= lam / prev;
            if (!plume_problem_is_fixed(p, 2 * i + 1))
                x[2 * i + 1] += 1e-4 * sin(12.9898 * (double)i);
        }
        plume_problem_gather(p, u);
        plume_solve_report rep;
        if ((st = plume_solver_solve(s, u, NULL, &rep)) != PLUME_OK)
            break;
        *iterations += rep.iterations;
        *converged &= rep.converged;
    }
    if (st == PLUME_OK) {
        *min_J = INFINITY, *max_J = -INFINITY;
        for (plume_index e = 0; e < m->nt; e++) {
            const plume_index *tr = m->tri + 3 * e;
            const double *a = x + 2 * tr[0], *b = x + 2 * tr[1], *c = x + 2 * tr[2];
            double J = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) / plume_mesh_ref_area(m, e);
            *min_J = fmin(*min_J, J), *max_J = fmax(*max_J, J);
        }
    }
    free(u);
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&m);
    return st;
}
