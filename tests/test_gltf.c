/* glTF export (lib/io/gltf.h, plume_run_write_gltf): the .glb read back by a reader of its own
 * (header, chunks, accessors): a hand-made document's morph targets and per-frame meshes give back
 * every frame's positions, normals and field; a run's file has a node per scene object named as in
 * the scene whose last frame is frames.h5's to float precision; bad documents, options and scene
 * keys are refused by name. (Khronos' validator and Blender read the same files in
 * tests/graphics/check_gltf.py.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "harness.h"
#include "../lib/io/frames.h"
#include "../lib/io/gltf.h"
#include "../macro/scene/run.h"
#include "../macro/scene/scene.h"

/* A .glb read back: its JSON and its binary chunk. */
typedef struct {
    json_t *json;
    unsigned char *file;
    const unsigned char *bin;
    size_t nbin;
} glb;

static uint32_t u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Reads path; 0 when its header and two chunks are well formed. */
static int glb_read(const char *path, glb *g)
{
    memset(g, 0, sizeof *g);
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    g->file = malloc((size_t)n + 1);
    int ok = g->file && fread(g->file, 1, (size_t)n, f) == (size_t)n;
    fclose(f);
    if (!ok || n < 28 || u32(g->file) != 0x46546C67 || u32(g->file + 4) != 2 || u32(g->file + 8) != (uint32_t)n)
        return -1;
    uint32_t nj = u32(g->file + 12);
    if (u32(g->file + 16) != 0x4E4F534A || nj % 4 || 20 + (size_t)nj + 8 > (size_t)n)
        return -1;
    g->json = json_loadb((const char *)g->file + 20, nj, 0, NULL);
    const unsigned char *b = g->file + 20 + nj;
    g->nbin = u32(b);
    g->bin = b + 8;
    return g->json && u32(b + 4) == 0x004E4942 && g->nbin % 4 == 0 && 28 + (size_t)nj + g->nbin == (size_t)n ? 0 : -1;
}

static void glb_free(glb *g)
{
    json_decref(g->json);
    free(g->file);
}

/* Accessor a's floats (NULL when it is not a float accessor inside the chunk); its count and
 * components in *count, *ncomp. */
static const float *floats(const glb *g, json_int_t a, size_t *count, int *ncomp)
{
    json_t *acc = json_array_get(json_object_get(g->json, "accessors"), (size_t)a);
    json_t *view = json_array_get(json_object_get(g->json, "bufferViews"),
                                  (size_t)json_integer_value(json_object_get(acc, "bufferView")));
    const char *type = json_string_value(json_object_get(acc, "type"));
    if (!acc || !view || !type || json_integer_value(json_object_get(acc, "componentType")) != 5126)
        return NULL;
    *count = (size_t)json_integer_value(json_object_get(acc, "count"));
    *ncomp = strcmp(type, "VEC3") == 0 ? 3 : 1;
    size_t off = (size_t)json_integer_value(json_object_get(view, "byteOffset"));
    size_t len = (size_t)json_integer_value(json_object_get(view, "byteLength"));
    if (off % 4 || off + len > g->nbin || len != *count * (size_t)*ncomp * sizeof(float))
        return NULL;
    return (const float *)(g->bin + off);
}

/* The positions of node `node`'s mesh at frame k (morph: base + target k - 1) into x[3 nv]; its
 * vertex count, 0 when unreadable. */
static size_t morph_positions(const glb *g, json_t *node, int k, const char *attr, float *x, size_t cap)
{
    json_t *mesh = json_array_get(json_object_get(g->json, "meshes"),
                                  (size_t)json_integer_value(json_object_get(node, "mesh")));
    json_t *prim = json_array_get(json_object_get(mesh, "primitives"), 0);
    size_t n = 0, nt = 0;
    int c = 0, ct = 0;
    const float *base = floats(g, json_integer_value(json_object_get(json_object_get(prim, "attributes"), attr)), &n, &c);
    if (!base || n * (size_t)c > cap)
        return 0;
    memcpy(x, base, n * (size_t)c * sizeof *x);
    if (k > 0) {
        json_t *t = json_array_get(json_object_get(prim, "targets"), (size_t)k - 1);
        const float *d = floats(g, json_integer_value(json_object_get(t, attr)), &nt, &ct);
        if (!d || nt != n || ct != c)
            return 0;
        for (size_t i = 0; i < n * (size_t)c; i++)
            x[i] += d[i];
    }
    return n;
}

/* A unit square split in two triangles of two materials, three frames: z rises by k, vertex 3
 * moves in y by k too; a field of k per vertex. */
