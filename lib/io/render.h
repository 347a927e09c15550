/** \file
 * plume: a shaded picture of a triangle-mesh state as PNG through gnuplot, for a quick look at a
 * frame without ParaView. */
#ifndef PLUME_RENDER_H
#define PLUME_RENDER_H

#include "../core/export.h"
#include "../core/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How plume_render_png draws: view, size, light and title. */
typedef struct {
    double rot_x;         /**< gnuplot view angle about x (degrees), in [0, 180]; default 60 */
    double rot_z;         /**< gnuplot view angle about z (degrees), in [0, 360]; default 30 */
    int width;            /**< picture width (pixels); default 1000 */
    int height;           /**< picture height (pixels); default 800 */
    double light[3];      /**< direction the light comes from, in the camera frame (x right, y up,
                             z toward the viewer); default (-0.3, 0.5, 1) */
    const char *title;    /**< drawn above the picture; NULL for none */
    const double *field;  /**< [nt] a value per triangle to colour by (a perceptual blue-green-yellow
                             map, shaded by the light, with a colour bar); NaN draws the triangle
                             grey (kinematic bodies); NULL: colours by material */
    const char *field_label; /**< the colour bar's label; NULL for none */
    double field_min;     /**< the colour bar's lower end; field_min == field_max (default 0, 0): the
                             2nd to 98th percentile of the finite values, so that a few outliers (a
                             crease) do not flatten the rest; values outside are drawn at the ends */
    double field_max;     /**< the colour bar's upper end */
    const int *category;  /**< [nt] or NULL: without a field, colour each triangle by its category
                             (e.g. its scene object) from the materials' palette of 12 distinct
                             colours, cycled, instead of by its material: neighbouring objects
                             numbered in a row are told apart. Default NULL */
} plume_render_opts;

/** Fills o with the defaults above (title NULL). */
void plume_render_opts_default(plume_render_opts *o);

/** Draws the triangles of `mesh` at positions x (3 nv; NULL: mesh->x, z = 0 when planar) to
 * png_path, flat-shaded: each triangle's colour is its material's (a fixed palette by material
 * id), or its field value's when o->field is set, scaled by |n . light| (two-sided), drawn back to front, with equal axis scales and the fixed
 * view of `o` (NULL: defaults). The picture is made in a private temporary directory and
 * renamed into place. Errors: invalid arguments or view (PLUME_EINVAL), gnuplot missing or
 * failing (PLUME_EDEP, with gnuplot's last message), files (PLUME_EIO). */
plume_status plume_render_png(const char *png_path, const plume_mesh *mesh, const double *x,
                                        const plume_render_opts *o, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
