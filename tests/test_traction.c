/* Macroscale traction: off-axis moduli, constraint accuracy, newton vs ipopt, locking, errors. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Runs a traction test on the aligned/unaligned patch; returns status, fills res. */
static plume_status run_traction(double angle, double edge, plume_patch_kind kind, const plume_vane *vane,
                                 plume_solver_kind solver, double strain_max, int steps,
                                 plume_traction_result *res, plume_mesh **mesh_out, plume_err *err)
{
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_status st = plume_patch_mesh(1.0, 1.3, angle, edge, kind, 2, &mesh, err);
    if (st == PLUME_OK)
        st = plume_problem_create(mesh->nv, 2, 1.3, &p, err);
    if (st == PLUME_OK)
        st = plume_vane_add(p, mesh, vane, &barbs, &nb, err);
    if (st == PLUME_OK) {
        plume_traction_opts o;
        plume_traction_opts_default(&o);
        plume_solver_opts so;
        plume_solver_opts_default(&so);
        o.solver_opts = &so;
        o.lx = 1.0, o.ly = 1.3, o.h = vane->h;
        o.strain_max = strain_max;
        o.steps = steps;
        o.solver = solver;
        o.progress = 0;
        so.max_iter = 400;
        st = plume_traction_run(mesh, p, barbs, nb, &o, res, err);
    }
    free(barbs);
    plume_problem_destroy(&p);
    if (mesh_out)
        *mesh_out = mesh;
    else
        plume_mesh_destroy(&mesh);
    return st;
}

/* A homogeneous orthotropic sheet in uniform uniaxial stress: grips constrain only y (one x
 * pinned), so the stress state is exactly uniaxial and the apparent modulus must follow
 * 1/E(t) = cos^4 t/E_xx + (1/G_xy - 2 nu_xy/E_xx) sin^2 t cos^2 t + sin^4 t/E_yy,
 * t the angle between the barbs and the pulling axis. */
void test_traction_off_axis_modulus(void)
{
    const double Exx = 10.0, Eyy = 1.0, G = 0.7, nu = 0.25, h = 0.01, eps = 1e-7;
    const double angles[] = {0, 20, 45, 60, 90, 135};
    for (size_t a = 0; a < sizeof angles / sizeof angles[0]; a++) {
        plume_err err = {{0}};
        plume_mesh *mesh = NULL;
        plume_problem *p = NULL;
        CHECK(plume_patch_mesh(1.0, 1.3, angles[a], 0.2, PLUME_PATCH_UNALIGNED, 2, &mesh, &err) == PLUME_OK);
        if (!mesh)
            return;
        plume_membrane_material mat = {{Exx, Eyy, nu, G}, h, 0.0, 0};
        plume_term term;
        CHECK(plume_problem_create(mesh->nv, 2, 1.3, &p, &err) == PLUME_OK);
        CHECK(plume_membrane_term_create(mesh, 2, &mat, 1, &term, &err) == PLUME_OK);
        CHECK(plume_problem_add_term(p, &term, &err) == PLUME_OK);
        double *x = plume_problem_x(p);
        plume_index pinned = -1;
        for (plume_index v = 0; v < mesh->nv; v++) {
            x[2 * v] = mesh->X[2 * v];
            x[2 * v + 1] = mesh->X[2 * v + 1];
            if (mesh->X[2 * v + 1] == 0.0) {
                plume_problem_fix_dof(p, 2 * v + 1, &err);
                if (pinned < 0)
                    plume_problem_fix_dof(p, 2 * v, &err), pinned = v;
            } else if (mesh->X[2 * v + 1] == 1.3) {
                plume_problem_fix_dof(p, 2 * v + 1, &err);
                x[2 * v + 1] = 1.3 * (1.0 + eps);
            }
        }
        CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
        plume_solver_opts so;
        plume_solver_opts_default(&so);
        plume_solver *s = NULL;
        CHECK(plume_solver_create(PLUME_SOLVER_NEWTON, p, &so, &s, NULL) == PLUME_OK);
        double *u = malloc((size_t)plume_problem_nfree(p) * sizeof *u);
        double *force = malloc((size_t)(2 * mesh->nv) * sizeof *force);
        plume_problem_gather(p, u);
        plume_solve_report rep;
        CHECK(plume_solver_solve(s, u, NULL, &rep) == PLUME_OK);
        CHECK(rep.converged);
        CHECK(plume_problem_forces(p, NULL, force) == PLUME_OK);
        double F = 0.0;
        for (plume_index v = 0; v < mesh->nv; v++)
            if (mesh->X[2 * v + 1] == 1.3)
                F += force[2 * v + 1];
        double t = angles[a] * M_PI / 180.0, c = cos(t), sn = sin(t);
        double invE = pow(c, 4) / Exx + (1.0 / G - 2.0 * nu / Exx) * sn * sn * c * c + pow(sn, 4) / Eyy;
        CHECK_REL(F / (1.0 * h * eps), 1.0 / invE, 1e-5, 0.0);
        free(u);
        free(force);
        plume_solver_destroy(&s);
        plume_problem_destroy(&p);
        plume_mesh_destroy(&mesh);
    }
}

