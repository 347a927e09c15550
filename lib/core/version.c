/* The library's version (version.h). */
#include "version.h"

const char *plume_version(void)
{
    return PLUME_VERSION_STRING;
}
