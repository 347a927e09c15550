/** \file
 * plume (micro): the separation law of a barb line from the periodic cell of a layout held by
 * hooks (plume_separation_law_of, include/plume/homogenize.h; docs/unzipping.md), and its
 * small-strain tensor (plume_separation_tensor, micro/separation_tensor.c). */
#ifndef PLUME_MICRO_SEPARATION_CELL_H
#define PLUME_MICRO_SEPARATION_CELL_H

#include "../include/plume/homogenize.h"

#endif
