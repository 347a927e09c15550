/** \file
 * plume: PLUME_API, the mark of the public face, is defined in include/plume/base.h; the library's
 * own headers include it through here. */
#ifndef PLUME_EXPORT_H
#define PLUME_EXPORT_H

#include "../../include/plume/base.h"

#endif
