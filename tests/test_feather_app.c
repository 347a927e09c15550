/* Scenes (macro/scene/scene.h) and apps/feather as a user runs them: parse errors with file, line and
 * key; the shipped scenes; a short run of the strip example with its outputs; restart "as if
 * never stopped"; a step that cannot converge. */
#define _DEFAULT_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "app_runner.h"
#include "harness.h"
#include "../lib/io/frames.h"
#include "../lib/io/vtu.h"
#include "../macro/scene/scene.h"

/* A valid scene on the strip example; line numbers matter to the error tests below. */
static const char base_scene[] =
    "{\n"                                                                          /* 1 */
    "  \"mesh\": {\"obj\": \"@OBJ@\", \"materials_by_group\": {\"strip\": 0}},\n"  /* 2 */
    "  \"materials\": [\n"                                                         /* 3 */
    "    {\"membrane\": {\"E\": 1e7, \"nu\": 0.3, \"thickness\": 1e-3},\n"          /* 4 */
    "     \"bending\": \"from_membrane\", \"density\": 0.1, \"constraint\": true}\n" /* 5 */
    "  ],\n"                                                                       /* 6 */
    "  \"handles\": [{\"box\": [0, 0, 0.005, 0.02], \"keyframes\": [[0, 0, 0, 0]]}],\n" /* 7 */
    "  \"dt\": 0.01,\n"                                                            /* 8 */
    "  \"duration\": 0.1,\n"                                                       /* 9 */
    "  \"solver\": \"newton\"\n"                                                   /* 10 */
    "}\n";

