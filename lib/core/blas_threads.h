/* plume internal: how many OpenBLAS threads one factorisation uses (lib/core/openmp_env.c).
 * After plume_openmp_serial, plume runs OpenBLAS on one thread, except inside factorisations of at
 * least PLUME_THREADED_FACTOR_FLOPS, which use plume_openmp_factor_threads' count (default: every
 * core the process may run on). Measured (docs/library.md, "Threads"): the feather at 44.7k
 * elements (3.0e10 flops, 1958 supernodes) 0.89 s an iteration with two threads against 1.22 s
 * with one; tilted traction at 1e5 elements (1.5e9 flops in 10832 small supernodes) is slower with
 * two, its BLAS calls too small to share. */
#ifndef PLUME_INTERNAL_BLAS_THREADS_H
#define PLUME_INTERNAL_BLAS_THREADS_H

#define PLUME_THREADED_FACTOR_FLOPS 1e10

/* the OpenBLAS threads for a factorisation of this many flops (1 when plume does not manage them) */
int plume_blas_threads_for(double flops);
/* sets OpenBLAS's threads when plume manages them; nothing otherwise */
void plume_blas_threads_set(int threads);
/* After plume_openmp_serial, makes the calling thread's OpenMP regions serial too: libgomp keeps
 * max-active-levels per thread, and a thread the program started itself begins with the default
 * (measured with GCC 12's libgomp: a pthread ran a num_threads(4) region as a team of 4 after the
 * main thread had set 0). Called before every analysis and factorisation; nothing when
 * plume_openmp_serial was not called. */
void plume_openmp_thread_serial(void);

#endif
