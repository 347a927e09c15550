/* libFuzzer: a triangle-mesh OBJ (faces, groups) read through an OBJ shell scene. */
#include "fuzz_scene_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scene_files();
    fuzz_write("mesh_in.obj", data, size);
    load_scene("obj_in.json");
    return 0;
}
