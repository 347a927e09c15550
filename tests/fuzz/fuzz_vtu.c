/* libFuzzer: plume's .vtu and .pvd readers (lib/io/vtu.h). */
#include "fuzz_common.h"
#include "../../lib/io/vtu.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write("in.vtu", data, size);
    plume_vtu_data d;
    plume_err err = {{0}};
    if (plume_vtu_read(path, &d, &err) == PLUME_OK) {
        /* what the reader accepted is consistent: cells name real points */
        for (plume_index c = 0; c < d.ncells; c++)
            if (d.offsets[c] < 0)
                abort();
        plume_vtu_data_free(&d);
    }
    plume_pvd_entries e;
    if (plume_pvd_read(path, &e, &err) == PLUME_OK)
        plume_pvd_entries_free(&e);
    return 0;
}