/* src with the first `from` replaced by `to` (malloc'ed). */
static char *replace(const char *src, const char *from, const char *to)
{
    const char *p = strstr(src, from);
    size_t n = strlen(src) + strlen(to) + 1;
    char *out = malloc(n);
    if (!p) {
        snprintf(out, n, "%s", src);
        return out;
    }
    snprintf(out, n, "%.*s%s%s", (int)(p - src), src, to, p + strlen(from));
    return out;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static char *strip_scene_text(void)
{
    char obj[PATH_MAX];
    if (!realpath("../data/shell/strip.obj", obj))
        snprintf(obj, sizeof obj, "../data/shell/strip.obj");
    return replace(base_scene, "@OBJ@", obj);
}

static void rm_rf(const char *dir)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

static int exists_nonempty(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && st.st_size > 0;
}

/* The ParaView series in dir against its frames.h5: one triangle part per frame (and a barb part
 * when the scene has constraints) at the frames' times; the last frame's points are the stored
 * positions bit for bit, with every field of a cell present and J finite on the elastic part. */
static void check_series(const char *dir, int nframes, int barbs)
{
    char pvd[300], h5[300], vtu[600];
    snprintf(pvd, sizeof pvd, "%s/frames.pvd", dir);
    snprintf(h5, sizeof h5, "%s/frames.h5", dir);
    plume_pvd_entries e;
    plume_err err = {{0}};
    CHECK(plume_pvd_read(pvd, &e, &err) == PLUME_OK);
    int tri = 0, lines = 0, times_ok = 1;
    const char *last = NULL;
    for (int i = 0; i < e.n; i++) {
        if (e.parts[i] == 1) {
            lines++;
            continue;
        }
        plume_frame f;
        times_ok &= plume_frames_read(h5, tri, &f, &err) == PLUME_OK && f.t == e.times[i];
        plume_frame_free(&f);
        tri++;
        last = e.files[i];
    }
    CHECK(tri == nframes && lines == (barbs ? nframes : 0) && times_ok);
    if (!last) {
        plume_pvd_entries_free(&e);
        return;
    }
    snprintf(vtu, sizeof vtu, "%s/%s", dir, last);
    plume_vtu_data d;
    plume_frame f;
    CHECK(plume_vtu_read(vtu, &d, &err) == PLUME_OK && plume_frames_read(h5, -1, &f, &err) == PLUME_OK);
    if (d.points && f.x) {
        CHECK(d.npoints == f.nv && memcmp(d.points, f.x, (size_t)(3 * f.nv) * sizeof *f.x) == 0);
        CHECK(d.has_time && d.time == f.t);
        const char *names[] = {"material", "barb_direction", "green_strain_barb", "stress_barb",
                               "membrane_energy_density", "bending_energy_density", "J", "mean_curvature"};
        for (int k = 0; k < 8; k++)
            CHECK(plume_vtu_find(&d, 0, names[k]) != NULL);
        const plume_vtu_array *J = plume_vtu_find(&d, 0, "J");
        CHECK(J && J->ntuples == d.ncells && isfinite(J->values[0]) && J->values[0] > 0.0);
        CHECK(plume_vtu_find(&d, 1, "displacement") != NULL);
    }
    plume_frame_free(&f);
    plume_vtu_data_free(&d);
    plume_pvd_entries_free(&e);
}

void test_feather_app_scene_errors(void)
{
    char dir[64] = "/tmp/plume-scene-XXXXXX", path[128];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/scene.json", dir);
    char *good = strip_scene_text();
    plume_err err = {{0}};
    plume_scene *s = NULL;
    write_text(path, good);
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK);
    if (s) {
        CHECK(s->mesh->nv == 125 && s->mesh->nt == 192 && s->nmat == 1 && s->nhandles == 1);
        CHECK(s->handles[0].nvertices == 10); /* two columns of five: a clamp, not a hinge */
        CHECK(s->nbarb == 24 * 5);            /* the edges along x of the five rows */
        CHECK_REL(s->mats[0].bending.D_long, 1e7 * 1e-9 / (12.0 * (1.0 - 0.09)), 1e-12, 0.0);
        CHECK(s->dt == 0.01 && s->solver == PLUME_SOLVER_NEWTON && s->output_every == 1);
    }
    plume_scene_destroy(&s);
    CHECK(s == NULL);
    /* each bad input: the text replaced, then what the message must say */
    const char *cases[][3] = {
        {"  \"dt\": 0.01,\n", "  \"dt\": 0.01\n", "scene.json:9:"},
        {"\"newton\"", "\"cg\"", "scene.json:10: solver must be \"newton\", \"ipopt\" or \"linearized\" (got \"cg\")"},
        {"\"density\": 0.1", "\"density\": -0.1", "scene.json:5: materials[0].density must be > 0 (got -0.1)"},
        {"\"box\": [0, 0, 0.005, 0.02]", "\"near\": [5, 5], \"radius\": 0.001", "scene.json:7: handles[0].near with radius 0.001 selects no vertex"},
        {"[[0, 0, 0, 0]]", "[[0.5, 0, 0, 0], [0.2, 0, 0, 0]]", "scene.json:7: handles[0].keyframes[1] time 0.2 is not after"},
        {"{\"strip\": 0}", "{\"strip\": 1}", "scene.json:2: mesh.materials_by_group material id without a material"},
        {"\"E\": 1e7", "\"E\": -1e7", "scene.json:4: materials[0].membrane.E must be > 0"},
        {"\"dt\": 0.01", "\"dt\": 0", "scene.json:8: dt must be > 0 (got 0)"},
        {"\"dt\": 0.01", "\"dt\": 0.01, \"render_field\": \"curl\"",
         "scene.json:8: render_field must be \"material\", \"object\" or one of mean_curvature, J"},
        {"\"duration\"", "\"duraton\"", "scene.json:9: duraton is an unknown key"},
        {"\"duration\": 0.1", "\"duration\": 0.1, \"adaptive_dt\": 1", "scene.json:9: adaptive_dt must be true or false"},
        {"\"duration\": 0.1", "\"duration\": 0.1, \"dt_max\": 0.02", "scene.json:9: dt_max needs \"adaptive_dt\": true"},
        {"\"duration\": 0.1", "\"duration\": 0.1, \"adaptive_dt\": true, \"dt_max\": 0.005",
         "scene.json:9: dt_max must be >= dt"},
        {"\"strip\": 0", "\"strp\": 0", "scene.json:2: mesh.materials_by_group.strp names a group"},
        {"\"thickness\": 1e-3", "\"thickness\": 1e-3, \"kappa\": -1", "scene.json:4: materials[0].membrane.kappa must be >= 0"},
        {"\"constraint\": true", "\"constraint\": 1", "materials[0].constraint must be true or false"},
        {"\"bending\": \"from_membrane\"", "\"bending\": {\"D_long\": 1e-4, \"D_trans\": -1}", "materials[0].bending.D_trans must be >= 0"},
        {"\"handles\": [{\"box\": [0, 0, 0.005, 0.02], \"keyframes\": [[0, 0, 0, 0]]}]",
         "\"handles\": [{\"box\": [0, 0, 0.005, 0.02], \"keyframes\": [[0, 0, 0, 0]]}, {\"vertices\": [0], \"keyframes\": [[0, 0, 0, 0]]}]",
         "handles[1] shares vertex 0 with handles[0]"},
    };
    /* the contact block: each key checked and named (line 9 is "duration") */
    const char *contact_cases[][3] = {
        {"\"model\": \"barrier\"", "\"model\": \"springs\"", "scene.json:9: contact.model must be \"barrier\" or \"penalty\""},
        {"\"dhat\": 1e-3", "\"dhat\": -1e-3", "scene.json:9: contact.dhat must be > 0"},
        {", \"stiffness\": 1", "", "contact.stiffness is missing"},
        {"\"stiffness\": 1", "\"stiffness\": 0", "scene.json:9: contact.stiffness must be > 0"},
        {"\"stiffness\": 1", "\"stiffness\": 1, \"self\": 1", "scene.json:9: contact.self must be true or false"},
        {"\"stiffness\": 1", "\"stiffness\": 1, \"margin\": -1", "scene.json:9: contact.margin must be >= 0"},
        {"\"stiffness\": 1", "\"stiffness\": 1, \"friction\": -0.3", "scene.json:9: contact.friction must be >= 0"},
        {"\"stiffness\": 1", "\"stiffness\": 1, \"eps_v\": 0", "scene.json:9: contact.eps_v must be > 0"},
        {"\"stiffness\": 1", "\"stiffness\": 1, \"kappa\": 2", "scene.json:9: contact.kappa is an unknown key"},
        {"\"duration\": 0.1", "\"duration\": 0.1, \"solve\": \"static\"", "contact is for dynamic scenes only"},
    };
    char *with_contact = replace(good, "  \"duration\": 0.1,\n",
                                 "  \"duration\": 0.1, \"contact\": {\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 1},\n");
    write_text(path, with_contact);
    CHECK(plume_scene_load(path, &s, &err) == PLUME_OK && s && s->has_contact && s->contact.pair.dhat == 1e-3 &&
          s->contact.pair.model == PLUME_CONTACT_BARRIER && !s->contact.self_contact);
    plume_scene_destroy(&s);
    for (size_t k = 0; k < sizeof contact_cases / sizeof contact_cases[0]; k++) {
        char *text = replace(with_contact, contact_cases[k][0], contact_cases[k][1]);
        CHECK(strcmp(text, with_contact) != 0);
        write_text(path, text);
        free(text);
        CHECK(plume_scene_load(path, &s, &err) != PLUME_OK && s == NULL);
        if (!strstr(err.msg, contact_cases[k][2])) {
            plume_test_failures++;
            fprintf(stderr, "    contact case %zu: expected '%s' in: %s\n", k, contact_cases[k][2], err.msg);
        }
    }
    free(with_contact);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char *text = replace(good, cases[k][0], cases[k][1]);
        CHECK(strcmp(text, good) != 0);
        write_text(path, text);
        free(text);
        CHECK(plume_scene_load(path, &s, &err) != PLUME_OK && s == NULL);
        if (!strstr(err.msg, cases[k][2]) || !strstr(err.msg, dir)) {
            plume_test_failures++;
            fprintf(stderr, "    case %zu: expected '%s' in: %s\n", k, cases[k][2], err.msg);
        }
    }
    /* a missing mesh file is named */
    char *text = replace(good, "\"obj\": \"/", "\"obj\": \"/nonexistent/");
    write_text(path, text);
    free(text);
    CHECK(plume_scene_load(path, &s, &err) == PLUME_EIO && strstr(err.msg, "/nonexistent/"));
    CHECK(plume_scene_load("/nonexistent/scene.json", &s, &err) == PLUME_EIO && strstr(err.msg, "/nonexistent/scene.json"));

    /* feather meshes: the shape file's errors name it; the rachis needs its material */
    char outline[PATH_MAX], shape[128], scene_text[PATH_MAX + 1024];
    if (!realpath("../data/feather/outline.obj", outline))
        snprintf(outline, sizeof outline, "../data/feather/outline.obj");
    snprintf(shape, sizeof shape, "%s/shape.json", dir);
    write_text(shape, "{\"rachis\": {\"points\": [[0, 0], [0, 0.2]], \"width_base\": 0.003, \"width_tip\": 0.001},\n"
                      " \"barbs_right\": [[[0, 0.05], [0.01, 0.06]]]}\n");
    static const char mat[] = "{\"membrane\": {\"E\": 1e6, \"nu\": 0, \"thickness\": 1e-4}, \"density\": 0.026}";
    snprintf(scene_text, sizeof scene_text,
             "{\"mesh\": {\"feather\": \"shape.json\", \"outline\": \"%s\", \"edge\": 0.005},\n"
             " \"materials\": [%s, %s], \"dt\": 0.01, \"duration\": 0.1}\n", outline, mat, mat);
    write_text(path, scene_text);
    CHECK(plume_scene_load(path, &s, &err) == PLUME_EFORMAT && strstr(err.msg, "shape.json: barbs_left must be"));
    write_text(shape, "{\"rachis\": {\"points\": [[0, 0], [0, 0.2]], \"width_base\": 0.003, \"width_tip\": -1},\n"
                      " \"barbs_right\": [[[0, 0.05], [0.01, 0.06]]]}\n");
    CHECK(plume_scene_load(path, &s, &err) == PLUME_EINVAL && strstr(err.msg, "shape.json:1: rachis.width_tip must be > 0"));
    write_text(shape, "{\"rachis\": [[0, 0]\n");
    CHECK(plume_scene_load(path, &s, &err) == PLUME_EFORMAT && strstr(err.msg, "shape.json:2:"));
    snprintf(scene_text, sizeof scene_text,
             "{\"mesh\": {\"feather\": \"../data/feather/feather_shape.json\", \"edge\": 0.005},\n"
             " \"materials\": [%s], \"dt\": 0.01, \"duration\": 0.1}\n", mat);
    char cwd_shape[PATH_MAX];
    char *scene_rel = replace(scene_text, "../data/feather/feather_shape.json",
                              realpath("../data/feather/feather_shape.json", cwd_shape) ? cwd_shape : "x");
    write_text(path, scene_rel);
    free(scene_rel);
    CHECK(plume_scene_load(path, &s, &err) == PLUME_EINVAL && strstr(err.msg, "1 (rachis)") && strstr(err.msg, "materials"));
    if (s)
        plume_scene_destroy(&s);

    /* through the app: exit 2 and the same message */
    char args[512], out[8192], errs[8192];
    text = replace(good, "\"newton\"", "\"cg\"");
    write_text(path, text);
    free(text);
    snprintf(args, sizeof args, "%s -o %s/out", path, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 2);
    CHECK(strstr(errs, "scene.json:10: solver") != NULL);
    write_text(path, good);
    const char *bad[][2] = {{"", "no scene file"}, {"@ --frames 0", "--frames"}, {"@ --solver cg", "--solver"},
                            {"@ --bogus", "unknown option '--bogus'"}, {"/nonexistent.json", "/nonexistent.json"},
                            {"@ --frames 2 --duration 1", "exclusive"}, {"@ --restart /nonexistent.h5", "/nonexistent.h5"},
                            {"@ --render-field curl", "--render-field must be \"material\", \"object\" or one of"},
                            {"@ --gltf-animation gif", "--gltf-animation must be \"morph\""},
                            {"@ --gltf-field nope", "--gltf-field \"nope\" is not a field"},
                            {"@ --gltf-field curvature_bb", "midedge operator's curvature"},
                            {"@ --gltf /dev/null/x.glb", "glTF file '/dev/null/x.glb': cannot create its directory"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char *a = replace(bad[k][0], "@", path);
        snprintf(args, sizeof args, "%s -o %s/out --quiet", a, dir);
        free(a);
        CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 2);
        if (!strstr(errs, bad[k][1])) {
            plume_test_failures++;
            fprintf(stderr, "    feather %s: expected '%s' in: %s\n", args, bad[k][1], errs);
        }
    }
    CHECK(app_run(dir, "feather", "--help", out, sizeof out, errs, sizeof errs) == 0 && strstr(out, "--restart"));
    /* a static scene: exit 2, the file named once, apps/shell named, nothing written */
    snprintf(args, sizeof args, "../data/benchmarks/cantilever_shear.json -o %s/static --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 2);
    const char *first = strstr(errs, "cantilever_shear.json");
    CHECK(first && !strstr(first + 1, "cantilever_shear.json") && strstr(errs, "apps/shell"));
    snprintf(args, sizeof args, "%s/static", dir);
    CHECK(access(args, F_OK) != 0);
    free(good);
    rm_rf(dir);
}

