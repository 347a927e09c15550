/* libFuzzer: the feather mesher's shape file (rachis, barb curves; data/feather/feather_shape.json)
 * read through a feather scene. */
#include "fuzz_scene_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scene_files();
    fuzz_copy("data/feather/outline.obj", "outline_in.obj");
    fuzz_write("shape_in.json", data, size);
    load_scene("feather_in.json");
    return 0;
}
