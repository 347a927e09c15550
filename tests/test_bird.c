/* The bird generator (data/bird/make_bird.py) and its scene: what it writes loads as at least 100
 * feathers and 20k elements that start apart (the loader's start check), the shipped bird is what
 * it writes by default, an out-of-range parameter exits 2 naming the flag, the generator's own
 * check refuses feathers closer than dhat naming them, and the loader refuses two crossed feathers
 * naming them. */
#define _DEFAULT_SOURCE
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include <jansson.h>

#include "harness.h"
#include "../macro/scene/scene.h"
#include "../lib/io/frames.h"
#include "app_runner.h"

/* runs a shell command with stdout and stderr into dir/out.txt; returns its exit code and the
 * output in out */
static int run(const char *dir, const char *cmd, char *out, size_t n)
{
    char line[2048], path[256];
    snprintf(line, sizeof line, "%s >%s/out.txt 2>&1", cmd, dir);
    int rc = system(line);
    snprintf(path, sizeof path, "%s/out.txt", dir);
    FILE *f = fopen(path, "r");
    out[0] = 0;
    if (f) {
        size_t got = fread(out, 1, n - 1, f);
        out[got] = 0;
        fclose(f);
    }
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

static void remove_dir(const char *dir)
{
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "    could not remove %s\n", dir);
}

/* The default bird written into a scratch folder: the same files as the shipped data/bird/bird.json
 * and data/bird/bird/, at least 100 feathers attached to the body and the six segments, at least
 * 20k elements, and a start the loader accepts (no two bodies crossed). */
