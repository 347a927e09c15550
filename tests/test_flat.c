/* The flat interface for bindings (include/plume/flat.h): JSON requests and results that agree with the
 * library's own calls, errors that name the key, and a scene stepped through its handle (also run
 * under the sanitizers, which the Python tests are not). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "harness.h"
#include "../lib/io/curves.h"
#include "../lib/io/vtu.h"
#include "../drivers/flat.h"
#include "../micro/homogenize.h"

static json_t *run(plume_status (*f)(const char *, char **, char *, long), const char *req, plume_status *st,
                   char *msg)
{
    char *out = NULL;
    *st = f(req, &out, msg, 512);
    json_t *j = out ? json_loads(out, 0, NULL) : NULL;
    plume_flat_free(out);
    return j;
}

/* homogenize agrees with plume_homogenize, bit for bit through the JSON text */
void test_flat_homogenize(void)
{
    char msg[512];
    plume_status st;
    json_t *j = run(plume_flat_homogenize, "{\"strain_max\": 0.05, \"steps\": 2, \"layout\": {\"phi\": 0.2}}", &st, msg);
    CHECK(st == PLUME_OK && j);
    plume_layout l;
    plume_layout_default(&l);
    l.phi = 0.2;
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.strain_max = 0.05, o.steps = 2;
    plume_homog_result r;
    plume_err err = {{0}};
    CHECK(plume_homogenize(&l, &o, &r, &err) == PLUME_OK);
    if (j) {
        CHECK(json_real_value(json_object_get(j, "E_xx")) == r.moduli.E_xx);
        CHECK(json_real_value(json_object_get(j, "G_xy")) == r.moduli.G_xy);
        json_t *c = json_object_get(json_object_get(j, "curves"), "shear");
        CHECK(json_array_size(json_object_get(c, "stress")) == 3);
        CHECK(json_real_value(json_array_get(json_object_get(c, "stress"), 2)) == r.shear.stress[2]);
    }
    plume_homog_result_free(&r);
    json_decref(j);
    /* errors name what is wrong; nothing is returned */
    char *out = (char *)1;
    CHECK(plume_flat_homogenize("{\"stepz\": 2}", &out, msg, sizeof msg) == PLUME_EINVAL && out == NULL);
    CHECK(strstr(msg, "unknown key \"stepz\"") != NULL);
    CHECK(plume_flat_homogenize("{\"layout\": {\"phi\": \"a\"}}", &out, msg, sizeof msg) == PLUME_EINVAL);
    CHECK(strstr(msg, "request.layout") && strstr(msg, "\"phi\""));
    CHECK(plume_flat_homogenize("{\"steps\": 2.5}", &out, msg, sizeof msg) == PLUME_EINVAL && strstr(msg, "\"steps\""));
    CHECK(plume_flat_homogenize("[1, 2", &out, msg, sizeof msg) == PLUME_EFORMAT && strstr(msg, "request:1:"));
    CHECK(plume_flat_homogenize("{}", NULL, msg, sizeof msg) == PLUME_EINVAL);
    CHECK(plume_flat_homogenize("{\"steps\": \"x\"}", &out, NULL, 0) == PLUME_EINVAL); /* no message buffer */
}

/* homogenize "output": the moduli file a scene's from_moduli reads, holding the moduli of the result
 * (its directory created); a path that cannot be written is refused before the solve, naming the key
 * and the file, and nothing is returned */
