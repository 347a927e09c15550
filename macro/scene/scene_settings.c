/* The run settings of a scene (macro/scene/scene.h): gravity, static or dynamic, bending model, the
 * contact block, steps, dt and duration, solver, halvings, iterations, output, render, camera; and
 * plume_scene_set, which changes some of them after loading with the same checks. Each parser
 * changes only the keys its document holds: the defaults are set once, before them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal/scene_internal.h"

/* What is solved: gravity, static or dynamic, the bending model, the contact block, the predictor
 * and the globalisation. */
static plume_status parse_model(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    json_t *v;
    if ((v = json_object_get(doc, "gravity")) && (st = plume_json_vector(c, v, "gravity", 3, s->gravity)) != PLUME_OK)
        return st;
    if ((v = json_object_get(doc, "solve"))) {
        const char *sv = json_is_string(v) ? json_string_value(v) : "";
        if (strcmp(sv, "static") != 0 && strcmp(sv, "dynamic") != 0)
            return plume_json_bad(c, PLUME_EINVAL, "solve", "must be \"static\" or \"dynamic\"");
        s->is_static = sv[0] == 's';
    }
    if ((v = json_object_get(doc, "bending_model"))) {
        const char *bv = json_is_string(v) ? json_string_value(v) : "";
        int k = PLUME_BENDING_SHAPE_OPERATOR;
        while (k <= PLUME_BENDING_MIDEDGE && strcmp(bv, plume_scene_bending_name(k)) != 0)
            k++;
        if (k > PLUME_BENDING_MIDEDGE)
            return plume_json_bad(c, PLUME_EINVAL, "bending_model",
                                  "must be \"shape_operator\", \"hinge\" or \"midedge\"");
        s->bending_model = k;
    }
    if ((v = json_object_get(doc, "contact")) && (st = plume_scene_parse_contact(c, v, s)) != PLUME_OK)
        return st;
    if ((v = json_object_get(doc, "predictor")) &&
        (!json_is_string(v) || plume_predictor_parse(json_string_value(v), &s->predictor) != PLUME_OK))
        return plume_json_bad(c, PLUME_EINVAL, "predictor", "must be \"secant\", \"none\", \"tangent\" or \"secant_tangent\"");
    if ((v = json_object_get(doc, "globalization")) &&
        (!json_is_string(v) || plume_globalization_parse(json_string_value(v), &s->globalization) != PLUME_OK))
        return plume_json_bad(c, PLUME_EINVAL, "globalization",
                              "must be \"curved_line_search\", \"line_search\" or \"trust_region\"");
    return PLUME_OK;
}

/* The clock: steps, dt and duration (required by a dynamic scene only), adaptive steps and dt_max. */
static plume_status parse_stepping(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    json_t *v;
    long steps = s->steps;
    if ((st = plume_json_int(c, doc, "", "steps", 1, 1000000, &steps)) != PLUME_OK)
        return st;
    s->steps = (int)steps;
    /* a static scene has no clock: dt and duration are optional (and unused) there */
    if ((st = plume_json_positive(c, doc, "", "dt", !s->is_static, 0, &s->dt, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, doc, "", "duration", !s->is_static, 0, &s->duration, NULL)) != PLUME_OK)
        return st;
    if ((v = json_object_get(doc, "adaptive_dt"))) {
        if (!json_is_boolean(v))
            return plume_json_bad(c, PLUME_EFORMAT, "adaptive_dt", "must be true or false");
        s->adaptive_dt = json_is_true(v);
    }
    if ((st = plume_json_positive(c, doc, "", "dt_max", 0, 0, &s->dt_max, NULL)) != PLUME_OK)
        return st;
    if (s->dt_max > 0.0 && !s->adaptive_dt)
        return plume_json_bad(c, PLUME_EINVAL, "dt_max", "needs \"adaptive_dt\": true");
    if (s->dt_max > 0.0 && s->dt > 0.0 && s->dt_max < s->dt)
        return plume_json_bad(c, PLUME_EINVAL, "dt_max", "must be >= dt (got %g < %g)", s->dt_max, s->dt);
    return PLUME_OK;
}

/* The solver and its limits: halvings of a step, iterations. */
static plume_status parse_solver(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    json_t *v;
    if ((v = json_object_get(doc, "solver"))) {
        if (!json_is_string(v) || plume_solver_kind_parse(json_string_value(v), &s->solver) != PLUME_OK)
            return plume_json_bad(c, PLUME_EINVAL, "solver", "must be \"newton\", \"ipopt\" or \"linearized\" (got %s%s%s)",
                       json_is_string(v) ? "\"" : "", json_is_string(v) ? json_string_value(v) : "a non-string",
                       json_is_string(v) ? "\"" : "");
    }
    long lv = s->max_halvings;
    if ((st = plume_json_int(c, doc, "", "max_halvings", 0, 30, &lv)) != PLUME_OK)
        return st;
    s->max_halvings = (int)lv;
    lv = s->max_iter;
    if ((st = plume_json_int(c, doc, "", "max_iter", 1, 100000, &lv)) != PLUME_OK)
        return st;
    s->max_iter = (int)lv;
    return PLUME_OK;
}