/* The shipped scenes load and mean what their names say (meshing only, no time step). */
void test_feather_app_shipped_scenes(void)
{
    const char *files[] = {"../data/feather/scene_anisotropic.json", "../data/feather/scene_isotropic.json",
                           "../data/feather/scene_no_constraint.json", "../data/shell/strip_scene.json"};
    for (int k = 0; k < 4; k++) {
        plume_scene *s = NULL;
        plume_err err = {{0}};
        CHECK(plume_scene_load(files[k], &s, &err) == PLUME_OK);
        if (!s) {
            fprintf(stderr, "    %s: %s\n", files[k], err.msg);
            continue;
        }
        CHECK(s->mesh->dim == 3 && s->mesh->nt > 100 && s->nhandles >= 1);
        CHECK((s->nbarb > 0) == (k == 0 || k == 3)); /* constrained: anisotropic and strip */
        if (k < 3) {
            CHECK(s->nmat == 2 && s->dt == 0.011 && s->nhandles == 2);
            CHECK(s->mats[1].membrane.moduli.E_xx == 1e9 && s->mats[1].membrane.h == 3e-3 && s->mats[1].density == 0.54);
            CHECK(s->mats[0].density == 2.6e-2 && s->mats[0].membrane.kappa == 5.04e7);
            int rachis = 0;
            for (plume_index t = 0; t < s->mesh->nt; t++)
                rachis += s->mesh->material[t] == 1;
            CHECK(rachis > 0 && rachis < s->mesh->nt);
        }
        if (k == 0)
            CHECK(s->mats[0].bending.D_long == 2.5e-4 && s->mats[0].bending.D_trans == 1e-7);
        if (k == 1)
            CHECK(s->mats[0].bending.D_long == 7.9e-4 && s->mats[0].bending.D_trans == 2.5e-8 &&
                  s->mats[0].membrane.moduli.E_xx == s->mats[0].membrane.moduli.E_yy);
        plume_scene_destroy(&s);
    }
}

