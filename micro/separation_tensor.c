/* plume (micro): the small-strain tensor of a layout's cell held by hooks (plume_separation_tensor,
 * include/plume/homogenize.h; docs/monoclinic-vane.md): the hooked vane before any hook lets go. */
#include <string.h>

#include "hooked_cell.h"
#include "separation_cell.h"

/* The opened cell with its hooks engaged, strained by +-PLUME_SEPARATION_TENSOR_STRAIN in each
 * Voigt component: the hooks are linear springs, so central differences leave only the geometric
 * nonlinearity's second order (1e-12 relative). */
#define PLUME_SEPARATION_TENSOR_STRAIN 1e-6

plume_status plume_separation_tensor(const plume_layout *l, double C[9], plume_err *err)
{
    if (!l || !C)
        return plume_err_set(err, PLUME_EINVAL, "hooked cell tensor: a layout and an output are required");
    memset(C, 0, 9 * sizeof *C);
    plume_hooked_cell c;
    plume_status st = plume_hooked_cell_init(&c, l, "hooked cell tensor", err);
    const double eps = PLUME_SEPARATION_TENSOR_STRAIN;
    for (int j = 0; j < 3 && st == PLUME_OK; j++) {
        double Pv[2][3];
        for (int side = 0; side < 2 && st == PLUME_OK; side++) {
            const double d = side ? -eps : eps;
            /* E11, E22, and 2E12 = d with a symmetric gradient (no rotation) */
            const double F[4] = {1.0 + (j == 0 ? d : 0.0), j == 2 ? 0.5 * d : 0.0, j == 2 ? 0.5 * d : 0.0,
                                 1.0 + (j == 1 ? d : 0.0)};
            double P[4], E;
            if ((st = plume_hooked_cell_solve_F(&c, F, P, &E, err)) == PLUME_OK)
                Pv[side][0] = P[0], Pv[side][1] = P[3], Pv[side][2] = 0.5 * (P[1] + P[2]);
        }
        for (int i = 0; st == PLUME_OK && i < 3; i++)
            C[3 * i + j] = (Pv[0][i] - Pv[1][i]) / (2.0 * eps) / l->h;
    }
    plume_hooked_cell_free(&c);
    if (st != PLUME_OK) {
        memset(C, 0, 9 * sizeof *C);
        return st;
    }
    for (int i = 0; i < 3; i++) /* symmetric to the differences' rounding */
        for (int j = i + 1; j < 3; j++)
            C[3 * i + j] = C[3 * j + i] = 0.5 * (C[3 * i + j] + C[3 * j + i]);
    return PLUME_OK;
}
