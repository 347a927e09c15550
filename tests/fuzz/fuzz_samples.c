/* libFuzzer: a samples file (data/samples.json, supplementary Table 1). */
#include "fuzz_common.h"
#include "../../lib/io/sample.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write("samples.json", data, size);
    plume_err err = {{0}};
    int n = 0;
    if (plume_sample_count(path, &n, &err) == PLUME_OK)
        for (int k = 0; k < n && k < 64; k++) {
            plume_sample s;
            plume_sample_at(path, k, &s, &err);
        }
    plume_sample s;
    plume_sample_load(path, "T01", &s, &err);
    return 0;
}