/* The tilted constrained vane's small-strain probe (strain 1e-6), one load step to 1e-3. */
static plume_status probe_run(double edge, plume_solver_kind solver, double probe_tol, double tol_step,
                              plume_traction_result *r, plume_err *err)
{
    plume_mesh *m = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_vane vane;
    plume_vane_default(&vane);
    plume_status st = plume_patch_mesh(1.0, 1.3, 45.0, edge, PLUME_PATCH_ALIGNED, 2, &m, err);
    if (st == PLUME_OK)
        st = plume_problem_create(m->nv, 2, 1.3, &p, err);
    if (st == PLUME_OK)
        st = plume_vane_add(p, m, &vane, &barbs, &nb, err);
    if (st == PLUME_OK) {
        plume_traction_opts o;
        plume_traction_opts_default(&o);
        plume_solver_opts so;
        plume_solver_opts_default(&so);
        o.solver_opts = &so;
        o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = 1, o.strain_max = 1e-3, o.progress = 0;
        o.solver = solver;
        o.probe_tol_kkt = probe_tol;
        so.tol_step = tol_step;
        st = plume_traction_run(m, p, barbs, nb, &o, r, err);
    }
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&m);
    return st;
}

/* The probe is solved to round-off (its KKT tolerance scaled by probe strain / first step's
 * strain, 1e-12 here) and its reaction taken as a virtual work over the sample, so newton and
 * ipopt give the same initial slope to 1e-7 relative at edge 0.016 (12k triangles). Measured:
 * 5.2829630 and 5.2829631 Pa, 1.7e-8 apart. Each half alone fails here: newton with the steps'
 * tolerance is 7.9e-7 off, and by the grip's force sum (before) newton and ipopt were 4.3e-5 and
 * 1.2e-6 off. A probe tolerance out of reach (1e-30, no step test) falls back on the steps'
 * tolerance: the run converges and says which tolerance was met. */
static void probe_checks(void)
{
    plume_err err = {{0}};
    plume_traction_result rn, ri, rf;
    CHECK(probe_run(0.016, PLUME_SOLVER_NEWTON, 0.0, 1e-13, &rn, &err) == PLUME_OK);
    CHECK(probe_run(0.016, PLUME_SOLVER_IPOPT, 0.0, 1e-13, &ri, &err) == PLUME_OK);
    CHECK(rn.converged && ri.converged);
    CHECK_REL(rn.probe_tol_kkt, 1e-9 * 1e-6 / 1e-3, 1e-12, 0.0);
    CHECK_REL(ri.probe_tol_kkt, 1e-9 * 1e-6 / 1e-3, 1e-12, 0.0);
    fprintf(stderr, "    initial slope newton %.9f, ipopt %.9f Pa (relative difference %.2g)\n", rn.initial_slope,
            ri.initial_slope, fabs(rn.initial_slope / ri.initial_slope - 1.0));
    CHECK_REL(rn.initial_slope, ri.initial_slope, 1e-7, 0.0);
    CHECK(rn.initial_slope > 5.2 && rn.initial_slope < 5.4);
    CHECK(probe_run(0.04, PLUME_SOLVER_NEWTON, -1.0, 1e-13, &rf, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "probe_tol_kkt") != NULL);
    CHECK(probe_run(0.04, PLUME_SOLVER_NEWTON, NAN, 1e-13, &rf, &err) == PLUME_EINVAL);
    CHECK(probe_run(0.04, PLUME_SOLVER_NEWTON, 1e-30, 0.0, &rf, &err) == PLUME_OK);
    CHECK(rf.converged && rf.probe_tol_kkt == 1e-9);
    CHECK_REL(rf.initial_slope, 5.2931437, 1e-5, 0.0); /* the tight probe's at edge 0.04 */
    plume_traction_result_free(&rn);
    plume_traction_result_free(&ri);
    plume_traction_result_free(&rf);
}

