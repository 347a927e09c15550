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
    /* mesh the cell when it stays small: the library meshes up to 5e6 triangles (a 9000:1 barbule
     * cell of 1.4e6 took more than the 20 s timeout under the sanitizers: slow, not wrong) */
    double w = plume_layout_barb_width(&l), e = plume_layout_element_edge(&l, PLUME_MESH_CELL);
    double a = l.kind == PLUME_LAYOUT_STRIPS ? 4.0 * w : l.barbule_spacing;
    if (e > 0.0 && 2.0 * (a / e + 4.0) * (l.d_B / e + 4.0) <= 2e4) {
        plume_cell *c = NULL;
        if (plume_cell_mesh(&l, &c, &err) == PLUME_OK)
            plume_cell_destroy(&c);
    }
    return 0;
}
