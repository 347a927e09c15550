/* RTLD_DEFAULT is a GNU extension */
#define _GNU_SOURCE
#include "openmp_env.h"

#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>

/* the one OpenMP call plume makes, declared as the OpenMP API defines it (libgomp provides it):
 * GCC's omp.h does not parse under clang, which builds the fuzzing harnesses */
void omp_set_max_active_levels(int max_levels);

/* OpenBLAS's thread count (pthread and OpenMP builds alike), looked up at run time: the BLAS the
 * distribution's alternatives chose may be another one, without it. */
static void one_blas_thread(void)
{
    if (getenv("OPENBLAS_NUM_THREADS") || getenv("GOTO_NUM_THREADS") || getenv("OMP_NUM_THREADS"))
        return;
    void *sym = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
    void (*set_threads)(int) = NULL;
    if (sym)
        memcpy(&set_threads, &sym, sizeof sym);
    if (set_threads)
        set_threads(1);
}

/* Only OpenMP's own API: max-active-levels 0 is the ICV that makes every parallel region,
 * num_threads clause or not, run as a team of one (the specification's rule for the number of threads). libgomp still builds and
 * frees that one-thread team per region; plume does not replace libgomp's entry points to avoid
 * it (a library defining another library's symbols changes every program that links it). */
void plume_openmp_serial(void)
{
    one_blas_thread();
    if (getenv("OMP_MAX_ACTIVE_LEVELS") || getenv("OMP_THREAD_LIMIT"))
        return;
    omp_set_max_active_levels(0);
}
