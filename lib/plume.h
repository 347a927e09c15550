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
#include "../macro/patch_mesh.h"
#include "../macro/vane.h"

#endif
