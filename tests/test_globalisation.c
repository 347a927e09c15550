/* Tests of the native solver's globalisation and work per load step: the filter line
 * search and the l1 merit, with and without chord steps (reused factorisations), reach the same
 * equilibria as Ipopt, and the reports count what they claim. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"

typedef struct {
    int converged, iterations, factorizations, chord_steps;
    double stress, slope;
} traction_run;

/* the tilted 45 deg vane (E_xx/E_yy = 1e4, inextensible barbs, aligned mesh) to 5 % in 5 steps */
static traction_run tilted(plume_solver_kind kind, plume_line_search ls, int reuse)
{
    traction_run r;
    memset(&r, 0, sizeof r);
    plume_err err = {{0}};
    plume_mesh *m = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_vane vane;
    plume_vane_default(&vane);
    CHECK(plume_patch_mesh(1.0, 1.3, 45.0, 0.05, PLUME_PATCH_ALIGNED, 2, &m, &err) == PLUME_OK);
    if (!m)
        return r;
    CHECK(plume_problem_create(m->nv, 2, 1.3, &p, &err) == PLUME_OK);
    CHECK(plume_vane_add(p, m, &vane, &barbs, &nb, &err) == PLUME_OK);
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    o.solver_opts = &so;
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = 5, o.strain_max = 0.05, o.progress = 0, o.solver = kind;
    so.line_search = ls;
    so.reuse_factorization = reuse;
    plume_traction_result res;
    CHECK(plume_traction_run(m, p, barbs, nb, &o, &res, &err) == PLUME_OK);
    r.converged = res.converged;
    r.iterations = res.newton_iterations;
    r.factorizations = res.factorizations;
    r.chord_steps = res.chord_steps;
    r.stress = res.curve.n > 0 ? res.curve.stress[res.curve.n - 1] : NAN;
    r.slope = res.initial_slope;
    plume_traction_result_free(&res);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&m);
    return r;
}

void test_globalisation_traction_methods(void)
{
    traction_run def = tilted(PLUME_SOLVER_NEWTON, PLUME_LS_FILTER, 1);
    traction_run merit = tilted(PLUME_SOLVER_NEWTON, PLUME_LS_MERIT, 1);
    traction_run plain = tilted(PLUME_SOLVER_NEWTON, PLUME_LS_FILTER, 0);
    traction_run old = tilted(PLUME_SOLVER_NEWTON, PLUME_LS_MERIT, 0);
    traction_run ip = tilted(PLUME_SOLVER_IPOPT, PLUME_LS_FILTER, 1);
    const traction_run *all[5] = {&def, &merit, &plain, &old, &ip};
    const char *names[5] = {"filter + chord", "merit + chord", "filter", "merit (old)", "ipopt"};
    for (int k = 0; k < 5; k++) {
        fprintf(stderr, "    %-15s stress %.10f Pa  slope %.8f  iterations %3d  factorisations %3d  chord %3d\n", names[k],
                all[k]->stress, all[k]->slope, all[k]->iterations, all[k]->factorizations, all[k]->chord_steps);
        CHECK(all[k]->converged);
        CHECK_REL(all[k]->stress, def.stress, 1e-8, 0.0);
        CHECK_REL(all[k]->slope, def.slope, 1e-6, 0.0);
    }
    /* chord steps happen only when asked, each one an iteration without a factorisation */
    CHECK(def.chord_steps > 0 && merit.chord_steps > 0);
    CHECK(plain.chord_steps == 0 && old.chord_steps == 0);
    CHECK(def.chord_steps < def.iterations);
    CHECK(plain.factorizations >= plain.iterations);
    /* and they save factorisations */
    CHECK(def.factorizations < plain.factorizations);
}

/* Adaptive load stepping: the tilted vane (aligned, barbs inextensible, edge 0.1, 2 steps to 5 %)
 * with a cap of 4 Newton iterations a step hits the cap with fixed steps; with the default cutting
 * it converges, and the report counts the cuts and the intermediate equilibria, while the curve
 * keeps the nominal strains only. */
