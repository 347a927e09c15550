/* plume: a run's frames as a glTF 2.0 binary file (scene.h, plume_run_write_gltf): one node per scene
 * object, a primitive per material, the frames of a frames file as its animation (lib/io/gltf.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/vec3.h"
#include "../../lib/io/gltf.h"
#include "internal/run.h"

/* Colours of the glTF materials, linear RGB: a pale vane, a dark rachis, then distinct hues; the
 * kinematic bodies a neutral grey. A renderer (scripts/blender/render.py) replaces them by name. */
static const float material_rgb[][3] = {{0.80f, 0.72f, 0.58f}, {0.20f, 0.15f, 0.11f}, {0.45f, 0.60f, 0.80f},
                                        {0.80f, 0.50f, 0.35f}, {0.50f, 0.70f, 0.45f}, {0.70f, 0.50f, 0.70f}};
static const float body_rgb[3] = {0.55f, 0.55f, 0.58f};
#define NCOLOURS ((int)(sizeof material_rgb / sizeof material_rgb[0]))

void plume_gltf_opts_default_sized(plume_gltf_opts *o, size_t size)
{
    if (!o || size < sizeof(size_t))
        return;
    plume_gltf_opts d = {.size = sizeof(plume_gltf_opts), .animation = PLUME_GLTF_MORPH, .field = NULL};
    memcpy(o, &d, size < sizeof d ? size : sizeof d);
    o->size = size < sizeof d ? size : sizeof d;
}

/* One object of the file: its vertices and triangles in the scene mesh. */
typedef struct {
    const char *name;
    int kinematic;
    plume_index v0, nv, t0, nt;
} object_range;

/* The objects (a "mesh" scene: one, named after the scene file). */
static int object_ranges(const plume_run *r, object_range **out)
{
    const plume_scene *s = r->scene;
    const int n = s->nobjects > 0 ? s->nobjects : 1;
    object_range *o = calloc((size_t)n, sizeof *o);
    if (!o)
        return -1;
    if (s->nobjects == 0)
        o[0] = (object_range){r->stem, 0, 0, s->mesh->nv, 0, s->mesh->nt};
    for (int i = 0; i < s->nobjects; i++) {
        const plume_scene_object *so = &s->objects[i];
        o[i] = (object_range){so->name, so->kinematic, so->v0, so->nv, so->t0, so->nt};
    }
    *out = o;
    return n;
}

/* A triangle value per vertex of object o: the mean over its triangles, weighted by their areas at
 * x; NaN values (kinematic triangles) left out, vertices with none get NaN. wsum: 2 o->nv doubles. */
static void vertex_values(const plume_mesh *m, const object_range *o, const double *x, const double *tv, float *out,
                          double *wsum)
{
    double *acc = wsum + o->nv;
    for (plume_index i = 0; i < o->nv; i++)
        wsum[i] = acc[i] = 0.0;
    for (plume_index t = o->t0; t < o->t0 + o->nt; t++) {
        if (!isfinite(tv[t]))
            continue;
        const plume_index *v = m->tri + 3 * t;
        double e1[3], e2[3], a[3];
        sub3(x + 3 * v[1], x + 3 * v[0], e1);
        sub3(x + 3 * v[2], x + 3 * v[0], e2);
        cross3(e1, e2, a);
        const double area = 0.5 * sqrt(dot3(a, a));
        for (int k = 0; k < 3; k++)
            acc[v[k] - o->v0] += area * tv[t], wsum[v[k] - o->v0] += area;
    }
    for (plume_index i = 0; i < o->nv; i++)
        out[i] = wsum[i] > 0.0 ? (float)(acc[i] / wsum[i]) : NAN;
}

/* The primitives of object o: one per material among its triangles (kinematic bodies: one, with
 * the body material nmat), vertex ids local to the object. Returns their count, -1 out of memory. */
