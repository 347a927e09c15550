/* libFuzzer: a measured curve as text (apps/fit --target FILE.txt). */
#include "fuzz_common.h"
#include "../../micro/fit.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write("curve.txt", data, size);
    plume_curve c;
    plume_err err = {{0}};
    if (plume_curve_read_text(path, &c, &err) == PLUME_OK) {
        for (plume_index k = 0; k < c.n; k++)
            if (c.strain[k] != c.strain[k] || c.stress[k] != c.stress[k])
                abort(); /* NaN accepted as data */
        plume_curve_free(&c);
    } else if (!err.msg[0]) {
        abort();
    }
    return 0;
}