/* What is written: every how many steps a frame, the frames rendered and the field that colours them. */
static plume_status parse_output(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    json_t *v;
    long lv = s->output_every;
    if ((st = plume_json_int(c, doc, "", "output_every", 1, 1000000, &lv)) != PLUME_OK)
        return st;
    s->output_every = (int)lv;
    if ((v = json_object_get(doc, "render"))) {
        if (!json_is_array(v))
            return plume_json_bad(c, PLUME_EFORMAT, "render", "must be an array of frame indices");
        s->render = malloc((json_array_size(v) + 1) * sizeof *s->render);
        if (!s->render)
            return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        for (size_t i = 0; i < json_array_size(v); i++) {
            json_t *e = json_array_get(v, i);
            double d = json_is_number(e) ? json_number_value(e) : -1.0;
            if (!json_is_number(e) || d != floor(d) || d < 0 || d > 1e9) {
                char kp[PLUME_JSON_KEY_MAX];
                plume_json_subindex(kp, "render", i);
                return plume_json_bad(c, PLUME_EINVAL, kp, "must be a frame index (an integer >= 0)");
            }
            s->render[s->nrender++] = (long)d;
        }
    }
    if ((v = json_object_get(doc, "render_field"))) {
        const char *name = json_string_value(v);
        if (!name || !plume_render_field_valid(name))
            return plume_json_bad(c, PLUME_EINVAL, "render_field", "must be \"material\", \"object\" or one of %s",
                                  plume_field_names());
        snprintf(s->render_field, sizeof s->render_field, "%s", name);
    }
    return PLUME_OK;
}

/* The renders' camera: rot_x in [0, 180] and rot_z in [0, 360] degrees. */
static plume_status parse_camera(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    json_t *v;
    if ((v = json_object_get(doc, "camera"))) {
        static const char *const ck[] = {"rot_x", "rot_z", NULL};
        if (!json_is_object(v))
            return plume_json_bad(c, PLUME_EFORMAT, "camera", "must be an object {\"rot_x\": deg, \"rot_z\": deg}");
        if ((st = plume_json_check_keys(c, v, "camera", ck)) != PLUME_OK ||
            (st = plume_json_number(c, v, "camera", "rot_x", 0, &s->camera[0], NULL)) != PLUME_OK ||
            (st = plume_json_number(c, v, "camera", "rot_z", 0, &s->camera[1], NULL)) != PLUME_OK)
            return st;
        if (!(s->camera[0] >= 0.0 && s->camera[0] <= 180.0))
            return plume_json_bad(c, PLUME_EINVAL, "camera.rot_x", "must be in [0, 180] degrees (got %g)", s->camera[0]);
        if (!(s->camera[1] >= 0.0 && s->camera[1] <= 360.0))
            return plume_json_bad(c, PLUME_EINVAL, "camera.rot_z", "must be in [0, 360] degrees (got %g)", s->camera[1]);
    }
    return PLUME_OK;
}

/* "gltf": true, or {"file": name, "animation": "morph" | "frames", "field": render field}: the run's
 * frames written as glTF when it ends (docs/graphics.md). false turns it off. */
static plume_status parse_gltf(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    static const char *const keys[] = {"file", "animation", "field", NULL};
    json_t *v = json_object_get(doc, "gltf");
    if (!v)
        return PLUME_OK;
    if (json_is_boolean(v)) {
        s->gltf = json_is_true(v);
        return PLUME_OK;
    }
    if (!json_is_object(v))
        return plume_json_bad(c, PLUME_EFORMAT, "gltf", "must be true, false or an object {\"file\", \"animation\", "
                              "\"field\"}");
    plume_status st = plume_json_check_keys(c, v, "gltf", keys);
    if (st != PLUME_OK)
        return st;
    json_t *f = json_object_get(v, "file"), *a = json_object_get(v, "animation"), *fl = json_object_get(v, "field");
    if (f && (!json_is_string(f) || !json_string_length(f) || json_string_length(f) >= sizeof s->gltf_file))
        return plume_json_bad(c, PLUME_EFORMAT, "gltf.file", "must be a file name (absolute, or relative to the output "
                              "directory), shorter than %d bytes", (int)sizeof s->gltf_file);
    if (a && (!json_is_string(a) ||
              (strcmp(json_string_value(a), "morph") != 0 && strcmp(json_string_value(a), "frames") != 0)))
        return plume_json_bad(c, PLUME_EINVAL, "gltf.animation", "must be \"morph\" (morph targets of one mesh per "
                              "object) or \"frames\" (a mesh per frame shown in turn)");
    if (fl) {
        const char *name = json_string_value(fl);
        char why[512];
        if (!name || strlen(name) >= sizeof s->gltf_field)
            return plume_json_bad(c, PLUME_EINVAL, "gltf.field", "must be one of %s", plume_field_names());
        if (plume_gltf_field_refused(name, why, sizeof why))
            return plume_json_bad(c, PLUME_EINVAL, "gltf.field", "%s", why);
        snprintf(s->gltf_field, sizeof s->gltf_field, "%s", name);
    }
    if (f)
        snprintf(s->gltf_file, sizeof s->gltf_file, "%s", json_string_value(f));
    if (a)
        s->gltf_animation = strcmp(json_string_value(a), "frames") == 0 ? PLUME_GLTF_FRAMES : PLUME_GLTF_MORPH;
    s->gltf = 1;
    return PLUME_OK;
}

