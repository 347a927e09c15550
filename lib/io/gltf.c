/* plume: glTF 2.0 binary files of animated triangle meshes (lib/io/gltf.h). The JSON chunk is built
 * with jansson; the binary chunk holds every array, each buffer view 4-byte aligned. */
#include "gltf.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../core/vec3.h"

enum {
    GLB_MAGIC = 0x46546C67,      /* "glTF" */
    GLB_JSON = 0x4E4F534A,       /* "JSON" */
    GLB_BIN = 0x004E4942,        /* "BIN\0" */
    GL_FLOAT = 5126,
    GL_UNSIGNED_INT = 5125,
    GL_ARRAY_BUFFER = 34962,
    GL_ELEMENT_ARRAY_BUFFER = 34963,
    GL_TRIANGLES = 4
};

/* The binary chunk being filled, and the JSON arrays of its views and accessors. */
typedef struct {
    unsigned char *data;
    size_t n, cap;
    json_t *views, *accessors;
    double *normal_acc; /* [3 nv] of the largest mesh: vertex_normals' sums */
    int failed; /* out of memory somewhere: reported once at the end */
} glb_builder;

static int grow(glb_builder *b, size_t more)
{
    if (b->n + more <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 1 << 16;
    while (cap < b->n + more)
        cap *= 2;
    unsigned char *p = realloc(b->data, cap);
    if (!p)
        return -1;
    b->data = p, b->cap = cap;
    return 0;
}

/* Appends `bytes` of data as a new buffer view (target 0: none); returns its index, or -1. */
static int add_view(glb_builder *b, const void *data, size_t bytes, int target)
{
    size_t pad = (4 - b->n % 4) % 4;
    if (b->failed || grow(b, pad + bytes) != 0)
        return b->failed = 1, -1;
    memset(b->data + b->n, 0, pad);
    b->n += pad;
    memcpy(b->data + b->n, data, bytes);
    json_t *v = json_pack("{s:i, s:I, s:I}", "buffer", 0, "byteOffset", (json_int_t)b->n, "byteLength",
                          (json_int_t)bytes);
    if (v && target)
        json_object_set_new(v, "target", json_integer(target));
    b->n += bytes;
    if (!v || json_array_append_new(b->views, v) != 0)
        return b->failed = 1, -1;
    return (int)json_array_size(b->views) - 1;
}

/* An accessor of `count` elements of `ncomp` floats (type "SCALAR" or "VEC3") with min and max per
 * component (glTF requires them on positions; the validator checks them everywhere given). */
static int add_floats(glb_builder *b, const float *v, size_t count, int ncomp, int target)
{
    int view = add_view(b, v, count * (size_t)ncomp * sizeof(float), target);
    if (view < 0)
        return -1;
    json_t *mn = json_array(), *mx = json_array();
    for (int c = 0; c < ncomp; c++) {
        float lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < count; i++) {
            float a = v[i * (size_t)ncomp + (size_t)c];
            lo = a < lo ? a : lo;
            hi = a > hi ? a : hi;
        }
        json_array_append_new(mn, json_real(lo));
        json_array_append_new(mx, json_real(hi));
    }
    json_t *a = json_pack("{s:i, s:i, s:I, s:s, s:o, s:o}", "bufferView", view, "componentType", GL_FLOAT, "count",
                          (json_int_t)count, "type", ncomp == 1 ? "SCALAR" : "VEC3", "min", mn, "max", mx);
    if (!a || json_array_append_new(b->accessors, a) != 0)
        return b->failed = 1, -1;
    return (int)json_array_size(b->accessors) - 1;
}

static int add_indices(glb_builder *b, const uint32_t *idx, size_t count)
{
    int view = add_view(b, idx, count * sizeof *idx, GL_ELEMENT_ARRAY_BUFFER);
    if (view < 0)
        return -1;
    json_t *a = json_pack("{s:i, s:i, s:I, s:s}", "bufferView", view, "componentType", GL_UNSIGNED_INT, "count",
                          (json_int_t)count, "type", "SCALAR");
    if (!a || json_array_append_new(b->accessors, a) != 0)
        return b->failed = 1, -1;
    return (int)json_array_size(b->accessors) - 1;
}

