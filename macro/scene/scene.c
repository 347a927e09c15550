/* plume: reading and validating a shell scene from JSON (format in docs/scene-format.md): the
 * document's order and ownership here; its settings (scene_settings.c), materials
 * (scene_materials.c), mesh (scene_mesh.c) or objects (scene_objects.c), handles
 * (scene_handles.c), static part (scene_loads.c) and contact block (scene_contact.c) in their
 * files; the problem is built in scene_build.c. */
#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/opts.h"
#include "internal/scene_internal.h"

void plume_scene_destroy(plume_scene **ps)
{
    if (!ps || !*ps)
        return;
    plume_scene *s = *ps;
    free(s->path);
    plume_scene_splits_free(s);
    plume_mesh_destroy(&s->mesh);
    plume_mesh_destroy(&s->elastic);
    for (int k = 0; k < s->nobjects; k++)
        free(s->objects[k].name);
    free(s->objects);
    free(s->mats);
    for (int h = 0; h < s->nhandles; h++) {
        free((void *)s->handles[h].vertices);
        free((void *)s->handles[h].times);
        free((void *)s->handles[h].offsets);
        free((void *)s->handles[h].rotations);
    }
    free(s->handles);
    free(s->barb_edges);
    free(s->render);
    free(s->clamped);
    free(s->supported);
    free(s->force);
    for (int k = 0; k < s->nmoments; k++) {
        free(s->moments[k].end);
        free(s->moments[k].row);
    }
    free(s->moments);
    for (int k = 0; k < s->nprobes; k++) {
        free(s->probes[k].name);
        free(s->probes[k].vertices);
        free(s->probes[k].source);
    }
    free(s->probes);
    free(s);
    *ps = NULL;
}

static plume_status parse_scene(plume_json_ctx *c, json_t *doc, plume_scene *s, const plume_scene_load_opts *o)
{
    static const char *const keys[] = {"mesh", "materials", "handles", "gravity", "dt", "duration", "solver",
                                       "max_halvings", "max_iter", "output_every", "render", "render_field", "camera", "gltf", "solve",
                                       "steps", "clamps", "supports", "loads", "probes", "bending_model", "contact",
                                       "objects", "predictor", "globalization", "adaptive_dt", "dt_max", "splits", NULL};
    plume_status st;
    plume_index *map = NULL, nobj = 0;
    if (!json_is_object(doc))
        return plume_err_set(c->err, PLUME_EFORMAT, "%s: expected a JSON object at the top level", c->file);
    if ((st = plume_json_check_keys(c, doc, "", keys)) != PLUME_OK)
        return st;

    /* run settings first: cheap, and their errors need no mesh */
    if ((st = plume_scene_parse_settings(c, doc, s)) != PLUME_OK)
        return st;

    if ((st = plume_scene_parse_materials(c, doc, s)) != PLUME_OK)
        return st;

    /* objects: many bodies, each meshed, placed and held on its own */
    json_t *objects = json_object_get(doc, "objects");
    if (objects) {
        if (json_object_get(doc, "mesh"))
            return plume_json_bad(c, PLUME_EFORMAT, "mesh", "cannot be given with \"objects\" (each object has its own)");
        if (json_object_get(doc, "handles"))
            return plume_json_bad(c, PLUME_EFORMAT, "handles", "cannot be given with \"objects\" (each object has its own "
                                                               "\"handles\" and \"attach\")");
        if (s->is_static)
            return plume_json_bad(c, PLUME_EINVAL, "objects", "are for dynamic scenes (\"solve\": \"static\" takes a \"mesh\")");
        if (json_object_get(doc, "splits"))
            return plume_json_bad(c, PLUME_EINVAL, "splits", "belong in the object that splits (objects[k].splits)");
        if ((st = plume_scene_parse_objects(c, objects, s, o)) != PLUME_OK)
            return st;
        return plume_scene_parse_static(c, doc, s, NULL, 0);
    }

    /* mesh */
    json_t *mesh = json_object_get(doc, "mesh");
    if (!json_is_object(mesh))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh",
                              mesh ? "must be an object {\"obj\": ...}, {\"feather\": ...} or {\"rectangle\": ...}"
                                   : "is missing ({\"obj\": \"file.obj\"}, {\"feather\": \"shape.json\", ...} or "
                                     "{\"rectangle\": [lx, ly], ...})");
    int feather = json_object_get(mesh, "feather") != NULL, rectangle = json_object_get(mesh, "rectangle") != NULL;
    if (feather + rectangle + (json_object_get(mesh, "obj") != NULL) != 1)
        return plume_json_bad(c, PLUME_EFORMAT, "mesh", "needs one of \"obj\" (a triangle mesh), \"feather\" (a feather "
                                                        "shape file) or \"rectangle\" ([lx, ly])");
    if (o && (o->edge > 0.0 || o->pattern) && !feather && !rectangle)
        return plume_json_bad(c, PLUME_EINVAL, "mesh", "is an OBJ file: its edge and pattern cannot be overridden");
    if (o && o->pattern && !rectangle)
        return plume_json_bad(c, PLUME_EINVAL, "mesh", "is not a rectangle: only a rectangle has a pattern to override");
    if (feather)
        st = plume_scene_mesh_from_feather(c, mesh, s, o);
    else if (rectangle)
        st = plume_scene_mesh_from_rectangle(c, mesh, s, o);
    else
        st = plume_scene_mesh_from_obj(c, mesh, s, &map, &nobj);
    if (st != PLUME_OK)
        goto done;
    const plume_mesh *m = s->mesh;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (plume_index i = 0; i < m->nv; i++)
        for (int a = 0; a < 2; a++)
            lo[a] = fmin(lo[a], m->X[2 * i + a]), hi[a] = fmax(hi[a], m->X[2 * i + a]);
    s->length = hypot(hi[0] - lo[0], hi[1] - lo[1]);
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] < 0 || m->material[t] >= s->nmat) {
            st = plume_json_bad(c, PLUME_EINVAL, feather ? "materials" : "mesh.materials_by_group",
                     "%s: triangle %ld has material %d, but materials has %d entr%s (ids 0 to %d)",
                     feather ? "the feather mesh uses material 0 (vane) and 1 (rachis)" : "material id without a material",
                     (long)t, m->material[t], s->nmat, s->nmat == 1 ? "y" : "ies", s->nmat - 1);
            goto done;
        }

    /* split lines before anything selects vertices: handles and clamps see the copies too (an OBJ's
     * vertex map still holds: the input's vertices come first) */
    if ((st = plume_scene_parse_splits(c, doc, s)) != PLUME_OK)
        goto done;
    if ((st = plume_scene_parse_handles(c, doc, s, map, nobj)) != PLUME_OK)
        goto done;
    if ((st = plume_scene_parse_static(c, doc, s, map, nobj)) != PLUME_OK)
        goto done;
    st = plume_scene_constrained_edges(s, c->err);
