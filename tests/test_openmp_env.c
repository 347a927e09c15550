/* Tests of lib/openmp_env: after plume_openmp_serial (the runner calls it first) an OpenMP region
 * runs its body once, as a team of one, and OpenBLAS runs on one thread; where the environment
 * keeps OpenMP's teams and sets OpenBLAS's threads the regions have their threads and OpenBLAS
 * the threads asked for (checked in a child runner, whose environment sets OMP_MAX_ACTIVE_LEVELS
 * and OPENBLAS_NUM_THREADS). The regions are libgomp's own: plume defines none of its symbols. */
#define _GNU_SOURCE /* RTLD_DEFAULT, dladdr */
#include <dlfcn.h>
#include <limits.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "../lib/core/blas_threads.h"
#include "../lib/core/openmp_env.h"
#include "../lib/solve/cholesky.h"

/* libgomp's entry points, as GCC calls them (GCC's omp.h does not parse under clang) */
void GOMP_parallel(void (*fn)(void *), void *data, unsigned num_threads, unsigned flags);
int omp_get_num_threads(void);

typedef struct {
    int calls, threads;
} region_seen;

static void body(void *data)
{
    region_seen *s = data;
    __atomic_add_fetch(&s->calls, 1, __ATOMIC_SEQ_CST);
    __atomic_store_n(&s->threads, omp_get_num_threads(), __ATOMIC_SEQ_CST);
}

/* Run by the runner itself (serial: one call, a team of one) and by the child below (teams kept:
 * two calls from a team of two). */
void test_openmp_env_zchild_regions(void)
{
    int teams = getenv("OMP_MAX_ACTIVE_LEVELS") || getenv("OMP_THREAD_LIMIT");
    region_seen s = {0, 0};
    GOMP_parallel(body, &s, 2, 0);
    fprintf(stderr, "    %s: the body ran %d times, omp_get_num_threads() = %d\n",
            teams ? "teams kept" : "serial", s.calls, s.threads);
    /* a thread limit of the user's own bounds libgomp's team */
    int expect = teams ? (getenv("OMP_THREAD_LIMIT") ? s.threads : 2) : 1;
    CHECK(s.calls == expect && s.calls >= 1);
    CHECK(s.threads == expect);
}

/* OpenBLAS's thread count after plume_openmp_serial: 1, or what the environment asked for (at most
 * the cores: OpenBLAS caps it). Skipped, saying so, when the BLAS is not OpenBLAS. */
void test_openmp_env_zchild_blas(void)
{
    void *sym = dlsym(RTLD_DEFAULT, "openblas_get_num_threads");
    int (*get_threads)(void) = NULL;
    if (sym)
        memcpy(&get_threads, &sym, sizeof sym);
    if (!get_threads) {
        fprintf(stderr, "    the BLAS is not OpenBLAS: its threads are not plume's to set (skipped)\n");
        return;
    }
    const char *env = getenv("OPENBLAS_NUM_THREADS"); /* OpenBLAS's own order of precedence */
    if (!env)
        env = getenv("GOTO_NUM_THREADS");
    if (!env)
        env = getenv("OMP_NUM_THREADS");
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    const int asked = env ? atoi(env) : 1;
    const int expect = asked < cores ? asked : (int)cores;
    fprintf(stderr, "    threads asked %s: openblas_get_num_threads() = %d (expected %d)\n", env ? env : "unset",
            get_threads(), expect);
    CHECK(get_threads() == expect);
}

void test_openmp_env_teams_kept(void)
{
    char self[PATH_MAX], cmd[PATH_MAX + 256];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    CHECK(n > 0);
    if (n <= 0)
        return;
    self[n] = 0;
    snprintf(cmd, sizeof cmd,
             "env -u OMP_THREAD_LIMIT -u OMP_NUM_THREADS -u GOTO_NUM_THREADS OMP_MAX_ACTIVE_LEVELS=2 "
             "OPENBLAS_NUM_THREADS=2 '%s' test_openmp_env_zchild >/dev/null 2>&1",
             self);
    CHECK(system(cmd) == 0);
}

/* GOMP_parallel, as the runner (and CHOLMOD) binds it, is libgomp's: the library interposes nothing */
void test_openmp_env_libgomp_own(void)
{
    void *sym = dlsym(RTLD_DEFAULT, "GOMP_parallel");
    Dl_info info;
    CHECK(sym != NULL);
    if (!sym || !dladdr(sym, &info) || !info.dli_fname) {
        CHECK(!"dladdr of GOMP_parallel");
        return;
    }
    fprintf(stderr, "    GOMP_parallel from %s\n", info.dli_fname);
    CHECK(strstr(info.dli_fname, "libgomp") != NULL);
}

/* The threads of large factorisations: after plume_openmp_serial, factorisations of at least
 * PLUME_THREADED_FACTOR_FLOPS run OpenBLAS on every core the runner may use (or the count given to
 * plume_openmp_factor_threads), smaller ones on one; where the environment chose OpenBLAS's
 * threads, or the BLAS is not OpenBLAS, plume sets none. */
void test_openmp_env_factor_threads(void)
{
    void *sym = dlsym(RTLD_DEFAULT, "openblas_get_num_threads");
    int (*get_threads)(void) = NULL;
    if (sym)
        memcpy(&get_threads, &sym, sizeof sym);
    const int managed = get_threads && !getenv("OPENBLAS_NUM_THREADS") && !getenv("GOTO_NUM_THREADS") &&
                        !getenv("OMP_NUM_THREADS");
    cpu_set_t set;
    CHECK(sched_getaffinity(0, sizeof set, &set) == 0);
    const int cores = CPU_COUNT(&set);
    fprintf(stderr, "    %s, %d cores: %d threads at 1e9 flops, %d at 3e10\n",
            managed ? "plume manages OpenBLAS" : "OpenBLAS's threads are not plume's", cores,
            plume_blas_threads_for(1e9), plume_blas_threads_for(3e10));
    CHECK(plume_blas_threads_for(0.5 * PLUME_THREADED_FACTOR_FLOPS) == 1);
    CHECK(plume_blas_threads_for(3.0 * PLUME_THREADED_FACTOR_FLOPS) == (managed ? cores : 1));
    plume_openmp_factor_threads(1); /* processes sharing the cores */
    CHECK(plume_blas_threads_for(3.0 * PLUME_THREADED_FACTOR_FLOPS) == 1);
    plume_openmp_factor_threads(0); /* refused: unchanged */
    CHECK(plume_blas_threads_for(3.0 * PLUME_THREADED_FACTOR_FLOPS) == 1);
    plume_openmp_factor_threads(cores);
    CHECK(plume_blas_threads_for(3.0 * PLUME_THREADED_FACTOR_FLOPS) == (managed ? cores : 1));
    if (!managed)
        return;
    /* the setter reaches OpenBLAS, and a factorisation leaves it on one thread */
    plume_blas_threads_set(2);
    CHECK(get_threads() == (cores < 2 ? cores : 2));
    plume_blas_threads_set(1);
    CHECK(get_threads() == 1);
    plume_index colptr[3] = {0, 1, 3}, rowind[3] = {0, 0, 1};
    double values[3] = {4.0, 1.0, 3.0};
    plume_chol *c = NULL;
    plume_err err = {{0}};
    CHECK(plume_chol_create(2, colptr, rowind, 0, &c, &err) == PLUME_OK);
    if (c)
        CHECK(plume_chol_factor(c, values, 0.0) == PLUME_OK);
    plume_chol_destroy(&c);
    CHECK(get_threads() == 1);
}
