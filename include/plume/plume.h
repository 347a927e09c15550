/** \file
 * plume — feather vanes as strongly anisotropic elastic shells, at two scales. The umbrella
 * header: `#include <plume/plume.h>` and link with `pkg-config --cflags --libs plume`. Each header
 * it includes serves one job (docs/library.md); include just that one if you prefer. */
#ifndef PLUME_PUBLIC_PLUME_H
#define PLUME_PUBLIC_PLUME_H

#include "base.h"
#include "problem.h"
#include "curves.h"
#include "homogenize.h"
#include "traction.h"
#include "fit.h"
#include "scene.h"
#include "experiments.h"
#include "flat.h"

#endif