/* The contact example (data/shell/strip_on_plate.json): a strip lowered onto a plate. With the
 * barrier no step has an intersecting triangle pair and the strip ends within dhat of the plate;
 * the paper's penalty (stiffness 1e11 J/m^2, Table 3 (b)) runs the same scene and, this slow,
 * holds the strip at its repulsion thickness (the fast fall that it lets through is in
 * tests/test_contact.c). */
void test_feather_app_contact_scene(void)
{
    char dir[64] = "/tmp/plume-contact-XXXXXX", args[512], out[8192], err[4096];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_scene *s = NULL;
    plume_err e = {{0}};
    CHECK(plume_scene_load("../data/shell/strip_on_plate.json", &s, &e) == PLUME_OK && s && s->has_contact);
    if (s) {
        int *body = malloc((size_t)s->mesh->nv * sizeof *body);
        CHECK(plume_scene_bodies(s, body) == 2); /* the strip and the plate */
        CHECK(body[0] == 0 && body[s->mesh->nv - 1] == 1);
        free(body);
    }
    plume_scene_destroy(&s);
    double dmin[2] = {-1.0, -1.0};
    long inter[2] = {-1, -1};
    for (int model = 0; model < 2; model++) {
        const char *scene = "../data/shell/strip_on_plate.json";
        char variant[128];
        if (model) { /* the same scene with the paper's penalty */
            char src[PATH_MAX];
            CHECK(realpath(scene, src) != NULL);
            FILE *f = fopen(src, "r");
            static char text[8192];
            size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
            text[n] = 0;
            if (f)
                fclose(f);
            char obj[PATH_MAX];
            CHECK(realpath("../data/shell/strip_on_plate.obj", obj) != NULL);
            char *a = replace(text, "\"model\": \"barrier\", \"dhat\": 1e-3, \"stiffness\": 1.0",
                              "\"model\": \"penalty\", \"dhat\": 1e-3, \"stiffness\": 1e11");
            char *b = replace(a, "\"strip_on_plate.obj\"", "\"@\"");
            char *c = replace(b, "@", obj);
            snprintf(variant, sizeof variant, "%s/penalty.json", dir);
            write_text(variant, c);
            free(a), free(b), free(c);
            scene = variant;
        }
        snprintf(args, sizeof args, "%s -o %s/%d --json --quiet", scene, dir, model);
        int rc = app_run(dir, "feather", args, out, sizeof out, err, sizeof err);
        CHECK(rc == 0);
        const char *jc = strstr(out, "\"contact\"");
        CHECK(jc != NULL);
        if (rc != 0 || !jc) {
            fprintf(stderr, "    %s\n", err);
            continue;
        }
        const char *p = strstr(jc, "\"steps_intersecting\":"), *q = strstr(jc, "\"min_distance\":");
        CHECK(p && q);
        if (p && q) {
            inter[model] = strtol(p + strlen("\"steps_intersecting\":"), NULL, 10);
            dmin[model] = strtod(q + strlen("\"min_distance\":"), NULL);
        }
        CHECK(strstr(out, "\"converged\": true") != NULL);
    }
    fprintf(stderr, "    barrier: intersecting in %ld steps, smallest distance %.3g m; penalty (1e11): %ld, %.3g m\n",
            inter[0], dmin[0], inter[1], dmin[1]);
    CHECK(inter[0] == 0 && dmin[0] > 0.0 && dmin[0] < 1e-3); /* in contact, never through */
    /* the stiff penalty holds the strip at its repulsion thickness, here without passing through */
    CHECK(inter[1] == 0 && dmin[1] > 0.9e-3 && dmin[1] <= 1e-3 + 1e-12);
    rm_rf(dir);
}