static void adaptive_run(int adaptive, int cap, int steps, int constraint, plume_patch_kind kind,
                         plume_traction_result *r)
{
    plume_err err = {{0}};
    plume_mesh *m = NULL;
    plume_problem *p = NULL;
    plume_vane vane;
    plume_vane_default(&vane);
    vane.constraint = constraint;
    plume_index *barbs = NULL, nb = 0;
    memset(r, 0, sizeof *r);
    CHECK(plume_patch_mesh(1.0, 1.3, 45.0, 0.1, kind, 2, &m, &err) == PLUME_OK);
    if (!m)
        return;
    CHECK(plume_problem_create(m->nv, 2, 1.3, &p, &err) == PLUME_OK);
    CHECK(plume_vane_add(p, m, &vane, &barbs, &nb, &err) == PLUME_OK);
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    o.solver_opts = &so;
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = steps, o.strain_max = 0.05, o.progress = 0;
    so.max_iter = cap;
    if (adaptive) { /* bad input: max_cuts out of [0, 30] names itself */
        o.max_cuts = 31;
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "max_cuts"));
        o.max_cuts = 8;
        o.max_settles = -1; /* and max_settles below 0 */
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "max_settles"));
        o.max_settles = 100;
        /* a load path: too long, a leg that does not move the grip, a strain that is not finite */
        const double flat[2] = {0.05, 0.05}, nan_leg[1] = {NAN};
        o.path = flat, o.npath = 1001;
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "npath"));
        o.npath = 2;
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "path[1] = 0.05"));
        o.path = nan_leg, o.npath = 1;
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "path[0]"));
        o.path = NULL, o.npath = 0;
        o.peel = 1.5; /* a grip that turns beyond its end, one that holds nothing */
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "peel"));
        o.peel = 0.0, o.top_grip_free = 1.0;
        CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_EINVAL && strstr(err.msg, "top_grip_free"));
        o.top_grip_free = 0.0;
    } else {
        o.max_cuts = 0;
    }
    CHECK(plume_traction_run(m, p, barbs, nb, &o, r, &err) == PLUME_OK);
    fprintf(stderr, "    %s, cap %d: converged %d (failed step %d, %s), cuts %d, substeps %d, %d iterations, %ld points\n",
            adaptive ? "adaptive" : "fixed steps", cap, r->converged, r->failed_step, plume_reason_name(r->failed_reason),
            r->cuts, r->substeps, r->newton_iterations, (long)r->curve.n);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&m);
}

void test_globalisation_traction_adaptive(void)
{
    for (int adaptive = 0; adaptive < 2; adaptive++) {
        plume_traction_result r;
        adaptive_run(adaptive, 4, 2, 1, PLUME_PATCH_ALIGNED, &r);
        if (!adaptive) {
            CHECK(!r.converged && r.failed_step > 0 && r.failed_reason == PLUME_REASON_ITERATION_CAP);
            CHECK(r.cuts == 0 && r.substeps == 0);
        } else {
            CHECK(r.converged && r.cuts >= 1 && r.substeps >= 1);
            CHECK(r.curve.n == 3);
            for (long k = 0; k < (long)r.curve.n; k++)
                CHECK_REL(r.curve.strain[k], 0.025 * (double)k, 1e-12, 1e-15);
        }
        plume_traction_result_free(&r);
    }
    /* The unaligned penalty model at E_xx/E_yy = 1e4 (10 steps, the default cap of 100): a buckling
     * path whose hard steps need 50-60 iterations at any increment. It converges without a cut
     * since the exact Hessian's inertia is tested on small matrices too (CHOLMOD's simplicial
     * LDL^T had passed indefinite ones). */
    plume_traction_result r;
    adaptive_run(1, 100, 10, 0, PLUME_PATCH_UNALIGNED, &r);
    CHECK(r.converged && r.curve.n == 11);
    plume_traction_result_free(&r);
}
