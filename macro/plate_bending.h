/** \file
 * plume: the bending test of a plate specimen, one procedure for both scales (docs/bending-homogenisation.md,
 * "Both scales in bending"): a shell-mode specimen [0, lx] x [0, ly] — the resolved barbs and barbules
 * of a layout (plume_specimen_mesh, micro/cell_mesh.h) or the homogeneous plate with the homogenised moduli
 * (plume_plate_specimen below) — loaded by self-equilibrated end moments and measured by the
 * curvature fitted in its centre.
 *
 * Loads (PLUME_BEND_EDGE_MOMENTS, the default): the boundary loads of the uniform state, i.e. the
 * work of a uniform moment on the shell's own discrete curvatures, sum_T A_T mbar . kappa_T, which
 * the shape operator's discrete divergence theorem puts on the boundary: the end moment m_yy per
 * unit width at y = 0 and y = ly (cylinder: m_yy lx about the x axis at each end) or the
 * Kirchhoff corner forces 2 m_xy of a uniform twisting moment (twist: 2 m_xy lx about the y axis).
 * For a homogeneous plate of any D the uniform state D^-1 m is then the discrete solution, on any
 * mesh. PLUME_BEND_END_STRIPS instead spreads vertical dead forces over each end strip
 * (y <= c and y >= ly - c, c = end_strip * ly), f_v = A_v (a + b (x - xc) + g (y - yc)), A_v the
 * vertex's lumped area, with no resultant and the same end moment: their departure from the
 * uniform state's loads makes end layers, which a strongly orthotropic plate carries across the
 * whole specimen (docs/bending-homogenisation.md). PLUME_BEND_UNIFORM_CURVATURE takes the same
 * construction with the specimen's own phases: the boundary loads of its uniform-curvature state,
 * which for a twisted laminate grip every barb. Either way the two ends carry opposite moments:
 * the specimen is free, held only against rigid motion by six fixed coordinates at three vertices
 * near its centre, which carry no reaction.
 *
 * Measure: the height z(X) of the vertices of the central window (window * lx by window * ly) is
 * fitted, weighted by lumped area, with a quadratic
 * c0 + c1 x + c2 y + 1/2 (k_xx x^2 + 2 k_xy x y + k_yy y^2); the periodic fluctuation of a
 * microstructure averages out. For a homogeneous plate of tensor D (specimen frame) the centre
 * is the uniform state kappa = D^-1 m, so bending gives m_yy / k_yy = 1 / (D^-1)_yy and twist
 * m_xy / (2 k_xy) = 1 / (D^-1)_66.
 *
 * The test is geometrically exact (the shell's own terms) but meant for the linear range: the load
 * is refused when the curvature it produces, times the specimen's length, exceeds max_rotation.
 * The linearized solver is the linear plate (every step solved from the rest state); the native
 * Newton's KKT tolerance is taken relative to the end loads, which in a soft direction lie far
 * below the problem's round-off floor. */
#ifndef PLUME_PLATE_BENDING_H
#define PLUME_PLATE_BENDING_H

#include "../include/plume/traction.h"

#include "../lib/io/curves.h"
#include "../lib/core/export.h"
#include "../lib/core/membrane.h"
#include "../lib/core/mesh.h"
#include "../lib/core/problem.h"
#include "../lib/solve/solver.h"
#include "bending.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef __cplusplus
}
#endif
#endif