static int object_primitives(const plume_scene *s, const object_range *o, plume_gltf_primitive **prims,
                             uint32_t **tris)
{
    const plume_mesh *m = s->mesh;
    const int nkinds = s->nmat + 1;
    uint32_t *count = calloc((size_t)nkinds, sizeof *count);
    uint32_t *tri = malloc((3 * (size_t)o->nt + 1) * sizeof *tri);
    plume_gltf_primitive *p = calloc((size_t)nkinds, sizeof *p);
    if (!count || !tri || !p) {
        free(count), free(tri), free(p);
        return -1;
    }
    for (plume_index t = o->t0; t < o->t0 + o->nt; t++)
        count[o->kinematic ? s->nmat : m->material[t]]++;
    int np = 0;
    size_t at = 0;
    for (int k = 0; k < nkinds; k++) {
        if (!count[k])
            continue;
        p[np] = (plume_gltf_primitive){k, count[k], tri + at};
        for (plume_index t = o->t0; t < o->t0 + o->nt; t++)
            if ((o->kinematic ? s->nmat : m->material[t]) == k)
                for (int c = 0; c < 3; c++)
                    tri[at++] = (uint32_t)(m->tri[3 * t + c] - o->v0);
        np++;
    }
    free(count);
    *prims = p, *tris = tri;
    return np;
}

/* The field's per-triangle values at x into tv. */
static plume_status field_at(plume_fields *f, const char *name, const double *x, double *tv, plume_err *err)
{
    plume_field_values fv;
    plume_status st = plume_fields_compute(f, x, &fv, err);
    return st != PLUME_OK ? st : plume_field_values_select(&fv, name, tv, err);
}

int plume_gltf_field_refused(const char *field, char *why, size_t n)
{
    if (!plume_field_label(field) || strcmp(field, "material") == 0 || strcmp(field, "object") == 0)
        snprintf(why, n, "\"%s\" is not a field; one of: %s", field, plume_field_names());
    else if (strncmp(field, "curvature_", 10) == 0) /* the export reads positions only */
        snprintf(why, n, "\"%s\" is the midedge operator's curvature, which needs the edge unknowns of every "
                 "frame; \"mean_curvature\" is a curvature of every bending model", field);
    else
        return 0;
    return 1;
}

/* The scene's "extras": where the file came from, the renders' camera and the frames' times. */
static char *scene_extras(const plume_run *r, const plume_frames_info *info, const double *times, long nframes,
                          const char *field)
{
    size_t cap = 512 + strlen(info->scene) * 2 + 24 * (size_t)nframes;
    char *s = malloc(cap);
    if (!s)
        return NULL;
    size_t n = (size_t)snprintf(s, cap, "{\"plume\": {\"scene\": \"");
    for (const char *c = info->scene; *c && n + 8 < cap; c++)
        n += (size_t)snprintf(s + n, cap - n, (*c == '"' || *c == '\\') ? "\\%c" : ((unsigned char)*c < 32 ? "?" : "%c"),
                              *c);
    n += (size_t)snprintf(s + n, cap - n,
                          "\", \"camera\": {\"rot_x\": %.17g, \"rot_z\": %.17g}, \"up\": \"the scene's z is glTF's y\", "
                          "\"field\": %s%s%s, \"frame_times\": [",
                          r->scene->camera[0], r->scene->camera[1], field ? "\"" : "", field ? field : "null",
                          field ? "\"" : "");
    for (long k = 0; k < nframes && n + 32 < cap; k++)
        n += (size_t)snprintf(s + n, cap - n, "%s%.17g", k ? ", " : "", times[k]);
    snprintf(s + n, cap - n, "]}}");
    return s;
}

