#include "openmp_env.h"

#include <stdlib.h>

/* the one OpenMP call plume makes, declared as the OpenMP API defines it (libgomp provides it):
 * GCC's omp.h does not parse under clang, which builds the fuzzing harnesses */
void omp_set_max_active_levels(int max_levels);

void plume_openmp_serial(void)
{
    if (getenv("OMP_MAX_ACTIVE_LEVELS") || getenv("OMP_THREAD_LIMIT"))
        return;
    omp_set_max_active_levels(0);
}
