/** \file
 * plume: fit macroscale moduli to traction curves (NLopt), through the macro model or a model of your own. */
#ifndef PLUME_PUBLIC_FIT_H
#define PLUME_PUBLIC_FIT_H

#include "traction.h"


#ifdef __cplusplus
extern "C" {
#endif

/** Which moduli are free; the others keep the start value. */
enum {
    PLUME_FIT_EXX = 1, /**< E_xx free */
    PLUME_FIT_EYY = 2, /**< E_yy free */
    PLUME_FIT_NU = 4,  /**< nu_xy free */
    PLUME_FIT_GXY = 8, /**< G_xy free */
    PLUME_FIT_D_LONG = 1,     /**< plume_fit_bending_moduli: D_long free */
    PLUME_FIT_D_TRANS = 2,    /**< D_trans free */
    PLUME_FIT_D_COUPLING = 4, /**< D_coupling free */
    PLUME_FIT_D_TWIST = 8     /**< D_twist free */
};

/* ---- fitting ---- */
/** Computes the model's curve for target curve `icurve` with moduli `m`: fills `out` (arrays
 * malloc'ed by the callback, freed by the fitter with plume_curve_free). Returns PLUME_OK, or an
 * error status; a model run that does not converge should return PLUME_EINFEASIBLE (the fitter
 * then treats that point as very bad rather than stopping). */
typedef plume_status (*plume_fit_model)(void *ctx, const plume_ortho *m, int icurve, plume_curve *out,
                                        plume_err *err);

/** Options of the fit (plume_fit_opts_default). */
typedef struct {
    size_t size;         /**< sizeof the caller's struct, set by plume_fit_opts_default */
    unsigned free_mask;  /**< default PLUME_FIT_EYY | PLUME_FIT_GXY (the barbs are inextensible) */
    int max_eval;        /**< default 300 */
    double xtol_rel;     /**< relative tolerance on the moduli; default 1e-6 */
    double min_strain;   /**< target points with |strain| below this are skipped; default 1e-12 */
} plume_fit_opts;

/** Fills o (size bytes) with the defaults each field names and sets o->size; NULL-safe; call it
 * through the macro plume_fit_opts_default(o). */
PLUME_API void plume_fit_opts_default_sized(plume_fit_opts *o, size_t size);
/** Fills *o with the defaults (plume_fit_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_fit_opts_default(o) plume_fit_opts_default_sized((o), sizeof(plume_fit_opts))

/** How a fit went (optional output of plume_fit_moduli). */
typedef struct {
    int evaluations;     /**< model evaluations (each runs every curve) */
    double residual;     /**< final RMS relative stress misfit over all points */
    double seconds;      /**< wall time of the fit */
    int nlopt_result;    /**< NLopt's return code (positive: success) */
    char stop[64];       /**< "xtol reached", "maxeval reached", ... */
} plume_fit_report;

/** Minimises the RMS over every point of every target curve of
 * (model stress - target stress) / max(|target stress|, 1e-3 max |target stress of that curve|),
 * the model stress linearly interpolated at the target strains, over the free moduli (searched in
 * log space, so they stay positive; nu_xy linearly), derivative-free (NLopt LN_BOBYQA). `start`
 * gives the initial moduli and the fixed ones. Errors: no curves, empty curve, non-finite data,
 * a model error other than PLUME_EINFEASIBLE. */
PLUME_API plume_status plume_fit_moduli(plume_fit_model model, void *ctx, const plume_curve *targets, int ncurves,
                                        const plume_ortho *start, const plume_fit_opts *o, plume_ortho *result,
                                        plume_fit_report *rep, plume_err *err);


/* ---- fitting bending moduli ---- */
/** A model of bending curves: computes curve `icurve` with the plate's bending moduli `b` (N m),
 * as plume_fit_model does with membrane moduli (the curves' strain a curvature, 1/m, their stress
 * a moment per width, N m / m). */
typedef plume_status (*plume_fit_bending_model)(void *ctx, const plume_bending_material *b, int icurve,
                                                plume_curve *out, plume_err *err);

/** plume_fit_moduli for a plate's bending moduli: the same misfit and search, over the free ones
 * of D_long, D_trans, D_twist (log space) and D_coupling (through D_coupling / sqrt(D_long
 * D_trans), linearly in (-1, 1), so that every plate tried is positive definite); o->free_mask
 * names them with PLUME_FIT_D_LONG, _D_TRANS, _D_COUPLING and _D_TWIST. PLUME_EINVAL for a start
 * plate that is not positive definite. */
PLUME_API plume_status plume_fit_bending_moduli(plume_fit_bending_model model, void *ctx, const plume_curve *targets,
                                                int ncurves, const plume_bending_material *start,
                                                const plume_fit_opts *o, plume_bending_material *result,
                                                plume_fit_report *rep, plume_err *err);

/* ---- the macro traction test as a model ---- */
/** The macro traction test as a model (the ctx of plume_macro_model_curve); borrowed arrays. */
typedef struct {
    double lx;              /**< sample width (m) */
    double ly;              /**< sample length between the grips (m) */
    double h;               /**< thickness (m) */
    double edge;            /**< mesh edge (m) */
    plume_patch_kind mesh;  /**< aligned or unaligned patch mesh (plume_patch_mesh) */
    int constraint;         /**< barbs inextensible */
    double kappa;           /**< compression coefficient of the membrane (Pa); 0 disables it */
    double strain_max;      /**< final nominal strain of each curve */
    int steps;              /**< quasi-static steps of each curve */
    int ncurves;            /**< curves the model computes (entries of angles) */
    const double *angles;   /**< [ncurves] barb angle of curve i (deg) */
    plume_solver_kind solver; /**< the traction test's solver backend */
} plume_macro_model;

/** plume_fit_model for the macroscale vane: runs the traction test at angles[icurve] with moduli
 * m and returns its curve (arrays malloc'ed, owned by out). A run that does not converge gives
 * PLUME_EINFEASIBLE; barbs spanning both grips too. */
PLUME_API plume_status plume_macro_model_curve(void *ctx, const plume_ortho *m, int icurve, plume_curve *out,
                                               plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
