/* plume: serial OpenMP regions for the Debian CHOLMOD build.
 *
 * Why: CHOLMOD 5.12's supernodal factorisation opens OpenMP regions with a compiled-in
 * num_threads(4) (CHOLMOD_OMP_NUM_THREADS in cholmod_core.h) around loops that clear and scatter
 * one supernode at a time. OMP_NUM_THREADS cannot lower a num_threads clause. On this project's
 * 2-core machines those 4-thread teams woke and parked for every supernode: perf showed the main
 * thread in futex wake/wait and the scheduler for a quarter of the feather's run. Serial regions
 * (measured with OMP_THREAD_LIMIT=1, the same iterates; README "Threads"):
 *   feather, 865 elements, 20 frames: 1.68-1.76 -> 1.21-1.29 s of solves;
 *   tilted traction at 4e4 elements: factorisations 2.16 -> 1.45 s, run 3.50 -> 2.86 s.
 * BLAS threads (OpenBLAS's own pthreads, which do the supernodes' dense work) are set to one as
 * well. On 2 cores OpenBLAS's second thread spins (sched_yield) between calls, so the run shares
 * its core with it and a busy machine's other work: tilted traction at 4e4 elements took
 * 1.94-2.18 s with one BLAS thread against 2.27-2.49 s with two (at half the CPU time), Ipopt's
 * run 9.6-10.8 s against 10.2-11.6 s; at 1e4 newton's run spread over 0.47-0.55 s with two and
 * took 0.50 s with one (bench_traction --one, 2026-11-26). apps/sweep's 24 runs took 6.2 s
 * instead of 13.6 s.
 * Even serial, libgomp builds and frees a team for each region (about 9 % of a traction run at
 * 4e4 elements, README "Profile"): once this was called, plume's own definition of GOMP_parallel
 * (lib/openmp_env.c), to which the program's calls bind, runs each region's body directly; before
 * it, and wherever the user's environment keeps OpenMP's teams, it hands every call to libgomp.
 *
 * The library never changes a process-wide setting by itself: the apps, tests and benchmarks call
 * this at start, and so may any program that links libplume. */
#ifndef PLUME_OPENMP_ENV_H
#define PLUME_OPENMP_ENV_H

#ifdef __cplusplus
extern "C" {
#endif

/* Every OpenMP parallel region of the process runs on one thread from now on (OpenMP's
 * max-active-levels set to 0), unless the environment sets OMP_MAX_ACTIVE_LEVELS or
 * OMP_THREAD_LIMIT: the user's choice wins (OMP_MAX_ACTIVE_LEVELS=1 keeps CHOLMOD's teams).
 * OpenBLAS, when it is the BLAS, runs on one thread, unless the environment sets
 * OPENBLAS_NUM_THREADS, GOTO_NUM_THREADS or OMP_NUM_THREADS (the variables OpenBLAS reads).
 * Process-wide; call it once at start, from one thread. */
void plume_openmp_serial(void);

#ifdef __cplusplus
}
#endif
#endif
