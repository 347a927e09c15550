/* Implicit Euler as a constrained minimisation: free fall, the barb constraint in every step,
 * halving of failed steps, and restart from a saved state. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"
#include "../lib/sim/dynamics.h"
#include "../lib/core/load.h"

/* Free fall: with only inertia and gravity, implicit Euler gives v_n = n dt g and
 * z_n = dt^2 g n (n + 1) / 2 exactly. */
void test_dynamics_free_fall(void)
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
    double rho = 0.026;
    plume_dynamics *d = NULL;
    CHECK(plume_dynamics_create(mesh, p, &rho, 1, NULL, 0, &o, &d, &err) == PLUME_OK);
    double mass = 0.0;
    for (plume_index v = 0; v < mesh->nv; v++)
        mass += plume_dynamics_masses(d)[v];
    CHECK_REL(mass, rho * 1.0, 1e-12, 0.0); /* lumped masses add up to the total */
    for (int n = 1; n <= 5; n++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK && rep.converged && rep.substeps == 1);
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

static int hanging_build_adaptive(hanging *h, int max_iter, double dt, int adaptive, double dt_max, int stall);

static int hanging_build(hanging *h, int max_iter, double dt)
{
    return hanging_build_adaptive(h, max_iter, dt, 0, 0.0, 0);
}

static int hanging_build_adaptive(hanging *h, int max_iter, double dt, int adaptive, double dt_max, int stall)
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
    if (plume_problem_create(h->mesh->nv, 3, 0.13, &h->p, &err) != PLUME_OK ||
        plume_vane_add(h->p, h->mesh, &vane, &h->barbs, &h->nb, &err) != PLUME_OK)
        return 0;
    memcpy(plume_problem_x(h->p), h->mesh->x, (size_t)(3 * h->mesh->nv) * sizeof(double));
    h->top = malloc((size_t)h->mesh->nv * sizeof *h->top);
    for (plume_index v = 0; v < h->mesh->nv; v++)
        if (fabs(h->mesh->X[2 * v + 1] - 0.13) < 1e-12)
            h->top[h->ntop++] = v;
    const double times[2] = {0.0, 0.1}, offsets[6] = {0, 0, 0, 0.02, 0, 0.01};
    plume_handle handle = {.nvertices = h->ntop, .vertices = h->top, .nkeys = 2, .times = times, .offsets = offsets};
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = dt;
    o.gravity[0] = 0.0, o.gravity[1] = -9.81, o.gravity[2] = 0.0;
    o.solver_opts.max_iter = max_iter;
    o.adaptive = adaptive;
    o.dt_max = dt_max;
    if (stall > 0)
        o.stall_iterations = stall;
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
        CHECK(plume_dynamics_advance(h.d, 0.0, &rep, NULL) == PLUME_OK && rep.converged);
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
    CHECK(plume_dynamics_advance(h.d, 0.0, &rep, NULL) == PLUME_OK);
    fprintf(stderr, "    halvings %d, substeps %d, converged %d (%s)\n", rep.halvings, rep.substeps, rep.converged,
            plume_reason_name(rep.reason));
    CHECK(rep.halvings > 0);
    CHECK(rep.converged && rep.substeps >= 2 && rep.max_violation <= 1e-8);
    CHECK(rep.reason == PLUME_REASON_ITERATION_CAP); /* what stopped the first, failed attempt */
    if (rep.converged)
        CHECK_REL(plume_dynamics_time(h.d), 0.05, 1e-12, 0.0);
    hanging_free(&h);
}

/* Adaptive steps: each advance lands on its nominal time exactly, whatever steps it took inside
 * (here they grow from dt to dt_max, so fewer than interval / dt), and the constraint holds. */
void test_dynamics_adaptive_frames(void)
{
    hanging h;
    CHECK(hanging_build_adaptive(&h, 100, 0.005, 1, 0.02, 0));
    if (!h.d) {
        hanging_free(&h);
        return;
    }
    int substeps = 0;
    double grown = 0.0;
    for (int k = 1; k <= 4; k++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(h.d, 0.025, &rep, NULL) == PLUME_OK && rep.converged);
        CHECK(rep.max_violation <= 1e-8);
        CHECK(plume_dynamics_time(h.d) == 0.025 * k); /* the nominal time, not a sum of steps */
        CHECK(rep.dt_max <= 0.02 * (1.0 + 1e-12) && rep.dt_min > 0.0);
        substeps += rep.substeps;
        grown = fmax(grown, rep.dt_max);
    }
    fprintf(stderr, "    %d steps for 4 intervals of 5 dt, the largest %g s\n", substeps, grown);
    CHECK(grown > 0.005 * 1.5);
    CHECK(substeps < 20);
    hanging_free(&h);
}