static void square_doc(plume_gltf_doc *d, plume_gltf_mesh *m, plume_gltf_primitive p[2], plume_gltf_material mat[2],
                       float x[36], float f[12], double t[3])
{
    static const uint32_t t0[3] = {0, 1, 2}, t1[3] = {0, 2, 3};
    static const float sq[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < 12; i++)
            x[12 * k + i] = sq[i] + (i % 3 == 2 ? (float)k : 0.0f);
        x[12 * k + 10] += (float)k;
        for (int i = 0; i < 4; i++)
            f[4 * k + i] = (float)k;
        t[k] = 0.5 * k;
    }
    p[0] = (plume_gltf_primitive){0, 1, t0};
    p[1] = (plume_gltf_primitive){1, 1, t1};
    mat[0] = (plume_gltf_material){"vane", {0.8f, 0.7f, 0.6f, 1.0f}, 0.6f, 1};
    mat[1] = (plume_gltf_material){"rachis", {0.2f, 0.1f, 0.1f, 1.0f}, 0.5f, 1};
    *m = (plume_gltf_mesh){"square", 4, 2, p, x, f, "{\"plume_object\": 0}"};
    *d = (plume_gltf_doc){1, m, 2, mat, 3, t, PLUME_GLTF_MORPH, "mean_curvature", "test", "{\"plume\": {}}"};
}

/* Morph targets give back every frame; normals are unit; the weights key target k at frame k. */
void test_gltf_morph_document(void)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/plume-gltf-%ld.glb", (long)getpid());
    plume_gltf_doc d;
    plume_gltf_mesh m;
    plume_gltf_primitive p[2];
    plume_gltf_material mat[2];
    float x[36], f[12], got[12];
    double t[3];
    square_doc(&d, &m, p, mat, x, f, t);
    plume_err err = {{0}};
    CHECK(plume_gltf_write(path, &d, &err) == PLUME_OK);
    glb g;
    CHECK(glb_read(path, &g) == 0);
    json_t *nodes = json_object_get(g.json, "nodes");
    CHECK(json_array_size(nodes) == 1);
    json_t *node = json_array_get(nodes, 0);
    CHECK(strcmp(json_string_value(json_object_get(node, "name")), "square") == 0);
    CHECK(strcmp(json_string_value(json_object_get(json_object_get(g.json, "asset"), "version")), "2.0") == 0);
    json_t *mesh = json_array_get(json_object_get(g.json, "meshes"), 0);
    CHECK(json_array_size(json_object_get(mesh, "primitives")) == 2);
    CHECK(json_array_size(json_object_get(json_array_get(json_object_get(mesh, "primitives"), 1), "targets")) == 2);
    CHECK(strcmp(json_string_value(json_object_get(json_array_get(json_object_get(g.json, "materials"), 1), "name")),
                 "rachis") == 0);
    for (int k = 0; k < 3; k++) {
        CHECK(morph_positions(&g, node, k, "POSITION", got, 12) == 4);
        for (int i = 0; i < 12; i++)
            CHECK(fabsf(got[i] - x[12 * k + i]) <= 1e-6f);
        CHECK(morph_positions(&g, node, k, "_MEAN_CURVATURE", got, 12) == 4);
        for (int i = 0; i < 4; i++)
            CHECK(fabsf(got[i] - (float)k) <= 1e-6f);
        CHECK(morph_positions(&g, node, k, "NORMAL", got, 12) == 4);
        for (int i = 0; i < 4; i++)
            CHECK(fabsf(got[3 * i] * got[3 * i] + got[3 * i + 1] * got[3 * i + 1] + got[3 * i + 2] * got[3 * i + 2] -
                        1.0f) < 1e-5f);
    }
    /* frame 0 is flat: normals (0, 0, 1) */
    CHECK(morph_positions(&g, node, 0, "NORMAL", got, 12) == 4 && fabsf(got[2] - 1.0f) < 1e-6f);
    /* weights: input the three times, output target k - 1 = 1 at frame k */
    json_t *anim = json_array_get(json_object_get(g.json, "animations"), 0);
    json_t *sampler = json_array_get(json_object_get(anim, "samplers"), 0);
    size_t n = 0;
    int c = 0;
    const float *in = floats(&g, json_integer_value(json_object_get(sampler, "input")), &n, &c);
    CHECK(in && n == 3 && in[0] == 0.0f && in[2] == 1.0f);
    const float *w = floats(&g, json_integer_value(json_object_get(sampler, "output")), &n, &c);
    CHECK(w && n == 6 && w[0] == 0.0f && w[1] == 0.0f && w[2] == 1.0f && w[3] == 0.0f && w[4] == 0.0f && w[5] == 1.0f);
    CHECK(strcmp(json_string_value(json_object_get(json_object_get(json_array_get(json_object_get(anim, "channels"), 0),
                                                                   "target"), "path")), "weights") == 0);
    glb_free(&g);

    /* frames: a parent and a child per frame, its own positions, shown by a step scale */
    d.animation = PLUME_GLTF_FRAMES;
    CHECK(plume_gltf_write(path, &d, &err) == PLUME_OK);
    CHECK(glb_read(path, &g) == 0);
    nodes = json_object_get(g.json, "nodes");
    CHECK(json_array_size(nodes) == 4);
    CHECK(strcmp(json_string_value(json_object_get(json_array_get(nodes, 3), "name")), "square") == 0);
    CHECK(json_array_size(json_object_get(json_array_get(nodes, 3), "children")) == 3);
    for (int k = 0; k < 3; k++) {
        CHECK(morph_positions(&g, json_array_get(nodes, (size_t)k), 0, "POSITION", got, 12) == 4);
        for (int i = 0; i < 12; i++)
            CHECK(got[i] == x[12 * k + i]);
        CHECK(json_real_value(json_array_get(json_object_get(json_array_get(nodes, (size_t)k), "scale"), 0)) ==
              (k == 0 ? 1.0 : 0.0));
    }
    anim = json_array_get(json_object_get(g.json, "animations"), 0);
    CHECK(json_array_size(json_object_get(anim, "channels")) == 3);
    CHECK(strcmp(json_string_value(json_object_get(json_array_get(json_object_get(anim, "samplers"), 1),
                                                   "interpolation")), "STEP") == 0);
    glb_free(&g);
    unlink(path);
}

