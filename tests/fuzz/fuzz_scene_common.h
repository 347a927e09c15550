/* The scene harnesses: each writes its input as one file of a scene (the scene JSON, a feather
 * shape, an outline OBJ, a mesh OBJ) beside fixed copies of the others, and loads the scene as
 * apps/feather does. */
#ifndef PLUME_FUZZ_SCENE_COMMON_H
#define PLUME_FUZZ_SCENE_COMMON_H

#include "fuzz_common.h"
#include "../../macro/scene/scene.h"

/* the fixed files: the shipped feather's shape and outline, the strip and bone meshes, and scenes
 * that use each of them */
static void scene_files(void)
{
    static int done;
    if (done)
        return;
    done = 1;
    fuzz_copy("data/feather/feather_shape.json", "feather_shape.json");
    fuzz_copy("data/feather/outline.obj", "outline.obj");
    fuzz_copy("data/shell/strip.obj", "strip.obj");
    fuzz_copy("data/bird/bone.obj", "bone.obj");
    /* a feather scene reading shape_in.json and outline_in.obj (the harnesses' inputs). Its bending is
     * the hinge model: the shape operator's stencil search took 88% of each input's time (120 ms
     * of 145 ms under the sanitizers), on coarse meshes the most, as its rings then span the whole
     * feather; the shape operator on feather meshes is fuzzed by fuzz_scene's feather scenes. */
    fuzz_write_text("feather_in.json",
                    "{\"bending_model\": \"hinge\","
                    " \"mesh\": {\"feather\": \"shape_in.json\", \"outline\": \"outline_in.obj\", \"edge\": 0.02},"
                    " \"materials\": [{\"membrane\": {\"E\": 1e6, \"thickness\": 1e-4}, \"density\": 0.03,"
                    " \"constraint\": true}, {\"membrane\": {\"E\": 1e9, \"thickness\": 3e-3}, \"density\": 0.5}],"
                    " \"dt\": 0.01, \"duration\": 0.1}");
    /* an OBJ shell scene reading mesh_in.obj */
    fuzz_write_text("obj_in.json",
                    "{\"mesh\": {\"obj\": \"mesh_in.obj\", \"materials_by_group\": {\"rachis\": 1}, \"barb_direction\": [1, 0]},"
                    " \"materials\": [{\"membrane\": {\"E\": 1e6, \"thickness\": 1e-4}, \"density\": 0.03,"
                    " \"constraint\": true}, {\"membrane\": {\"E\": 1e9, \"thickness\": 3e-3}, \"density\": 0.5}],"
                    " \"dt\": 0.01, \"duration\": 0.1}");
}

/* loads <scratch>/name as a scene and frees it; the output fields too when it loads */
static void load_scene(const char *name)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", fuzz_scratch(), name);
    plume_scene *s = NULL;
    plume_err err = {{0}};
    if (plume_scene_load(path, &s, &err) == PLUME_OK) {
        plume_fields *f = NULL;
        if (plume_scene_fields(s, &f, &err) == PLUME_OK)
            plume_fields_destroy(&f);
        plume_scene_destroy(&s);
    } else if (!err.msg[0]) {
        abort(); /* every failure carries a message */
    }
}

#endif
