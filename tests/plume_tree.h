/** \file
 * Every header of the tree, the internal ones too: the tests and the benchmarks reach below the
 * public face (include/plume/plume.h, what a program outside the tree includes). */
#ifndef PLUME_TREE_H
#define PLUME_TREE_H

/* core: the mesh, the problem and its energy terms, the dense algebra */
#include "../lib/core/export.h"
#include "../lib/core/status.h"
#include "../lib/core/version.h"
#include "../lib/core/mesh.h"
#include "../lib/core/mesh_quadratic.h"
#include "../lib/core/cdt.h"
#include "../lib/core/term.h"
#include "../lib/core/problem.h"
#include "../lib/core/membrane.h"
#include "../lib/core/membrane_p2.h"
#include "../lib/core/edge_length.h"
#include "../lib/core/dense.h"
#include "../lib/core/pslg.h"
#include "../lib/core/load.h"
#include "../lib/core/moment.h"
#include "../lib/core/openmp_env.h"
#include "../lib/core/rigid_motion.h"

/* io: HDF5 curves and frames, VTK, JSON and OBJ input, plots and renders */
#include "../lib/io/curves.h"
#include "../lib/io/sample.h"
#include "../lib/io/plot.h"
#include "../lib/io/gnuplot.h"
#include "../lib/io/progress.h"
#include "../lib/io/frames.h"
#include "../lib/io/fs.h"
#include "../lib/io/vtk.h"
#include "../lib/io/vtu.h"
#include "../lib/io/render.h"

/* solve: CHOLMOD, the native Newton/SQP, Ipopt, one dispatcher */
#include "../lib/solve/cholesky.h"
#include "../lib/solve/report.h"
#include "../lib/solve/options.h"
#include "../lib/solve/ipopt_solver.h"
#include "../lib/solve/solver.h"
#include "../lib/solve/newton.h"
#include "../lib/solve/predict.h"

/* contact: barrier, broad and narrow phase, CCD, friction */
#include "../lib/contact/contact_narrow.h"
#include "../lib/contact/ccd.h"
#include "../lib/contact/contact_broad.h"
#include "../lib/contact/contact.h"
#include "../lib/contact/contact_friction.h"

/* sim: the steppers (statics, dynamics, the traction scenario) */
#include "../lib/sim/statics.h"
#include "../lib/sim/traction.h"
#include "../lib/sim/dynamics.h"

/* macro: the shell, the meshers and scenes */
#include "../macro/shell/patch_mesh.h"
#include "../macro/shell/grid_mesh.h"
#include "../macro/feather/obj_outline.h"
#include "../macro/shell/vane.h"
#include "../macro/shell/traction_model.h"
#include "../macro/shell/plate_bending.h"
#include "../macro/shell/bending.h"
#include "../macro/shell/shape_bending.h"
#include "../macro/shell/midedge_bending.h"
#include "../macro/shell/midedge_term.h"
#include "../macro/feather/feather_mesh.h"
#include "../macro/scene/scene.h"
#include "../macro/shell/fields.h"
#include "../macro/scene/run.h"

/* micro: layouts, cells, specimens, homogenisation, fitting */
#include "../micro/layout.h"
#include "../micro/layout_json.h"
#include "../micro/cell_mesh.h"
#include "../micro/periodic.h"
#include "../micro/cell_linear.h"
#include "../micro/cell_plate.h"
#include "../micro/homogenize.h"
#include "../micro/micro_model.h"
#include "../micro/fit.h"

/* drivers: the experiments over both scales (study, sweep, stability) and the flat interface */
#include "../drivers/flat.h"
#include "../drivers/sweep.h"
#include "../drivers/study.h"
#include "../drivers/stability.h"

#endif
