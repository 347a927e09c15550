/* libFuzzer: a microstructure layout JSON (apps/homogenize --config), checked and meshed when
 * valid and small. */
#include "fuzz_common.h"
#include "../../micro/cell_mesh.h"
#include "../../micro/layout_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write("layout.json", data, size);
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {{0}};
    if (plume_layout_load_json(path, &l, &err) != PLUME_OK) {
        if (!err.msg[0])
            abort();
        return 0;
    }
    if (plume_layout_check(&l, &err) != PLUME_OK)
        return 0;
    /* mesh the cell when it stays small (e_rel bounds the element count per cell) */
    if (l.e_rel >= 0.25) {
        plume_cell *c = NULL;
        if (plume_cell_mesh(&l, &c, &err) == PLUME_OK)
            plume_cell_destroy(&c);
    }
    return 0;
}
