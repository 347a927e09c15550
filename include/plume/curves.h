/** \file
 * plume: curves and moduli in HDF5 files (docs/hdf5-layout.md), measured curves from text, and charts of them. */
#ifndef PLUME_PUBLIC_CURVES_H
#define PLUME_PUBLIC_CURVES_H

#include "problem.h"


#ifdef __cplusplus
extern "C" {
#endif

/* ---- curves and moduli in HDF5 ---- */
/** A named scalar parameter stored as an HDF5 attribute. */
typedef struct {
    const char *name; /**< attribute name (borrowed) */
    double value;     /**< its value */
} plume_param;

/** A named string parameter stored as an HDF5 attribute. */
typedef struct {
    const char *name;  /**< attribute name (borrowed) */
    const char *value; /**< its value (borrowed, NUL-terminated) */
} plume_sparam;

/** One curve of a quasi-static run: n points. Arrays owned by whoever fills the struct; a curve
 * read by plume_curve_read owns them (free with plume_curve_free). */
typedef struct {
    plume_index n;       /**< points (the length of every array) */
    double *strain;      /**< nominal strain */
    double *stress;      /**< nominal stress, Pa */
    double *wbar;        /**< average relative width change (supplementary equation 7) */
    double *iterations;  /**< solver iterations of each step */
    double *seconds;     /**< wall time of each step */
} plume_curve;

/** Writes `curve` as `/curves/<scale>/<scenario>/{strain,stress,wbar,iterations,seconds}` with the
 * parameters as attributes of the group. If `path` exists its other content is kept (a group of
 * the same name is replaced). Written to a temporary file and renamed over `path`. PLUME_EINVAL
 * for a scale or scenario that is empty or contains '/', or a curve missing an array;
 * PLUME_EIO / PLUME_EFORMAT naming the file. */
PLUME_API plume_status plume_curve_write(const char *path, const char *scale, const char *scenario,
                                         const plume_curve *curve, const plume_param *params, int nparams,
                                         const plume_sparam *sparams, int nsparams, plume_err *err);

/** Writes a table of states beside a curve written by plume_curve_write: the 2-D dataset
 * `/curves/<scale>/<scenario>/<name>` (rows x cols, 8-bit integers, row-major; replaced if there)
 * with its "units" "1". apps/traction writes the hooks' states this way ("hooks": one row per point
 * of the curve, one column per vertex pair, 1 engaged, 0 let go; docs/hdf5-layout.md). Written to
 * a temporary file and renamed over `path`. PLUME_EINVAL for an empty name or one with '/', or no
 * values; PLUME_EFORMAT when the curve's group is not there. */
PLUME_API plume_status plume_curve_write_states(const char *path, const char *scale, const char *scenario,
                                                const char *name, long rows, long cols, const int *states,
                                                plume_err *err);

/** Reads the curve `/curves/<scale>/<scenario>` into `curve`, whose arrays it allocates (free with
 * plume_curve_free; on failure nothing is left allocated). PLUME_EIO (unreadable file),
 * PLUME_EFORMAT (no such group, a dataset missing, not 1-D numeric, or of another length), each
 * message naming the file and the dataset. */
PLUME_API plume_status plume_curve_read(const char *path, const char *scale, const char *scenario,
                                        plume_curve *curve, plume_err *err);

/** Frees the arrays of a curve (as plume_curve_read allocates them) and zeroes it; NULL-safe. */
PLUME_API void plume_curve_free(plume_curve *curve);

/** One curve of a plate bending test (plume_bend_run, traction.h): n points, ownership as plume_curve's
 * (plume_bend_curve_read's arrays: free with plume_bend_curve_free). */
typedef struct {
    plume_index n;      /**< points (the length of every array) */
    double *curvature;  /**< the curvature the load works on (1/m): k_yy when bent about x, the twist
                           2 k_xy when twisted */
    double *moment;     /**< the applied moment per unit width (N m / m = N): m_yy, or m_xy twisted */
    double *k_xx;       /**< the fitted curvature field's k_xx (1/m) */
    double *k_yy;       /**< the fitted curvature field's k_yy (1/m) */
    double *twist;      /**< the fitted curvature field's twist 2 k_xy (1/m) */
    double *energy;     /**< elastic energy stored (J) */
    double *iterations; /**< solver iterations of the step */
    double *seconds;    /**< wall time of the step */
} plume_bend_curve;

/** Writes `curve` as
 * `/curves/bending/<scale>/<scenario>/{curvature,moment,k_xx,k_yy,twist,energy,iterations,seconds}`
 * with the parameters as attributes, atomically and with the errors of plume_curve_write. */
PLUME_API plume_status plume_bend_curve_write(const char *path, const char *scale, const char *scenario,
                                              const plume_bend_curve *curve, const plume_param *params, int nparams,
                                              const plume_sparam *sparams, int nsparams, plume_err *err);

/** Reads the bending curve `/curves/bending/<scale>/<scenario>` into `curve`, allocating its arrays
 * (free with plume_bend_curve_free), with the errors of plume_curve_read. */
PLUME_API plume_status plume_bend_curve_read(const char *path, const char *scale, const char *scenario,
                                             plume_bend_curve *curve, plume_err *err);

/** Frees the arrays of a bending curve and zeroes it; NULL-safe. */
PLUME_API void plume_bend_curve_free(plume_bend_curve *curve);

/** The names of the bending curves of one scale in a curves file (the groups under
 * `/curves/bending/<scale>`, in HDF5's name order): *names an array of *n malloc'ed strings, freed by
 * plume_bend_curve_names_free. PLUME_EIO (unreadable file), PLUME_EFORMAT (not HDF5, or no such
 * curve: the message names the file and `/curves/bending/<scale>`), PLUME_ENOMEM. */
PLUME_API plume_status plume_bend_curve_names(const char *path, const char *scale, char ***names, int *n,
                                              plume_err *err);

/** Frees the n strings of plume_bend_curve_names and the array; NULL-safe. */
PLUME_API void plume_bend_curve_names_free(char **names, int n);

/** One numeric parameter (attribute) of the bending curve `/curves/bending/<scale>/<scenario>`, as
 * apps/traction --bending writes them (lx, ly, angle_deg, D_long, ...), into *value, unchecked.
 * PLUME_EIO, PLUME_EFORMAT (no such curve, attribute missing or not one number; the message names
 * the file, the group and the attribute). */
PLUME_API plume_status plume_bend_curve_param(const char *path, const char *scale, const char *scenario,
                                              const char *name, double *value, plume_err *err);

/** /moduli with attributes E_xx, E_yy, nu_xy, G_xy and a string attribute "provenance". */
PLUME_API plume_status plume_moduli_write(const char *path, const plume_ortho *m, const char *provenance,
                                          plume_err *err);

/** The same with extra numeric attributes of /moduli (how converged the moduli are, the mesh);
 * their names may not be the moduli's, "units" or "provenance" (PLUME_EINVAL). */
PLUME_API plume_status plume_moduli_write_params(const char *path, const plume_ortho *m, const char *provenance,
                                                 const plume_param *params, int nparams, plume_err *err);

/** Reads /moduli; validates that the moduli are finite and positive (nu finite). */
PLUME_API plume_status plume_moduli_read(const char *path, plume_ortho *m, plume_err *err);

/** Reads one extra numeric attribute of /moduli (e.g., "D_long", written by apps/homogenize) into
 * *value, unchecked. PLUME_EIO (unreadable file), PLUME_EFORMAT (no /moduli, attribute missing or
 * not a single number), each message naming the file and the attribute. */
PLUME_API plume_status plume_moduli_read_param(const char *path, const char *name, double *value, plume_err *err);


/* ---- charts ---- */
/** Draws stress-strain (left) and wbar-strain (right) of `ncurves` curves with their labels into
 * png_path and the same chart as SVG beside it (extension replaced by .svg). Runs gnuplot;
 * PLUME_EDEP with a message if gnuplot is missing or fails. Strain is shown in %, stress in Pa. */
PLUME_API plume_status plume_plot_curves(const char *png_path, const char *title, const plume_curve *curves,
                                         const char *const *labels, int ncurves, plume_err *err);

/** Axis labels replacing the defaults (NULL fields keep them). */
typedef struct {
    const char *stress_label; /**< left panel, default "nominal stress (Pa)" */
    const char *wbar_label;   /**< right panel, default "w-bar (average relative width change)" */
    const char *x_label;      /**< both panels, default "nominal strain (%)" */
    double x_scale;           /**< x drawn = x_scale * curve.strain; 0 selects 100 (percent) */
    int small_key;            /**< 1: a smaller legend font, for charts with many series */
    const int *color;         /**< per curve: gnuplot colour index 1..8 (NULL: curve k gets k + 1, which
                                 repeats after 8), so that families share a colour */
    const int *point;         /**< per curve: gnuplot point type (NULL: 7, a filled circle) */
    int key_below;            /**< 1: the legend under each panel in columns, clear of the data */
} plume_plot_axes;

/** plume_plot_curves with other axis labels (axes may be NULL). */
PLUME_API plume_status plume_plot_curves_axes(const char *png_path, const char *title, const plume_plot_axes *axes,
                                              const plume_curve *curves, const char *const *labels, int ncurves,
                                              plume_err *err);


/* ---- measured curves from text ---- */
/** Reads a measured curve from a text file: two columns, nominal strain and nominal stress (Pa),
 * separated by spaces, tabs or a comma; '#' starts a comment; a header line of words is skipped.
 * Errors name the file and line. wbar/iterations/seconds are zero-filled. */
PLUME_API plume_status plume_curve_read_text(const char *path, plume_curve *out, plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