/* Unit vertex normals of positions x (3 nv) over every primitive's triangles: the sum of the
 * triangles' area vectors around each vertex (accumulated in acc, 3 nv), normalised; (0, 1, 0)
 * where that sum vanishes. */
static void vertex_normals(const plume_gltf_mesh *m, const float *x, double *acc, float *n)
{
    memset(acc, 0, 3 * (size_t)m->nv * sizeof *acc);
    for (int p = 0; p < m->nprim; p++)
        for (uint32_t t = 0; t < m->prims[p].ntri; t++) {
            const uint32_t *v = m->prims[p].tri + 3 * (size_t)t;
            double c[3][3], e1[3], e2[3], a[3];
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++)
                    c[k][j] = x[3 * (size_t)v[k] + j];
            sub3(c[1], c[0], e1);
            sub3(c[2], c[0], e2);
            cross3(e1, e2, a);
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++)
                    acc[3 * (size_t)v[k] + j] += a[j];
        }
    for (uint32_t i = 0; i < m->nv; i++) {
        const double *a = acc + 3 * (size_t)i, len = sqrt(dot3(a, a));
        for (int c = 0; c < 3; c++)
            n[3 * (size_t)i + c] = len > 0.0 ? (float)(a[c] / len) : (c == 1 ? 1.0f : 0.0f);
    }
}

static json_t *parse_extras(const char *text)
{
    if (!text)
        return NULL;
    json_t *j = json_loads(text, 0, NULL);
    if (j && !json_is_object(j)) {
        json_decref(j);
        return NULL;
    }
    return j;
}

/* Appends `node` (stolen) to nodes with the extras of the JSON text `extras` (NULL: none). */
static void append_node(json_t *nodes, json_t *node, const char *extras)
{
    json_t *ex = parse_extras(extras);
    if (node && ex)
        json_object_set_new(node, "extras", ex);
    else
        json_decref(ex);
    json_array_append_new(nodes, node);
}

static char *attribute_name(const char *field)
{
    size_t n = strlen(field);
    char *s = malloc(n + 2);
    if (!s)
        return NULL;
    s[0] = '_';
    for (size_t i = 0; i < n; i++)
        s[i + 1] = isalnum((unsigned char)field[i]) ? (char)toupper((unsigned char)field[i]) : '_';
    s[n + 1] = '\0';
    return s;
}

static plume_status check_doc(const plume_gltf_doc *d, plume_err *err)
{
    if (!d || d->nmesh < 1 || !d->meshes || d->nmat < 1 || !d->mats || d->nframes < 1 || !d->times)
        return plume_err_set(err, PLUME_EINVAL, "glTF: a document needs meshes, materials and frames");
    if (d->animation != PLUME_GLTF_MORPH && d->animation != PLUME_GLTF_FRAMES)
        return plume_err_set(err, PLUME_EINVAL, "glTF: unknown animation %d", d->animation);
    for (int k = 0; k < d->nframes; k++)
        if (!isfinite(d->times[k]) || (k > 0 && !(d->times[k] > d->times[k - 1])))
            return plume_err_set(err, PLUME_EINVAL, "glTF: frame times must increase (frame %d at %g s)", k,
                                 d->times[k]);
    for (int i = 0; i < d->nmesh; i++) {
        const plume_gltf_mesh *m = &d->meshes[i];
        if (!m->name || m->nv < 1 || m->nprim < 1 || !m->prims || !m->x)
            return plume_err_set(err, PLUME_EINVAL, "glTF: mesh %d ('%s') needs vertices, positions and primitives", i,
                                 m->name ? m->name : "");
        for (int p = 0; p < m->nprim; p++) {
            const plume_gltf_primitive *pr = &m->prims[p];
            if (pr->material < 0 || pr->material >= d->nmat || pr->ntri < 1 || !pr->tri)
                return plume_err_set(err, PLUME_EINVAL, "glTF: mesh '%s' primitive %d: a material and triangles needed",
                                     m->name, p);
            for (size_t j = 0; j < 3 * (size_t)pr->ntri; j++)
                if (pr->tri[j] >= m->nv)
                    return plume_err_set(err, PLUME_EINVAL, "glTF: mesh '%s' primitive %d: vertex %u of %u", m->name,
                                         p, pr->tri[j], m->nv);
        }
        for (size_t j = 0; j < 3 * (size_t)m->nv * (size_t)d->nframes; j++)
            if (!isfinite(m->x[j]))
                return plume_err_set(err, PLUME_EINVAL, "glTF: mesh '%s': position %zu of frame %zu is not finite",
                                     m->name, j / 3 % m->nv, j / (3 * (size_t)m->nv));
    }
    return PLUME_OK;
}

