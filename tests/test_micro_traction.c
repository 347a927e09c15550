/* Supplementary Figure 10 as assertions: micro traction curves converge as the element size over
 * the barb width (e-bar) goes to 0, and approach the macro curve with the homogenised moduli as
 * the barb spacing over the sample length (d-bar_B) goes to 0. Tilted 45 deg, phi = 0.16, E ratio
 * 1e-6, aspect 1.3. */
#include <math.h>
#include <stdlib.h>

#include "harness.h"
#include "micro_specimen.h"
#include "plume_tree.h"
#include "../micro/homogenize.h"
#include "../micro/layout.h"
#include "../micro/micro_model.h"

static double micro_stress(double dB_rel, double e_rel, double strain, plume_index *elements)
{
    plume_layout l;
    plume_layout_default(&l);
    l.d_B = dB_rel * 1.3;
    l.e_rel = e_rel;
    l.h = 1.0;
    return tilted_specimen_stress(&l, strain, NULL, elements);
}

void test_micro_traction_converges_in_element_size(void)
{
    const double e[3] = {2.0, 1.0, 0.5};
    double s[3];
    plume_index n[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++)
        s[k] = micro_stress(0.17, e[k], 0.02, &n[k]);
    double d1 = fabs(s[1] - s[0]), d2 = fabs(s[2] - s[1]);
    fprintf(stderr, "    e-bar 2, 1, 0.5 (%ld, %ld, %ld elements): stress %.6g %.6g %.6g, differences %.3g %.3g\n",
            (long)n[0], (long)n[1], (long)n[2], s[0], s[1], s[2], d1, d2);
    CHECK(isfinite(s[0]) && isfinite(s[1]) && isfinite(s[2]));
    CHECK(d2 < 0.8 * d1);
    CHECK(d2 < 0.05 * fabs(s[2]));
}

void test_micro_traction_approaches_homogenised(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_homog_opts ho;
    plume_homog_opts_default(&ho);
    ho.strain_max = 0.0;
    plume_homog_result hr;
    plume_err err = {{0}};
    CHECK(plume_homogenize(&l, &ho, &hr, &err) == PLUME_OK);
    /* the macro model with those moduli, barbs inextensible, a fine aligned mesh */
    plume_vane vane;
    plume_vane_default(&vane);
    vane.moduli = hr.moduli;
    vane.h = 1.0;
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    CHECK(plume_patch_mesh(1.0, 1.3, 45.0, 0.02, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_OK);
    CHECK(plume_problem_create(mesh->nv, 2, 1.3, &p, &err) == PLUME_OK);
    CHECK(plume_vane_add(p, mesh, &vane, &barbs, &nb, &err) == PLUME_OK);
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.strain_max = 0.02, o.steps = 1, o.progress = 0;
    plume_traction_result r;
    CHECK(plume_traction_run(mesh, p, barbs, nb, &o, &r, &err) == PLUME_OK && r.converged);
    double macro = r.curve.stress[r.curve.n - 1];
    plume_traction_result_free(&r);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    const double dB[3] = {0.086, 0.043, 0.0215};
    double diff[3];
    for (int k = 0; k < 3; k++) {
        plume_index n = 0;
        double s = micro_stress(dB[k], 2.9, 0.02, &n);
        diff[k] = fabs(s - macro) / fabs(macro);
        fprintf(stderr, "    d-bar_B %.4g (%ld elements): micro %.6g vs macro %.6g, relative difference %.3g\n", dB[k],
                (long)n, s, macro, diff[k]);
    }
    CHECK(diff[1] < diff[0]);
    CHECK(diff[2] < diff[1]);
    /* first order in d_B (the barbs' bending boundary layers at the grips scale with d_B): with
     * quadratic elements each halving halves the difference */
    for (int k = 0; k < 2; k++)
        CHECK(diff[k] / diff[k + 1] > 1.6 && diff[k] / diff[k + 1] < 2.6);
}