void test_flat_homogenize_output(void)
{
    char msg[512], dir[64] = "/tmp/plume-flath-XXXXXX", path[200], req[400];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/sub/cell.h5", dir);
    snprintf(req, sizeof req, "{\"strain_max\": 0, \"layout\": {\"phi\": 0.2}, \"output\": \"%s\"}", path);
    plume_status st;
    json_t *j = run(plume_flat_homogenize, req, &st, msg);
    CHECK(st == PLUME_OK && j);
    plume_ortho m;
    double D_long = 0.0;
    plume_err err = {{0}};
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_OK);
    CHECK(plume_moduli_read_param(path, "D_long", &D_long, &err) == PLUME_OK);
    if (j) {
        CHECK(strcmp(json_string_value(json_object_get(j, "output")), path) == 0);
        CHECK(json_real_value(json_object_get(j, "E_xx")) == m.E_xx);
        CHECK(json_real_value(json_object_get(j, "E_yy")) == m.E_yy);
        CHECK(json_real_value(json_object_get(j, "nu_xy")) == m.nu_xy);
        CHECK(json_real_value(json_object_get(j, "G_xy")) == m.G_xy);
        CHECK(json_real_value(json_object_get(j, "D_long")) == D_long && D_long > 0.0);
    }
    json_decref(j);
    /* without the key, no "output" in the result */
    j = run(plume_flat_homogenize, "{\"strain_max\": 0, \"layout\": {\"phi\": 0.2}}", &st, msg);
    CHECK(st == PLUME_OK && j && !json_object_get(j, "output"));
    json_decref(j);
    /* bad outputs: a file where a directory is wanted, a directory, an empty name, not a string */
    char *out = (char *)1;
    snprintf(req, sizeof req, "{\"output\": \"%s/sub/cell.h5/x.h5\"}", dir);
    CHECK(plume_flat_homogenize(req, &out, msg, sizeof msg) == PLUME_EIO && out == NULL);
    CHECK(strstr(msg, "\"output\"") && strstr(msg, "cell.h5/x.h5"));
    snprintf(req, sizeof req, "{\"output\": \"%s/sub\"}", dir);
    CHECK(plume_flat_homogenize(req, &out, msg, sizeof msg) == PLUME_EINVAL && strstr(msg, "directory"));
    CHECK(plume_flat_homogenize("{\"output\": \"\"}", &out, msg, sizeof msg) == PLUME_EINVAL &&
          strstr(msg, "\"output\""));
    CHECK(plume_flat_homogenize("{\"output\": 1}", &out, msg, sizeof msg) == PLUME_EINVAL &&
          strstr(msg, "\"output\" must be a string"));
    CHECK(plume_flat_homogenize("{\"output\": \"a.h5\", \"outptu\": 1}", &out, msg, sizeof msg) == PLUME_EINVAL &&
          strstr(msg, "unknown key \"outptu\""));
    CHECK(access("a.h5", F_OK) != 0);
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    CHECK(system(path) == 0);
}