/* The field's values of frame k with NaN (no value: kinematic parts) written as 0. */
static void field_frame(const plume_gltf_mesh *m, int k, float *out)
{
    const float *f = m->field + (size_t)k * m->nv;
    for (uint32_t i = 0; i < m->nv; i++)
        out[i] = isfinite(f[i]) ? f[i] : 0.0f;
}

/* The attributes of frame k (positions, normals, field) as new accessors, as displacements from
 * frame 0 when `base` holds frame 0's (morph targets). */
static json_t *frame_attributes(glb_builder *b, const plume_gltf_mesh *m, int k, const char *fattr, const float *base_x,
                                const float *base_n, const float *base_f, float *xs, float *ns, float *fs)
{
    const size_t n3 = 3 * (size_t)m->nv;
    const float *x = m->x + (size_t)k * n3;
    vertex_normals(m, x, b->normal_acc, ns);
    memcpy(xs, x, n3 * sizeof *xs);
    if (fattr)
        field_frame(m, k, fs);
    if (base_x) {
        for (size_t j = 0; j < n3; j++)
            xs[j] -= base_x[j], ns[j] -= base_n[j];
        if (fattr)
            for (uint32_t i = 0; i < m->nv; i++)
                fs[i] -= base_f[i];
    }
    int ax = add_floats(b, xs, m->nv, 3, GL_ARRAY_BUFFER), an = add_floats(b, ns, m->nv, 3, GL_ARRAY_BUFFER);
    json_t *attr = json_pack("{s:i, s:i}", "POSITION", ax, "NORMAL", an);
    if (fattr && attr)
        json_object_set_new(attr, fattr, json_integer(add_floats(b, fs, m->nv, 1, GL_ARRAY_BUFFER)));
    if (!attr)
        b->failed = 1;
    return attr;
}

/* A mesh of primitives sharing `attributes` (stolen), with `targets` (stolen, may be NULL). */
static json_t *mesh_json(const char *name, const plume_gltf_mesh *m, const int *indices, json_t *attributes,
                         json_t *targets, json_t *weights)
{
    json_t *prims = json_array();
    for (int p = 0; p < m->nprim; p++) {
        json_t *pr = json_pack("{s:O, s:i, s:i, s:i}", "attributes", attributes, "indices", indices[p], "material",
                               m->prims[p].material, "mode", GL_TRIANGLES);
        if (pr && targets)
            json_object_set(pr, "targets", targets);
        json_array_append_new(prims, pr);
    }
    json_t *mesh = json_pack("{s:s, s:o}", "name", name, "primitives", prims);
    if (mesh && weights)
        json_object_set(mesh, "weights", weights);
    json_decref(attributes);
    json_decref(targets);
    json_decref(weights);
    return mesh;
}

