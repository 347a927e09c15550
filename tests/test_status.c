#include <string.h>

#include "harness.h"
#include "../lib/status.h"

void test_status_strerror(void)
{
    CHECK(strcmp(plume_strerror(PLUME_OK), "ok") == 0);
    CHECK(strcmp(plume_strerror(PLUME_EINVAL), "invalid input") == 0);
    CHECK(strcmp(plume_strerror((plume_status)-99), "unknown status") == 0);
    plume_err e;
    CHECK(plume_err_set(&e, PLUME_EIO, "file %s line %d", "a.json", 3) == PLUME_EIO);
    CHECK(strcmp(e.msg, "file a.json line 3") == 0);
    CHECK(plume_err_set(NULL, PLUME_EINVAL, "x") == PLUME_EINVAL);
}
