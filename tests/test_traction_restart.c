/* The traction run's checkpoint and restart (lib/sim/traction_checkpoint.c): a micro specimen held
 * by hooks, loaded, unloaded and reloaded, stopped in the middle of the unloading leg and restarted
 * from its checkpoint, ends bit for bit where the run that never stopped does: the curve, the
 * counts, the energies, the hooks' state and the table of their states at every point. What a run
 * cannot continue from is refused by name. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "../include/plume/homogenize.h"
#include "../include/plume/traction.h"
#include "../lib/core/problem.h"
#include "../micro/micro_model.h"

static const double cycle_path[3] = {0.03, 0.0, 0.03};

/* steps a leg */
#define LEG_STEPS 4

/* the specimen's size: make asan's sanitised build (PLUME_TEST_SMALL) runs a specimen half as wide
 * and long, the same code at an eighth of the cost */
static double size_scale(void)
{
    return getenv("PLUME_TEST_SMALL") ? 0.5 : 1.0;
}

/* on_step: the steps a run solved, first and count */
typedef struct {
    int first, count;
} steps_seen;

static plume_status count_step(void *user, int step, double strain, const double *x)
{
    (void)strain, (void)x;
    steps_seen *s = user;
    if (s->count++ == 0)
        s->first = step;
    return PLUME_OK;
}

/* The Table 3 (a) specimen at 45 deg with 50 mN hooks that catch again within 20 um (as
 * test_micro_hooks_cycle), built afresh. */
static void specimen(plume_layout *l, plume_mesh **mesh, plume_problem **p)
{
    plume_err err = {{0}};
    plume_layout_default(l);
    CHECK(plume_layout_load_json("../data/layout_barbules_table3a.json", l, &err) == PLUME_OK);
    l->hooks.strength = 5e-2, l->hooks.opening = l->hooks.strength / 1e8, l->hooks.capture = 2e-5;
    CHECK(plume_micro_specimen(l, 4e-3 * size_scale(), 5.2e-3 * size_scale(), 45.0, mesh, p, &err) == PLUME_OK);
}

/* One run of the cycle, 4 steps a leg: checkpoint, restart and stop_after as given; the hooks'
 * final state into *state (allocated, *ns values). Returns the run's status. */
static plume_status cycle(const char *checkpoint, const char *restart, int stop_after, plume_traction_result *r,
                          double **state, plume_index *ns, steps_seen *seen, plume_err *err)
{
    plume_layout l;
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    specimen(&l, &mesh, &p);
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 4e-3 * size_scale(), o.ly = 5.2e-3 * size_scale(), o.h = l.h, o.steps = LEG_STEPS, o.progress = 0;
    o.path = cycle_path, o.npath = 3;
    o.checkpoint = checkpoint, o.restart = restart, o.stop_after = stop_after;
    o.on_step = count_step, o.on_step_user = seen;
    memset(seen, 0, sizeof *seen);
    memset(r, 0, sizeof *r);
    plume_status st = plume_traction_run(mesh, p, NULL, 0, &o, r, err);
    if (state) {
        *ns = plume_problem_state_size(p);
        *state = malloc((size_t)(*ns + 1) * sizeof **state);
        plume_problem_state_get(p, *state);
    }
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return st;
}