/* Morph mode: mesh i as one mesh with a target per later frame, and its weights channel. */
static void morph_object(glb_builder *b, const plume_gltf_doc *d, int i, const char *fattr, const int *indices,
                         json_t *meshes, json_t *nodes, json_t *channels, json_t *samplers, int times_acc, float *work)
{
    const plume_gltf_mesh *m = &d->meshes[i];
    const size_t n3 = 3 * (size_t)m->nv;
    float *x0 = work, *n0 = x0 + n3, *f0 = n0 + n3, *xs = f0 + m->nv, *ns = xs + n3, *fs = ns + n3;
    json_t *attributes = frame_attributes(b, m, 0, fattr, NULL, NULL, NULL, x0, n0, f0);
    json_t *targets = NULL, *weights = NULL;
    const int nt = d->nframes - 1;
    if (nt > 0) {
        targets = json_array(), weights = json_array();
        for (int k = 1; k <= nt; k++) {
            json_array_append_new(targets, frame_attributes(b, m, k, fattr, x0, n0, f0, xs, ns, fs));
            json_array_append_new(weights, json_real(0.0));
        }
    }
    json_t *mesh = mesh_json(m->name, m, indices, attributes, targets, weights);
    json_array_append_new(meshes, mesh);
    append_node(nodes, json_pack("{s:s, s:I}", "name", m->name, "mesh", (json_int_t)json_array_size(meshes) - 1),
                m->extras);
    if (nt <= 0)
        return;
    /* weights at frame k: target k - 1 at 1, the others 0 (frame 0: all 0) */
    float *w = calloc((size_t)d->nframes * (size_t)nt, sizeof *w);
    if (!w) {
        b->failed = 1;
        return;
    }
    for (int k = 1; k <= nt; k++)
        w[(size_t)k * nt + (size_t)(k - 1)] = 1.0f;
    int out = add_floats(b, w, (size_t)d->nframes * nt, 1, 0);
    free(w);
    json_array_append_new(samplers, json_pack("{s:i, s:i, s:s}", "input", times_acc, "output", out, "interpolation",
                                              "LINEAR"));
    json_array_append_new(channels,
                          json_pack("{s:I, s:{s:I, s:s}}", "sampler", (json_int_t)json_array_size(samplers) - 1,
                                    "target", "node", (json_int_t)json_array_size(nodes) - 1, "path", "weights"));
}

/* Frames mode: mesh i as a parent node with one child (and mesh) per frame, each shown over its
 * frame by a scale channel with step interpolation. */
static void frames_object(glb_builder *b, const plume_gltf_doc *d, int i, const char *fattr, const int *indices,
                          json_t *meshes, json_t *nodes, json_t *channels, json_t *samplers, float *work)
{
    const plume_gltf_mesh *m = &d->meshes[i];
    const size_t n3 = 3 * (size_t)m->nv;
    float *xs = work, *ns = xs + n3, *fs = ns + n3;
    json_t *children = json_array();
    for (int k = 0; k < d->nframes; k++) {
        char name[512];
        snprintf(name, sizeof name, "%s@%d", m->name, k);
        json_array_append_new(meshes,
                              mesh_json(name, m, indices, frame_attributes(b, m, k, fattr, NULL, NULL, NULL, xs, ns, fs),
                                        NULL, NULL));
        const float on = k == 0 ? 1.0f : 0.0f;
        json_t *node = json_pack("{s:s, s:I, s:[f,f,f]}", "name", name, "mesh", (json_int_t)json_array_size(meshes) - 1,
                                 "scale", on, on, on);
        json_array_append_new(nodes, node);
        json_array_append_new(children, json_integer((json_int_t)json_array_size(nodes) - 1));
        if (d->nframes < 2)
            continue;
        /* shown from t_k until t_{k+1}: keys at t_0 (hidden unless k = 0), t_k, t_{k+1} */
        float t[3], s[9];
        int n = 0;
        if (k > 0)
            t[n] = (float)d->times[0], s[3 * n] = s[3 * n + 1] = s[3 * n + 2] = 0.0f, n++;
        t[n] = (float)d->times[k], s[3 * n] = s[3 * n + 1] = s[3 * n + 2] = 1.0f, n++;
        if (k + 1 < d->nframes)
            t[n] = (float)d->times[k + 1], s[3 * n] = s[3 * n + 1] = s[3 * n + 2] = 0.0f, n++;
        int in = add_floats(b, t, (size_t)n, 1, 0), out = add_floats(b, s, (size_t)n, 3, 0);
        json_array_append_new(samplers, json_pack("{s:i, s:i, s:s}", "input", in, "output", out, "interpolation", "STEP"));
        json_array_append_new(channels, json_pack("{s:I, s:{s:I, s:s}}", "sampler",
                                                  (json_int_t)json_array_size(samplers) - 1, "target", "node",
                                                  (json_int_t)json_array_size(nodes) - 1, "path", "scale"));
    }
    append_node(nodes, json_pack("{s:s, s:o}", "name", m->name, "children", children), m->extras);
}