/* Bad documents are refused by name, and nothing is written. */
void test_gltf_bad_document(void)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/plume-gltf-bad-%ld.glb", (long)getpid());
    unlink(path);
    plume_gltf_doc d;
    plume_gltf_mesh m;
    plume_gltf_primitive p[2];
    plume_gltf_material mat[2];
    float x[36], f[12];
    double t[3];
    plume_err err = {{0}};
    square_doc(&d, &m, p, mat, x, f, t);
    t[2] = t[1];
    CHECK(plume_gltf_write(path, &d, &err) == PLUME_EINVAL && strstr(err.msg, "frame times must increase"));
    square_doc(&d, &m, p, mat, x, f, t);
    uint32_t bad[3] = {0, 1, 4};
    p[1].tri = bad;
    CHECK(plume_gltf_write(path, &d, &err) == PLUME_EINVAL && strstr(err.msg, "'square'") && strstr(err.msg, "vertex 4"));
    square_doc(&d, &m, p, mat, x, f, t);
    x[20] = NAN;
    CHECK(plume_gltf_write(path, &d, &err) == PLUME_EINVAL && strstr(err.msg, "'square'") && strstr(err.msg, "frame 1"));
    square_doc(&d, &m, p, mat, x, f, t);
    p[0].material = 2;
    CHECK(plume_gltf_write(path, &d, &err) == PLUME_EINVAL && strstr(err.msg, "primitive 0"));
    square_doc(&d, &m, p, mat, x, f, t);
    CHECK(plume_gltf_write("/nonexistent-dir/a.glb", &d, &err) == PLUME_EIO && strstr(err.msg, "/nonexistent-dir/a.glb"));
    CHECK(access(path, F_OK) != 0);
}

/* A run of data/contact/stack.json (five sheets between two kinematic bodies): a node per object
 * named as in the scene, kinematic ones in the "kinematic" material, every vertex of the last
 * frame within 1e-6 of the scene's size of frames.h5's, in glTF's axes; the field per vertex. */