/* After every converged step the barb edges keep their rest length to 1e-8 relative (checked on
 * the final geometry edge by edge), and newton and ipopt agree on the stress to 1e-6, and on the
 * initial slope to 1e-7 (probe_checks). */
void test_traction_constraint_and_solvers_agree(void)
{
    probe_checks();
    plume_vane vane;
    plume_vane_default(&vane); /* E_xx/E_yy = 1e4, G = 1: the paper's Table 4 vane */
    plume_traction_result rn, ri;
    plume_mesh *mesh = NULL;
    plume_err err = {{0}};
    CHECK(run_traction(45.0, 0.08, PLUME_PATCH_ALIGNED, &vane, PLUME_SOLVER_NEWTON, 0.05, 5, &rn, &mesh, &err) == PLUME_OK);
    CHECK(run_traction(45.0, 0.08, PLUME_PATCH_ALIGNED, &vane, PLUME_SOLVER_IPOPT, 0.05, 5, &ri, NULL, &err) == PLUME_OK);
    CHECK(rn.converged && ri.converged);
    CHECK(rn.max_violation <= 1e-8);
    CHECK(ri.max_violation <= 1e-8);
    CHECK(rn.curve.n == 6 && ri.curve.n == 6);
    for (plume_index k = 1; k < rn.curve.n && k < ri.curve.n; k++) {
        CHECK_REL(ri.curve.stress[k], rn.curve.stress[k], 1e-6, 0.0);
        CHECK_REL(ri.curve.wbar[k], rn.curve.wbar[k], 1e-6, 0.0);
    }
    CHECK(rn.curve.stress[5] > rn.curve.stress[1]); /* loaded, not a trivial zero curve */
    CHECK(rn.initial_slope > 0.0);
    plume_traction_result_free(&rn);
    plume_traction_result_free(&ri);
    plume_mesh_destroy(&mesh);
}

