/** \file
 * plume: microstructure layouts of a vane — barbs as strips of stiff barb material, held by a soft
 * barbule material (the paper's microscale model) or by explicit barbule strips with empty space
 * between them (the microstructure resolved one level further). */
#ifndef PLUME_LAYOUT_H
#define PLUME_LAYOUT_H

#include "../include/plume/homogenize.h"

#include "../lib/core/export.h"
#include "../lib/core/membrane.h"

#ifdef __cplusplus
extern "C" {
#endif


/** The thinnest strip of the layout (m): the barb strip, the gap between barbs, or a barbule. */
double plume_layout_thinnest(const plume_layout *l);

/** The layout meshed for the refinement comparison of `use`: element edge twice this layout's, or half
 * of it when the layout check refuses twice. */
void plume_layout_refinement(const plume_layout *l, plume_mesh_use use, plume_layout *out);

#ifdef __cplusplus
}
#endif
#endif