void test_gltf_run_objects(void)
{
    char dir[64] = "/tmp/plume-gltfr-XXXXXX", glbp[128];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.output_dir = dir;
    o.frames = 2;
    plume_run *r = NULL;
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load("../data/contact/stack.json", &s, &err) == PLUME_OK);
    CHECK(s && plume_run_create(s, &o, &r, &err) == PLUME_OK);
    CHECK(r && plume_run_to_end(r, &err) == PLUME_OK);
    snprintf(glbp, sizeof glbp, "%s/stack.glb", dir);
    plume_gltf_opts go;
    plume_gltf_opts_default(&go);
    go.field = "J";
    CHECK(r && plume_run_write_gltf(r, NULL, glbp, &go, &err) == PLUME_OK);
    glb g;
    CHECK(glb_read(glbp, &g) == 0);
    plume_frame last = {0};
    char frames[128];
    snprintf(frames, sizeof frames, "%s/frames.h5", dir);
    CHECK(plume_frames_read(frames, -1, &last, &err) == PLUME_OK && last.index == 2);
    json_t *nodes = json_object_get(g.json, "nodes");
    CHECK(s && (int)json_array_size(nodes) == s->nobjects && s->nobjects == 7);
    double worst = 0.0;
    float *x = malloc(3 * (size_t)(s ? s->mesh->nv : 1) * sizeof *x), *J = malloc((size_t)(s ? s->mesh->nv : 1) * sizeof *J);
    for (int i = 0; s && last.x && i < s->nobjects; i++) {
        json_t *node = json_array_get(nodes, (size_t)i);
        const plume_scene_object *so = &s->objects[i];
        CHECK(strcmp(json_string_value(json_object_get(node, "name")), so->name) == 0);
        CHECK(json_is_true(json_object_get(json_object_get(node, "extras"), "kinematic")) == (so->kinematic != 0));
        json_t *mesh = json_array_get(json_object_get(g.json, "meshes"), (size_t)json_integer_value(json_object_get(node, "mesh")));
        json_t *prim = json_array_get(json_object_get(mesh, "primitives"), 0);
        json_t *mat = json_array_get(json_object_get(g.json, "materials"),
                                     (size_t)json_integer_value(json_object_get(prim, "material")));
        CHECK((strcmp(json_string_value(json_object_get(mat, "name")), "kinematic") == 0) == (so->kinematic != 0));
        CHECK(morph_positions(&g, node, 2, "POSITION", x, 3 * (size_t)s->mesh->nv) == (size_t)so->nv);
        for (plume_index v = 0; v < so->nv; v++) {
            const double *p = last.x + 3 * (so->v0 + v);
            const double q[3] = {p[0], p[2], -p[1]};
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(x[3 * v + c] - q[c]) / s->length);
        }
        CHECK(morph_positions(&g, node, 2, "_J", J, (size_t)s->mesh->nv) == (size_t)so->nv);
        for (plume_index v = 0; v < so->nv; v++) /* a sheet's J near 1; the kinematic bodies have none (0) */
            CHECK(so->kinematic ? J[v] == 0.0f : fabsf(J[v] - 1.0f) < 0.05f);
    }
    printf("    stack: 7 objects, last frame's largest gap to frames.h5 %.2e of the scene's size\n", worst);
    CHECK(worst <= 1e-6);
    free(x);
    free(J);
    plume_frame_free(&last);
    glb_free(&g);
    plume_run_destroy(&r);
    plume_scene_destroy(&s);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

/* The scene key "gltf" writes DIR/<file> when the run ends; a file whose directory cannot be made,
 * bad keys, bad material names, a static scene, unknown or midedge-only fields and another scene's frames are refused
 * by name (the directory before the run). */