/* traction: a converged curve, a ParaView series on request, bad values named */
void test_flat_traction(void)
{
    char msg[512], dir[64] = "/tmp/plume-flat-XXXXXX", req[512];
    plume_status st;
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(req, sizeof req, "{\"steps\": 2, \"angle\": 45, \"vtk\": \"%s/v\"}", dir);
    json_t *j = run(plume_flat_traction, req, &st, msg);
    CHECK(st == PLUME_OK && j && json_is_true(json_object_get(j, "converged")));
    json_t *s = json_object_get(j, "stress");
    CHECK(json_array_size(s) == 3 && json_real_value(json_array_get(s, 2)) > json_real_value(json_array_get(s, 1)) &&
          json_real_value(json_array_get(s, 1)) > 0.0);
    CHECK(json_real_value(json_object_get(j, "initial_slope")) > 0.0);
    json_decref(j);
    char path[200];
    snprintf(path, sizeof path, "%s/v/steps.pvd", dir);
    plume_pvd_entries e;
    plume_err err = {{0}};
    CHECK(plume_pvd_read(path, &e, &err) == PLUME_OK && e.n == 6); /* 3 states, triangles and barbs */
    plume_pvd_entries_free(&e);
    j = run(plume_flat_traction, "{\"model\": \"micro\", \"steps\": 1}", &st, msg);
    CHECK(st == PLUME_OK && j && json_real_value(json_array_get(json_object_get(j, "stress"), 1)) > 0.0);
    json_decref(j);
    const char *bad[][2] = {{"{\"model\": \"meso\"}", "\"model\""},
                            {"{\"angle\": 200}", "\"angle\""},
                            {"{\"moduli\": {\"E_zz\": 1}}", "unknown key \"E_zz\""},
                            {"{\"moduli\": {\"E_xx\": 1e4, \"E_yy\": -1, \"nu_xy\": 0, \"G_xy\": 1}}", "E_yy"},
                            /* a partial set is refused, naming what is missing */
                            {"{\"moduli\": {\"E_yy\": 1e3}}", "missing E_xx, nu_xy, G_xy"},
                            {"{\"layout\": {\"phi\": 0.1}}", "micro model"},
                            {"{\"solver\": \"cg\"}", "\"solver\""},
                            {"{\"constraint\": 1}", "\"constraint\""},
                            {"{\"lx\": 0}", "lx, ly and thickness"},
                            {"{\"steps\": 0}", "\"steps\" >= 1"},
                            {"{\"model\": \"micro\", \"convergence\": 1}", "\"convergence\""},
                            {"{\"model\": \"micro\", \"layout\": {\"order\": 3}}", "\"order\" must be 1 or 2"},
                            /* a load path that is not a list, or holds a word; grips out of range; hooks on strips */
                            {"{\"path\": 0.03}", "\"path\" must be a list of 1 to 1000 strains"},
                            {"{\"path\": [0.03, \"back\"]}", "\"path\"[1] must be a number"},
                            {"{\"peel\": -0.5}", "peel must be in [0, 1]"},
                            {"{\"top_grip_free\": 1}", "top_grip_free must be in [0, 1)"},
                            {"{\"model\": \"micro\", \"layout\": {\"hook_strength\": 1e-3}}", "needs the layout"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char *out = NULL;
        st = plume_flat_traction(bad[k][0], &out, msg, sizeof msg);
        CHECK(st != PLUME_OK && out == NULL);
        if (!strstr(msg, bad[k][1])) {
            plume_test_failures++;
            fprintf(stderr, "    %s: expected '%s' in '%s'\n", bad[k][0], bad[k][1], msg);
        }
    }
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    CHECK(system(path) == 0);
}

/* fit recovers the moduli of curves made by traction */
void test_flat_fit(void)
{
    char msg[512], req[8192];
    plume_status st;
    json_t *t[2];
    const double angles[2] = {45.0, 90.0};
    for (int k = 0; k < 2; k++) {
        snprintf(req, sizeof req, "{\"steps\": 2, \"edge\": 0.13, \"angle\": %g, \"moduli\": {\"E_xx\": 1e4, \"E_yy\": 1.5, \"nu_xy\": 0, \"G_xy\": 3}}",
                 angles[k]);
        t[k] = run(plume_flat_traction, req, &st, msg);
        CHECK(st == PLUME_OK && t[k]);
    }
    if (!t[0] || !t[1]) {
        json_decref(t[0]), json_decref(t[1]);
        return;
    }
    json_t *targets = json_array();
    for (int k = 0; k < 2; k++)
        json_array_append_new(targets, json_pack("{s:f, s:O, s:O}", "angle", angles[k], "strain",
                                                 json_object_get(t[k], "strain"), "stress", json_object_get(t[k], "stress")));
    json_t *r = json_pack("{s:o, s:{s:f, s:f, s:f, s:f}, s:i, s:f}", "targets", targets, "start", "E_xx", 1e4, "E_yy",
                          3.0, "G_xy", 1.5, "nu_xy", 0.0, "steps", 2, "edge", 0.13);
    char *text = json_dumps(r, JSON_REAL_PRECISION(17));
    json_t *f = run(plume_flat_fit, text, &st, msg);
    CHECK(st == PLUME_OK && f);
    if (f) {
        CHECK_REL(json_real_value(json_object_get(f, "E_yy")), 1.5, 1e-4, 0.0);
        CHECK_REL(json_real_value(json_object_get(f, "G_xy")), 3.0, 1e-4, 0.0);
        fprintf(stderr, "    fit: E_yy %.6g G_xy %.6g after %lld evaluations (%s)\n",
                json_real_value(json_object_get(f, "E_yy")), json_real_value(json_object_get(f, "G_xy")),
                (long long)json_integer_value(json_object_get(f, "evaluations")),
                json_string_value(json_object_get(f, "stop")));
    }
    free(text);
    json_decref(f);
    json_decref(r);
    json_decref(t[0]), json_decref(t[1]);
    char *out = NULL;
    CHECK(plume_flat_fit("{\"targets\": []}", &out, msg, sizeof msg) == PLUME_EINVAL && strstr(msg, "\"start\""));
    CHECK(plume_flat_fit("{\"start\": {\"E_xx\": 1, \"E_yy\": 1, \"G_xy\": 1}, \"targets\": []}", &out, msg,
                         sizeof msg) == PLUME_EINVAL && strstr(msg, "start: missing nu_xy"));
    CHECK(plume_flat_fit("{\"start\": {\"E_xx\": 1, \"E_yy\": 1, \"nu_xy\": 0, \"G_xy\": 1}, \"targets\": [{\"angle\": 45}]}",
                         &out, msg, sizeof msg) == PLUME_EINVAL && strstr(msg, "targets[0]"));
    CHECK(plume_flat_fit("{\"start\": {\"E_xx\": 1, \"E_yy\": 1, \"nu_xy\": 0, \"G_xy\": 1}, \"free\": [\"E_q\"], "
                         "\"targets\": []}",
                         &out, msg, sizeof msg) == PLUME_EINVAL && strstr(msg, "\"free\"[0]"));
}

/* a scene stepped through the handle: time, sizes, state arrays, a ParaView series, errors */
void test_flat_scene(void)
{
    char msg[512], dir[64] = "/tmp/plume-flats-XXXXXX", path[200];
    plume_flat_scene *s = NULL;
    CHECK(plume_flat_scene_open("../data/shell/strip_scene.json", &s, msg, sizeof msg) == PLUME_OK && s);
    if (!s || !mkdtemp(dir))
        return;
    long nv = plume_flat_scene_nv(s), nt = plume_flat_scene_nt(s);
    CHECK(nv == 125 && nt == 192 && plume_flat_scene_time(s) == 0.0);
    char *rep = NULL;
    CHECK(plume_flat_scene_write_vtk(s, dir, msg, sizeof msg) == PLUME_OK);
    CHECK(plume_flat_scene_step(s, 3, &rep, msg, sizeof msg) == PLUME_OK && rep);
    json_t *j = rep ? json_loads(rep, 0, NULL) : NULL;
    CHECK(j && json_is_true(json_object_get(j, "converged")) && json_integer_value(json_object_get(j, "steps")) == 3);
    json_decref(j);
    plume_flat_free(rep);
    CHECK(fabs(plume_flat_scene_time(s) - 0.03) < 1e-12);
    double *x = malloc(3 * (size_t)nv * sizeof *x), *X = malloc(2 * (size_t)nv * sizeof *X), zmin = 0.0;
    long *tri = malloc(3 * (size_t)nt * sizeof *tri);
    plume_flat_scene_positions(s, x);
    plume_flat_scene_reference(s, X);
    plume_flat_scene_triangles(s, tri);
    for (long v = 0; v < nv; v++)
        zmin = fmin(zmin, x[3 * v + 2]);
    CHECK(zmin < -1e-5); /* it sags */
    long tmax = 0;
    for (long k = 0; k < 3 * nt; k++)
        tmax = tri[k] > tmax ? tri[k] : tmax;
    CHECK(tmax == nv - 1);
    CHECK(plume_flat_scene_write_vtk(s, dir, msg, sizeof msg) == PLUME_OK);
    snprintf(path, sizeof path, "%s/frames.pvd", dir);
    plume_pvd_entries e;
    plume_err err = {{0}};
    CHECK(plume_pvd_read(path, &e, &err) == PLUME_OK && e.n == 4 && e.times[2] == 0.03); /* 2 frames, 2 parts */
    plume_pvd_entries_free(&e);
    CHECK(plume_flat_scene_step(s, -1, NULL, msg, sizeof msg) == PLUME_EINVAL);
    free(x), free(X), free(tri);
    plume_flat_scene_close(&s);
    CHECK(s == NULL);
    plume_flat_scene_close(&s); /* NULL-safe */
    CHECK(plume_flat_scene_open("/nonexistent/scene.json", &s, msg, sizeof msg) == PLUME_EIO && s == NULL);
    CHECK(strstr(msg, "/nonexistent/scene.json") != NULL);
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    CHECK(system(path) == 0);
}

/* The flat scene steps under the runner's acceptance rule (macro/scene/run.h), as apps/feather does: a
 * `linearized` step that advanced is accepted, one that did not (a ground keyframed up through the
 * plate at t = 0.01 s: no halving can start step 3) stops the call, "converged" false. */
void test_flat_scene_linearized(void)
{
    char msg[512], dir[64] = "/tmp/plume-flatl-XXXXXX", path[200], obj[200];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(obj, sizeof obj, "%s/ground.obj", dir);
    FILE *f = fopen(obj, "w");
    if (f) {
        fputs("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n", f);
        fclose(f);
    }
    snprintf(path, sizeof path, "%s/through.json", dir);
    const char *doc =
        "{\"objects\": [{\"name\": \"ground\", \"kinematic\": {\"obj\": \"ground.obj\", \"keyframes\": "
        "[[0, 0, 0, 0], [0.01, 0, 0, 0], [0.015, 0, 0, 0.5]]}},"
        "{\"name\": \"plate\", \"mesh\": {\"rectangle\": [0.1, 0.1], \"edge\": 0.05, \"pattern\": \"grid\"},"
        " \"place\": {\"translate\": [-0.05, -0.05, 0.002]}}],"
        "\"materials\": [{\"membrane\": {\"E\": 1e9, \"nu\": 0.3, \"thickness\": 1e-3}, \"density\": 1.0}],"
        "\"contact\": {\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 10}, \"solver\": \"linearized\","
        "\"gravity\": [0, 0, 0], \"dt\": 0.005, \"duration\": 0.015, \"max_halvings\": 4}";
    plume_flat_scene *s = NULL;
    CHECK(plume_flat_scene_open_json(doc, path, &s, msg, sizeof msg) == PLUME_OK && s);
    char *rep = NULL;
    for (int call = 0; s && call < 2; call++) {
        CHECK(plume_flat_scene_step(s, 3, &rep, msg, sizeof msg) == PLUME_OK && rep);
        json_t *j = rep ? json_loads(rep, 0, NULL) : NULL;
        /* steps 1 and 2 advance (unconverged by design) and are accepted; step 3 does not advance */
        CHECK(j && json_is_false(json_object_get(j, "converged")) &&
              json_integer_value(json_object_get(j, "steps")) == (call == 0 ? 2 : 0));
        CHECK(j && strcmp(json_string_value(json_object_get(j, "stop_reason")), "prescribed motion runs into a body") == 0);
        CHECK(j && json_integer_value(json_object_get(j, "halvings")) == 4);
        json_decref(j);
        plume_flat_free(rep);
        CHECK(fabs(plume_flat_scene_time(s) - 0.01) < 1e-15);
    }
    plume_flat_scene_close(&s);
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    CHECK(system(path) == 0);
}
