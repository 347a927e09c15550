/* Implicit Euler as a constrained minimisation: free fall, the barb constraint in every step,
 * halving of failed steps, and restart from a saved state. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../lib/plume.h"
#include "../lib/dynamics.h"

/* Free fall: with only inertia and gravity, implicit Euler gives v_n = n dt g and
 * z_n = dt^2 g n (n + 1) / 2 exactly. */
void test_dynamics_free_fall(void)
{
    plume_mesh *mesh = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 0.0, 0.5, PLUME_PATCH_UNALIGNED, 3, &mesh, &err) == PLUME_OK);
    plume_problem *p = NULL;
    CHECK(plume_problem_create(mesh->nv, 3, 1.0, &p) == PLUME_OK);
    memcpy(plume_problem_x(p), mesh->x, (size_t)(3 * mesh->nv) * sizeof(double));
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = 0.01;
    double rho = 0.026;
    plume_dynamics *d = NULL;
    CHECK(plume_dynamics_create(mesh, p, &rho, 1, NULL, 0, &o, &d, &err) == PLUME_OK);
    double mass = 0.0;
    for (plume_index v = 0; v < mesh->nv; v++)
        mass += plume_dynamics_masses(d)[v];
    CHECK_REL(mass, rho * 1.0, 1e-12, 0.0); /* lumped masses add up to the total */
    for (int n = 1; n <= 5; n++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(d, 0.0, &rep) == PLUME_OK && rep.converged && rep.substeps == 1);
        const double *x = plume_dynamics_positions(d), *v = plume_dynamics_velocities(d);
        CHECK_REL(v[3 * 2 + 2], -9.81 * n * o.dt, 1e-9, 1e-12);
        CHECK_REL(x[3 * 2 + 2], -9.81 * o.dt * o.dt * n * (n + 1) / 2.0, 1e-9, 1e-12);
    }
    CHECK_REL(plume_dynamics_time(d), 0.05, 1e-12, 0.0);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
}

/* A vane sheet hanging from a handle along its top edge, barbs at 45 deg inextensible, under
 * gravity in its plane and a sideways pull of the handle. */
typedef struct {
    plume_mesh *mesh;
    plume_problem *p;
    plume_dynamics *d;
    plume_index *barbs, nb, *top, ntop;
} hanging;

static void hanging_free(hanging *h)
{
    plume_dynamics_destroy(&h->d);
    plume_problem_destroy(&h->p);
    plume_mesh_destroy(&h->mesh);
    free(h->barbs);
    free(h->top);
}

static int hanging_build(hanging *h, int max_iter, double dt)
{
    memset(h, 0, sizeof *h);
    plume_err err = {{0}};
    if (plume_patch_mesh(0.1, 0.13, 45.0, 0.02, PLUME_PATCH_ALIGNED, 3, &h->mesh, &err) != PLUME_OK)
        return 0;
    plume_vane vane;
    plume_vane_default(&vane);
    vane.moduli.E_yy = vane.moduli.G_xy = 1e3;
    vane.moduli.E_xx = 1e7;
    vane.h = 1e-4;
    if (plume_problem_create(h->mesh->nv, 3, 0.13, &h->p) != PLUME_OK ||
        plume_vane_add(h->p, h->mesh, &vane, &h->barbs, &h->nb, &err) != PLUME_OK)
        return 0;
    memcpy(plume_problem_x(h->p), h->mesh->x, (size_t)(3 * h->mesh->nv) * sizeof(double));
    h->top = malloc((size_t)h->mesh->nv * sizeof *h->top);
    for (plume_index v = 0; v < h->mesh->nv; v++)
        if (fabs(h->mesh->X[2 * v + 1] - 0.13) < 1e-12)
            h->top[h->ntop++] = v;
    const double times[2] = {0.0, 0.1}, offsets[6] = {0, 0, 0, 0.02, 0, 0.01};
    plume_handle handle = {h->ntop, h->top, 2, times, offsets};
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = dt;
    o.gravity[0] = 0.0, o.gravity[1] = -9.81, o.gravity[2] = 0.0;
    o.solver_opts.max_iter = max_iter;
    double rho = 0.026;
    return plume_dynamics_create(h->mesh, h->p, &rho, 1, &handle, 1, &o, &h->d, &err) == PLUME_OK;
}