void test_gltf_scene_key(void)
{
    char dir[64] = "/tmp/plume-gltfk-XXXXXX", path[128];
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    json_t *doc = json_load_file("../data/shell/strip_on_plate.json", 0, NULL);
    CHECK(doc != NULL);
    json_object_set_new(doc, "gltf", json_pack("{s:s, s:s}", "file", "strip.glb", "animation", "frames"));
    char *scene_text = json_dumps(doc, 0);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    CHECK(plume_scene_load_json(scene_text, "../data/shell/strip_on_plate.json", NULL, &s, &err) == PLUME_OK);
    plume_run_opts o;
    plume_run_opts_default(&o);
    o.output_dir = dir;
    o.frames = 1;
    plume_run *r = NULL;
    CHECK(s && plume_run_create(s, &o, &r, &err) == PLUME_OK && plume_run_to_end(r, &err) == PLUME_OK);
    snprintf(path, sizeof path, "%s/strip.glb", dir);
    glb g;
    CHECK(glb_read(path, &g) == 0);
    json_t *nodes = json_object_get(g.json, "nodes");
    /* a "mesh" scene: one object named after the scene file, two frames and its parent */
    CHECK(json_array_size(nodes) == 3);
    CHECK(strcmp(json_string_value(json_object_get(json_array_get(nodes, 2), "name")), "strip_on_plate") == 0);
    CHECK(json_array_size(json_object_get(json_array_get(json_object_get(g.json, "meshes"), 0), "primitives")) == 2);
    glb_free(&g);

    /* options and frames that do not fit */
    plume_gltf_opts go;
    plume_gltf_opts_default(&go);
    go.field = "nope";
    CHECK(r && plume_run_write_gltf(r, NULL, path, &go, &err) == PLUME_EINVAL && strstr(err.msg, "\"nope\""));
    go.field = "curvature_bb";
    CHECK(r && plume_run_write_gltf(r, NULL, path, &go, &err) == PLUME_EINVAL && strstr(err.msg, "mean_curvature"));
    go.field = NULL;
    go.animation = 7;
    CHECK(r && plume_run_write_gltf(r, NULL, path, &go, &err) == PLUME_EINVAL && strstr(err.msg, "animation"));
    go.animation = PLUME_GLTF_MORPH;
    CHECK(r && plume_run_write_gltf(r, "/nonexistent.h5", path, &go, &err) != PLUME_OK &&
          strstr(err.msg, "/nonexistent.h5"));
    plume_run_destroy(&r);
    plume_scene_destroy(&s);
    /* another scene's run against these frames */
    char frames[128];
    snprintf(frames, sizeof frames, "%s/frames.h5", dir);
    CHECK(plume_run_open("../data/shell/strip_scene.json", NULL, &r, &err) == PLUME_OK);
    CHECK(r && plume_run_write_gltf(r, frames, path, NULL, &err) == PLUME_EINVAL && strstr(err.msg, "vertices"));
    plume_run_destroy(&r);

    /* a file whose directory cannot be made is refused before the run, naming it */
    char blocker[128];
    snprintf(blocker, sizeof blocker, "%s/a_file", dir);
    FILE *bf = fopen(blocker, "w");
    CHECK(bf != NULL);
    if (bf)
        fclose(bf);
    json_object_set_new(doc, "gltf", json_pack("{s:s}", "file", "a_file/x.glb"));
    free(scene_text);
    scene_text = json_dumps(doc, 0);
    CHECK(plume_scene_load_json(scene_text, "../data/shell/strip_on_plate.json", NULL, &s, &err) == PLUME_OK);
    CHECK(s && plume_run_create(s, &o, &r, &err) == PLUME_OK);
    CHECK(r && plume_run_start(r, &err) == PLUME_EIO && strstr(err.msg, "a_file/x.glb") &&
          strstr(err.msg, "cannot create its directory"));
    plume_run_destroy(&r);
    plume_scene_destroy(&s);

    /* the key's bad values name it */
    static const char *const bad[][2] = {{"3", "gltf"},
                                         {"{\"animation\": \"gif\"}", "gltf.animation"},
                                         {"{\"field\": \"curvature_bt\"}", "gltf.field"},
                                         {"{\"field\": \"nope\"}", "gltf.field"},
                                         {"{\"file\": \"\"}", "gltf.file"},
                                         {"{\"fps\": 24}", "fps"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        json_object_set_new(doc, "gltf", json_loads(bad[i][0], JSON_DECODE_ANY, NULL));
        free(scene_text);
        scene_text = json_dumps(doc, 0);
        CHECK(plume_scene_load_json(scene_text, "strip_on_plate.json", NULL, &s, &err) != PLUME_OK &&
              strstr(err.msg, bad[i][1]));
        plume_scene_destroy(&s);
    }
    /* a material's bad name names it */
    json_object_set_new(doc, "gltf", json_true());
    static const char *const bad_names[] = {"3", "\"\"",
                                            "\"a name longer than sixty-three bytes, which is where material names stop\""};
    for (size_t i = 0; i < sizeof bad_names / sizeof bad_names[0]; i++) {
        json_object_set_new(json_array_get(json_object_get(doc, "materials"), 0), "name",
                            json_loads(bad_names[i], JSON_DECODE_ANY, NULL));
        free(scene_text);
        scene_text = json_dumps(doc, 0);
        CHECK(plume_scene_load_json(scene_text, "strip_on_plate.json", NULL, &s, &err) == PLUME_EFORMAT &&
              strstr(err.msg, "materials[0].name"));
        plume_scene_destroy(&s);
    }
    /* a static scene has no frames */
    json_t *st = json_load_file("../data/benchmarks/cantilever_shear.json", 0, NULL);
    json_object_set_new(st, "gltf", json_true());
    free(scene_text);
    scene_text = json_dumps(st, 0);
    CHECK(plume_scene_load_json(scene_text, "../data/benchmarks/cantilever_shear.json", NULL, &s, &err) == PLUME_OK);
    CHECK(s && plume_run_create(s, NULL, &r, &err) == PLUME_EINVAL && strstr(err.msg, "\"gltf\" is for dynamic scenes"));
    plume_scene_destroy(&s);
    json_decref(st);
    json_decref(doc);
    free(scene_text);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}
