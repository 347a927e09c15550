/* libFuzzer: a scene JSON (macro/scene/scene.h), with the shipped meshes beside it. */
#include "fuzz_scene_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scene_files();
    fuzz_write("scene.json", data, size);
    load_scene("scene.json");
    return 0;
}
