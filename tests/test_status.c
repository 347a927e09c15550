#include <string.h>

#include "harness.h"
#include "../lib/core/status.h"
#include "../lib/core/version.h"
#include <stdio.h>

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

/* The version: the macros, the run-time string and the Makefile (which names the shared library
 * libplume.so.MAJOR.MINOR) agree. */
void test_status_version(void)
{
    char want[32];
    snprintf(want, sizeof want, "%d.%d.%d", PLUME_VERSION_MAJOR, PLUME_VERSION_MINOR, PLUME_VERSION_PATCH);
    CHECK(strcmp(plume_version(), want) == 0 && strcmp(PLUME_VERSION_STRING, want) == 0);
    FILE *f = fopen("../Makefile", "r");
    CHECK(f != NULL);
    if (!f)
        return;
    char line[256];
    int found = 0, major = -1, minor = -1, patch = -1;
    while (fgets(line, sizeof line, f)) {
        found += sscanf(line, "VERSION_MAJOR := %d", &major) == 1;
        found += sscanf(line, "VERSION_MINOR := %d", &minor) == 1;
        found += sscanf(line, "VERSION_PATCH := %d", &patch) == 1;
    }
    fclose(f);
    CHECK(found == 3 && major == PLUME_VERSION_MAJOR && minor == PLUME_VERSION_MINOR && patch == PLUME_VERSION_PATCH);
}
