/* libFuzzer: the feather's outline OBJ (a closed polyline) read through a feather scene. */
#include "fuzz_scene_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scene_files();
    fuzz_copy("data/feather/feather_shape.json", "shape_in.json");
    fuzz_write("outline_in.obj", data, size);
    load_scene("feather_in.json");
    return 0;
}
