/* The scene runner (macro/scene/run.h): a run's frames are apps/feather's byte for byte (a static
 * scene's series apps/shell's), a restart after
 * N frames is the straight run bit for bit, the acceptance rule for each solver kind, and bad
 * options named. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "app_runner.h"
#include "../lib/io/frames.h"
#include "../macro/scene/run.h"

#define STRIP "../data/shell/strip_scene.json"

/* 1 when the files a and b hold the same bytes */
static int same_bytes(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        same = ca == cb;
        if (ca == EOF || cb == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

/* 1 when frame k of the frames files a and b is the same bit for bit (t, step, x, v, lambda) */
static int same_frame(const char *a, long ka, const char *b, long kb)
{
    plume_frame fa = {0}, fb = {0};
    int same = plume_frames_read(a, ka, &fa, NULL) == PLUME_OK && plume_frames_read(b, kb, &fb, NULL) == PLUME_OK &&
               fa.nv == fb.nv && fa.ncons == fb.ncons && fa.step == fb.step && fa.index == fb.index &&
               memcmp(&fa.t, &fb.t, sizeof fa.t) == 0 &&
               memcmp(fa.x, fb.x, 3 * (size_t)fa.nv * sizeof *fa.x) == 0 &&
               memcmp(fa.v, fb.v, 3 * (size_t)fa.nv * sizeof *fa.v) == 0 &&
               (fa.ncons == 0 || memcmp(fa.lambda, fb.lambda, (size_t)fa.ncons * sizeof *fa.lambda) == 0);
    plume_frame_free(&fa);
    plume_frame_free(&fb);
    return same;
}

static void remove_tree(const char *dir)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

/* A run of `path` into dir with the options' plan; the run's report into *rep (may be NULL). */
static plume_status run_scene(const char *path, const char *dir, long frames, const char *restart, int solver,
                              plume_run_report *rep, plume_err *err)
{
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.output_dir = dir;
    o.frames = frames;
    o.restart = restart;
    o.solver = solver;
    plume_run *r = NULL;
    plume_status st = plume_run_open(path, &o, &r, err);
    if (st == PLUME_OK)
        st = plume_run_to_end(r, err);
    if (rep)
        plume_run_get_report(r, rep);
    plume_run_destroy(&r);
    return st;
}

/* The strip stepped by the runner and by apps/feather: the same frames file, series and render. */
void test_run_matches_app(void)
{
    char dir[64] = "/tmp/plume-run-XXXXXX", args[512], out[8192], errs[8192], a[256], b[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "%s -o %s/app --frames 3 --quiet", STRIP, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(a, sizeof a, "%s/lib", dir);
    plume_err err = {{0}};
    plume_run_report rep;
    CHECK(run_scene(STRIP, a, 3, NULL, -1, &rep, &err) == PLUME_OK);
    CHECK(rep.frames == 4 && rep.next_frame == 4 && rep.steps == 6 && rep.step == 6 && rep.planned_steps == 6);
    CHECK(rep.converged && !rep.stopped && rep.stop_reason == PLUME_REASON_CONVERGED && rep.iterations > 0);
    CHECK(fabs(rep.time - 0.06) < 1e-12 && !rep.audited && rep.restart_dt == 0.0);
    snprintf(a, sizeof a, "%s/app/frames.h5", dir);
    snprintf(b, sizeof b, "%s/lib/frames.h5", dir);
    for (long k = 0; k < 4; k++)
        CHECK(same_frame(a, k, b, k));
    const char *files[] = {"frames.pvd", "frame_00000.vtu", "frame_00003.vtu", "frame_barbs_00003.vtu",
                           "frame_00000.png"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(a, sizeof a, "%s/app/%s", dir, files[i]);
        snprintf(b, sizeof b, "%s/lib/%s", dir, files[i]);
        CHECK(access(a, R_OK) == 0 && same_bytes(a, b));
    }
    remove_tree(dir);
}

/* 4 frames straight against 2 frames, the run destroyed, and 2 more from its frames file: the same
 * last frame bit for bit, and the same series file for frame 4. */
void test_run_restart(void)
{
    char dir[64] = "/tmp/plume-runr-XXXXXX", s[128], h[128], a[512], b[512];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(s, sizeof s, "%s/straight", dir);
    snprintf(h, sizeof h, "%s/half", dir);
    plume_err err = {{0}};
    plume_run_report rep;
    CHECK(run_scene(STRIP, s, 4, NULL, -1, NULL, &err) == PLUME_OK);
    CHECK(run_scene(STRIP, h, 2, NULL, -1, NULL, &err) == PLUME_OK);
    snprintf(a, sizeof a, "%s/frames.h5", h);
    CHECK(run_scene(STRIP, h, 2, a, -1, &rep, &err) == PLUME_OK);
    CHECK(rep.step == 8 && rep.steps == 4 && rep.frames == 2 && rep.next_frame == 5 && rep.restart_dt == 0.01);
    snprintf(b, sizeof b, "%s/frames.h5", s);
    for (long k = 0; k <= 4; k++)
        CHECK(same_frame(a, k, b, k));
    snprintf(a, sizeof a, "%s/frame_00004.vtu", h);
    snprintf(b, sizeof b, "%s/frame_00004.vtu", s);
    CHECK(same_bytes(a, b));
    /* restarting into another directory copies the frames file there and goes on */
    snprintf(a, sizeof a, "%s/frames.h5", s);
    snprintf(b, sizeof b, "%s/other", dir);
    CHECK(run_scene(STRIP, b, 1, a, -1, &rep, &err) == PLUME_OK && rep.next_frame == 6);
    snprintf(b, sizeof b, "%s/other/frames.h5", dir);
    plume_frames_info info;
    CHECK(plume_frames_info_read(b, &info, &err) == PLUME_OK && info.count == 6);
    CHECK(same_frame(a, 4, b, 4));
    /* restart without frames: the state only */
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.restart = a;
    o.open = 1;
    plume_run *r = NULL;
    CHECK(plume_run_open(STRIP, &o, &r, &err) == PLUME_OK && plume_run_start(r, &err) == PLUME_OK);
    CHECK(r && fabs(plume_run_time(r) - 0.08) < 1e-12 && plume_run_frames_path(r) == NULL);
    plume_run_destroy(&r);
    remove_tree(dir);
}

/* The prescribed crossing of the scene objects' test: a ground that rises through a plate at t =
 * 0.01 s, so that step 3 cannot start at any halving. */
static void write_crossing(const char *dir, const char *solver, char *path, size_t n)
{
    char obj[256];
    snprintf(obj, sizeof obj, "%s/ground.obj", dir);
    FILE *f = fopen(obj, "w");
    if (f) {
        fputs("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n", f);
        fclose(f);
    }
    snprintf(path, n, "%s/%s.json", dir, solver);
    f = fopen(path, "w");
    if (!f)
        return;
    fprintf(f,
            "{\"objects\": [{\"name\": \"ground\", \"kinematic\": {\"obj\": \"ground.obj\", \"keyframes\": "
            "[[0, 0, 0, 0], [0.01, 0, 0, 0], [0.015, 0, 0, 0.5]]}},"
            "{\"name\": \"plate\", \"mesh\": {\"rectangle\": [0.1, 0.1], \"edge\": 0.05, \"pattern\": \"grid\"},"
            " \"place\": {\"translate\": [-0.05, -0.05, 0.002]}}],"
            "\"materials\": [{\"membrane\": {\"E\": 1e9, \"nu\": 0.3, \"thickness\": 1e-3}, \"density\": 1.0}],"
            "\"contact\": {\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 10}, \"solver\": \"%s\","
            "\"gravity\": [0, 0, 0], \"dt\": 0.005, \"duration\": 0.015, \"max_halvings\": 4}",
            solver);
    fclose(f);
}

/* The rule for each solver kind, then on scenes: linearized steps that advance are accepted
 * (unconverged by design), a step that does not advance is refused by every solver. */
void test_run_acceptance(void)
{
    plume_step_report conv = {.converged = 1}, unconv = {.converged = 0};
    const double dt = 0.01;
    for (int k = PLUME_SOLVER_NEWTON; k <= PLUME_SOLVER_LINEARIZED; k++) {
        const int lin = k == PLUME_SOLVER_LINEARIZED;
        CHECK(plume_run_accepts(k, &conv, 0.1, dt, 0.11, dt) == 1);
        CHECK(plume_run_accepts(k, &conv, 0.1, dt, 0.1, dt) == 1); /* a converged step is its own judge */
        CHECK(plume_run_accepts(k, &unconv, 0.1, dt, 0.11, dt) == lin);
        CHECK(plume_run_accepts(k, &unconv, 0.1, dt, 0.11 + 1e-13, dt) == lin); /* round-off */
        CHECK(plume_run_accepts(k, &unconv, 0.1, dt, 0.105, dt) == 0);           /* halved, not all the way */
        CHECK(plume_run_accepts(k, &unconv, 0.1, dt, 0.1, dt) == 0);             /* did not advance */
    }
    char dir[64] = "/tmp/plume-runa-XXXXXX", path[256], out[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_err err = {{0}};
    plume_run_report rep;
    snprintf(out, sizeof out, "%s/lin", dir);
    CHECK(run_scene(STRIP, out, 2, NULL, PLUME_SOLVER_LINEARIZED, &rep, &err) == PLUME_OK);
    CHECK(!rep.stopped && !rep.converged && rep.steps == 4 && rep.frames == 3);
    const char *solvers[] = {"linearized", "newton"};
    for (int i = 0; i < 2; i++) {
        write_crossing(dir, solvers[i], path, sizeof path);
        snprintf(out, sizeof out, "%s/out_%s", dir, solvers[i]);
        CHECK(run_scene(path, out, 0, NULL, -1, &rep, &err) == PLUME_OK);
        CHECK(rep.stopped && rep.stop_reason == PLUME_REASON_PRESCRIBED_CROSSING && rep.stop_step == 3);
        CHECK(rep.steps == 2 && rep.step == 2 && rep.next_frame == 3 && rep.stop_halvings == 4 && !rep.converged);
        CHECK(fabs(rep.time - 0.01) < 1e-15 && fabs(rep.stop_time - 0.01) < 1e-15 && rep.planned_steps == 3);
        CHECK(strstr(rep.stop_detail, "'ground'") && strstr(rep.stop_detail, "'plate'"));
        CHECK(rep.audited && rep.min_distance > 0.0 && rep.min_distance <= rep.distance_cap &&
              rep.max_intersecting == 0);
        /* a stopped planned run takes no more steps */
        plume_run_opts o;
        plume_run_opts_default(&o);
        plume_run *r = NULL;
        plume_run_step_info info;
        CHECK(plume_run_open(path, &o, &r, &err) == PLUME_OK && plume_run_to_end(r, &err) == PLUME_OK);
        CHECK(plume_run_done(r) && plume_run_step(r, &info, &err) == PLUME_EINVAL && strstr(err.msg, "refused"));
        plume_run_destroy(&r);
        /* an open run reports each step and may try again */
        o.open = 1;
        CHECK(plume_run_open(path, &o, &r, &err) == PLUME_OK);
        for (int s = 0; r && s < 2; s++)
            CHECK(plume_run_step(r, &info, &err) == PLUME_OK && info.accepted && info.frame == -1 &&
                  info.intersecting == 0.0 && info.contact_pairs >= 0.0);
        CHECK(r && plume_run_step(r, &info, &err) == PLUME_OK && !info.accepted && info.t1 == info.t0);
        CHECK(r && plume_run_step(r, &info, &err) == PLUME_OK && !info.accepted && plume_run_done(r));
        CHECK(plume_run_to_end(r, &err) == PLUME_EINVAL && strstr(err.msg, "open"));
        plume_run_destroy(&r);
    }
    remove_tree(dir);
}

/* Each bad option names its parameter; restart errors begin with "restart: " and name the file. */
void test_run_bad_options(void)
{
    char dir[64] = "/tmp/plume-runb-XXXXXX", path[256], file[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_err err = {{0}};
    plume_scene *scene = NULL;
    CHECK(plume_scene_load(STRIP, &scene, &err) == PLUME_OK);
    if (!scene)
        return;
    plume_run *r = NULL;
    plume_run_opts o;
    struct {
        long frames;
        double end_time;
        int open, solver;
        const char *output_dir, *restart, *expect;
    } bad[] = {
        {-1, 0, 0, -1, NULL, NULL, "plume_run_opts.frames must be >= 0 (got -1)"},
        {0, -0.5, 0, -1, NULL, NULL, "plume_run_opts.end_time"},
        {0, NAN, 0, -1, NULL, NULL, "plume_run_opts.end_time"},
        {2, 0.5, 0, -1, NULL, NULL, "exclusive"},
        {2, 0, 1, -1, NULL, NULL, "plume_run_opts.open"},
        {0, 0, 0, 7, NULL, NULL, "plume_run_opts.solver"},
        {0, 0, 0, -1, "", NULL, "plume_run_opts.output_dir"},
        {0, 0, 0, -1, NULL, "", "plume_run_opts.restart"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        plume_run_opts_default(&o);
        o.frames = bad[i].frames, o.end_time = bad[i].end_time, o.open = bad[i].open, o.solver = bad[i].solver;
        o.output_dir = bad[i].output_dir, o.restart = bad[i].restart;
        err.msg[0] = 0;
        r = NULL;
        CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_EINVAL && r == NULL);
        CHECK(strstr(err.msg, bad[i].expect) != NULL);
        fprintf(stderr, "    %s\n", err.msg);
    }
    CHECK(plume_run_create(NULL, NULL, &r, &err) == PLUME_EINVAL && strstr(err.msg, "scene"));
    CHECK(plume_run_create(scene, NULL, NULL, &err) == PLUME_EINVAL);
    /* an output directory under a regular file */
    snprintf(file, sizeof file, "%s/file", dir);
    FILE *f = fopen(file, "w");
    if (f)
        fclose(f);
    snprintf(path, sizeof path, "%s/file/out", dir);
    plume_run_opts_default(&o);
    o.output_dir = path;
    o.frames = 1;
    CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_OK);
    CHECK(plume_run_start(r, &err) == PLUME_EIO && strstr(err.msg, "output_dir") && strstr(err.msg, path));
    CHECK(plume_run_step(r, NULL, &err) == PLUME_EINVAL && plume_run_done(r));
    plume_run_destroy(&r);
    CHECK(r == NULL);
    plume_run_destroy(&r); /* NULL-safe */
    plume_run_destroy(NULL);
    /* restart from a missing file, and from the frames of another mesh */
    plume_run_opts_default(&o);
    o.restart = "/nonexistent/frames.h5";
    CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_OK);
    CHECK(plume_run_start(r, &err) != PLUME_OK && strncmp(err.msg, "restart: ", 9) == 0 &&
          strstr(err.msg, "/nonexistent/frames.h5"));
    plume_run_destroy(&r);
    snprintf(file, sizeof file, "%s/other.h5", dir);
    double x[6] = {0}, v[6] = {0};
    CHECK(plume_frames_create(file, 2, 0, 0.02, "other.json", &err) == PLUME_OK &&
          plume_frames_append(file, 2, 0, 0.0, 0, x, v, NULL, &err) == PLUME_OK);
    o.restart = file;
    CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_OK);
    CHECK(plume_run_start(r, &err) == PLUME_EINVAL && strncmp(err.msg, "restart: ", 9) == 0 &&
          strstr(err.msg, "holds frames of 2 vertices"));
    plume_run_report rep;
    plume_run_get_report(r, &rep);
    CHECK(rep.restart_dt == 0.02); /* known before the failure, for a caller's warning */
    plume_run_destroy(&r);
    /* a planned run with no step left, and an open run has no frame or end to step to */
    plume_run_opts_default(&o);
    o.end_time = 0.01;
    CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_OK && plume_run_to_end(r, &err) == PLUME_OK);
    CHECK(plume_run_done(r) && plume_run_step(r, NULL, &err) == PLUME_EINVAL && strstr(err.msg, "no step left"));
    plume_run_destroy(&r);
    plume_run_opts_default(&o);
    o.open = 1;
    CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_OK);
    CHECK(plume_run_frame(r, &err) == PLUME_EINVAL && strstr(err.msg, "plume_run_step"));
    CHECK(plume_run_to_end(r, &err) == PLUME_EINVAL && strstr(err.msg, "open"));
    plume_run_destroy(&r);
    CHECK(plume_run_open("/nonexistent/scene.json", NULL, &r, &err) == PLUME_EIO && r == NULL &&
          strstr(err.msg, "/nonexistent/scene.json"));
    plume_scene_destroy(&scene);
    remove_tree(dir);
}