static json_t *materials_json(const plume_gltf_doc *d)
{
    json_t *mats = json_array();
    for (int i = 0; i < d->nmat; i++) {
        const plume_gltf_material *m = &d->mats[i];
        json_t *pbr = json_pack("{s:[f,f,f,f], s:f, s:f}", "baseColorFactor", m->rgba[0], m->rgba[1], m->rgba[2],
                                m->rgba[3], "metallicFactor", 0.0, "roughnessFactor", m->roughness);
        json_t *j = json_pack("{s:s, s:o, s:b}", "name", m->name ? m->name : "", "pbrMetallicRoughness", pbr, "doubleSided",
                              m->double_sided != 0);
        if (j && m->rgba[3] < 1.0f)
            json_object_set_new(j, "alphaMode", json_string("BLEND"));
        json_array_append_new(mats, j);
    }
    return mats;
}

static int write_u32(FILE *f, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16), (unsigned char)(v >> 24)};
    return fwrite(b, 1, 4, f) == 4 ? 0 : -1;
}

/* The .glb: header, JSON chunk padded with spaces, BIN chunk padded with zeros. */
static plume_status write_glb(const char *path, const char *json, const glb_builder *b, plume_err *err)
{
    const size_t nj = strlen(json), pj = (4 - nj % 4) % 4, pb = (4 - b->n % 4) % 4;
    const size_t total = 12 + 8 + nj + pj + 8 + b->n + pb;
    if (total > UINT32_MAX)
        return plume_err_set(err, PLUME_EINVAL, "glTF '%s': %zu bytes, beyond the 4 GiB a .glb holds (fewer frames?)",
                             path, total);
    char tmp[4400];
    if (snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid()) >= (int)sizeof tmp)
        return plume_err_set(err, PLUME_EINVAL, "glTF '%.64s...': the path is too long", path);
    FILE *f = fopen(tmp, "wb");
    if (!f)
        return plume_err_set(err, PLUME_EIO, "glTF '%s': cannot write: %s", path, strerror(errno));
    static const char spaces[4] = {' ', ' ', ' ', ' '}, zeros[4] = {0, 0, 0, 0};
    int ok = write_u32(f, GLB_MAGIC) == 0 && write_u32(f, 2) == 0 && write_u32(f, (uint32_t)total) == 0 &&
             write_u32(f, (uint32_t)(nj + pj)) == 0 && write_u32(f, GLB_JSON) == 0 && fwrite(json, 1, nj, f) == nj &&
             fwrite(spaces, 1, pj, f) == pj && write_u32(f, (uint32_t)(b->n + pb)) == 0 && write_u32(f, GLB_BIN) == 0 &&
             fwrite(b->data, 1, b->n, f) == b->n && fwrite(zeros, 1, pb, f) == pb;
    if (fclose(f) != 0)
        ok = 0;
    if (!ok || rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return plume_err_set(err, PLUME_EIO, "glTF '%s': cannot write: %s", path, strerror(e));
    }
    return PLUME_OK;
}

