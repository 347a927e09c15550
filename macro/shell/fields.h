/** \file
 * plume: the fields a user colours a deformed shell by, per triangle and per barb edge, and the
 * ParaView series that carries them (lib/io/vtu.h): one .vtu of triangles per frame, one of barb
 * edges when there are constrained barbs, and a .pvd with the frames' times. */
#ifndef PLUME_FIELDS_H
#define PLUME_FIELDS_H

#include "../../include/plume/scene.h"

#include "../../lib/core/export.h"
#include "../../lib/core/mesh.h"
#include "../../lib/core/membrane.h"
#include "../../lib/core/term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Per-triangle values of one state (triangles past the elastic ones, e.g., kinematic bodies, get
 * NaN). Arrays owned by the plume_fields object that computed them; valid until the next
 * compute or destroy. */
typedef struct {
    plume_index nt;                 /**< triangles (the mesh's) */
    plume_index nbarb;              /**< constrained barb edges */
    const double *green_strain;     /**< [3 nt] Green strain (bb, tt, bt) in the barb frame */
    const double *stress;           /**< [3 nt] second Piola–Kirchhoff stress (bb, tt, bt), Pa */
    const double *membrane_energy;  /**< [nt] membrane energy per reference area, J/m^2 */
    const double *bending_energy;   /**< [nt] bending energy per reference area, J/m^2 (0 without bending) */
    const double *J;                /**< [nt] deformed over reference area */
    const double *mean_curvature;   /**< [nt] 1/m, from the dihedral angles theta of the interior
                                       edges: theta |e| / 4 to each end vertex, over a third of its
                                       triangles' area, averaged over the triangle's vertices;
                                       positive where the surface bends away from its normals,
                                       e.g., +1/(2R) on a cylinder with outward normals; creases
                                       (|theta| > pi / 2) left out; 0 in planar mode
                                       (docs/paraview-output.md) */
    const double *crease_angle;     /**< [nt] rad: the largest |theta| > pi / 2 across the triangle's
                                       interior edges (it is folded over a neighbour), else 0 */
    const double *barb_strain;      /**< [nbarb] |x_a - x_b| / L - 1 of each constrained barb edge:
                                       the inextensibility constraint's violation */
    const double *curvature;        /**< [3 nt] 1/m or NULL: the bending operator's own curvature
                                       (bb, tt, bt in the barb frame; plume_fields_set_curvatures),
                                       NaN on kinematic triangles */
} plume_field_values;

/** The names of the per-triangle fields above, as a render takes them: "mean_curvature, J, ...". */
const char *plume_field_names(void);
/** 1 when a render can be coloured by `name`: "material", "object" or one of plume_field_names. */
int plume_render_field_valid(const char *name);
/** The colour-bar label of a field name (with its unit), NULL for an unknown name. */
const char *plume_field_label(const char *name);
/** Copies the field `name` (one of plume_field_names; strain_bb etc. are components of
 * green_strain and stress) into out[v->nt]. PLUME_EINVAL naming the names for an unknown one. */
plume_status plume_field_values_select(const plume_field_values *v, const char *name, double *out,
                                                 plume_err *err);

/** Computes the fields at positions x (dim * nv). */
plume_status plume_fields_compute(plume_fields *f, const double *x, plume_field_values *out, plume_err *err);

/** A bending term's curvatures at positions x: kappa [3 nt_elastic] (bb, tt, bt in the barb frame). */
typedef plume_status (*plume_fields_curvature_fn)(void *bending_ctx, int dim, const double *x, double *kappa);

/** From then on the fields carry the bending operator's own curvature, fn called with the bending
 * term's ctx: plume_field_values.curvature, the cell array "curvature_barb" of the frames and the
 * render fields curvature_bb, curvature_tt, curvature_bt (midedge bending: plume_midedge_term_view_curvatures).
 * PLUME_EINVAL without a bending term, PLUME_ENOMEM. */
plume_status plume_fields_set_curvatures(plume_fields *f, plume_fields_curvature_fn fn, plume_err *err);

/** From then on material k's stresses and energy density come from the plane-stress tensor
 * tensors[9 k .. 9 k + 8] (Pa, row-major; plume_membrane_term_create_tensor) instead of its moduli
 * (copied; nmat of the fields' materials). PLUME_EINVAL for a NULL tensors, PLUME_ENOMEM. */
plume_status plume_fields_set_tensors(plume_fields *f, const double *tensors, plume_err *err);

/** Gives each triangle the scene object it belongs to: object i has triangles t0[i] to
 * t0[i] + nt[i] - 1 (others get -1). From then on the frames carry the cell array "object"
 * (Int32), which tells a scene's bodies apart in ParaView. PLUME_EINVAL naming a range outside
 * the mesh, PLUME_ENOMEM. */
plume_status plume_fields_set_objects(plume_fields *f, int nobjects, const plume_index *t0, const plume_index *nt,
                                                plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
