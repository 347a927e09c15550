/* RTLD_DEFAULT, sched_getaffinity and CPU_COUNT are GNU extensions */
#define _GNU_SOURCE
#include "openmp_env.h"
#include "blas_threads.h"

#include <dlfcn.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* the one OpenMP call plume makes, declared as the OpenMP API defines it (libgomp provides it):
 * GCC's omp.h does not parse under clang, which builds the fuzzing harnesses */
void omp_set_max_active_levels(int max_levels);
int omp_get_max_active_levels(void);

/* OpenBLAS's thread setter, looked up at run time: the BLAS the distribution's alternatives chose
 * may be another one, without it. NULL when absent. */
static void (*openblas_setter(void))(int)
{
    void *sym = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
    void (*set_threads)(int) = NULL;
    if (sym)
        memcpy(&set_threads, &sym, sizeof sym);
    return set_threads;
}

/* the threads a large factorisation may use, and OpenBLAS's setter (0 and NULL: plume does not
 * manage OpenBLAS's threads: the environment chose, the BLAS is not OpenBLAS, or
 * plume_openmp_serial was not called) */
static int factor_threads;
static void (*blas_setter)(int);
/* 1 once plume_openmp_serial made OpenMP regions serial: libgomp keeps max-active-levels per
 * thread, so every other thread that factorises sets it too (plume_openmp_thread_serial) */
static _Atomic int serial_regions;

/* the cores this process may run on */
static int cores_available(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set);
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

/* One OpenBLAS thread (pthread and OpenMP builds alike), unless the environment chose */
static void one_blas_thread(void)
{
    if (getenv("OPENBLAS_NUM_THREADS") || getenv("GOTO_NUM_THREADS") || getenv("OMP_NUM_THREADS"))
        return;
    blas_setter = openblas_setter();
    if (!blas_setter)
        return;
    blas_setter(1);
    factor_threads = cores_available();
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
    serial_regions = 1;
}

void plume_openmp_thread_serial(void)
{
    if (serial_regions && omp_get_max_active_levels() != 0)
        omp_set_max_active_levels(0);
}

void plume_openmp_factor_threads(int threads)
{
    if (factor_threads > 0 && threads >= 1)
        factor_threads = threads;
}

int plume_blas_threads_for(double flops)
{
    return factor_threads > 1 && flops >= PLUME_THREADED_FACTOR_FLOPS ? factor_threads : 1;
}

void plume_blas_threads_set(int threads)
{
    if (blas_setter && threads >= 1)
        blas_setter(threads);
}
