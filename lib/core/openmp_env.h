/** \file
 * plume: serial OpenMP regions and one BLAS thread (all cores for large factorisations), for the
 * Debian CHOLMOD build.
 *
 * Why: CHOLMOD 5.12's supernodal factorisation opens OpenMP regions with a compiled-in
 * num_threads(4) (CHOLMOD_OMP_NUM_THREADS in cholmod_core.h) around loops that clear and scatter
 * one supernode at a time; OMP_NUM_THREADS cannot lower a num_threads clause. On 2-core machines
 * those 4-thread teams wake and park for every supernode, and OpenBLAS's second thread spins
 * between the supernodes' small BLAS calls. Serial regions and one BLAS thread give the same
 * iterates in less time (measurements: docs/library.md "Threads").
 *
 * The library never changes a process-wide setting by itself: the apps, tests and benchmarks call
 * this at start, and so may any program that links libplume. It uses OpenMP's own API only. */
#ifndef PLUME_OPENMP_ENV_H
#define PLUME_OPENMP_ENV_H

#include "export.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Every OpenMP parallel region of the process runs on one thread from now on (OpenMP's
 * max-active-levels set to 0, omp_set_max_active_levels), unless the environment sets
 * OMP_MAX_ACTIVE_LEVELS or OMP_THREAD_LIMIT: the user's choice wins (OMP_MAX_ACTIVE_LEVELS=1 keeps
 * CHOLMOD's teams). OpenBLAS, when it is the BLAS, runs on one thread, unless the environment sets
 * OPENBLAS_NUM_THREADS, GOTO_NUM_THREADS or OMP_NUM_THREADS (the variables OpenBLAS reads).
 * Process-wide; call it once at start, from one thread, before the program's first parallel
 * region. */
PLUME_API void plume_openmp_serial(void);

/** The OpenBLAS threads of large factorisations after plume_openmp_serial (default: every core the
 * process may run on; threads >= 1). A factorisation of at least 10^10 flops (CHOLMOD's count:
 * the feather at 44.7k elements, not the shipped scenes) runs its BLAS on that many threads, and
 * OpenBLAS goes back to one thread after it; smaller ones stay on one. Call it with 1 where
 * processes already share the cores (an MPI sweep). Nothing changes when the environment chose
 * OpenBLAS's threads or the BLAS is not OpenBLAS. */
PLUME_API void plume_openmp_factor_threads(int threads);

#ifdef __cplusplus
}
#endif
#endif
