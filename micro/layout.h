/** \file
 * plume: microstructure layouts of a vane — barbs as strips of stiff barb material, held by a soft
 * barbule material (the paper's microscale model) or by explicit barbule strips with empty space
 * between them (the microstructure resolved one level further). */
#ifndef PLUME_LAYOUT_H
#define PLUME_LAYOUT_H

#include "../lib/core/export.h"
#include "../lib/core/membrane.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The kind of microstructure (names "strips", "barbules" in JSON). */
typedef enum {
    PLUME_LAYOUT_STRIPS = 0,  /**< barb strips of width w_B every d_B in a soft barbule matrix */
    PLUME_LAYOUT_BARBULES = 1 /**< barb strips joined by explicit barbule strips; empty between */
} plume_layout_kind;

/** Largest element edge over strip width (e-bar): a strip narrower than a quarter of an element
 * is refused ("strips narrower than an element"). */
#define PLUME_LAYOUT_MAX_E_REL 4.0

/** Material ids used by every micro mesh. */
enum {
    PLUME_MAT_BARB = 0,   /**< the barb phase */
    PLUME_MAT_BARBULE = 1 /**< the barbule phase (soft matrix or explicit barbule strips) */
};

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

/** The thinnest strip of the layout (m): the barb strip, the gap between barbs, or a barbule. */
PLUME_API double plume_layout_thinnest(const plume_layout *l);

/** What a mesh is for: the automatic element edge differs (docs/micro-convergence.md). */
typedef enum {
    PLUME_MESH_CELL = 0,    /**< a periodic cell (micro/cell_mesh.h) */
    PLUME_MESH_SPECIMEN = 1 /**< a traction or bending specimen */
} plume_mesh_use;

/** The target element edge (m): e_rel * w_B when e_rel > 0, else the automatic choice for this use and
 * element order, a fraction of the thinnest feature measured to put the default within 1 % (cell) and
 * 2 % (specimen) of its own refined limit. */
PLUME_API double plume_layout_element_edge(const plume_layout *l, plume_mesh_use use);

/** The layout meshed for the refinement comparison of `use`: element edge twice this layout's, or half
 * of it when the layout check refuses twice. */
PLUME_API void plume_layout_refinement(const plume_layout *l, plume_mesh_use use, plume_layout *out);

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

#ifdef __cplusplus
}
#endif
#endif