/* Edge by edge on the final state of a constrained run. */
void test_traction_barb_lengths(void)
{
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_err err = {{0}};
    plume_vane vane;
    plume_vane_default(&vane);
    CHECK(plume_patch_mesh(1.0, 1.3, 60.0, 0.1, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_OK);
    CHECK(plume_problem_create(mesh->nv, 2, 1.3, &p, &err) == PLUME_OK);
    CHECK(plume_vane_add(p, mesh, &vane, &barbs, &nb, &err) == PLUME_OK);
    CHECK(nb > mesh->nt / 3); /* every triangle between two barb lines has a barb edge */
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = 4, o.strain_max = 0.08, o.progress = 0;
    plume_traction_result r;
    CHECK(plume_traction_run(mesh, p, barbs, nb, &o, &r, &err) == PLUME_OK);
    CHECK(r.converged);
    const double *x = plume_problem_x(p);
    double worst = 0.0;
    for (plume_index e = 0; e < nb; e++) {
        plume_index i = barbs[2 * e], j = barbs[2 * e + 1];
        double L = hypot(mesh->X[2 * i] - mesh->X[2 * j], mesh->X[2 * i + 1] - mesh->X[2 * j + 1]);
        double l = hypot(x[2 * i] - x[2 * j], x[2 * i + 1] - x[2 * j + 1]);
        worst = fmax(worst, fabs(l - L) / L);
    }
    CHECK(worst <= 1e-8);
    /* and the sample did deform: the barbs rotated, the width shrank */
    CHECK(r.curve.wbar[r.curve.n - 1] < -1e-3);
    plume_traction_result_free(&r);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
}

/* Supplementary Figure 2 as an assertion: without the constraint at E_xx/E_yy = 1e4, aligned
 * meshes converge in stress under refinement while an unaligned mesh of similar size locks. */
void test_traction_locking(void)
{
    plume_vane vane;
    plume_vane_default(&vane);
    vane.constraint = 0;
    const double edges[] = {0.1, 0.05, 0.025};
    double aligned[3] = {0}, unaligned = 0.0;
    plume_index n_unaligned = 0, n_aligned_fine = 0;
    plume_err err = {{0}};
    for (int k = 0; k < 3; k++) {
        plume_traction_result r;
        plume_mesh *mesh = NULL;
        CHECK(run_traction(45.0, edges[k], PLUME_PATCH_ALIGNED, &vane, PLUME_SOLVER_NEWTON, 0.01, 2, &r, &mesh, &err) == PLUME_OK);
        CHECK(r.converged);
        aligned[k] = r.curve.stress[r.curve.n - 1];
        if (k == 2)
            n_aligned_fine = mesh->nt;
        plume_traction_result_free(&r);
        plume_mesh_destroy(&mesh);
    }
    plume_traction_result r;
    plume_mesh *mesh = NULL;
    CHECK(run_traction(45.0, 0.035, PLUME_PATCH_UNALIGNED, &vane, PLUME_SOLVER_NEWTON, 0.01, 2, &r, &mesh, &err) == PLUME_OK);
    CHECK(r.converged);
    unaligned = r.curve.stress[r.curve.n - 1];
    n_unaligned = mesh->nt;
    plume_traction_result_free(&r);
    plume_mesh_destroy(&mesh);
    double d01 = fabs(aligned[1] - aligned[0]), d12 = fabs(aligned[2] - aligned[1]);
    fprintf(stderr, "    aligned stress %.6g %.6g %.6g (differences %.3g, %.3g); unaligned (%ld el vs %ld) %.6g\n",
            aligned[0], aligned[1], aligned[2], d01, d12, (long)n_unaligned, (long)n_aligned_fine, unaligned);
    /* Corner-exact aligned meshes (every triangle owns a barb edge) approach the limit from above
     * and the coarsest is already within 3 % of the finest. The differences themselves shrink only
     * once the edge resolves the penalty model's boundary layers along the corner fibres, of
     * width ~ ly sqrt(G_xy / E_xx) = 0.013 m (0.00053, 0.00053, then 0.00051, 0.00035 at 0.0125
     * and 0.00625 m), so their ratio is not asserted at these sizes. */
    CHECK(aligned[0] > aligned[1] && aligned[1] > aligned[2]);
    CHECK(d01 + d12 < 0.03 * fabs(aligned[2]));
    CHECK(d12 < 0.15 * fabs(aligned[2]));               /* and already close */
    CHECK(n_unaligned >= n_aligned_fine);               /* at least as many elements ... */
    CHECK(fabs(unaligned - aligned[2]) > 2.0 * fabs(aligned[2])); /* ... and still far off (locked) */
}

/* Longitudinal barbs with the constraint run from grip to grip: refused before any solve. */
void test_traction_spanning_barbs(void)
{
    plume_vane vane;
    plume_vane_default(&vane);
    plume_traction_result r;
    plume_err err = {{0}};
    CHECK(run_traction(0.0, 0.2, PLUME_PATCH_ALIGNED, &vane, PLUME_SOLVER_NEWTON, 0.05, 2, &r, NULL, &err) ==
          PLUME_EINFEASIBLE);
    CHECK(strstr(err.msg, "span both grips") != NULL);
    /* a shallow angle whose barbs still reach the top grip: tan(10 deg) * 1.3 < 1 */
    CHECK(run_traction(10.0, 0.2, PLUME_PATCH_ALIGNED, &vane, PLUME_SOLVER_NEWTON, 0.05, 2, &r, NULL, &err) ==
          PLUME_EINFEASIBLE);
    /* the transverse sample is fine */
    CHECK(run_traction(90.0, 0.2, PLUME_PATCH_ALIGNED, &vane, PLUME_SOLVER_NEWTON, 0.05, 2, &r, NULL, &err) == PLUME_OK);
    CHECK(r.converged);
    /* transverse pull across barbs of an orthotropic vane with nu = 0 behaves like E_yy at small strain */
    CHECK_REL(r.initial_slope, vane.moduli.E_yy, 1e-3, 0.0);
    plume_traction_result_free(&r);
}

/* Bad inputs through the library: each a clear error naming what is wrong. */
void test_traction_bad_inputs(void)
{
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    CHECK(plume_patch_mesh(0.0, 1.3, 45, 0.1, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "lx") != NULL);
    CHECK(plume_patch_mesh(1.0, 1.3, 200, 0.1, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "angle") != NULL);
    CHECK(plume_patch_mesh(1.0, 1.3, NAN, 0.1, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_EINVAL);
    CHECK(plume_patch_mesh(1.0, 1.3, 45, 2.0, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "edge") != NULL);
    CHECK(mesh == NULL);
    plume_vane v;
    plume_vane_default(&v);
    v.moduli.E_yy = -1.0;
    CHECK(plume_vane_check(&v, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "E_yy") != NULL);
    plume_vane_default(&v);
    v.moduli.G_xy = NAN;
    CHECK(plume_vane_check(&v, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "G_xy") != NULL);
    plume_vane_default(&v);
    v.h = 0.0;
    CHECK(plume_vane_check(&v, &err) == PLUME_EINVAL);
    plume_ortho m;
    CHECK(plume_moduli_read("/nonexistent/moduli.h5", &m, &err) != PLUME_OK);
    CHECK(strstr(err.msg, "/nonexistent/moduli.h5") != NULL);
}

/* The two factorisations of the native solver's KKT system give the same curve. */
void test_traction_kkt_modes_agree(void)
{
    plume_vane vane;
    plume_vane_default(&vane);
    plume_traction_result r[2];
    for (int mode = 0; mode < 2; mode++) {
        plume_mesh *mesh = NULL;
        plume_problem *p = NULL;
        plume_index *barbs = NULL, nb = 0;
        plume_err err = {{0}};
        CHECK(plume_patch_mesh(1.0, 1.3, 45.0, 0.06, PLUME_PATCH_ALIGNED, 2, &mesh, &err) == PLUME_OK);
        CHECK(plume_problem_create(mesh->nv, 2, 1.3, &p, &err) == PLUME_OK);
        CHECK(plume_vane_add(p, mesh, &vane, &barbs, &nb, &err) == PLUME_OK);
        plume_traction_opts o;
        plume_traction_opts_default(&o);
        plume_solver_opts so;
        plume_solver_opts_default(&so);
        o.solver_opts = &so;
        o.lx = 1.0, o.ly = 1.3, o.h = 1.0, o.steps = 4, o.progress = 0;
        so.kkt = mode ? PLUME_KKT_LDL : PLUME_KKT_ELIMINATE;
        CHECK(plume_traction_run(mesh, p, barbs, nb, &o, &r[mode], &err) == PLUME_OK);
        CHECK(r[mode].converged && r[mode].max_violation <= 1e-10);
        free(barbs);
        plume_problem_destroy(&p);
        plume_mesh_destroy(&mesh);
    }
    for (plume_index k = 1; k < r[0].curve.n && k < r[1].curve.n; k++) {
        CHECK_REL(r[1].curve.stress[k], r[0].curve.stress[k], 1e-8, 0.0);
        CHECK_REL(r[1].curve.wbar[k], r[0].curve.wbar[k], 1e-8, 0.0);
    }
    plume_traction_result_free(&r[0]);
    plume_traction_result_free(&r[1]);
}