done:
    free(map);
    return st;
}

plume_status plume_scene_load(const char *path, plume_scene **out, plume_err *err)
{
    return plume_scene_load_with(path, NULL, out, err);
}

/* The loading of a scene document in `text` (owned: freed here) that stands for the file `path`;
 * lines: errors name the line of the bad key in text (the text is the file's). */
void plume_scene_load_opts_default_sized(plume_scene_load_opts *o, size_t size)
{
    static const plume_scene_load_opts full = {.size = sizeof full};
    plume_opts_give(o, size, &full, sizeof full);
}

static plume_status load_text(char *text, const char *path, int lines, const plume_scene_load_opts *given,
                              plume_scene **out, plume_err *err)
{
    plume_scene_load_opts full; /* the caller's overrides (as many bytes as it has) over the defaults */
    const plume_scene_load_opts *o = given ? &full : NULL;
    plume_scene_load_opts_default(&full);
    if (given && plume_opts_take(&full, sizeof full, given, "plume_scene_load_opts", err) != PLUME_OK) {
        free(text);
        return PLUME_EINVAL;
    }
    plume_json_ctx c;
    memset(&c, 0, sizeof c);
    c.file = path;
    c.err = err;
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(c.dir, sizeof c.dir, "%.*s", (int)(slash == path ? 1 : slash - path), path);
    json_error_t je;
    json_t *doc = json_loads(text, JSON_REJECT_DUPLICATES, &je);
    if (!doc) {
        free(text);
        if (lines)
            return plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", path, je.line, je.column, je.text);
        return plume_err_set(err, PLUME_EFORMAT, "%s (a scene document): %s", path, je.text);
    }
    c.text = lines ? text : NULL; /* no text: a bad key is named without a line */
    plume_scene *s = calloc(1, sizeof *s);
    plume_status st = PLUME_ENOMEM;
    if (s && (s->path = malloc(strlen(path) + 1)) != NULL) {
        memcpy(s->path, path, strlen(path) + 1);
        st = parse_scene(&c, doc, s, o);
    } else {
        plume_err_set(err, st, "%s: out of memory", path);
    }
    json_decref(doc);
    free(text);
    if (st != PLUME_OK) {
        plume_scene_destroy(&s);
        return st;
    }
    *out = s;
    return PLUME_OK;
}

plume_status plume_scene_load_with(const char *path, const plume_scene_load_opts *o, plume_scene **out,
                                   plume_err *err)
{
    if (!path || !*path || !out)
        return plume_err_set(err, PLUME_EINVAL, "scene: no file given");
    *out = NULL;
    plume_status st;
    char *text = plume_read_text(path, err, "scene", &st);
    if (!text)
        return st;
    return load_text(text, path, 1, o, out, err);
}

plume_status plume_scene_load_json(const char *json, const char *path, const plume_scene_load_opts *o,
                                   plume_scene **out, plume_err *err)
{
    if (!json || !path || !*path || !out)
        return plume_err_set(err, PLUME_EINVAL, "scene: no document or no path given");
    *out = NULL;
    size_t n = strlen(json);
    char *text = malloc(n + 1);
    if (!text)
        return plume_err_set(err, PLUME_ENOMEM, "%s: out of memory", path);
    memcpy(text, json, n + 1);
    return load_text(text, path, 0, o, out, err);
}
