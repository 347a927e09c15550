/* plume: the flat interface for bindings (drivers/flat.c); its functions and request keys are
 * documented in the public header it implements, include/plume/flat.h. */
#ifndef PLUME_FLAT_H
#define PLUME_FLAT_H

#include "../include/plume/flat.h"

#endif
