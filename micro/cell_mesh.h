/** \file
 * plume: periodic cells of a layout, meshed so that every strip boundary is a mesh edge. */
#ifndef PLUME_CELL_MESH_H
#define PLUME_CELL_MESH_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"
#include "../lib/core/mesh_quadratic.h"
#include "layout.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A periodic cell in the barb frame: the rectangle [0, a] x [0, b] with lattice vectors (a, 0)
 * and (0, b), b = d_B. Vertices on opposite sides come in matching pairs (same y on x = 0 and
 * x = a, same x on y = 0 and y = b). Every vertex has a master: itself, or the vertex it is a
 * periodic image of; shift = X_v - X_master(v) is a lattice vector. */
struct plume_cell {
    plume_mesh *mesh;      /**< owned; triangles carry material ids and barb_dir = (1, 0). Order 2: the
                              quadratic triangles split in four, its vertices the 6-node elements' nodes */
    plume_quadratic_mesh quad; /**< order 2: the quadratic triangles (quad.split is NULL: it is `mesh`);
                                  order 1: zeroed */
    int order;             /**< element order, 1 or 2 (the layout's) */
    double a;              /**< cell length along the barbs (x) */
    double b;              /**< cell width across the barbs (y): d_B */
    plume_index *master;   /**< [nv] owned */
    double *shift;         /**< [2*nv] owned */
    plume_index nmasters;  /**< distinct masters */
};

/** Meshes the periodic cell of a layout (constrained Delaunay through lib/core/cdt.h, no Steiner
 * points on the cell boundary so the periodic pairs match). For strips the cell length a along
 * the barbs is the barb width times 4 (fields are constant along the barbs, any a works); for
 * barbules it is barbule_spacing. Element edges are about plume_layout_element_edge(l,
 * PLUME_MESH_CELL); order 2 adds a node at every edge's midpoint (their periodic pairs match too). Errors (PLUME_EINVAL with a
 * message): invalid layout, strips narrower than one element is fine but a strip that the mesh
 * cannot resolve (w_B or the gap below 1e-12 d_B), a barbule strip that does not fit in its cell
 * ("cell too small for its layout": barbule extent along the barbs >= barbule_spacing). */
plume_status plume_cell_mesh(const plume_layout *l, plume_cell **out, plume_err *err);
/** Frees the cell, its meshes and arrays; sets *c = NULL; NULL-safe. */
void plume_cell_destroy(plume_cell **c);

/** Elements of the cell: its quadratic triangles at order 2, its triangles at order 1. */
plume_index plume_cell_elements(const plume_cell *c);

/** The membrane term over a micro mesh: the linear element over `mesh` (quad NULL or empty), or the
 * quadratic one over quad's triangles with mesh's vertices as nodes (lib/core/membrane_p2.h). Planar. */
plume_status plume_micro_membrane_term(const plume_mesh *mesh, const plume_quadratic_mesh *quad,
                                                 const plume_membrane_material *mats, int nmat, plume_term *out,
                                                 plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