plume_status plume_scene_parse_settings(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    s->gravity[0] = s->gravity[1] = 0.0;
    s->gravity[2] = -9.81;
    s->solver = PLUME_SOLVER_NEWTON;
    s->max_halvings = 6;
    s->max_iter = 100;
    s->output_every = 1;
    s->steps = 10;
    /* every scene starts from the tangent predictor: each static increment, and each dynamic step
     * whose handles start, stop or turn (docs/solver-nonconvexity.md) */
    s->predictor = PLUME_PREDICT_TANGENT;
    s->globalization = PLUME_GLOBAL_CURVED_LINE_SEARCH;
    s->camera[0] = 60.0;
    s->camera[1] = 30.0;
    snprintf(s->render_field, sizeof s->render_field, "material");
    snprintf(s->gltf_file, sizeof s->gltf_file, "frames.glb");
    if ((st = parse_model(c, doc, s)) != PLUME_OK || (st = parse_stepping(c, doc, s)) != PLUME_OK ||
        (st = parse_solver(c, doc, s)) != PLUME_OK || (st = parse_output(c, doc, s)) != PLUME_OK ||
        (st = parse_gltf(c, doc, s)) != PLUME_OK)
        return st;
    return parse_camera(c, doc, s);
}

const char *plume_scene_bending_name(int model)
{
    return model == PLUME_BENDING_HINGE ? "hinge" : model == PLUME_BENDING_MIDEDGE ? "midedge" : "shape_operator";
}

/* The settings plume_scene_set may change: none of them changes the mesh, the materials or what the
 * scene allocated ("render" does, "dt" and "duration" are checked against other keys at load). */
static const char *const settable[] = {"solver",        "max_halvings", "max_iter", "steps", "output_every",
                                       "bending_model", "predictor",    "globalization", "render_field",
                                       "camera",        "gltf",         "verbose",       NULL};

plume_status plume_scene_set(plume_scene *s, const char *settings, plume_err *err)
{
    if (!s || !settings)
        return plume_err_set(err, PLUME_EINVAL, "plume_scene_set: the scene and the settings are required");
    json_error_t je;
    json_t *doc = json_loads(settings, 0, &je);
    if (!doc || !json_is_object(doc)) {
        json_decref(doc);
        return doc ? plume_err_set(err, PLUME_EFORMAT, "plume_scene_set: the settings must be a JSON object")
                   : plume_err_set(err, PLUME_EFORMAT, "plume_scene_set: settings:%d: %s", je.line, je.text);
    }
    plume_json_ctx c = {.file = "plume_scene_set", .text = (char *)settings, .err = err};
    /* into a copy, so that a refused key changes nothing (no allowed key allocates) */
    plume_scene tmp = *s;
    plume_status st = plume_json_check_keys(&c, doc, "", settable);
    long steps = tmp.steps;
    json_t *v;
    if (st == PLUME_OK && (st = parse_model(&c, doc, &tmp)) == PLUME_OK &&
        (st = plume_json_int(&c, doc, "", "steps", 1, 1000000, &steps)) == PLUME_OK &&
        (st = parse_solver(&c, doc, &tmp)) == PLUME_OK && (st = parse_output(&c, doc, &tmp)) == PLUME_OK &&
        (st = parse_gltf(&c, doc, &tmp)) == PLUME_OK &&
        (st = parse_camera(&c, doc, &tmp)) == PLUME_OK && (v = json_object_get(doc, "verbose"))) {
        if (!json_is_boolean(v))
            st = plume_json_bad(&c, PLUME_EFORMAT, "verbose", "must be true or false");
        tmp.verbose = json_is_true(v);
    }
    tmp.steps = (int)steps;
    json_decref(doc);
    if (st == PLUME_OK)
        *s = tmp;
    return st;
}
