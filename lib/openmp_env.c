/* dlvsym and RTLD_NEXT are GNU extensions */
#define _GNU_SOURCE
#include "openmp_env.h"

#include <dlfcn.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* the one OpenMP call plume makes, declared as the OpenMP API defines it (libgomp provides it):
 * GCC's omp.h does not parse under clang, which builds the fuzzing harnesses */
void omp_set_max_active_levels(int max_levels);

/* Set once by plume_openmp_serial, before any thread of the program's own exists (its contract);
 * read by GOMP_parallel below. Process-wide by design, like the OpenMP setting it stands for. */
static int serial_regions;

typedef void (*gomp_parallel_fn)(void (*)(void *), void *, unsigned, unsigned);
static gomp_parallel_fn next_gomp_parallel;
static pthread_once_t next_once = PTHREAD_ONCE_INIT;

static void find_next_gomp_parallel(void)
{
    void *sym = dlvsym(RTLD_NEXT, "GOMP_parallel", "GOMP_4.0");
    if (!sym)
        sym = dlsym(RTLD_NEXT, "GOMP_parallel");
    /* object pointer to function pointer: through memcpy, as ISO C has no cast between them */
    if (sym)
        memcpy(&next_gomp_parallel, &sym, sizeof sym);
}

/* GCC compiles `#pragma omp parallel` into a call of libgomp's GOMP_parallel(fn, data, threads,
 * flags), which starts a team and runs fn(data) on each thread. CHOLMOD 5.12 opens such a region
 * for every supernode of every factorisation (a compiled-in num_threads(4)); even serial (OpenMP's
 * max-active-levels 0) libgomp builds and frees a team each time. perf, tilted traction at 4e4
 * elements (4335 supernodes, 19 factorisations): libgomp's team allocation, futex wakes and page
 * faults were about 9 % of the run. So, when plume_openmp_serial has made every region serial,
 * this definition (which the program's and libcholmod's calls bind to, plume being linked before
 * libgomp) runs fn(data) directly: a region of one thread, omp_get_num_threads() = 1 and
 * omp_get_thread_num() = 0 inside, as OpenMP specifies for one. Otherwise it hands the call to
 * the next definition, libgomp's, unchanged. Wherever plume's copy is not the one bound (an
 * unusual load order), libgomp's serial regions run as before: slower, the same results. */
void GOMP_parallel(void (*fn)(void *), void *data, unsigned num_threads, unsigned flags)
{
    if (!serial_regions) {
        pthread_once(&next_once, find_next_gomp_parallel);
        if (next_gomp_parallel) {
            next_gomp_parallel(fn, data, num_threads, flags);
            return;
        }
    }
    fn(data);
}

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

void plume_openmp_serial(void)
{
    one_blas_thread();
    if (getenv("OMP_MAX_ACTIVE_LEVELS") || getenv("OMP_THREAD_LIMIT"))
        return;
    omp_set_max_active_levels(0);
    serial_regions = 1;
}