plume_status plume_run_write_gltf(plume_run *r, const char *frames_path, const char *path, const plume_gltf_opts *opts,
                                  plume_err *err)
{
    plume_gltf_opts o;
    plume_gltf_opts_default(&o);
    if (opts)
        memcpy(&o, opts, opts->size < sizeof o ? opts->size : sizeof o);
    if (!r || !path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "plume_run_write_gltf: a run and a file name are required");
    if (!frames_path)
        frames_path = r->frames_path;
    if (!frames_path)
        return plume_err_set(err, PLUME_EINVAL, "glTF '%s': the run writes no frames file (an output directory, or "
                             "a frames file given)", path);
    if (o.animation != PLUME_GLTF_MORPH && o.animation != PLUME_GLTF_FRAMES)
        return plume_err_set(err, PLUME_EINVAL, "plume_gltf_opts.animation must be PLUME_GLTF_MORPH or PLUME_GLTF_FRAMES "
                             "(got %d)", o.animation);
    const plume_scene *s = r->scene;
    const plume_mesh *m = s->mesh;
    char why_field[512];
    if (o.field && plume_gltf_field_refused(o.field, why_field, sizeof why_field))
        return plume_err_set(err, PLUME_EINVAL, "glTF field %s", why_field);
    plume_status st;
    plume_err why = {{0}};
    plume_frames_info info;
    if ((st = plume_frames_info_read(frames_path, &info, &why)) != PLUME_OK)
        return plume_err_set(err, st, "glTF: %s", why.msg);
    if (info.nv != m->nv || info.count < 1)
        return plume_err_set(err, PLUME_EINVAL, "glTF: '%s' holds %ld frames of %ld vertices, the scene '%s' has %ld "
                             "vertices", frames_path, info.count, (long)info.nv, s->path, (long)m->nv);
    const long nf = info.count;
    object_range *obj = NULL;
    const int nobj = object_ranges(r, &obj);
    plume_gltf_mesh *gm = nobj > 0 ? calloc((size_t)nobj, sizeof *gm) : NULL;
    plume_gltf_primitive **prims = nobj > 0 ? calloc((size_t)nobj, sizeof *prims) : NULL;
    uint32_t **tris = nobj > 0 ? calloc((size_t)nobj, sizeof *tris) : NULL;
    char **extras = nobj > 0 ? calloc((size_t)nobj, sizeof *extras) : NULL;
    plume_gltf_material *mats = calloc((size_t)s->nmat + 1, sizeof *mats);
    char (*mat_names)[80] = calloc((size_t)s->nmat + 1, sizeof *mat_names);
    double *times = malloc((size_t)nf * sizeof *times), *tv = NULL, *wsum = NULL;
    plume_fields *fields = NULL;
    plume_frame fr = {0};
    char *scene_x = NULL;
    if (!gm || !prims || !tris || !extras || !mats || !mat_names || !times) {
        st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
        goto done;
    }
    plume_index maxnv = 0;
    for (int i = 0; i < nobj; i++) {
        int np = object_primitives(s, &obj[i], &prims[i], &tris[i]);
        float *x = malloc((3 * (size_t)obj[i].nv * (size_t)nf + 1) * sizeof *x);
        float *f = o.field ? malloc(((size_t)obj[i].nv * (size_t)nf + 1) * sizeof *f) : NULL;
        extras[i] = malloc(96);
        if (np < 0 || !x || (o.field && !f) || !extras[i]) {
            free(x), free(f);
            st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
            goto done;
        }
        snprintf(extras[i], 96, "{\"plume_object\": %d, \"kinematic\": %s, \"first_vertex\": %ld}", i,
                 obj[i].kinematic ? "true" : "false", (long)obj[i].v0);
        gm[i] = (plume_gltf_mesh){obj[i].name, (uint32_t)obj[i].nv, np, prims[i], x, f, extras[i]};
        maxnv = obj[i].nv > maxnv ? obj[i].nv : maxnv;
    }
    /* the materials the primitives use, in the scene's order (kinematic bodies last), numbered anew */
    int nused = 0, *index = calloc((size_t)s->nmat + 1, sizeof *index);
    if (!index) {
        st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
        goto done;
    }
    for (int i = 0; i < nobj; i++)
        for (int p = 0; p < gm[i].nprim; p++)
            index[prims[i][p].material] = 1;
    for (int k = 0; k <= s->nmat; k++) {
        if (!index[k])
            continue;
        if (k < s->nmat && s->mats[k].name[0])
            snprintf(mat_names[nused], sizeof mat_names[nused], "%s", s->mats[k].name);
        else
            snprintf(mat_names[nused], sizeof mat_names[nused], k < s->nmat ? "material_%d" : "kinematic", k);
        const float *rgb = k < s->nmat ? material_rgb[k % NCOLOURS] : body_rgb;
        mats[nused] = (plume_gltf_material){mat_names[nused], {rgb[0], rgb[1], rgb[2], 1.0f}, k < s->nmat ? 0.6f : 0.8f,
                                            k < s->nmat};
        index[k] = nused++;
    }
    for (int i = 0; i < nobj; i++)
        for (int p = 0; p < gm[i].nprim; p++)
            prims[i][p].material = index[prims[i][p].material];
    free(index);
    if (o.field) {
        tv = malloc(((size_t)m->nt + 1) * sizeof *tv);
        wsum = malloc((2 * (size_t)maxnv + 1) * sizeof *wsum);
        if (!tv || !wsum) {
            st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
            goto done;
        }
        if ((st = plume_scene_fields_of(s, r->p, &fields, err)) != PLUME_OK)
            goto done;
    }
    for (long k = 0; k < nf; k++) {
        if ((st = plume_frames_read(frames_path, k, &fr, &why)) != PLUME_OK) {
            plume_err_set(err, st, "glTF: %s", why.msg);
            goto done;
        }
        times[k] = fr.t;
        if (o.field && (st = field_at(fields, o.field, fr.x, tv, err)) != PLUME_OK)
            goto done;
        for (int i = 0; i < nobj; i++) {
            float *x = (float *)gm[i].x + 3 * (size_t)obj[i].nv * (size_t)k;
            for (plume_index v = 0; v < obj[i].nv; v++) { /* glTF's y is the scene's z */
                const double *p = fr.x + 3 * (obj[i].v0 + v);
                x[3 * v] = (float)p[0], x[3 * v + 1] = (float)p[2], x[3 * v + 2] = (float)-p[1];
            }
            if (o.field)
                vertex_values(m, &obj[i], fr.x, tv, (float *)gm[i].field + (size_t)obj[i].nv * (size_t)k, wsum);
        }
        plume_frame_free(&fr);
    }
    if (!(scene_x = scene_extras(r, &info, times, nf, o.field))) {
        st = plume_err_set(err, PLUME_ENOMEM, "glTF: out of memory");
        goto done;
    }
    plume_gltf_doc d = {.nmesh = nobj, .meshes = gm, .nmat = nused, .mats = mats, .nframes = (int)nf,
                        .times = times, .animation = o.animation, .field_name = o.field, .scene_name = r->stem,
                        .extras = scene_x};
    st = plume_gltf_write(path, &d, err);
done:
    plume_frame_free(&fr);
    plume_fields_destroy(&fields);
    for (int i = 0; i < nobj && gm; i++) {
        free((void *)gm[i].x), free((void *)gm[i].field);
        if (prims)
            free(prims[i]);
        if (tris)
            free(tris[i]);
        if (extras)
            free(extras[i]);
    }
    free(obj), free(gm), free(prims), free(tris), free(extras), free(mats), free(mat_names);
    free(times), free(tv), free(wsum), free(scene_x);
    return st;
}

