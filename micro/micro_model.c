#include "micro_model.h"

#include <math.h>

#include "../lib/membrane.h"
#include "cell_mesh.h"

plume_status plume_micro_specimen(const plume_layout *l, double lx, double ly, double angle_deg,
                                  plume_mesh **mesh, plume_problem **p, plume_err *err)
{
    if (!l || !mesh || !p)
        return plume_err_set(err, PLUME_EINVAL, "micro specimen: invalid arguments");
    *mesh = NULL;
    *p = NULL;
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK || (st = plume_specimen_mesh(l, lx, ly, angle_deg, mesh, err)) != PLUME_OK)
        return st;
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    plume_term term;
    if ((st = plume_problem_create((*mesh)->nv, 2, fmax(lx, ly), p)) != PLUME_OK ||
        (st = plume_membrane_term_create(*mesh, 2, mats, 2, &term, err)) != PLUME_OK ||
        (st = plume_problem_add_term(*p, &term)) != PLUME_OK) {
        plume_problem_destroy(p);
        plume_mesh_destroy(mesh);
    }
    return st;
}
