/* plume: options structs that grow (lib/core/opts.h). */
#include "opts.h"

#include <string.h>

plume_status plume_opts_take(void *dst, size_t dst_size, const void *src, const char *name, plume_err *err)
{
    size_t size = 0;
    memcpy(&size, src, sizeof size);
    if (size < sizeof size)
        return plume_err_set(err, PLUME_EINVAL,
                             "%s.size is %zu: fill the struct with its _default macro first (it sets size)", name,
                             size);
    memcpy(dst, src, size < dst_size ? size : dst_size);
    memcpy(dst, &dst_size, sizeof dst_size);
    return PLUME_OK;
}

void plume_opts_give(void *dst, size_t size, const void *src, size_t full_size)
{
    if (size < sizeof size)
        return;
    memcpy(dst, src, size < full_size ? size : full_size);
    memcpy(dst, &size, sizeof size);
}