/* A static scene through the runner: apps/shell's series byte for byte, one load step a call with
 * its report, the load factor as the time, and the options that plan a dynamic run refused. */
void test_run_static_matches_app(void)
{
    const char *scene_path = "../data/benchmarks/cantilever_shear.json";
    char dir[64] = "/tmp/plume-runs-XXXXXX", args[512], out[65536], errs[8192], a[256], b[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "%s --edge 0.5 --steps 4 -o %s/app --quiet", scene_path, dir);
    CHECK(app_run(dir, "shell", args, out, sizeof out, errs, sizeof errs) == 0);
    plume_err err = {{0}};
    plume_scene *scene = NULL;
    plume_scene_load_opts lo;
    plume_scene_load_opts_default(&lo);
    lo.edge = 0.5;
    CHECK(plume_scene_load_with(scene_path, &lo, &scene, &err) == PLUME_OK);
    if (!scene)
        return;
    CHECK(plume_scene_set(scene, "{\"steps\": 4}", &err) == PLUME_OK);
    plume_run_opts o;
    plume_run_opts_default(&o);
    snprintf(a, sizeof a, "%s/lib", dir);
    o.output_dir = a;
    plume_run *r = NULL;
    CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_OK);
    long k = 0, factorizations = 0;
    double last = 0.0;
    while (r && !plume_run_done(r)) {
        plume_run_step_info info;
        CHECK(plume_run_step(r, &info, &err) == PLUME_OK);
        k++;
        CHECK(info.accepted && info.load.converged && info.load.step == k && info.frame == k && info.steps == 1);
        CHECK(info.t0 == last && fabs(info.t1 - 0.25 * (double)k) < 1e-12);
        last = info.t1;
        factorizations += info.load.factorizations;
    }
    plume_run_report rep;
    plume_run_get_report(r, &rep);
    CHECK(k == 4 && rep.steps == 4 && rep.planned_steps == 4 && rep.frames == 4 && rep.next_frame == 5);
    CHECK(rep.converged && !rep.stopped && fabs(rep.time - 1.0) < 1e-12 && rep.factorizations == factorizations);
    CHECK(plume_run_velocities(r) == NULL && plume_run_positions(r) != NULL && plume_run_frames_path(r) == NULL);
    CHECK(plume_run_step(r, NULL, &err) == PLUME_EINVAL && strstr(err.msg, "no step left"));
    snprintf(b, sizeof b, "%s/static.h5", dir);
    CHECK(plume_run_write_state(r, b, 1, &err) == PLUME_EINVAL && strstr(err.msg, "static") && access(b, F_OK) != 0);
    CHECK(plume_run_write_state(r, NULL, 1, &err) == PLUME_EINVAL && strstr(err.msg, "path"));
    plume_run_destroy(&r);
    const char *files[] = {"steps.pvd", "step_00001.vtu", "step_00004.vtu"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(a, sizeof a, "%s/app/%s", dir, files[i]);
        snprintf(b, sizeof b, "%s/lib/%s", dir, files[i]);
        CHECK(access(a, R_OK) == 0 && same_bytes(a, b));
    }
    /* what a static run cannot do */
    const char *expect[] = {"plume_run_opts.frames", "plume_run_opts.frames", "plume_run_opts.restart",
                            "cannot reach an equilibrium"};
    for (int i = 0; i < 4; i++) {
        plume_run_opts_default(&o);
        o.frames = i == 0 ? 2 : 0;
        o.open = i == 1;
        o.restart = i == 2 ? "frames.h5" : NULL;
        o.solver = i == 3 ? PLUME_SOLVER_LINEARIZED : -1;
        r = NULL;
        CHECK(plume_run_create(scene, &o, &r, &err) == PLUME_EINVAL && r == NULL && strstr(err.msg, expect[i]));
        fprintf(stderr, "    %s\n", err.msg);
    }
    plume_scene_destroy(&scene);
    remove_tree(dir);
}
