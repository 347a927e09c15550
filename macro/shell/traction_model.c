#include "traction_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/problem.h"
#include "../../lib/sim/traction.h"
#include "vane.h"

plume_status plume_macro_model_curve(void *ctx, const plume_ortho *m, int icurve, plume_curve *out, plume_err *err)
{
    const plume_macro_model *mm = ctx;
    if (!mm || !m || !out || icurve < 0 || icurve >= mm->ncurves)
        return plume_err_set(err, PLUME_EINVAL, "macro model: invalid arguments");
    memset(out, 0, sizeof *out);
    plume_vane vane;
    plume_vane_default(&vane);
    vane.moduli = *m;
    vane.h = mm->h;
    vane.kappa = mm->kappa;
    vane.constraint = mm->constraint;
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_status st = plume_patch_mesh(mm->lx, mm->ly, mm->angles[icurve], mm->edge, mm->mesh, 2, &mesh, err);
    if (st == PLUME_OK)
        st = plume_problem_create(mesh->nv, 2, fmax(mm->lx, mm->ly), &p, err);
    if (st == PLUME_OK)
        st = plume_vane_add(p, mesh, &vane, &barbs, &nb, err);
    if (st == PLUME_OK) {
        plume_traction_opts o;
        plume_traction_opts_default(&o);
        o.lx = mm->lx, o.ly = mm->ly, o.h = mm->h;
        o.strain_max = mm->strain_max;
        o.steps = mm->steps;
        o.solver = mm->solver;
        o.progress = 0;
        plume_traction_result r;
        st = plume_traction_run(mesh, p, barbs, nb, &o, &r, err);
        if (st == PLUME_OK && !r.converged) {
            plume_traction_result_free(&r);
            st = plume_err_set(err, PLUME_EINFEASIBLE, "macro model: curve %d did not converge", icurve);
        } else if (st == PLUME_OK) {
            *out = r.curve; /* the curve's arrays move to the caller */
        }
    }
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return st;
}