void test_bird_generator(void)
{
    char dir[64] = "/tmp/plume-bird-XXXXXX", cmd[512], out[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(cmd, sizeof cmd, "python3 ../data/bird/make_bird.py --out %s", dir);
    CHECK(run(dir, cmd, out, sizeof out) == 0);
    /* the shipped scene cannot drift from its generator */
    snprintf(cmd, sizeof cmd, "diff -r %s/bird ../data/bird/bird && cmp %s/bird.json ../data/bird/bird.json", dir, dir);
    CHECK(run(dir, cmd, out, sizeof out) == 0);
    if (*out)
        fprintf(stderr, "    %s", out);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    snprintf(path, sizeof path, "%s/bird.json", dir);
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
    if (!s) {
        fprintf(stderr, "    %s\n", err.msg);
        remove_dir(dir);
        return;
    }
    int feathers = 0, kinematic = 0;
    for (int k = 0; k < s->nobjects; k++)
        s->objects[k].kinematic ? kinematic++ : feathers++;
    CHECK(feathers >= 100 && kinematic == 7); /* the body and three segments a wing */
    CHECK(s->elastic && s->elastic->nt >= 20000);
    CHECK(s->has_contact && s->contact.pair.dhat == 1e-3 && s->contact.self_contact);
    CHECK(plume_scene_check_start(s, &err) == PLUME_OK);
    fprintf(stderr, "    %d feathers, %ld elements, %ld vertices\n", feathers, (long)(s->elastic ? s->elastic->nt : 0),
            (long)s->mesh->nv);
    plume_scene_destroy(&s);
    remove_dir(dir);
}

/* A parameter out of its range, or not a number: exit 2, the flag and its range named; nothing
 * written. */
void test_bird_generator_bad_flags(void)
{
    char dir[64] = "/tmp/plume-bird-XXXXXX", cmd[512], out[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    static const char *const bad[][2] = {
        {"--flap 90", "--flap must be between 0 and 45 (got 90)"},
        {"--primaries 20", "--primaries must be between 6 and 12 (got 20)"},
        {"--tolerance 0", "--tolerance must be between 1e-05 and 0.1 (got 0)"},
        {"--uniform-edge 1", "--uniform-edge must be between 0.002 and 0.05 (got 1)"},
        {"--period nan", "--period must be between 0.05 and 2 (got nan)"},
        {"--rectrices 7", "--rectrices must be even (got 7)"},
        {"--secondaries many", "--secondaries: invalid int value"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        snprintf(cmd, sizeof cmd, "python3 ../data/bird/make_bird.py --out %s %s", dir, bad[k][0]);
        int rc = run(dir, cmd, out, sizeof out);
        CHECK(rc == 2 && strstr(out, bad[k][1]) != NULL);
        if (rc != 2 || !strstr(out, bad[k][1]))
            fprintf(stderr, "    %s: exit %d, %s\n", bad[k][0], rc, out);
    }
    snprintf(path, sizeof path, "%s/bird.json", dir);
    FILE *f = fopen(path, "r");
    CHECK(f == NULL);
    if (f)
        fclose(f);
    remove_dir(dir);
}

/* Two feathers closer than dhat at t = 0: the generator's check names them and writes nothing (its
 * layering moved one feather down onto the other); two feathers crossed: the loader refuses the
 * scene naming both. */
void test_bird_overlaps_refused(void)
{
    char dir[64] = "/tmp/plume-bird-XXXXXX", cmd[1024], out[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    /* the generator's own check, on its bird with r_p02 lowered into r_p01's plane */
    snprintf(cmd, sizeof cmd,
             "cd ../data/bird && python3 -c 'import sys, make_bird as m\n"
             "p = m.parse([])\n"
             "shapes, fs, wings, bones = m.build(p)\n"
             "f = {x.name: x for x in fs}\n"
             "f[\"r_p02\"].z = f[\"r_p01\"].z + 0.0005\n"
             "for a, b, d in m.check(fs, bones): print(a, b, d)'");
    CHECK(run(dir, cmd, out, sizeof out) == 0 && strstr(out, "r_p01 r_p02 0.0005") != NULL);
    if (!strstr(out, "r_p01 r_p02"))
        fprintf(stderr, "    %s", out);
    /* the loader: the shipped bird (its files named from the scratch folder) with r_p02 moved into
     * r_p01's place and tilted 20 degrees about its rachis */
    char data[PATH_MAX], file[PATH_MAX + 64];
    CHECK(realpath("../data/bird", data) != NULL);
    json_error_t je;
    json_t *j = json_load_file("../data/bird/bird.json", 0, &je), *p1 = NULL, *p2 = NULL;
    CHECK(j != NULL);
    json_t *objs = j ? json_object_get(j, "objects") : NULL;
    for (size_t k = 0; k < json_array_size(objs); k++) {
        json_t *o = json_array_get(objs, k), *where = json_object_get(o, "mesh");
        const char *name = json_string_value(json_object_get(o, "name")), *key = "feather";
        if (!where)
            where = json_object_get(o, "kinematic"), key = "obj";
        snprintf(file, sizeof file, "%s/%s", data, json_string_value(json_object_get(where, key)));
        json_object_set_new(where, key, json_string(file));
        if (name && strcmp(name, "r_p01") == 0)
            p1 = o;
        if (name && strcmp(name, "r_p02") == 0)
            p2 = o;
    }
    CHECK(p1 && p2);
    if (p1 && p2) {
        json_t *place = json_deep_copy(json_object_get(p1, "place"));
        json_array_insert_new(json_object_get(place, "rotate"), 0, json_pack("[iiii]", 0, 1, 0, 20));
        json_object_set_new(p2, "place", place);
        snprintf(path, sizeof path, "%s/crossed.json", dir);
        CHECK(json_dump_file(j, path, JSON_INDENT(1)) == 0);
        plume_scene *s = NULL;
        plume_err err = {{0}};
        CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
        CHECK(s && plume_scene_check_start(s, &err) == PLUME_EINVAL);
        CHECK(strstr(err.msg, "intersect at rest") && strstr(err.msg, "'r_p02'"));
        fprintf(stderr, "    %s\n", err.msg);
        plume_scene_destroy(&s);
    }
    json_decref(j);
    remove_dir(dir);
}

/* The shipped bird stopped after its first step and restarted from its frames file for the second
 * ends where the straight two-step run does, bit for bit (positions and velocities): the segments'
 * keyframes, the attachments and the contact pairs all follow the saved state and time. */
void test_bird_restart(void)
{
    char dir[64] = "/tmp/plume-bird-XXXXXX", args[512], out[8192], errs[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "../data/bird/bird.json -o %s/straight --duration 0.0056 --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(args, sizeof args, "../data/bird/bird.json -o %s/half --duration 0.0028 --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(args, sizeof args, "../data/bird/bird.json --restart %s/half/frames.h5 --duration 0.0056 --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    plume_frame f, g;
    plume_err err = {{0}};
    snprintf(path, sizeof path, "%s/straight/frames.h5", dir);
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.step == 2);
    snprintf(path, sizeof path, "%s/half/frames.h5", dir);
    CHECK(plume_frames_read(path, -1, &g, &err) == PLUME_OK && g.step == 2);
    if (f.x && g.x && f.nv == g.nv) {
        CHECK(memcmp(f.x, g.x, (size_t)(3 * f.nv) * sizeof *f.x) == 0);
        CHECK(memcmp(f.v, g.v, (size_t)(3 * f.nv) * sizeof *f.v) == 0);
    }
    plume_frame_free(&f);
    plume_frame_free(&g);
    remove_dir(dir);
}