/* The ParaView frame's "object" cell array: each triangle carries its scene object's index. */
static void check_object_ids(const char *dir, const plume_scene *s)
{
    char path[256];
    snprintf(path, sizeof path, "%s/run/frame_00001.vtu", dir);
    plume_vtu_data d;
    plume_err err = {{0}};
    CHECK(plume_vtu_read(path, &d, &err) == PLUME_OK);
    const plume_vtu_array *a = plume_vtu_find(&d, 0, "object");
    CHECK(a && a->ncomp == 1 && a->ntuples == s->mesh->nt);
    int wrong = 0;
    for (int i = 0; a && i < s->nobjects; i++)
        for (plume_index t = s->objects[i].t0; t < s->objects[i].t0 + s->objects[i].nt; t++)
            wrong += a->values[t] != (double)i;
    CHECK(wrong == 0);
    plume_vtu_data_free(&d);
}

/* The shipped wing (data/bird/wing.json) as a user runs it, for its first two frames (10 steps):
 * exit 0, every feather and the bone in the outputs (VTK, HDF5 frames, the rendered frame 0), no
 * intersecting triangle pair, the bone turned by its keyframes, a restart after the first frame
 * that ends bit for bit where the straight run does, and the per-frame measures. */
void test_feather_app_wing(void)
{
    char dir[64] = "/tmp/plume-wing-XXXXXX", args[512], out[16384], errs[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load("../data/bird/wing.json", &s, &err) == PLUME_OK);
    if (!s) {
        fprintf(stderr, "    %s\n", err.msg);
        rm_rf(dir);
        return;
    }
    int nfeathers = 0;
    for (int k = 0; k < s->nobjects; k++)
        nfeathers += !s->objects[k].kinematic;
    CHECK(nfeathers >= 12 && s->nobjects == nfeathers + 1 && s->objects[s->nobjects - 1].kinematic);
    CHECK(s->has_contact && s->contact.pair.model == PLUME_CONTACT_BARRIER && s->contact.pair.dhat == 1e-3 &&
          s->contact.self_contact && s->dt == 0.0028); /* Table 3 (b) */
    int *body = malloc((size_t)s->mesh->nv * sizeof *body);
    CHECK(body && plume_scene_bodies(s, body) == nfeathers + 1);
    free(body);
    snprintf(args, sizeof args, "../data/bird/wing.json -o %s/run --frames 2 --json --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (!j)
        fprintf(stderr, "    stdout: %s\n    stderr: %s\n", out, errs);
    if (j) {
        json_t *c = json_object_get(j, "contact");
        CHECK(json_is_true(json_object_get(j, "converged")) && json_integer_value(json_object_get(j, "steps")) == 10);
        CHECK(json_integer_value(json_object_get(j, "vertices")) == s->mesh->nv);
        CHECK(c && json_integer_value(json_object_get(c, "steps_intersecting")) == 0);
        CHECK(c && json_real_value(json_object_get(c, "min_distance")) > 0.0);
        json_decref(j);
    }
    snprintf(path, sizeof path, "%s/run", dir);
    check_series(path, 3, 1);
    snprintf(path, sizeof path, "%s/run/frame_00000.png", dir);
    CHECK(exists_nonempty(path));
    check_object_ids(dir, s);
    snprintf(path, sizeof path, "%s/run/frames.h5", dir);
    plume_frame f;
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.step == 10 && f.nv == s->mesh->nv);
    if (f.x) { /* the bone's far end went down as the flap began: R_y(angle) about the shoulder */
        const plume_scene_object *bone = s->objects + s->nobjects - 1;
        double dz = 0.0;
        for (plume_index v = bone->v0; v < bone->v0 + bone->nv; v++)
            dz = fmin(dz, f.x[3 * v + 2] - s->mesh->x[3 * v + 2]);
        CHECK(dz < -1e-3);
    }
    /* stopped after one frame and restarted for another: bit for bit the same state (the bone's
     * motion and the attachments follow the time, the contact pairs the state) */
    char path2[256];
    snprintf(args, sizeof args, "../data/bird/wing.json -o %s/half --frames 1 --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(args, sizeof args, "../data/bird/wing.json --restart %s/half/frames.h5 --frames 1 --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(path2, sizeof path2, "%s/half/frames.h5", dir);
    plume_frame g;
    CHECK(plume_frames_read(path2, -1, &g, &err) == PLUME_OK && g.step == 10);
    if (f.x && g.x && g.nv == f.nv)
        CHECK(memcmp(f.x, g.x, (size_t)(3 * f.nv) * sizeof *f.x) == 0 && memcmp(f.v, g.v, (size_t)(3 * f.nv) * sizeof *f.v) == 0);
    plume_frame_free(&g);
    plume_frame_free(&f);
    /* every frame carries the measures of its steps */
    plume_frame_measures fm0, fm;
    CHECK(plume_frames_read_measures(path, 0, &fm0, &err) == PLUME_OK && fm0.newton_iterations == 0.0);
    CHECK(plume_frames_read_measures(path, -1, &fm, &err) == PLUME_OK);
    CHECK(fm.newton_iterations >= 5 && fm.steps_halved >= 0 && fm.seconds > 0.0);
    CHECK(fm.intersecting_pairs == 0.0 && fm.min_distance > 0.0 && fm.min_distance <= 1e-2 && fm.contact_pairs >= 0.0);
    fprintf(stderr, "    last frame: %g iterations, %g halvings, %g contact pairs, smallest distance %.3g m\n",
            fm.newton_iterations, fm.steps_halved, fm.contact_pairs, fm.min_distance);
    plume_scene_destroy(&s);
    rm_rf(dir);
}

/* The strip example for a few frames: exit 0, the JSON summary, the outputs on disk. */
void test_feather_app_strip_run(void)
{
    char dir[64] = "/tmp/plume-feather-XXXXXX", args[512], out[16384], errs[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "../data/shell/strip_scene.json -o %s/run --frames 3 --json --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j != NULL);
    if (!j)
        fprintf(stderr, "    stdout: %s\n    stderr: %s\n", out, errs);
    if (j) {
        const char *keys[] = {"frames", "steps", "steps_halved", "newton_iterations", "max_constraint_violation",
                              "converged", "seconds", "elements", "vertices"};
        for (int k = 0; k < 9; k++)
            CHECK(json_object_get(j, keys[k]) != NULL);
        CHECK(json_integer_value(json_object_get(j, "frames")) == 4); /* frame 0 and three more */
        CHECK(json_integer_value(json_object_get(j, "steps")) == 6);  /* output_every 2 */
        CHECK(json_integer_value(json_object_get(j, "elements")) == 192);
        CHECK(json_integer_value(json_object_get(j, "vertices")) == 125);
        CHECK(json_is_true(json_object_get(j, "converged")));
        CHECK(json_integer_value(json_object_get(j, "constraints")) > 0);
        CHECK(json_real_value(json_object_get(j, "max_constraint_violation")) <= 1e-8);
        CHECK_REL(json_real_value(json_object_get(j, "time")), 0.06, 1e-12, 0.0);
        json_decref(j);
    }
    for (int k = 0; k <= 3; k++) {
        snprintf(path, sizeof path, "%s/run/frame_%05d.vtu", dir, k);
        CHECK(exists_nonempty(path));
    }
    snprintf(path, sizeof path, "%s/run/frame_00004.vtu", dir);
    CHECK(!exists_nonempty(path));
    snprintf(path, sizeof path, "%s/run", dir);
    check_series(path, 4, 1);
    snprintf(path, sizeof path, "%s/run/frame_00000.png", dir); /* "render": [0, ...] */
    CHECK(exists_nonempty(path));
    /* coloured by a field: the same frame, a different picture */
    snprintf(args, sizeof args, "../data/shell/strip_scene.json -o %s/field --frames 1 --quiet --render-field J", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(path, sizeof path, "%s/field/frame_00000.png", dir);
    CHECK(exists_nonempty(path));
    {
        char a[256], b[256];
        snprintf(a, sizeof a, "%s/run/frame_00000.png", dir);
        snprintf(b, sizeof b, "%s/field/frame_00000.png", dir);
        FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
        int same = fa && fb;
        for (int ca = 0, cb = 0; same && ca != EOF;)
            ca = fgetc(fa), cb = fgetc(fb), same = ca == cb;
        CHECK(fa && fb && !same);
        if (fa)
            fclose(fa);
        if (fb)
            fclose(fb);
    }
    /* the midedge operator's curvature needs midedge bending: refused by name otherwise */
    snprintf(args, sizeof args, "../data/shell/strip_scene.json -o %s/curv --frames 1 --quiet --render-field curvature_bb",
             dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) != 0 && strstr(errs, "curvature_bb") &&
          strstr(errs, "\"midedge\""));
    snprintf(path, sizeof path, "%s/run/frames.h5", dir);
    plume_frames_info info;
    plume_err err = {{0}};
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 4 && info.nv == 125);
    plume_frame f;
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.step == 6);
    if (f.x) {
        double zmin = 0.0;
        for (plume_index v = 0; v < f.nv; v++)
            zmin = fmin(zmin, f.x[3 * v + 2]);
        CHECK(zmin < -1e-4 && zmin > -0.05); /* the strip sags under gravity */
    }
    plume_frame_free(&f);
    rm_rf(dir);
}

