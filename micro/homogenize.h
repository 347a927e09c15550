/** \file
 * plume: numerical homogenisation of a periodic microstructure cell into macroscale orthotropic
 * moduli, and the cell's nonlinear response curves at finite strain. */
#ifndef PLUME_HOMOGENIZE_H
#define PLUME_HOMOGENIZE_H

#include "../lib/core/export.h"
#include "../lib/io/curves.h"
#include "../lib/solve/solver.h"
#include "cell_mesh.h"
#include "cell_plate.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Options of plume_homogenize (plume_homog_opts_default). */
typedef struct {
    double strain_max;     /**< final strain of the cell curves; default 0.05 (0: no curves) */
    int steps;             /**< points of each cell curve; default 10 */
    plume_solver_opts solver_opts; /**< options of the native solver of the cell problems; default
                                        plume_solver_opts_default */
    int convergence;       /**< 1 (default): estimate how converged the tensor is (refinement_change); 0: skip */
    /** Optional (NULL: none): called with each state of the cell curves, the rest state as step 0
     * and then every accepted step: load case (0 uniaxial x, 1 uniaxial y, 2 shear), its
     * strain, the cell (its mesh: materials and barb directions) and the positions of all its
     * vertices (2 nv; periodic images placed by the macroscopic gradient). A status other than
     * PLUME_OK stops the homogenisation with that status (apps/homogenize --vtk). */
    plume_status (*on_state)(void *user, int load_case, int step, double strain, const plume_cell *cell,
                             const double *x);
    void *on_state_user;   /**< passed to on_state as `user` */
} plume_homog_opts;

/** Fills o with the defaults each field names (on_state NULL). */
PLUME_API void plume_homog_opts_default(plume_homog_opts *o);

/** What plume_homogenize gives: the moduli, the bending tensor, the cell curves and how converged
 * they are (free the curves with plume_homog_result_free). */
typedef struct {
    plume_ortho moduli;    /**< effective 3D moduli (Pa) in the barb frame (x along the barbs) */
    double C[9];           /**< effective plane-stress tensor (Pa), Voigt (E11, E22, 2 E12), row-major */
    double coupling;       /**< max(|C13|, |C23|) / sqrt(C11 C22): 0 for an orthotropic cell */
    /** Bending, from the periodic plate cell (micro/cell_plate.h): the tensor D (N m, Voigt (k11,
     * k22, 2 k12), row-major, barb frame). */
    double D[9];
    plume_plate_moduli bending; /**< the moduli of D in macro/bending.h's convention */
    plume_index plate_dofs; /**< unknowns of the plate cell problem */
    /** How converged the bending moduli are: the largest relative change of D_long, D_trans,
     * D_twist on the coarser mesh of refinement_change (-1 when not estimated). */
    double bending_change;
    /* The cell response curves (nominal = first Piola stress over the thickness, Pa), each
     * stress-controlled so that its initial slope is the compliance modulus above (also when the
     * cell couples normal stresses and shear, coupling > 0). Arrays owned by the result. */
    /** Uniaxial stress along the barbs: F = [1+e g; 0 1+w], stress P_xx, P_yy = P_xy = 0, wbar = w
     * the lateral strain. */
    plume_curve uniaxial_x;
    /** Uniaxial stress across the barbs: F = [1+w 0; g 1+e], stress P_yy, P_xx = P_yx = 0, wbar = w. */
    plume_curve uniaxial_y;
    /** Shear: F = [1+u gamma; 0 1+v], stress P_xy, P_xx = P_yy = 0 (free normal stretches), wbar = 0. */
    plume_curve shear;
    plume_index elements;  /**< elements of the cell mesh (quadratic triangles at order 2) */
    plume_index vertices;  /**< nodes of the cell mesh */
    int order;             /**< element order used */
    double element_edge;   /**< target element edge of the cell mesh (m) */
    /** How converged the moduli are: the same tensor on the cell meshed with elements twice as large
     * (half as large when the layout allows no coarser mesh), refinement_edge; the largest relative
     * change of E_xx, E_yy, G_xy and of max_ij |C_ij - C'_ij| / sqrt(C_ii C_jj) (scale-free, so a
     * small nu_xy's coupling counts at its weight in the energy). Under monotone convergence of
     * order >= 1 the change from the coarser mesh bounds this run's error. -1 when not estimated. */
    double refinement_change;
    double moduli_change[4]; /**< the relative changes of E_xx, E_yy, nu_xy, G_xy on that mesh (-1: not estimated) */
    double refinement_edge;  /**< the element edge of the comparison mesh (m) */
    int newton_iterations; /**< every solve */
    double seconds;        /**< wall time of the homogenisation */
} plume_homog_result;

/** Frees the three curves' arrays (the rest of r holds no memory); NULL-safe. */
PLUME_API void plume_homog_result_free(plume_homog_result *r);

/** Meshes the layout's periodic cell and homogenises it: the small-strain tensor from the exact
 * linearised cell problem (micro/cell_linear.h), the bending tensor from the plate cell problem
 * (micro/cell_plate.h), the curves from the nonlinear membrane. Errors: invalid layout or options
 * (PLUME_EINVAL with the field named), a cell solve that does not converge (PLUME_EINFEASIBLE
 * with the load case and the solver's reason). */
PLUME_API plume_status plume_homogenize(const plume_layout *l, const plume_homog_opts *o, plume_homog_result *r,
                                        plume_err *err);

/** Orthotropic moduli from a plane-stress tensor via its compliance: E_xx = 1/S11, E_yy = 1/S22,
 * G_xy = 1/S33, nu_xy = -S12/S11 (the shear coupling terms, if any, are ignored). PLUME_ESINGULAR
 * when the tensor is singular or not positive definite, with a message in err (NULL allowed). */
PLUME_API plume_status plume_ortho_from_tensor(const double C[9], plume_ortho *m, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