static int same_doubles(const double *a, const double *b, plume_index n)
{
    return memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

/* The per-point hooks table of a checkpoint (allocated), its rows and columns. */
static int *checkpoint_states(const char *path, long *rows, plume_index *cols)
{
    plume_err err = {{0}};
    CHECK(plume_traction_checkpoint_states(path, "hooks", NULL, rows, cols, &err) == PLUME_OK);
    int *s = malloc((size_t)(*rows * *cols + 1) * sizeof *s);
    CHECK(plume_traction_checkpoint_states(path, "hooks", s, rows, cols, &err) == PLUME_OK);
    return s;
}

void test_traction_restart_bit_for_bit(void)
{
    char whole[64], part[64];
    snprintf(whole, sizeof whole, "/tmp/plume_restart_whole_%ld.h5", (long)getpid());
    snprintf(part, sizeof part, "/tmp/plume_restart_part_%ld.h5", (long)getpid());
    plume_err err = {{0}};
    plume_traction_result a, b, c;
    double *sa = NULL, *sc = NULL;
    plume_index na = 0, nc = 0;
    steps_seen seen;
    const int ns = LEG_STEPS, npts = 3 * ns + 1, stop = ns + ns / 2;
    CHECK(cycle(whole, NULL, 0, &a, &sa, &na, &seen, &err) == PLUME_OK);
    CHECK(a.converged && a.curve.n == npts && a.released > 0 && a.reengaged > 0);
    CHECK(seen.first == 0 && seen.count == npts);
    /* stopped in the middle of the unloading leg, after releases */
    CHECK(cycle(part, NULL, stop, &b, NULL, NULL, &seen, &err) == PLUME_OK);
    CHECK(b.converged && b.curve.n == stop + 1 && seen.count == stop + 1);
    CHECK(b.curve.n == stop + 1 && same_doubles(a.curve.stress, b.curve.stress, stop + 1));
    /* restarted from it, checkpointing on to the same file */
    CHECK(cycle(part, part, 0, &c, &sc, &nc, &seen, &err) == PLUME_OK);
    CHECK(seen.first == stop + 1 && seen.count == npts - stop - 1); /* only the steps after the checkpoint */
    printf("    whole: %d points, %d iterations, %d cuts, released %ld, caught %ld, dissipated %.6e J\n",
           (int)a.curve.n, a.newton_iterations, a.cuts, a.released, a.reengaged, a.dissipated_energy);
    printf("    restarted after step %d: %d points, %d iterations, %d cuts, released %ld, caught %ld, dissipated "
           "%.6e J\n", (int)stop, (int)c.curve.n, c.newton_iterations, c.cuts, c.released, c.reengaged, c.dissipated_energy);
    CHECK(c.converged && c.curve.n == a.curve.n);
    if (c.curve.n == a.curve.n) {
        CHECK(same_doubles(a.curve.strain, c.curve.strain, a.curve.n));
        CHECK(same_doubles(a.curve.stress, c.curve.stress, a.curve.n));
        CHECK(same_doubles(a.curve.wbar, c.curve.wbar, a.curve.n));
        CHECK(same_doubles(a.curve.iterations, c.curve.iterations, a.curve.n));
    }
    CHECK(a.newton_iterations == c.newton_iterations && a.chord_steps == c.chord_steps && a.cuts == c.cuts &&
          a.overshoot_cuts == c.overshoot_cuts && a.substeps == c.substeps && a.factorizations == c.factorizations);
    CHECK(a.released == c.released && a.reengaged == c.reengaged && a.largest_cascade == c.largest_cascade &&
          a.release_events == c.release_events);
    CHECK(a.work == c.work && a.stored_energy == c.stored_energy && a.dissipated_energy == c.dissipated_energy &&
          a.energy_balance_error == c.energy_balance_error && a.peak_stress == c.peak_stress &&
          a.initial_slope == c.initial_slope && a.max_violation == c.max_violation);
    CHECK(na > 0 && na == nc && same_doubles(sa, sc, na));
    /* the hooks' table at every point, the rest state first */
    long ra = 0, rc = 0;
    plume_index ca = 0, cc = 0;
    int *ta = checkpoint_states(whole, &ra, &ca), *tc = checkpoint_states(part, &rc, &cc);
    CHECK(ra == npts && rc == npts && ca == cc && ca > 0);
    CHECK(ra == rc && ca == cc && memcmp(ta, tc, (size_t)(ra * ca) * sizeof *ta) == 0);
    long engaged_rest = 0, engaged_top = 0;
    for (plume_index j = 0; j < ca; j++)
        engaged_rest += ta[j], engaged_top += ta[ns * ca + j];
    printf("    hooks table: %ld x %ld; pairs engaged at rest %ld, at the top of the first load %ld\n", ra, (long)ca,
           engaged_rest, engaged_top);
    CHECK(engaged_rest == ca && engaged_top < ca);
    free(ta), free(tc), free(sa), free(sc);
    plume_traction_result_free(&a), plume_traction_result_free(&b), plume_traction_result_free(&c);
    remove(whole), remove(part);
}

/* What a run cannot continue from: another schedule (named), a file that is not a checkpoint, a
 * missing table, stop_after < 0. */
void test_traction_restart_refusals(void)
{
    char ck[64], other[64];
    snprintf(ck, sizeof ck, "/tmp/plume_restart_refuse_%ld.h5", (long)getpid());
    snprintf(other, sizeof other, "/tmp/plume_restart_other_%ld.h5", (long)getpid());
    plume_layout l;
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    specimen(&l, &mesh, &p);
    plume_err err = {{0}};
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 4e-3 * size_scale(), o.ly = 5.2e-3 * size_scale(), o.h = l.h, o.steps = 4, o.progress = 0,
    o.strain_max = 0.01, o.checkpoint = ck,
    o.stop_after = 1;
    plume_traction_result r;
    CHECK(plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_OK && r.curve.n == 2);
    plume_traction_result_free(&r);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);

    specimen(&l, &mesh, &p);
    o.checkpoint = NULL, o.restart = ck, o.steps = 5, o.stop_after = 0;
    CHECK(plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_EINVAL);
    printf("    %s\n", err.msg);
    CHECK(strstr(err.msg, "restart: ") == err.msg && strstr(err.msg, ck) && strstr(err.msg, "steps = 4"));
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);

    specimen(&l, &mesh, &p);
    o.steps = 4, o.strain_max = 0.02;
    CHECK(plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "strain_max"));
    o.strain_max = 0.01, o.stop_after = -1, o.restart = NULL;
    CHECK(plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_EINVAL && strstr(err.msg, "stop_after"));
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);

    /* an HDF5 file without a checkpoint, and one that is not HDF5 */
    plume_curve cv = {0};
    double s0[2] = {0, 1}, s1[2] = {0, 2};
    cv.n = 2, cv.strain = s0, cv.stress = s1, cv.wbar = s0, cv.iterations = s0, cv.seconds = s0;
    CHECK(plume_curve_write(other, "micro", "tilted", &cv, NULL, 0, NULL, 0, &err) == PLUME_OK);
    specimen(&l, &mesh, &p);
    o.stop_after = 0, o.restart = other;
    CHECK(plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_EFORMAT && strstr(err.msg, "not a traction checkpoint"));
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    specimen(&l, &mesh, &p);
    o.restart = "../data/layout_hooks.json";
    CHECK(plume_traction_run(mesh, p, NULL, 0, &o, &r, &err) == PLUME_EIO && strstr(err.msg, "layout_hooks.json"));
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    int s[1];
    long rows;
    plume_index cols;
    CHECK(plume_traction_checkpoint_states(ck, "splits", s, &rows, &cols, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "splits"));
    CHECK(plume_traction_checkpoint_states(ck, "a/b", s, &rows, &cols, &err) == PLUME_EINVAL);
    remove(ck), remove(other);
}