plume_status plume_gltf_write(const char *path, const plume_gltf_doc *d, plume_err *err)
{
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "glTF: no file name given");
    plume_status st = check_doc(d, err);
    if (st != PLUME_OK)
        return st;
    uint32_t maxv = 0;
    int maxp = 0;
    for (int i = 0; i < d->nmesh; i++) {
        maxv = d->meshes[i].nv > maxv ? d->meshes[i].nv : maxv;
        maxp = d->meshes[i].nprim > maxp ? d->meshes[i].nprim : maxp;
    }
    glb_builder b = {0};
    b.views = json_array(), b.accessors = json_array();
    json_t *meshes = json_array(), *nodes = json_array(), *channels = json_array(), *samplers = json_array();
    char *fattr = d->field_name ? attribute_name(d->field_name) : NULL;
    float *work = malloc((14 * (size_t)maxv + 1) * sizeof *work);
    int *indices = malloc((size_t)maxp * sizeof *indices);
    float *times = malloc((size_t)d->nframes * sizeof *times);
    b.normal_acc = malloc((3 * (size_t)maxv + 1) * sizeof *b.normal_acc);
    char *json = NULL;
    if (!b.views || !b.accessors || !meshes || !nodes || !channels || !samplers || (d->field_name && !fattr) || !work ||
        !indices || !times || !b.normal_acc) {
        st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
        goto done;
    }
    for (int k = 0; k < d->nframes; k++)
        times[k] = (float)d->times[k];
    int times_acc = d->animation == PLUME_GLTF_MORPH && d->nframes > 1 ? add_floats(&b, times, (size_t)d->nframes, 1, 0)
                                                                       : -1;
    json_t *roots = json_array();
    for (int i = 0; i < d->nmesh; i++) {
        const plume_gltf_mesh *m = &d->meshes[i];
        for (int p = 0; p < m->nprim; p++)
            indices[p] = add_indices(&b, m->prims[p].tri, 3 * (size_t)m->prims[p].ntri);
        if (d->animation == PLUME_GLTF_MORPH)
            morph_object(&b, d, i, m->field ? fattr : NULL, indices, meshes, nodes, channels, samplers, times_acc, work);
        else
            frames_object(&b, d, i, m->field ? fattr : NULL, indices, meshes, nodes, channels, samplers, work);
        json_array_append_new(roots, json_integer((json_int_t)json_array_size(nodes) - 1));
    }
    json_t *scene = json_pack("{s:s, s:o}", "name", d->scene_name ? d->scene_name : "plume", "nodes", roots);
    json_t *sx = parse_extras(d->extras);
    if (scene && sx)
        json_object_set_new(scene, "extras", sx);
    else
        json_decref(sx);
    json_t *doc = json_pack("{s:{s:s, s:s}, s:i, s:[o], s:O, s:O, s:o, s:[{s:I}], s:O, s:O}", "asset", "version",
                            "2.0", "generator", "plume", "scene", 0, "scenes", scene, "nodes", nodes, "meshes", meshes,
                            "materials", materials_json(d), "buffers", "byteLength", (json_int_t)((b.n + 3) / 4 * 4),
                            "bufferViews", b.views, "accessors", b.accessors);
    if (doc && json_array_size(channels) > 0)
        json_object_set_new(doc, "animations",
                            json_pack("[{s:s, s:O, s:O}]", "name", "frames", "channels", channels, "samplers", samplers));
    json = doc && !b.failed ? json_dumps(doc, JSON_COMPACT | JSON_REAL_PRECISION(9)) : NULL;
    json_decref(doc);
    if (!json) {
        st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
        goto done;
    }
    st = write_glb(path, json, &b, err);
done:
    free(json);
    free(times);
    free(indices);
    free(work);
    free(fattr);
    free(b.data);
    free(b.normal_acc);
    json_decref(b.views);
    json_decref(b.accessors);
    json_decref(meshes);
    json_decref(nodes);
    json_decref(channels);
    json_decref(samplers);
    return st;
}
