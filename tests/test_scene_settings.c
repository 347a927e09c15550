/* A loaded scene seen and changed through the public face (include/plume/scene.h):
 * plume_scene_describe's JSON, plume_scene_set's checks (the loader's, all or nothing) and the
 * probes' displacements. */
#include <jansson.h>
#include <math.h>
#include <string.h>

#include "harness.h"
#include "../include/plume/plume.h"

/* The scene's description, parsed (NULL on failure). */
static json_t *describe(const plume_scene *s)
{
    char *text = NULL;
    plume_err err = {{0}};
    json_t *j = NULL;
    CHECK(plume_scene_describe(s, &text, &err) == PLUME_OK && text);
    if (text)
        j = json_loads(text, 0, NULL);
    plume_free(text);
    CHECK(j != NULL);
    return j;
}

static const char *str(json_t *j, const char *key)
{
    const char *v = json_string_value(json_object_get(j, key));
    return v ? v : "";
}

void test_scene_describe(void)
{
    plume_err err = {{0}};
    plume_scene *s = NULL;
    CHECK(plume_scene_load("../data/benchmarks/cantilever_shear.json", &s, &err) == PLUME_OK);
    if (!s)
        return;
    json_t *j = describe(s);
    CHECK(!strcmp(str(j, "solve"), "static") && !strcmp(str(j, "solver"), "newton"));
    CHECK(json_integer_value(json_object_get(j, "elements")) > 0 && json_integer_value(json_object_get(j, "vertices")) > 0);
    json_t *probes = json_object_get(j, "probes"), *mats = json_object_get(j, "materials");
    CHECK(json_array_size(probes) == 1 && !strcmp(str(json_array_get(probes, 0), "name"), "tip"));
    CHECK(json_array_size(mats) == 1 &&
          json_number_value(json_object_get(json_object_get(json_array_get(mats, 0), "membrane"), "E_xx")) > 0.0);
    CHECK(!json_object_get(j, "dt") && !json_object_get(j, "contact"));
    /* the probe at the rest state has not moved; out of range is NaN */
    double u[3];
    const double *X = NULL;
    (void)X;
    plume_run *r = NULL;
    CHECK(plume_run_create(s, NULL, &r, &err) == PLUME_OK);
    plume_scene_probe_displacement(s, 0, plume_run_positions(r), u);
    CHECK(u[0] == 0.0 && u[1] == 0.0 && u[2] == 0.0);
    plume_scene_probe_displacement(s, 1, plume_run_positions(r), u);
    CHECK(isnan(u[0]) && isnan(u[2]));
    plume_run_destroy(&r);
    json_decref(j);
    plume_scene_destroy(&s);
    /* a dynamic scene with contact: its clock and its contact block */
    CHECK(plume_scene_load("../data/bird/wing.json", &s, &err) == PLUME_OK);
    if (!s)
        return;
    j = describe(s);
    CHECK(!strcmp(str(j, "solve"), "dynamic") && json_number_value(json_object_get(j, "dt")) > 0.0);
    CHECK(json_number_value(json_object_get(json_object_get(j, "contact"), "dhat")) > 0.0);
    CHECK(json_integer_value(json_object_get(j, "objects")) > 1 && !json_object_get(j, "probes"));
    json_decref(j);
    plume_scene_destroy(&s);
    char *text = (char *)1;
    CHECK(plume_scene_describe(NULL, &text, &err) == PLUME_EINVAL && text == NULL);
}

void test_scene_set(void)
{
    plume_err err = {{0}};
    plume_scene *s = NULL;
    CHECK(plume_scene_load("../data/benchmarks/cantilever_shear.json", &s, &err) == PLUME_OK);
    if (!s)
        return;
    CHECK(plume_scene_set(s, "{\"solver\": \"ipopt\", \"steps\": 3, \"bending_model\": \"hinge\", \"predictor\": "
                             "\"secant\", \"globalization\": \"line_search\", \"verbose\": false}",
                          &err) == PLUME_OK);
    json_t *j = describe(s);
    CHECK(!strcmp(str(j, "solver"), "ipopt") && json_integer_value(json_object_get(j, "steps")) == 3);
    CHECK(!strcmp(str(j, "bending_model"), "hinge") && !strcmp(str(j, "predictor"), "secant"));
    CHECK(!strcmp(str(j, "globalization"), "line_search"));
    json_decref(j);
    /* refused, naming the key; all or nothing: the solver of a refused object is not set */
    const char *bad[][2] = {
        {"{\"solver\": \"newton\", \"steps\": 0}", "steps"},
        {"{\"solver\": \"cg\"}", "solver must be"},
        {"{\"mesh\": {}}", "mesh is an unknown key"},
        {"{\"dt\": 0.1}", "dt is an unknown key"},
        {"{\"render_field\": \"curl\"}", "render_field must be"},
        {"{\"verbose\": 1}", "verbose must be true or false"},
        {"[1, 2]", "must be a JSON object"},
        {"{\"solver\": ", "settings:"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        err.msg[0] = 0;
        CHECK(plume_scene_set(s, bad[k][0], &err) != PLUME_OK && strstr(err.msg, bad[k][1]));
        fprintf(stderr, "    %s\n", err.msg);
    }
    j = describe(s);
    CHECK(!strcmp(str(j, "solver"), "ipopt") && json_integer_value(json_object_get(j, "steps")) == 3);
    json_decref(j);
    CHECK(plume_scene_set(s, NULL, &err) == PLUME_EINVAL && plume_scene_set(NULL, "{}", &err) == PLUME_EINVAL);
    CHECK(plume_scene_set(s, "{}", &err) == PLUME_OK);
    plume_scene_destroy(&s);
}
