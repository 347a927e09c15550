/* The vane with hooks at barb spacing d_B, shared by the tensor vane's tests
 * (tests/test_monoclinic_vane.c) and the micro-against-macro benchmark (bench/bench_unzip.c):
 * data/layout_hooks.json's cell scaled with d_B, and the macro vane C on a 45 deg traction specimen
 * (docs/monoclinic-vane.md). Header-only. */
#ifndef PLUME_TEST_HOOKED_VANE_H
#define PLUME_TEST_HOOKED_VANE_H

#include <math.h>
#include <stdlib.h>

#include "plume_tree.h"
#include "../micro/homogenize.h"
#include "../micro/layout.h"

/* data/layout_barbules_table3a.json (layout_hooks.json without its hooks) at barb spacing d_B,
 * the barbules scaled with it */
static inline void table3a_layout(double d_B, plume_layout *l)
{
    plume_layout_default(l);
    l->kind = PLUME_LAYOUT_BARBULES;
    l->phi = 0.3, l->ratio = 1.0, l->E_b = 2.5e9, l->nu_b = 0.3, l->nu_B = 0.3;
    l->d_B = d_B;
    l->barbule_width = 0.1 * d_B, l->barbule_spacing = 0.8 * d_B, l->barbule_angle = 60.0;
    l->h = 1e-4, l->h_barb = 1.59e-4, l->h_barbule = 1.39e-5;
}

/* data/layout_hooks.json at barb spacing d_B: the hook's strength scaled with the barbule spacing,
 * so that the line's strength per length stays one 0.93 mN hook per 0.8 mm */
static inline void hooked_layout(double d_B, plume_layout *l)
{
    table3a_layout(d_B, l);
    l->hooks.strength = 9.3e-4 * d_B / 1e-3;
    l->hooks.opening = 2e-6, l->hooks.slide = 0.0, l->hooks.capture = 5e-6;
}

/* Vane C of layout l on an lx x ly specimen pulled at 45 deg with the options o: the hooked cell's
 * tensor (plume_separation_tensor), which holds the hooks' compliance, and one split line per barb
 * spacing, a thousand times stiffer than the cell across one spacing, so that the lines only decide
 * where it opens; they let go at the cell's strength (brittle) or, cohesive, keep the cell's
 * separation energy under a softening branch (plume_split_stiff_law). Elements of
 * min(0.1 mm, d_B / 4). *r is filled (free it) when the status is PLUME_OK. */
static inline plume_status hooked_vane_c(const plume_layout *l, double lx, double ly, int cohesive,
                                         const plume_traction_opts *o, plume_traction_result *r, plume_err *err)
{
    plume_homog_opts ho;
    plume_homog_opts_default(&ho);
    ho.strain_max = 0.0;
    plume_homog_result hr;
    plume_separation_law law;
    double C[9];
    plume_status st = plume_homogenize(l, &ho, &hr, err);
    if (st != PLUME_OK)
        return st;
    plume_vane v;
    plume_vane_default(&v);
    v.moduli = hr.moduli, v.h = l->h;
    plume_homog_result_free(&hr);
    if ((st = plume_separation_law_of(l, &law, err)) != PLUME_OK || (st = plume_separation_tensor(l, C, err)) != PLUME_OK)
        return st;
    const double stiff = 1e3 * C[4] * l->h / l->d_B;
    if (cohesive)
        plume_split_stiff_law(&law, stiff, l->h);
    else
        law.stiffness = stiff;
    const int nlines = (int)lround((lx + ly) / sqrt(2.0) / l->d_B);
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_splits *sp = NULL;
    plume_index *barbs = NULL, nb = 0;
    if ((st = plume_patch_mesh(lx, ly, 45.0, fmin(1e-4, 0.25 * l->d_B), PLUME_PATCH_ALIGNED, 2, &mesh, err)) == PLUME_OK &&
        (st = plume_splits_open(mesh, 45.0, nlines, &sp, err)) == PLUME_OK &&
        (st = plume_problem_create(plume_splits_mesh(sp)->nv, 2, ly, &p, err)) == PLUME_OK &&
        (st = plume_vane_add_tensor(p, plume_splits_mesh(sp), &v, C, &barbs, &nb, err)) == PLUME_OK &&
        (st = plume_splits_add(p, sp, &law, err)) == PLUME_OK)
        st = plume_traction_run(plume_splits_mesh(sp), p, barbs, nb, o, r, err);
    free(barbs);
    plume_problem_destroy(&p);
    plume_splits_destroy(&sp);
    plume_mesh_destroy(&mesh);
    return st;
}

#endif
