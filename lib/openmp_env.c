#include "openmp_env.h"

#include <stdlib.h>

#include <omp.h>

void plume_openmp_serial(void)
{
    if (getenv("OMP_MAX_ACTIVE_LEVELS") || getenv("OMP_THREAD_LIMIT"))
        return;
    omp_set_max_active_levels(0);
}
