/* The energy balance of the implicit Euler stepper (lib/sim/dynamics_energy.h): a sheet in free fall
 * against the closed form (implicit Euler gives up 1/2 M g^2 dt^2 a step, exactly), and a vane
 * hanging from a moving handle with inextensible barbs: the handle's work goes into kinetic and
 * potential energy and implicit Euler's dissipation, to the trapezoidal rule's error; both the
 * dissipation and the error fall with the step. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../include/plume/traction.h"
#include "../lib/sim/dynamics.h"

void test_dynamics_energy_free_fall(void)
{
    plume_mesh *mesh = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 0.0, 0.5, PLUME_PATCH_UNALIGNED, 3, &mesh, &err) == PLUME_OK);
    plume_problem *p = NULL;
    CHECK(plume_problem_create(mesh->nv, 3, 1.0, &p, &err) == PLUME_OK);
    memcpy(plume_problem_x(p), mesh->x, (size_t)(3 * mesh->nv) * sizeof(double));
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = 0.01;
    const double rho = 0.026, M = rho * 1.0, g = 9.81, dt = o.dt;
    plume_dynamics *d = NULL;
    CHECK(plume_dynamics_create(mesh, p, &rho, 1, NULL, 0, &o, &d, &err) == PLUME_OK);
    const int N = 5;
    for (int n = 0; n < N; n++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK && rep.converged);
    }
    const plume_energy_ledger *l = plume_dynamics_energy(d);
    printf("    free fall, %d steps: kinetic %.10g J, potential %+.10g J, numerical %.10g J, error %.2e\n", N,
           l->ke - l->ke0, l->u - l->u0, l->numerical, plume_ledger_error(l));
    CHECK(l->started && l->work == 0.0);
    CHECK_REL(l->ke - l->ke0, 0.5 * M * (g * N * dt) * (g * N * dt), 1e-10, 0.0);
    CHECK_REL(l->u - l->u0, -M * g * g * dt * dt * N * (N + 1) / 2.0, 1e-10, 0.0);
    CHECK_REL(l->numerical, N * 0.5 * M * g * g * dt * dt, 1e-10, 0.0);
    CHECK(fabs(plume_ledger_error(l)) < 1e-10);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
}

/* A vane sheet hanging from a handle along its top edge, barbs at 45 deg inextensible, under
 * gravity in its plane; the handle moves 2 cm sideways and 1 cm out of plane in 0.1 s. Runs to
 * 0.2 s with step dt; the ledger into *out. */
static int hanging_run(double dt, plume_energy_ledger *out, double *error)
{
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    plume_index *barbs = NULL, nb = 0, *top = NULL, ntop = 0;
    int ok = 0;
    if (plume_patch_mesh(0.1, 0.13, 45.0, 0.02, PLUME_PATCH_ALIGNED, 3, &mesh, &err) != PLUME_OK)
        goto done;
    plume_vane vane;
    plume_vane_default(&vane);
    vane.moduli.E_yy = vane.moduli.G_xy = 1e3;
    vane.moduli.E_xx = 1e7;
    vane.h = 1e-4;
    if (plume_problem_create(mesh->nv, 3, 0.13, &p, &err) != PLUME_OK ||
        plume_vane_add(p, mesh, &vane, &barbs, &nb, &err) != PLUME_OK)
        goto done;
    memcpy(plume_problem_x(p), mesh->x, (size_t)(3 * mesh->nv) * sizeof(double));
    top = malloc((size_t)mesh->nv * sizeof *top);
    for (plume_index v = 0; v < mesh->nv; v++)
        if (fabs(mesh->X[2 * v + 1] - 0.13) < 1e-12)
            top[ntop++] = v;
    const double times[2] = {0.0, 0.1}, offsets[6] = {0, 0, 0, 0.02, 0, 0.01};
    plume_handle handle = {.nvertices = ntop, .vertices = top, .nkeys = 2, .times = times, .offsets = offsets};
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = dt;
    o.gravity[0] = 0.0, o.gravity[1] = -9.81, o.gravity[2] = 0.0;
    const double rho = 0.026;
    if (plume_dynamics_create(mesh, p, &rho, 1, &handle, 1, &o, &d, &err) != PLUME_OK)
        goto done;
    ok = 1;
    while (ok && plume_dynamics_time(d) < 0.2 - 1e-9) {
        plume_step_report rep;
        ok = plume_dynamics_advance(d, 0.0, &rep, &err) == PLUME_OK && rep.converged;
    }
    *out = *plume_dynamics_energy(d);
    *error = plume_ledger_error(out);
done:
    if (!ok)
        fprintf(stderr, "    hanging vane: %s\n", err.msg);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    free(barbs);
    free(top);
    return ok;
}

void test_dynamics_energy_hanging(void)
{
    const double dts[3] = {0.01, 0.005, 0.0025};
    double numerical[3] = {0}, errors[3] = {0};
    for (int k = 0; k < 3; k++) {
        plume_energy_ledger l;
        CHECK(hanging_run(dts[k], &l, &errors[k]));
        numerical[k] = l.numerical;
        printf("    dt %.4g s: work %.6g J = kinetic %+.6g + potential %+.6g + numerical %.6g (error %.2e)\n", dts[k],
               l.work, l.ke - l.ke0, l.u - l.u0, l.numerical, errors[k]);
        CHECK(l.work > 0.0 && l.numerical > 0.0 && l.commits == 0.0);
        CHECK(fabs(errors[k]) < 1e-2);
    }
    /* implicit Euler's dissipation falls with the step (not in proportion: the handle starts and stops
     * at once, and the velocity jumps there cost the same at any step), and the balance's error, the
     * trapezoidal rule's, falls too */
    CHECK(numerical[1] < numerical[0] && numerical[2] < numerical[1]);
    CHECK(fabs(errors[1]) < fabs(errors[0]) && fabs(errors[2]) < fabs(errors[1]));
}
