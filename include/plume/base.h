/** \file
 * plume: the base every other header builds on: the export macro, the version, status codes and error messages, the solver report, the process-wide threading settings. */
#ifndef PLUME_PUBLIC_BASE_H
#define PLUME_PUBLIC_BASE_H

#include <stddef.h>

/** Marks a function of the public face: default visibility (exported from libplume.so) with
 * GCC and clang, nothing elsewhere. The library is compiled with -fvisibility=hidden, so nothing
 * else is exported. */
#if defined(__GNUC__) || defined(__clang__)
#define PLUME_API __attribute__((visibility("default")))
#else
#define PLUME_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the version ---- */
#define PLUME_VERSION_MAJOR 3       /**< major version of the headers compiled against */

#define PLUME_VERSION_MINOR 5       /**< minor version of the headers compiled against */

#define PLUME_VERSION_PATCH 0       /**< patch version of the headers compiled against */

#define PLUME_VERSION_STRING "3.5.0" /**< "MAJOR.MINOR.PATCH" of the headers compiled against */

/** "MAJOR.MINOR.PATCH" of the library linked in (static string). */
PLUME_API const char *plume_version(void);


/* ---- status codes and error messages ---- */
/** Index type for vertices, dofs and sparse entries; matches CHOLMOD's _l_ (SuiteSparse_long). */
typedef long plume_index;

/** Every library call returns one of these; 0 is success, negative values are errors.
 * Convergence outcomes are not errors: they are a reason in the solver report. */
typedef enum {
    PLUME_OK = 0,          /**< success */
    PLUME_EINVAL = -1,     /**< invalid input (a parameter out of range, inconsistent sizes) */
    PLUME_ENOMEM = -2,     /**< allocation failed */
    PLUME_EIO = -3,        /**< file could not be read or written */
    PLUME_EFORMAT = -4,    /**< a file was read but its content is malformed */
    PLUME_EDEP = -5,       /**< a dependency (CHOLMOD, Ipopt, CGAL, HDF5, gnuplot) failed */
    PLUME_ESINGULAR = -6,  /**< a matrix could not be factorised */
    PLUME_EINFEASIBLE = -7 /**< the problem as posed has no solution (e.g., barbs spanning both grips) */
} plume_status;

/** Short static name of a status ("invalid input", ...). Never NULL. */
PLUME_API const char *plume_strerror(plume_status s);

/** A human message that travels with an error: functions that can fail on user input take an
 * optional `plume_err *` (NULL allowed) and fill `msg` with what went wrong, naming the file,
 * line, key or parameter. */
typedef struct {
    char msg[768]; /**< the message, NUL-terminated, truncated to fit; left as it was when no error
                        was set, so zero-initialise the struct */
} plume_err;

/** Frees memory the library allocated for the caller (plume_scene_describe's text, ...); NULL-safe. */
PLUME_API void plume_free(void *p);

/** printf-style; safe with err == NULL. Returns `s` so callers can `return plume_err_set(...)`. */
PLUME_API plume_status plume_err_set(plume_err *err, plume_status s, const char *fmt, ...)
#if defined(__GNUC__)
              __attribute__((format(printf, 3, 4)))
#endif
              ;


/* ---- threads ---- */
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


/* ---- what a solve reports ---- */
/** Why a solve stopped. Only CONVERGED means the tolerances below were met. */
typedef enum {
    PLUME_REASON_CONVERGED = 0,   /**< the KKT residual and the violation met their tolerances; or (newton)
                                     the violation met its tolerance and the KKT residual stopped at its
                                     round-off floor within sqrt(tol_kkt) (the report's kkt_residual
                                     tells which) */
    PLUME_REASON_ITERATION_CAP,   /**< max_iter reached */
    PLUME_REASON_LINE_SEARCH,     /**< no step decreased the merit function */
    PLUME_REASON_INFEASIBLE,      /**< constraints could not be satisfied */
    PLUME_REASON_NUMERICAL,       /**< non-finite values or a factorisation that kept failing */
    PLUME_REASON_SINGLE_STEP,     /**< `linearized`: one step taken, convergence not sought */
    PLUME_REASON_CONTACT_SET      /**< newton with continuous collision detection: the steps were cut
                                     to almost nothing for several iterations in a row, as when a
                                     pair outside the contact set blocks them (its barrier is not in
                                     the problem yet): the caller updates the terms' stencils and
                                     solves again from the point returned */,
    PLUME_REASON_STALLED          /**< newton with stall_iterations: that many iterations in a row
                                     cut neither the KKT residual nor the constraint violation to
                                     half of its best in this solve (a caller with a smaller step
                                     to try gives up early, instead of at the cap) */,
    PLUME_REASON_PRESCRIBED_CROSSING /**< dynamics with continuous collision detection: the step's
                                     prescribed motion alone (handles, attached and kinematic
                                     vertices moving, the rest standing still) runs into another
                                     body, so no solve can start (plume_contact_last_limit names
                                     the pair); smaller steps help only while the other body can
                                     get out of the way */
} plume_reason;

/** A short static name of r ("converged", "iteration cap", ...); "unknown" out of range. */
PLUME_API const char *plume_reason_name(plume_reason r);

/** What one solve did and where it stopped (plume_solver_solve fills every field). */
typedef struct {
    plume_reason reason;  /**< why the solve stopped */
    int converged;        /**< reason == CONVERGED */
    int iterations;       /**< Newton / SQP / Ipopt iterations */
    int factorizations;   /**< numeric factorisations (native solvers) */
    double energy;        /**< f at the returned point */
    double kkt_residual;  /**< plume_problem_kkt_residual at the returned point */
    double max_violation; /**< max relative constraint violation at the returned point */
    double seconds;       /**< wall time of the solve */
    int backtracks;       /**< newton: trial steps the line search rejected */
    int shifts;           /**< newton: factorisations rejected for inertia (each followed by a larger
                             diagonal shift, or by the projected Hessian) */
    int partial_projections; /**< newton: factorisations whose Hessian had the terms with a cheap
                              projection projected (the exact one was not positive definite) */
    int rejected_steps;   /**< newton, trust region: trial steps refused (each followed by a larger
                             regularisation and a new factorisation) */
    int curved_searches;  /**< newton: line searches along the geodesic-acceleration curve */
    int merit_fallbacks;  /**< newton, filter line search: iterations that fell back to the l1 merit
                             (no step down to 2^-29 was acceptable to the filter) */
    int chord_steps;      /**< newton: steps taken with an earlier factorisation (no new one) */
    int chord_rejected;   /**< newton: chord steps the line search refused whole (refactorised) */
    int refinements;      /**< newton, kkt_refine: iterative refinement passes over all solves */
    int step_limited;     /**< iterations whose step a term cut short (plume_term.max_step: continuous
                             collision detection), newton; ipopt: trial points refused for it */
} plume_solve_report;



/* ---- folders ---- */
/** mkdir -p: creates path and its missing parents (0777 before umask). 0 when path is a directory
 * on return; -1 with errno set otherwise (ENAMETOOLONG, ENOTDIR when path names something else). */
PLUME_API int plume_make_dirs(const char *path);


/* ---- the wall clock ---- */
/** Monotonic wall clock in seconds. */
PLUME_API double plume_wall_seconds(void);


#ifdef __cplusplus
}
#endif
#endif