void test_dynamics_constraint_every_step(void)
{
    hanging h;
    CHECK(hanging_build(&h, 100, 0.01));
    if (!h.d) {
        hanging_free(&h);
        return;
    }
    double worst = 0.0;
    for (int n = 0; n < 10; n++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(h.d, 0.0, &rep) == PLUME_OK && rep.converged);
        CHECK(rep.max_violation <= 1e-8);
        const double *x = plume_dynamics_positions(h.d);
        for (plume_index e = 0; e < h.nb; e++) { /* edge by edge, in 3D */
            plume_index i = h.barbs[2 * e], j = h.barbs[2 * e + 1];
            double L = hypot(h.mesh->X[2 * i] - h.mesh->X[2 * j], h.mesh->X[2 * i + 1] - h.mesh->X[2 * j + 1]);
            double l = sqrt(pow(x[3 * i] - x[3 * j], 2) + pow(x[3 * i + 1] - x[3 * j + 1], 2) + pow(x[3 * i + 2] - x[3 * j + 2], 2));
            worst = fmax(worst, fabs(l - L) / L);
        }
    }
    CHECK(worst <= 1e-8);
    /* the handle moved the top edge to its last keyframe */
    const double *x = plume_dynamics_positions(h.d);
    CHECK_REL(x[3 * h.top[0]], h.mesh->X[2 * h.top[0]] + 0.02, 1e-12, 1e-12);
    CHECK_REL(x[3 * h.top[0] + 2], 0.01, 1e-12, 0.0);
    hanging_free(&h);
}

/* A solver capped at 2 iterations cannot take the full step: it is halved and retried, the
 * report says so, and the substeps still satisfy the constraint. */
void test_dynamics_halving(void)
{
    hanging h;
    CHECK(hanging_build(&h, 6, 0.05));
    if (!h.d) {
        hanging_free(&h);
        return;
    }
    plume_step_report rep;
    CHECK(plume_dynamics_advance(h.d, 0.0, &rep) == PLUME_OK);
    fprintf(stderr, "    halvings %d, substeps %d, converged %d (%s)\n", rep.halvings, rep.substeps, rep.converged,
            plume_reason_name(rep.reason));
    CHECK(rep.halvings > 0);
    CHECK(rep.converged && rep.substeps >= 2 && rep.max_violation <= 1e-8);
    CHECK(rep.reason == PLUME_REASON_ITERATION_CAP); /* what stopped the first, failed attempt */
    if (rep.converged)
        CHECK_REL(plume_dynamics_time(h.d), 0.05, 1e-12, 0.0);
    hanging_free(&h);
}

/* Six steps straight, or three, a save, a new simulation restored from the save, three more:
 * the same state. */
void test_dynamics_restart(void)
{
    hanging a, b;
    CHECK(hanging_build(&a, 100, 0.01));
    CHECK(hanging_build(&b, 100, 0.01));
    if (!a.d || !b.d) {
        hanging_free(&a);
        hanging_free(&b);
        return;
    }
    plume_step_report rep;
    for (int n = 0; n < 6; n++)
        CHECK(plume_dynamics_advance(a.d, 0.0, &rep) == PLUME_OK && rep.converged);
    for (int n = 0; n < 3; n++)
        CHECK(plume_dynamics_advance(b.d, 0.0, &rep) == PLUME_OK && rep.converged);
    size_t nd = (size_t)(3 * b.mesh->nv);
    plume_index m;
    const double *lam = plume_dynamics_multipliers(b.d, &m);
    double t = plume_dynamics_time(b.d), *x = malloc(nd * sizeof *x), *v = malloc(nd * sizeof *v),
           *l = malloc((size_t)(m + 1) * sizeof *l);
    memcpy(x, plume_dynamics_positions(b.d), nd * sizeof *x);
    memcpy(v, plume_dynamics_velocities(b.d), nd * sizeof *v);
    memcpy(l, lam, (size_t)m * sizeof *l);
    hanging_free(&b);
    CHECK(hanging_build(&b, 100, 0.01));
    CHECK(plume_dynamics_set_state(b.d, t, x, v, l) == PLUME_OK);
    for (int n = 0; n < 3; n++)
        CHECK(plume_dynamics_advance(b.d, 0.0, &rep) == PLUME_OK && rep.converged);
    double worst = 0.0;
    for (size_t i = 0; i < nd; i++)
        worst = fmax(worst, fabs(plume_dynamics_positions(a.d)[i] - plume_dynamics_positions(b.d)[i]));
    CHECK(worst <= 1e-12);
    CHECK_REL(plume_dynamics_time(b.d), plume_dynamics_time(a.d), 1e-14, 0.0);
    free(x), free(v), free(l);
    hanging_free(&a);
    hanging_free(&b);
}
