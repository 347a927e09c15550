/** \file
 * plume: homogenise a vane microstructure: barb layouts (from a layout file or set by hand), the periodic cell, and the macroscale membrane and bending moduli it gives. */
#ifndef PLUME_PUBLIC_HOMOGENIZE_H
#define PLUME_PUBLIC_HOMOGENIZE_H

#include "problem.h"
#include "curves.h"


#ifdef __cplusplus
extern "C" {
#endif

/* ---- barb layouts ---- */
/** Material ids used by every micro mesh. */
enum {
    PLUME_MAT_BARB = 0,   /**< the barb phase */
    PLUME_MAT_BARBULE = 1 /**< the barbule phase (soft matrix or explicit barbule strips) */
};

/** The kind of microstructure (names "strips", "barbules" in JSON). */
typedef enum {
    PLUME_LAYOUT_STRIPS = 0,  /**< barb strips of width w_B every d_B in a soft barbule matrix */
    PLUME_LAYOUT_BARBULES = 1 /**< barb strips joined by explicit barbule strips; empty between */
} plume_layout_kind;

/** Largest element edge over strip width (e-bar): a strip narrower than a quarter of an element
 * is refused ("strips narrower than an element"). */
#define PLUME_LAYOUT_MAX_E_REL 4.0

/** The law of a barbule hook, the join of a barbule's distal end to the next barb that lets go and
 * catches again (SI units; docs/unzipping.md). */
typedef struct {
    double strength; /**< N, > 0: the force at which an engaged hook slides or lets go; 0 in a layout:
                        no hooks, the barbules bonded to the next barb */
    double opening;  /**< m, > 0: its elastic opening at that force (stiffness strength / opening) */
    double slide;    /**< m, >= 0: the slide it allows before it lets go (0: none) */
    double capture;  /**< m, >= 0: a released hook that has opened beyond this mean gap catches again
                        when pressed back within it (0: never) */
} plume_hook_law;

/** The law from the literature: a hooklet lets go at 14 uN (Kovalev, Filippov & Gorb 2014); the
 * opening (2 um) and the capture (5 um) are assumed at the hooklet's scale; no slide
 * (data/layout_hooks.json cites the sources). */
PLUME_API void plume_hook_law_default(plume_hook_law *l);

/** A layout, in the barb frame: x along the barbs, y across. All lengths in m, moduli in Pa. */
typedef struct {
    plume_layout_kind kind; /**< strips in a matrix, or explicit barbules */
    double phi;            /**< barb surface fraction w_B / d_B, in (0, 1) */
    double d_B;            /**< barb spacing (period across the barbs) */
    double E_b;            /**< barb material Young's modulus */
    double nu_b;           /**< barb material Poisson ratio */
    double ratio;          /**< E_B / E_b: barbule material modulus over barb modulus, > 0 */
    double nu_B;           /**< barbule material Poisson ratio */
    double h;              /**< reference thickness: the membrane moduli in Pa are the membrane
                              stiffness A (N/m) over h (docs/bending-homogenisation.md) */
    double h_barb;         /**< thickness of the barb phase; 0 (default): h */
    double h_barbule;      /**< thickness of the barbule phase (matrix or explicit barbules); 0
                              (default): h. Either may exceed the other (layout.c says why) */
    double kappa;          /**< compression-term coefficient of both materials (Pa), >= 0 */
    /* PLUME_LAYOUT_BARBULES only: */
    double barbule_width;    /**< width of a barbule strip */
    double barbule_spacing;  /**< distance between consecutive barbules along a barb (the period
                                along x) */
    double barbule_angle;    /**< angle between barbules and barbs, degrees, in (0, 180) */
    plume_hook_law hooks;    /**< the barbules' distal ends: strength 0 (default) bonded to the next barb,
                                else held by hooks of this law (a capture below barbule_spacing); the
                                default's other fields are plume_hook_law_default's */
    /* meshing: */
    int order;             /**< element order: 2 (default) quadratic triangles, which do not lock when
                              a slender strip bends in-plane; 1 linear triangles (the paper's) */
    double e_rel;          /**< target element edge over the barb width, e-bar = e / w_B, in
                              (0, PLUME_LAYOUT_MAX_E_REL] and e_rel * w_B <= d_B; 0 (default): chosen
                              from the thinnest feature (plume_layout_element_edge) */
} plume_layout;

/** Defaults: strips, phi = 0.16 (supplementary Figure 10), d_B = 1e-3, E_b = 2.5e9, nu_b = 0.3,
 * ratio = 1e-6, nu_B = 0.3, h = 1e-4, h_barb = h_barbule = 0 (both h), kappa = 0, barbules 0.2 d_B wide every d_B at 60 deg (they
 * span < 0.82 d_B along the barbs for any phi, so they fit the cell), order 2, e_rel = 0 (automatic). */
PLUME_API void plume_layout_default(plume_layout *l);

/** Sets the barb spacing d_B (m, > 0) and scales the barbules' width and spacing with it, so the
 * microstructure keeps its shape at another size (a specimen's d_B = d l_y, a size-effect family). */
PLUME_API void plume_layout_set_spacing(plume_layout *l, double d_B);

/** w_B = phi d_B. */
PLUME_API double plume_layout_barb_width(const plume_layout *l);

/** What a mesh is for: the automatic element edge differs (docs/micro-convergence.md). */
typedef enum {
    PLUME_MESH_CELL = 0,    /**< a periodic cell (plume_cell) */
    PLUME_MESH_SPECIMEN = 1 /**< a traction or bending specimen */
} plume_mesh_use;

/** The target element edge (m): e_rel * w_B when e_rel > 0, else the automatic choice for this use and
 * element order, a fraction of the thinnest feature measured to put the default within 1 % (cell) and
 * 2 % (specimen) of its own refined limit. */
PLUME_API double plume_layout_element_edge(const plume_layout *l, plume_mesh_use use);

/** Validates every field (PLUME_EINVAL naming the field and its value: "phi must be in (0, 1)
 * (got 1.2)", "ratio must be > 0", "strips narrower than an element ...", "cell too small for its
 * layout ..."). */
PLUME_API plume_status plume_layout_check(const plume_layout *l, plume_err *err);

/** The thickness of phase PLUME_MAT_BARB or PLUME_MAT_BARBULE (m): h_barb or h_barbule, or h where
 * that is 0. */
PLUME_API double plume_layout_thickness(const plume_layout *l, int phase);

/** The two membrane materials: mats[PLUME_MAT_BARB], mats[PLUME_MAT_BARBULE] (isotropic), each with
 * its phase's thickness (plume_layout_thickness). */
PLUME_API void plume_layout_materials(const plume_layout *l, plume_membrane_material mats[2]);


/* ---- layout files ---- */
/** Reads keys into *l (which holds the defaults or earlier values; absent keys are kept):
 *   {"layout": "strips" | "barbules", "phi": 0.16, "d_B": 1e-3, "w_B": 1.6e-4, "E_b": 2.5e9,
 *    "nu_b": 0.3, "ratio": 1e-6, "nu_B": 0.3, "thickness": 1e-4, "thickness_barb": 1e-4,
 *    "thickness_barbule": 1e-5, "kappa": 0, "order": 2, "e_rel": 0, "barbule_width": 1e-4, "barbule_spacing": 8e-4, "barbule_angle": 60}
 * ("w_B" sets d_B = w_B / phi after every other key; "note", of any value, is a comment). Each key's
 * units, meaning and default: docs/layout-format.md. Errors name the file and the line for
 * malformed JSON (PLUME_EFORMAT), an unknown key (listing the keys) or a non-numeric value (PLUME_EFORMAT), an
 * unreadable file (PLUME_EIO). Values are not range-checked here (call plume_layout_check), except
 * the phase thicknesses: "thickness_barb" and "thickness_barbule" must be finite and > 0
 * (PLUME_EFORMAT naming the key; left out, a phase has the "thickness"). */
PLUME_API plume_status plume_layout_load_json(const char *path, plume_layout *l, plume_err *err);

/** The same keys from a JSON text (a binding's request); `where` names it in messages
 * ("request.layout"). */
PLUME_API plume_status plume_layout_apply_json(const char *text, const char *where, plume_layout *l, plume_err *err);


/* ---- bending moduli of a plate cell ---- */
/** The bending moduli of a plate (N m) in the barb frame (1 along the barbs), with the energy
 * density of plume_bending_material (problem.h) plus the bending-twist couplings
 *
 *     1/2 (D_long k11^2 + D_trans k22^2 + 2 D_coupling k11 k22 + 4 D_twist k12^2
 *          + 4 D_16 k11 k12 + 4 D_26 k22 k12),
 *
 * i.e., 1/2 kappa^T D kappa with kappa = (k11, k22, 2 k12) and
 * D = [D_long D_coupling D_16; D_coupling D_trans D_26; D_16 D_26 D_twist]. */
typedef struct {
    double D_long;     /**< D_11: curvature along the barbs */
    double D_trans;    /**< D_22: curvature across the barbs */
    double D_coupling; /**< D_12: coupling of k11 and k22 */
    double D_twist;    /**< D_66: twist */
    double D_16;       /**< coupling of k11 and the twist (0 for an orthotropic cell) */
    double D_26;       /**< coupling of k22 and the twist (0 for an orthotropic cell) */
} plume_plate_moduli;


/** A periodic cell of a layout (opaque). */
typedef struct plume_cell plume_cell;

/** The mesh of a periodic cell (borrowed: it lives as long as the cell), e.g. for a ParaView series
 * of the states plume_homog_opts.on_state passes (plume_fields_create, scene.h). */
PLUME_API const plume_mesh *plume_cell_mesh_of(const plume_cell *cell);

/* ---- homogenisation ---- */
/** Options of plume_homogenize (plume_homog_opts_default). */
typedef struct {
    size_t size;           /**< sizeof the caller's struct, set by plume_homog_opts_default */
    double strain_max;     /**< final strain of the cell curves; default 0.05 (0: no curves) */
    int steps;             /**< points of each cell curve; default 10 */
    /** options of the native solver of the cell problems; NULL (default): plume_solver_opts_default's */
    const plume_solver_opts *solver_opts;
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

/** Fills o (size bytes) with the defaults each field names (on_state NULL) and sets o->size; call it
 * through the macro plume_homog_opts_default(o). */
PLUME_API void plume_homog_opts_default_sized(plume_homog_opts *o, size_t size);
/** Fills *o with the defaults (plume_homog_opts_default_sized with sizeof the struct the caller compiled against). */
#define plume_homog_opts_default(o) plume_homog_opts_default_sized((o), sizeof(plume_homog_opts))

/** What plume_homogenize gives: the moduli, the bending tensor, the cell curves and how converged
 * they are (free the curves with plume_homog_result_free). */
typedef struct {
    plume_ortho moduli;    /**< effective 3D moduli (Pa) in the barb frame (x along the barbs) */
    double C[9];           /**< effective plane-stress tensor (Pa), Voigt (E11, E22, 2 E12), row-major */
    double coupling;       /**< max(|C13|, |C23|) / sqrt(C11 C22): 0 for an orthotropic cell */
    /** Bending, from the periodic plate cell (docs/bending-homogenisation.md): the tensor D (N m, Voigt (k11,
     * k22, 2 k12), row-major, barb frame). */
    double D[9];
    plume_plate_moduli bending; /**< the moduli of D in plume_bending_material's convention */
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

/** Writes a homogenisation's results to the HDF5 file `path` (created, or updated in place; written
 * atomically, docs/hdf5-layout.md): /moduli with E_xx, E_yy, nu_xy, G_xy, the bending moduli
 * D_long, D_trans, D_coupling, D_twist, D_16, D_26, the thickness they are over, how converged they
 * are and the layout as provenance, and the cell curves (those r has) under /curves/cell. This is
 * the file a scene material reads with "from_moduli" for its membrane and its bending, and the one
 * apps/homogenize -o writes. Errors name the file. */
PLUME_API plume_status plume_homog_write(const char *path, const plume_layout *l, const plume_homog_result *r,
                                         plume_err *err);

/* ---- the separation law of a barb line ---- */
/** How a barb line of the vane opens when its barbules' hooks let go, per barb length: the
 * macroscale law homogenised from the layout's periodic cell (docs/unzipping.md). */
typedef struct {
    double strength;     /**< N/m: the largest traction across the barb line (force per barb length; its
                            magnitude, normal and shear: one hook's strength per period) */
    double energy;       /**< J/m^2: the work to open it until its hooks let go, per crack area (barb
                            length times the layout's thickness h), elastic energy given back excluded */
    double opening;      /**< m: the opening across the barbs at which the traction is gone */
    double capture;      /**< m: the opening back within which the line catches again (0: never) */
    double stiffness;    /**< N/m^2: the traction over the hooks' own gap at the strength (the cell's
                            elastic stretch excluded): a barb line's stiffness per length while it
                            holds, the hooks' alone (the hooked cell's tensor has more compliance,
                            plume_separation_tensor) */
    double peak_opening; /**< m: the opening at the strength, the cell's elastic stretch included */
    double cell_length;  /**< m: the cell's period along the barbs (one barbule, one hook) */
    int cell_hooks;      /**< hooks in the cell */
    int solves;          /**< cell solves */
    int newton_iterations; /**< over every solve */
} plume_separation_law;

/** The separation law of a layout with hooks (kind barbules, hooks.strength > 0): its periodic
 * cell with the barbules' distal ends held by hooks instead of periodic images, opened across the
 * barbs at no stretch along them, the hooks committed at every equilibrium until they let go, then
 * closed until they catch again. Errors: an invalid layout (PLUME_EINVAL naming the field), a
 * layout without hooks (PLUME_EINVAL), a cell solve that does not converge (PLUME_EINFEASIBLE). */
PLUME_API plume_status plume_separation_law_of(const plume_layout *l, plume_separation_law *out, plume_err *err);

/** The small-strain plane-stress tensor C (Pa, row-major, Voigt E11, E22, 2E12 in the barb frame,
 * as plume_homog_result.C) of the layout's cell with its hooks engaged: the hooked vane before any
 * hook lets go. A hook holds a barbule's end by its position only, so the cell is much softer
 * across the barbs and in shear than the bonded cell, and more than the hooks' own opening adds
 * (docs/monoclinic-vane.md). The macro vane that unzips takes it with stiff split lines
 * (plume_vane_add_tensor). Errors as plume_separation_law_of. */
PLUME_API plume_status plume_separation_tensor(const plume_layout *l, double C[9], plume_err *err);

/** plume_homog_write with the separation law as well, as the /moduli attributes
 * separation_strength (N/m), separation_energy (J/m^2), separation_opening (m),
 * separation_capture (m), separation_stiffness (N/m^2) and separation_peak_opening (m) (s NULL:
 * plume_homog_write). */
PLUME_API plume_status plume_homog_write_separation(const char *path, const plume_layout *l, const plume_homog_result *r,
                                                    const plume_separation_law *s, plume_err *err);

/** Reads the separation attributes of /moduli (plume_homog_write_separation) into s (the cell's
 * length, hooks and counts zeroed): strength, energy, opening, capture and stiffness, and the
 * peak opening, which files written before libplume 3.5 lack (then the opening: a brittle law).
 * PLUME_EIO (unreadable file), PLUME_EFORMAT (an attribute missing, naming the file and the
 * attribute: the moduli were homogenised without hooks), PLUME_EINVAL (a value out of range:
 * strength, energy, opening, stiffness not > 0, capture < 0, the peak opening not in (0, opening]). */
PLUME_API plume_status plume_separation_read(const char *path, plume_separation_law *s, plume_err *err);

/** The bending part of plume_homogenize alone: the periodic plate cell of the layout (Morley
 * triangles on its cell mesh; docs/bending-homogenisation.md) gives D (N m, Voigt (k11, k22,
 * 2 k12), row-major, barb frame) and, when moduli is not NULL, its moduli. Much cheaper than
 * plume_homogenize (no membrane cell problems, no curves, no convergence estimate). Errors: an
 * invalid layout (PLUME_EINVAL naming the field), a singular cell (PLUME_ESINGULAR). */
PLUME_API plume_status plume_homogenize_bending(const plume_layout *l, double D[9], plume_plate_moduli *moduli,
                                                plume_err *err);

/** Meshes the layout's periodic cell and homogenises it: the small-strain tensor from the exact
 * linearised cell problem, the bending tensor from the plate cell problem
 * (docs/bending-homogenisation.md), the curves from the nonlinear membrane. Errors: invalid layout or options
 * (PLUME_EINVAL with the field named), a cell solve that does not converge (PLUME_EINFEASIBLE
 * with the load case and the solver's reason). */
PLUME_API plume_status plume_homogenize(const plume_layout *l, const plume_homog_opts *o, plume_homog_result *r,
                                        plume_err *err);


#ifdef __cplusplus
}
#endif
#endif