/* The scene's glTF file: absolute, or relative to the output directory. */
static void gltf_path(const plume_run *r, char *out, size_t n)
{
    const plume_scene *s = r->scene;
    if (s->gltf_file[0] == '/')
        snprintf(out, n, "%s", s->gltf_file);
    else
        snprintf(out, n, "%s/%s", r->output_dir, s->gltf_file);
}

plume_status plume_run_gltf_prepare(plume_run *r, plume_err *err)
{
    if (!r->scene->gltf || !r->d || !r->output_dir)
        return PLUME_OK;
    char path[2 * PLUME_SCENE_PATH_MAX + 2];
    gltf_path(r, path, sizeof path);
    char *slash = strrchr(path, '/');
    if (!slash || slash == path)
        return PLUME_OK;
    *slash = '\0';
    if (plume_make_dirs(path) != 0)
        return plume_err_set(err, PLUME_EIO, "glTF file '%s/%s': cannot create its directory: %s", path, slash + 1,
                             strerror(errno));
    return PLUME_OK;
}

plume_status plume_run_gltf_at_end(plume_run *r, plume_err *err)
{
    const plume_scene *s = r->scene;
    if (!s->gltf || !r->d || !r->output_dir)
        return PLUME_OK;
    char path[2 * PLUME_SCENE_PATH_MAX + 2];
    gltf_path(r, path, sizeof path);
    plume_gltf_opts o;
    plume_gltf_opts_default(&o);
    o.animation = s->gltf_animation;
    o.field = s->gltf_field[0] ? s->gltf_field : NULL;
    return plume_run_write_gltf(r, NULL, path, &o, err);
}