/* The stalling case: a step of 0.05 s is too large for the sheet (test_dynamics_halving). With
 * adaptive steps the solver gives up after 2 non-contracting iterations, far below the cap of 100,
 * and the step is cut; the interval is still covered and every step converged. */
void test_dynamics_adaptive_stall(void)
{
    hanging h;
    CHECK(hanging_build_adaptive(&h, 100, 0.05, 1, 0.0, 2));
    if (!h.d) {
        hanging_free(&h);
        return;
    }
    plume_step_report rep;
    CHECK(plume_dynamics_advance(h.d, 0.0, &rep, NULL) == PLUME_OK);
    fprintf(stderr, "    cuts %d, stalls %d, steps %d, iterations %d, converged %d (first failure: %s)\n", rep.halvings,
            rep.stalls, rep.substeps, rep.iterations, rep.converged, plume_reason_name(rep.reason));
    CHECK(rep.halvings > 0 && rep.stalls > 0);
    CHECK(rep.reason == PLUME_REASON_STALLED); /* not the iteration cap */
    CHECK(rep.converged && rep.max_violation <= 1e-8);
    CHECK(plume_dynamics_time(h.d) == 0.05);
    CHECK(rep.dt_min < 0.05);
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
        CHECK(plume_dynamics_advance(a.d, 0.0, &rep, NULL) == PLUME_OK && rep.converged);
    for (int n = 0; n < 3; n++)
        CHECK(plume_dynamics_advance(b.d, 0.0, &rep, NULL) == PLUME_OK && rep.converged);
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
    /* bad input is refused with a message naming it, and the state is left alone */
    plume_err why = {{0}};
    double keep = x[4];
    x[4] = NAN;
    CHECK(plume_dynamics_set_state(b.d, t, x, v, l, &why) == PLUME_EINVAL && strstr(why.msg, "vertex 1"));
    x[4] = keep;
    CHECK(plume_dynamics_set_state(b.d, INFINITY, x, v, l, &why) == PLUME_EINVAL && strstr(why.msg, "time"));
    CHECK(plume_dynamics_advance(b.d, NAN, &rep, &why) == PLUME_EINVAL && strstr(why.msg, "finite"));
    CHECK(plume_dynamics_time(b.d) == 0.0);
    CHECK(plume_dynamics_set_state(b.d, t, x, v, l, NULL) == PLUME_OK);
    for (int n = 0; n < 3; n++)
        CHECK(plume_dynamics_advance(b.d, 0.0, &rep, NULL) == PLUME_OK && rep.converged);
    double worst = 0.0;
    for (size_t i = 0; i < nd; i++)
        worst = fmax(worst, fabs(plume_dynamics_positions(a.d)[i] - plume_dynamics_positions(b.d)[i]));
    CHECK(worst <= 1e-12);
    CHECK_REL(plume_dynamics_time(b.d), plume_dynamics_time(a.d), 1e-14, 0.0);
    free(x), free(v), free(l);
    hanging_free(&a);
    hanging_free(&b);
}

/* Finite differences of an assembled problem at u: gradient against energy, Hessian (upper CSC,
 * symmetric) applied to a direction against gradient differences. Returns the relative errors. */
