/* plume — feather vanes as strongly anisotropic elastic shells, at two scales.
 * The umbrella header: include this and link libplume (pkg-config plume). */
#ifndef PLUME_H
#define PLUME_H

#include "status.h"
#include "mesh.h"
#include "cdt.h"
#include "term.h"
#include "problem.h"
#include "membrane.h"
#include "edge_length.h"
#include "cholesky.h"
#include "solver.h"
#include "newton.h"
#include "traction.h"
#include "curves.h"
#include "sample.h"
#include "plot.h"
#include "progress.h"
#include "pslg.h"
#include "../macro/patch_mesh.h"
#include "../macro/vane.h"
#include "../macro/traction_model.h"
#include "../micro/layout.h"
#include "../micro/layout_json.h"
#include "../micro/cell_mesh.h"
#include "../micro/periodic.h"
#include "../micro/cell_linear.h"
#include "../micro/homogenize.h"
#include "../micro/micro_model.h"
#include "../micro/fit.h"

#endif
