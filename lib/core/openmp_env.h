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

#include "../../include/plume/base.h"

#include "export.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