static void problem_fd(plume_problem *p, const double *u, double *gerr, double *herr)
{
    plume_index n = plume_problem_nfree(p);
    plume_sparsity sp = plume_problem_hessian_pattern(p);
    double *g = malloc((size_t)n * sizeof *g), *g1 = malloc((size_t)n * sizeof *g1), *g2 = malloc((size_t)n * sizeof *g2);
    double *up = malloc((size_t)n * sizeof *up), *dir = malloc((size_t)n * sizeof *dir), *Hd = calloc((size_t)n, sizeof *Hd);
    double *H = malloc((size_t)sp.nnz * sizeof *H), f, fp, fm, h = 1e-7;
    plume_problem_objective(p, u, &f, g);
    plume_problem_hessian(p, u, 1.0, NULL, 0, H);
    double gs = 0.0, ge = 0.0;
    for (plume_index i = 0; i < n; i += (n > 40 ? n / 40 : 1)) {
        memcpy(up, u, (size_t)n * sizeof *up);
        up[i] = u[i] + h;
        plume_problem_objective(p, up, &fp, NULL);
        up[i] = u[i] - h;
        plume_problem_objective(p, up, &fm, NULL);
        ge = fmax(ge, fabs((fp - fm) / (2 * h) - g[i]));
        gs = fmax(gs, fabs(g[i]));
    }
    for (plume_index i = 0; i < n; i++)
        dir[i] = sin(1.7 * (double)i + 0.3);
    for (plume_index c = 0; c < n; c++)
        for (plume_index k = sp.colptr[c]; k < sp.colptr[c + 1]; k++) {
            plume_index r = sp.rowind[k];
            Hd[r] += H[k] * dir[c];
            if (r != c)
                Hd[c] += H[k] * dir[r];
        }
    for (plume_index i = 0; i < n; i++)
        up[i] = u[i] + h * dir[i];
    plume_problem_objective(p, up, &fp, g1);
    for (plume_index i = 0; i < n; i++)
        up[i] = u[i] - h * dir[i];
    plume_problem_objective(p, up, &fm, g2);
    double he = 0.0, hs = 0.0;
    for (plume_index i = 0; i < n; i++) {
        he = fmax(he, fabs((g1[i] - g2[i]) / (2 * h) - Hd[i]));
        hs = fmax(hs, fabs(Hd[i]));
    }
    *gerr = ge / gs;
    *herr = he / hs;
    free(g), free(g1), free(g2), free(up), free(dir), free(Hd), free(H);
}

/* The inertia-and-gravity term (with the membrane and bending-free sheet around it) and the
 * dead-load term: derivatives of the assembled problem against central differences. */
void test_dynamics_terms_fd(void)
{
    hanging h;
    CHECK(hanging_build(&h, 100, 0.01));
    if (!h.d) {
        hanging_free(&h);
        return;
    }
    plume_step_report rep;
    CHECK(plume_dynamics_advance(h.d, 0.0, &rep, NULL) == PLUME_OK); /* x~ and dt set, a deformed state */
    plume_index n = plume_problem_nfree(h.p);
    double *u = malloc((size_t)n * sizeof *u), ge, he;
    plume_problem_gather(h.p, u);
    for (plume_index i = 0; i < n; i++)
        u[i] += 1e-3 * cos(0.9 * (double)i);
    problem_fd(h.p, u, &ge, &he);
    fprintf(stderr, "    inertia + gravity + membrane: gradient %.2e, Hessian %.2e\n", ge, he);
    CHECK(ge < 1e-6 && he < 1e-5);
    free(u);
    hanging_free(&h);

    /* dead loads on a membrane patch */
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 30.0, 0.25, PLUME_PATCH_ALIGNED, 3, &mesh, &err) == PLUME_OK);
    plume_membrane_material mat = {{5.0, 2.0, 0.1, 1.0}, 0.1, 10.0, 0};
    plume_term mem, load;
    const plume_index v[2] = {1, 2};
    const double f[6] = {0.3, -0.2, 0.5, -0.1, 0.4, 0.2};
    CHECK(plume_problem_create(mesh->nv, 3, 1.0, &p, &err) == PLUME_OK);
    CHECK(plume_membrane_term_create(mesh, 3, &mat, 1, &mem, &err) == PLUME_OK && plume_problem_add_term(p, &mem, &err) == PLUME_OK);
    CHECK(plume_load_term_create(v, 2, 3, f, &load, &err) == PLUME_OK && plume_problem_add_term(p, &load, &err) == PLUME_OK);
    memcpy(plume_problem_x(p), mesh->x, (size_t)(3 * mesh->nv) * sizeof(double));
    for (int a = 0; a < 3; a++)
        plume_problem_fix_dof(p, a, &err);
    CHECK(plume_problem_finalize(p, &err) == PLUME_OK);
    n = plume_problem_nfree(p);
    u = malloc((size_t)n * sizeof *u);
    plume_problem_gather(p, u);
    for (plume_index i = 0; i < n; i++)
        u[i] += 0.05 * sin(1.3 * (double)i);
    problem_fd(p, u, &ge, &he);
    fprintf(stderr, "    load + membrane: gradient %.2e, Hessian %.2e\n", ge, he);
    CHECK(ge < 1e-6 && he < 1e-5);
    const double bad[3] = {NAN, 0, 0};
    CHECK(plume_load_term_create(v, 1, 3, bad, &load, &err) == PLUME_EINVAL && strstr(err.msg, "not finite"));
    free(u);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
}
