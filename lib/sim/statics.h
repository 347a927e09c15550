/** \file
 * plume: static equilibrium under load stepping (docs/design.md "Quasi-static"): the load factor goes
 * from 0 to 1 in `steps` equal increments; at each one  min W(x) - factor f^T x  s.t. g(x) = 0 is
 * solved to convergence, starting from the secant extrapolation through the last two equilibria
 * (or from the last equilibrium). An increment that does not converge is halved (the state
 * restored) and the increment grows back (doubling, up to the nominal one) after each converged
 * sub-step, so a hard stretch of the load path costs more sub-steps, not a failure. */
#ifndef PLUME_STATICS_H
#define PLUME_STATICS_H

#include "../core/export.h"
#include "../core/problem.h"
#include "../solve/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Where each solve of a load increment starts. */
typedef enum {
    PLUME_PREDICT_NONE = 0,  /**< the last equilibrium */
    PLUME_PREDICT_SECANT = 1, /**< the last equilibrium plus the secant through the last two, scaled to the
                                increment (first-order continuation; from the second increment on). Its
                                error is O(increment^2) where the last equilibrium's is O(increment): on
                                the shell benchmarks it takes 35-56 % fewer Newton iterations to the same
                                equilibria (docs/benchmarks.md). A solve that fails from it is retried from
                                the last equilibrium before the increment is cut */
    PLUME_PREDICT_TANGENT = 2, /**< the tangent (consistent) predictor on every increment: one linear solve
                                with the tangent at the last equilibrium for the response to the load
                                increment and the prescribed dofs' move (plume_solver_predict; one more
                                factorisation an increment; native solvers only). Retried from the last
                                equilibrium as the secant is */
    PLUME_PREDICT_SECANT_TANGENT = 3 /**< the secant where it is available, the tangent where it is not
                                (the first increment) */
} plume_predictor;

/** Options of the load-stepping driver (plume_statics_opts_default). */
typedef struct {
    int steps;            /**< nominal load steps; default 10 */
    int max_cuts;         /**< an increment is halved at most this often below the nominal one; default 10 */
    plume_predictor predictor; /**< default PLUME_PREDICT_TANGENT (docs/solver-nonconvexity.md); with
                                  Ipopt, which has no tangent solve, the tangent ones act as the secant */
    plume_solver_kind solver;      /**< the backend of every solve; default newton */
    plume_solver_opts solver_opts; /**< its options; default plume_solver_opts_default */
} plume_statics_opts;

/** Fills o with the defaults each field names. */
PLUME_API void plume_statics_opts_default(plume_statics_opts *o);

/** Sets the loads (and any load-dependent prescribed positions in plume_problem_x) for a load
 * factor in [0, 1]. */
typedef void (*plume_load_scaler)(void *user, double factor);

/** What one nominal step took. */
typedef struct {
    int step;              /**< 1-based nominal step */
    double factor;         /**< load factor reached (step / steps when converged) */
    int substeps;          /**< converged solves taken (1 when nothing was cut) */
    int cuts;              /**< times an increment was halved */
    int iterations;        /**< solver iterations, failed attempts included */
    int factorizations;    /**< numeric factorisations (native solvers), failed attempts included */
    int backtracks;        /**< newton's line-search rejections (plume_solve_report) */
    int shifts;            /**< newton's inertia shifts (plume_solve_report) */
    int predictions;       /**< tangent predictor solves (each one factorisation, counted in
                              factorizations, not in iterations) */
    int predictor_retries; /**< solves that failed from the predictor and were retried from the last
                              equilibrium */
    double max_violation;  /**< over the converged sub-steps */
    int converged;         /**< the step reached its factor */
    plume_reason reason;   /**< why the first failed attempt stopped (CONVERGED when none failed) */
    double seconds;        /**< wall time of the step's solves */
} plume_load_step_report;

/** Opaque load-stepping driver over one problem: the load factor, the solver and the saved
 * states (plume_statics_create, freed by plume_statics_destroy). */
typedef struct plume_statics plume_statics;

/** Takes a finalised problem whose x holds the unloaded state, and the scaler of its loads with
 * its data `user`; free_user (may be NULL) frees user when the driver is destroyed, or at once
 * if creation fails. The problem stays the caller's and must outlive the driver. */
PLUME_API plume_status plume_statics_create(plume_problem *p, const plume_statics_opts *o, plume_load_scaler scale,
                                            void *user, void (*free_user)(void *), plume_statics **out, plume_err *err);
/** Frees the driver and its solver and calls free_user(user); not the problem. Sets *s = NULL;
 * NULL-safe. */
PLUME_API void plume_statics_destroy(plume_statics **s);

/** Advances to the next nominal factor. Not converging at the smallest increment is reported
 * (state left at the last equilibrium), not an error; so is calling it after the last step
 * (rep->converged = 0, reason CONVERGED, nothing done). */
PLUME_API plume_status plume_statics_step(plume_statics *s, plume_load_step_report *rep);

/** The load factor of the last equilibrium (0 before the first step). */
PLUME_API double plume_statics_factor(const plume_statics *s);
/** The solver's numeric factorisations so far and the seconds spent in them (native solvers). */
PLUME_API void plume_statics_stats(const plume_statics *s, int *factorizations, double *factor_seconds);
/** The predictor's name, "none", "secant", "tangent" or "secant_tangent" (static string; "unknown"
 * out of range). */
PLUME_API const char *plume_predictor_name(plume_predictor k);
/** The predictor named "none", "secant", "tangent" or "secant_tangent" into *k; PLUME_EINVAL (no
 * message) for another name. */
PLUME_API plume_status plume_predictor_parse(const char *name, plume_predictor *k);
/** Nominal steps completed so far (each one reached its load factor). */
PLUME_API int plume_statics_steps_done(const plume_statics *s);
/** The constraint multipliers of the last equilibrium, *m of them (m may be NULL); the driver's
 * array, valid until it is destroyed. */
PLUME_API const double *plume_statics_multipliers(const plume_statics *s, plume_index *m);

#ifdef __cplusplus
}
#endif
#endif
