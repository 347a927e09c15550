#include "stability.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/cholesky.h"
#include "../lib/problem.h"
#include "patch_mesh.h"
#include "vane.h"

/* a sample with both grips clamped (bottom at rest, top at `delta` along y), finalised */
static plume_status clamped_sample(double angle, double edge, const plume_vane *v, plume_mesh **mesh, plume_problem **p,
                                   plume_err *err)
{
    plume_status st = plume_patch_mesh(1.0, 1.3, angle, edge, PLUME_PATCH_ALIGNED, 2, mesh, err);
    if (st != PLUME_OK)
        return st;
    if ((st = plume_problem_create((*mesh)->nv, 2, 1.3, p)) != PLUME_OK ||
        (st = plume_vane_add(*p, *mesh, v, NULL, NULL, err)) != PLUME_OK)
        return st;
    double *x = plume_problem_x(*p);
    for (plume_index i = 0; i < (*mesh)->nv; i++) {
        x[2 * i] = (*mesh)->X[2 * i];
        x[2 * i + 1] = (*mesh)->X[2 * i + 1];
        double Y = (*mesh)->X[2 * i + 1];
        if (Y < 1e-12 || Y > 1.3 - 1e-12)
            plume_problem_fix_dof(*p, 2 * i), plume_problem_fix_dof(*p, 2 * i + 1);
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
