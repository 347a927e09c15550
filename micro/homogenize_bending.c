/* plume: the bending moduli of a layout alone (include/plume/homogenize.h's
 * plume_homogenize_bending): the periodic plate cell of micro/cell_plate.h on the layout's cell
 * mesh, without the membrane homogenisation. */
#include <stddef.h>

#include "../include/plume/homogenize.h"
#include "cell_mesh.h"
#include "cell_plate.h"

plume_status plume_homogenize_bending(const plume_layout *l, double D[9], plume_plate_moduli *moduli, plume_err *err)
{
    if (!l || !D)
        return plume_err_set(err, PLUME_EINVAL, "plume_homogenize_bending: the layout and D are required");
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    plume_cell *cell = NULL;
    if ((st = plume_cell_mesh(l, &cell, err)) == PLUME_OK)
        st = plume_cell_plate_tensor(cell, mats, 2, D, NULL, err);
    plume_cell_destroy(&cell);
    if (st == PLUME_OK && moduli)
        plume_plate_moduli_from_tensor(D, moduli);
    return st;
}