/* Writes the strip scene with output_every 1 (and `extra` replacements) into dir/name. */
static void write_strip_variant(const char *dir, const char *name, const char *from, const char *to)
{
    char path[256];
    char *text = strip_scene_text();
    if (from) {
        char *t2 = replace(text, from, to);
        free(text);
        text = t2;
    }
    snprintf(path, sizeof path, "%s/%s", dir, name);
    write_text(path, text);
    free(text);
}

/* 6 steps in one run against 3 steps and a restart for 3 more: the same final state. */
void test_feather_app_restart(void)
{
    char dir[64] = "/tmp/plume-restart-XXXXXX", args[768], out[16384], errs[8192], pa[256], pb[256], pc[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    /* a handle that moves, so the restart must also get the time right */
    write_strip_variant(dir, "s.json", "[[0, 0, 0, 0]]", "[[0, 0, 0, 0], [0.1, 0, 0, 0.01]]");
    snprintf(args, sizeof args, "%s/s.json -o %s/a --frames 6 --quiet", dir, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(args, sizeof args, "%s/s.json -o %s/b --frames 3 --quiet", dir, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(pb, sizeof pb, "%s/b/frames.h5", dir);
    snprintf(args, sizeof args, "%s/s.json --restart %s --frames 3 --quiet --json", dir, pb); /* in place */
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j && json_integer_value(json_object_get(j, "step")) == 6 && json_integer_value(json_object_get(j, "frames")) == 3);
    json_decref(j);
    snprintf(pa, sizeof pa, "%s/a/frames.h5", dir);
    plume_frame fa, fb;
    plume_err err = {{0}};
    CHECK(plume_frames_read(pa, -1, &fa, &err) == PLUME_OK);
    CHECK(plume_frames_read(pb, -1, &fb, &err) == PLUME_OK);
    if (fa.x && fb.x) {
        CHECK(fa.index == 6 && fb.index == 6 && fa.step == 6 && fb.step == 6 && fa.t == fb.t);
        double dx = 0.0, dv = 0.0, span = 0.0;
        for (plume_index i = 0; i < 3 * fa.nv; i++) {
            dx = fmax(dx, fabs(fa.x[i] - fb.x[i]));
            dv = fmax(dv, fabs(fa.v[i] - fb.v[i]));
            span = fmax(span, fabs(fa.x[i]));
        }
        CHECK(dx <= 1e-10);
        CHECK(dv <= 1e-8);
        CHECK(span > 0.05);
    }
    plume_frame_free(&fa);
    plume_frame_free(&fb);
    snprintf(pc, sizeof pc, "%s/b/frame_00006.vtu", dir);
    CHECK(exists_nonempty(pc));
    snprintf(pc, sizeof pc, "%s/b", dir);
    check_series(pc, 7, 1); /* the restart kept frames 0-3 in the collection and added 4-6 */
    /* restarting into another directory copies the frames file there first */
    snprintf(args, sizeof args, "%s/s.json --restart %s -o %s/c --frames 1 --quiet", dir, pa, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    plume_frames_info info;
    snprintf(pc, sizeof pc, "%s/c/frames.h5", dir);
    CHECK(plume_frames_info_read(pc, &info, &err) == PLUME_OK && info.count == 8);
    CHECK(plume_frames_info_read(pa, &info, &err) == PLUME_OK && info.count == 7);
    /* a frames file of another scene is refused */
    write_strip_variant(dir, "free.json", "\"constraint\": true", "\"constraint\": false");
    snprintf(args, sizeof args, "%s/free.json --restart %s -o %s/d --frames 1 --quiet", dir, pa, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 2);
    CHECK(strstr(errs, "another scene") != NULL);
    rm_rf(dir);
}

/* A step that cannot converge even halved: exit 3, the reason on stderr, frames so far kept. */
void test_feather_app_nonconvergence(void)
{
    char dir[64] = "/tmp/plume-noconv-XXXXXX", args[512], out[16384], errs[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    write_strip_variant(dir, "s.json", "\"solver\": \"newton\"", "\"solver\": \"newton\", \"max_iter\": 1, \"max_halvings\": 1");
    snprintf(args, sizeof args, "%s/s.json -o %s/run --frames 4 --quiet --json", dir, dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 3);
    CHECK(strstr(errs, "did not converge") && strstr(errs, "iteration cap"));
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    CHECK(j && json_is_false(json_object_get(j, "converged")) && json_integer_value(json_object_get(j, "steps")) == 0);
    CHECK(j && json_integer_value(json_object_get(j, "steps_halved")) == 1);
    json_decref(j);
    snprintf(path, sizeof path, "%s/run/frame_00000.vtu", dir);
    CHECK(exists_nonempty(path));
    snprintf(path, sizeof path, "%s/run/frames.h5", dir);
    plume_frames_info info;
    plume_err err = {{0}};
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 1);
    snprintf(path, sizeof path, "%s/run", dir);
    check_series(path, 1, 1); /* what was written before the failure is a valid series */
    rm_rf(dir);
}

/* The solver benchmarks' scenes (docs/solver-nonconvexity.md) load: the feather at 1.25 mm (11.4k
 * elements) and the contact stack, whose start is not crossed. */
void test_feather_app_benchmark_scenes(void)
{
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load("../data/feather/scene_anisotropic_1.25mm.json", &s, &err) == PLUME_OK);
    if (s)
        CHECK(s->mesh->nt > 11000 && s->mesh->nt < 12000 && s->nbarb > 5000);
    else
        fprintf(stderr, "    %s\n", err.msg);
    plume_scene_destroy(&s);
    CHECK(plume_scene_load("../data/contact/stack.json", &s, &err) == PLUME_OK);
    if (s) {
        CHECK(s->nobjects == 7 && s->has_contact && s->mesh->nt > 3800 && s->mesh->nt < 4000);
        CHECK(plume_scene_check_start(s, &err) == PLUME_OK);
    } else {
        fprintf(stderr, "    %s\n", err.msg);
    }
    plume_scene_destroy(&s);
}

/* --duration T ends at t = T: whole steps of dt, then a shorter one when dt does not divide T, and
 * the last state is a frame (strip: dt 0.01, a frame every 2 steps; the shipped feather: dt 0.011) */
void test_feather_app_duration_end_time(void)
{
    char dir[64] = "/tmp/plume-feather-XXXXXX", args[512], out[16384], errs[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    const struct {
        const char *scene, *duration;
        double t;
        long steps, frames;
    } cases[] = {{"../data/shell/strip_scene.json", "0.035", 0.035, 4, 3},
                 {"../data/shell/strip_scene.json", "0.04", 0.04, 4, 3},
                 {"../data/feather/scene_anisotropic.json", "0.05", 0.05, 5, 6}};
    for (int c = 0; c < 3; c++) {
        snprintf(args, sizeof args, "%s --duration %s -o %s/%d --json --quiet", cases[c].scene, cases[c].duration, dir, c);
        CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
        json_error_t je;
        json_t *j = json_loads(out, 0, &je);
        CHECK(j != NULL);
        if (!j) {
            fprintf(stderr, "    stdout: %s\n    stderr: %s\n", out, errs);
            continue;
        }
        double t = json_real_value(json_object_get(j, "time"));
        fprintf(stderr, "    %s --duration %s: t = %.17g after %lld steps, %lld frames\n", cases[c].scene,
                cases[c].duration, t, (long long)json_integer_value(json_object_get(j, "steps")),
                (long long)json_integer_value(json_object_get(j, "frames")));
        CHECK_REL(t, cases[c].t, 1e-12, 0.0);
        CHECK(json_integer_value(json_object_get(j, "steps")) == cases[c].steps);
        CHECK(json_integer_value(json_object_get(j, "frames")) == cases[c].frames);
        json_decref(j);
        /* the frames file's last frame is the end state */
        plume_frame f = {0};
        plume_err err;
        snprintf(path, sizeof path, "%s/%d/frames.h5", dir, c);
        CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK);
        CHECK_REL(f.t, cases[c].t, 1e-12, 0.0);
        CHECK(f.index == cases[c].frames - 1);
        plume_frame_free(&f);
    }
    rm_rf(dir);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The shipped feather's mean_curvature stays in a range ParaView can colour: at the end of its
 * second, the largest |H| is within 400 times the median (each edge's angle spread over its
 * vertices' areas; a triangle-area division gave outline slivers 10^3-10^4 times the median), and
 * crease_angle is 0 or a fold beyond pi / 2 */
void test_feather_app_curvature_range(void)
{
    char dir[64] = "/tmp/plume-feather-XXXXXX", args[512], out[16384], errs[8192], path[256];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    snprintf(args, sizeof args, "../data/feather/scene_anisotropic.json -o %s/run --json --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, errs, sizeof errs) == 0);
    json_error_t je;
    json_t *j = json_loads(out, 0, &je);
    long last = j ? (long)json_integer_value(json_object_get(j, "last_frame")) : -1;
    json_decref(j);
    CHECK(last > 0);
    for (long k = 1; k <= last; k += last - 1) { /* the first step's frame and the last one */
        snprintf(path, sizeof path, "%s/run/frame_%05ld.vtu", dir, k);
        plume_vtu_data d;
        plume_err err;
        if (plume_vtu_read(path, &d, &err) != PLUME_OK) {
            CHECK(!"the frame reads back");
            continue;
        }
        const plume_vtu_array *H = plume_vtu_find(&d, 0, "mean_curvature"), *C = plume_vtu_find(&d, 0, "crease_angle");
        CHECK(H && C && H->ntuples == d.ncells && C->ntuples == d.ncells);
        if (H && C && H->ntuples > 0) {
            long n = H->ntuples, creases = 0;
            double *a = malloc((size_t)n * sizeof *a);
            for (long i = 0; i < n; i++) {
                a[i] = fabs(H->values[i]);
                CHECK(C->values[i] == 0.0 || (C->values[i] > 0.5 * M_PI && C->values[i] <= M_PI));
                creases += C->values[i] > 0.0;
            }
            qsort(a, (size_t)n, sizeof *a, cmp_double);
            double median = a[n / 2], max = a[n - 1];
            fprintf(stderr, "    frame %ld: |mean_curvature| median %.3g, max %.3g (%.0f times), %ld triangles on a crease\n",
                    k, median, max, max / median, creases);
            CHECK(median > 0.0 && max <= 400.0 * median);
            free(a);
        }
        plume_vtu_data_free(&d);
    }
    rm_rf(dir);
}

/* data/feather/scene_anisotropic_homogenised.json: the vane's bending read from the moduli that
 * apps/homogenize writes for data/layout_barbules_table3a.json (make writes the file beside the
 * scene; here a copy of the scene and its mesh inputs in a scratch directory gets its own). Its
 * D_long and D_trans are Table 3 (a)'s to 1 %, its D_16 and D_26 small enough to be taken as is. */
void test_feather_app_homogenised_scene(void)
{
    char dir[] = "/tmp/plume-feather-hom-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    char cmd[1024], out[4096], errs[4096];
    snprintf(cmd, sizeof cmd, "cp ../data/feather/scene_anisotropic_homogenised.json ../data/feather/feather_shape.json "
             "../data/feather/outline.obj %s/", dir);
    CHECK(system(cmd) == 0);
    snprintf(cmd, sizeof cmd, "--config ../data/layout_barbules_table3a.json -o %s/moduli_table3a.h5", dir);
    CHECK(app_run(dir, "homogenize", cmd, out, sizeof out, errs, sizeof errs) == 0);
    snprintf(cmd, sizeof cmd, "%s/scene_anisotropic_homogenised.json", dir);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load(cmd, &s, &err) == PLUME_OK);
    if (s) {
        CHECK_REL(s->mats[0].bending.D_long, 2.5e-4, 0.01, 0.0);
        CHECK_REL(s->mats[0].bending.D_trans, 1e-7, 0.01, 0.0);
        CHECK(s->mats[0].bending.D_twist > 0.0 && s->mats[0].constraint && s->nmat == 2);
    } else {
        fprintf(stderr, "    %s\n", err.msg);
    }
    plume_scene_destroy(&s);
    rm_rf(dir);
}
