/* The tilted (45 deg) traction test of a micro specimen 1 x 1.3 m of a layout, shared by the micro
 * convergence tests (tests/test_micro_traction.c, tests/test_micro_convergence.c). Header-only. */
#ifndef PLUME_TEST_MICRO_SPECIMEN_H
#define PLUME_TEST_MICRO_SPECIMEN_H

#include <math.h>
#include <stdio.h>

#include "plume_tree.h"
#include "../micro/micro_model.h"

/* The stress at `strain` (one step), NaN when the run fails (printed); seconds and elements (quadratic
 * ones counted once, not as the four triangles they are split in) may be NULL. The initial slope is
 * not read, so its probe is solved at the steps' tolerance. */
static inline double tilted_specimen_stress(const plume_layout *l, double strain, double *seconds,
                                            plume_index *elements)
{
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_err err = {{0}};
    double s = NAN;
    if (seconds)
        *seconds = 0.0;
    if (plume_micro_specimen(l, 1.0, 1.3, 45.0, &mesh, &p, &err) == PLUME_OK) {
        plume_traction_opts o;
        plume_traction_opts_default(&o);
        plume_solver_opts so;
        plume_solver_opts_default(&so);
        o.solver_opts = &so;
        o.lx = 1.0, o.ly = 1.3, o.h = l->h, o.strain_max = strain, o.steps = 1, o.progress = 0;
        o.probe_tol_kkt = so.tol_kkt;
        plume_traction_result r;
        if (plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_OK && r.converged)
            s = r.curve.stress[r.curve.n - 1];
        else
            fprintf(stderr, "    micro run failed: %s\n", err.msg);
        if (seconds)
            *seconds = r.seconds;
        if (elements)
            *elements = plume_micro_specimen_elements(l, mesh);
        plume_traction_result_free(&r);
    } else {
        fprintf(stderr, "    %s\n", err.msg);
    }
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return s;
}

#endif
