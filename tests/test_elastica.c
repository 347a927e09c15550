/* Large deflection: a clamped strip under an end load follows the elastica (Euler's large-
 * deflection cantilever), computed here by shooting with GSL's ODE solver. */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"
#include "../lib/core/load.h"
#include "../macro/shell/bending.h"

/* theta'' = -alpha cos(theta), theta(0) = 0; y = (theta, theta', deflection) over s in [0, 1] */
static int elastica_rhs(double s, const double y[], double dy[], void *params)
{
    (void)s;
    double alpha = *(double *)params;
    dy[0] = y[1];
    dy[1] = -alpha * cos(y[0]);
    dy[2] = sin(y[0]);
    return GSL_SUCCESS;
}

/* tip deflection over length for alpha = P L^2 / EI, by bisection on theta'(0) so that
 * theta'(1) = 0 (no moment at the free end) */
static double elastica_deflection(double alpha)
{
    gsl_odeiv2_system sys = {elastica_rhs, NULL, 3, &alpha};
    double lo = 0.0, hi = alpha, y[3] = {0};
    for (int it = 0; it < 100; it++) {
        double k0 = 0.5 * (lo + hi), s = 0.0;
        y[0] = 0.0, y[1] = k0, y[2] = 0.0;
        gsl_odeiv2_driver *dr = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-6, 1e-13, 1e-13);
        gsl_odeiv2_driver_apply(dr, &s, 1.0, y);
        gsl_odeiv2_driver_free(dr);
        if (y[1] > 0.0) /* still curving at the tip: the root moment was too large */
            hi = k0;
        else
            lo = k0;
    }
    return y[2];
}

/* FE strip along y: clamped rows at y <= edge, load P (total, -z) on the tip row; returns tip
 * deflection / L; *n elements */
static double strip_deflection(double edge, double alpha, plume_index *nel)
{
    const double L = 1.0, w = 0.05, D = 1.0, EI = D * w, P = alpha * EI / (L * L);
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    double defl = NAN;
    /* a quality Delaunay mesh: the material is isotropic, and hinge energies on the cocircular
     * right-triangle rows of an aligned strip mesh drift softer under refinement */
    if (plume_patch_mesh(w, L, 0.0, edge, PLUME_PATCH_UNALIGNED, 3, &mesh, &err) != PLUME_OK)
        return NAN;
    *nel = mesh->nt;
    plume_membrane_material mat = {{1e8, 1e8, 0.3, 1e8 / 2.6}, 1e-3, 0.0, 0};
    plume_bending_material bm = {D, D, 0.0, 0.0};
    plume_term mem, bend, load;
    plume_index *tip = malloc((size_t)mesh->nv * sizeof *tip), ntip = 0;
    for (plume_index v = 0; v < mesh->nv; v++)
        if (fabs(mesh->X[2 * v + 1] - L) < 1e-12)
            tip[ntip++] = v;
    double *f = calloc((size_t)(3 * ntip), sizeof *f);
    for (plume_index k = 0; k < ntip; k++)
        f[3 * k + 2] = -P / (double)ntip;
    if (plume_problem_create(mesh->nv, 3, L, &p, &err) != PLUME_OK ||
        plume_membrane_term_create(mesh, 3, &mat, 1, &mem, &err) != PLUME_OK || plume_problem_add_term(p, &mem, &err) ||
        plume_bending_term_create(mesh, &bm, 1, NULL, &bend, &err) != PLUME_OK || plume_problem_add_term(p, &bend, &err) ||
        plume_load_term_create(tip, ntip, 3, f, &load, &err) != PLUME_OK || plume_problem_add_term(p, &load, &err)) {
        fprintf(stderr, "    setup: %s\n", err.msg);
        goto done;
    }
    double *x = plume_problem_x(p);
    memcpy(x, mesh->x, (size_t)(3 * mesh->nv) * sizeof *x);
    for (plume_index v = 0; v < mesh->nv; v++)
        if (mesh->X[2 * v + 1] <= edge * 1.01) /* two rows: a clamp, not a hinge */
            for (int a = 0; a < 3; a++)
                plume_problem_fix_dof(p, 3 * v + a, &err);
    if (plume_problem_finalize(p, &err) != PLUME_OK)
        goto done;
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    so.max_iter = 200;
    plume_solver *s = NULL;
    if (plume_solver_create(PLUME_SOLVER_NEWTON, p, &so, &s, NULL) != PLUME_OK)
        goto done;
    double *u = malloc((size_t)plume_problem_nfree(p) * sizeof *u);
    int ok = 1;
    for (int k = 1; k <= 20 && ok; k++) { /* load stepping */
        plume_load_scale(&load, k / 20.0);
        plume_problem_gather(p, u);
        plume_solve_report rep;
        ok = plume_solver_solve(s, u, NULL, &rep) == PLUME_OK && rep.converged;
        if (!ok)
            fprintf(stderr, "    load step %d: %s\n", k, plume_reason_name(rep.reason));
    }
    if (ok) {
        defl = 0.0;
        for (plume_index k = 0; k < ntip; k++)
            defl -= x[3 * tip[k] + 2] / (double)ntip;
        defl /= L;
    }
    free(u);
    plume_solver_destroy(&s);
done:
    free(tip);
    free(f);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return defl;
}

void test_elastica_cantilever(void)
{
    const double alpha = 2.0;
    double exact = elastica_deflection(alpha);
    /* small-load check of the shooting: alpha -> 0 gives the linear alpha / 3 */
    CHECK_REL(elastica_deflection(1e-4), 1e-4 / 3.0, 1e-3, 0.0);
    const double edges[3] = {0.05, 0.025, 0.0125};
    double err[3];
    for (int k = 0; k < 3; k++) {
        plume_index n = 0;
        double d = strip_deflection(edges[k], alpha, &n);
        err[k] = fabs(d - exact) / exact;
        fprintf(stderr, "    edge %g (%ld elements): tip deflection %.6f L, elastica %.6f L, error %.3g\n", edges[k],
                (long)n, d, exact, err[k]);
        CHECK(isfinite(d));
    }
    CHECK(err[1] < err[0]);
    CHECK(err[2] < err[1]);
    CHECK(err[2] < 0.015);
}
