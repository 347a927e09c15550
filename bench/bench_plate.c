/* make bench — the cost of the bending moduli: the periodic plate cell (micro/cell_plate.h, Morley
 * triangles) against the membrane cell (micro/cell_linear.h) on the same cell meshes, each timed as
 * the best of three runs, side by side with their ratio. */
#include <math.h>
#include <stdio.h>

#include "../include/plume.h"
#include "../micro/cell_linear.h"
#include "../micro/cell_plate.h"
#include "../micro/layout.h"

#define REPS 3

static void row(const char *name, const plume_layout *l)
{
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    plume_cell *c = NULL;
    plume_err err = {{0}};
    if (plume_cell_mesh(l, &c, &err) != PLUME_OK) {
        printf("%-30s | mesh failed: %s\n", name, err.msg);
        return;
    }
    double tm = INFINITY, tp = INFINITY, C[9], D[9];
    plume_cell_plate_info info = {0, 0, 0};
    for (int r = 0; r < REPS; r++) {
        double t0 = plume_wall_seconds();
        if (plume_cell_linear_tensor(c, mats, 2, l->h, C, NULL, &err) != PLUME_OK) {
            printf("%-30s | membrane failed: %s\n", name, err.msg);
            break;
        }
        double t1 = plume_wall_seconds();
        if (plume_cell_plate_tensor(c, mats, 2, D, &info, &err) != PLUME_OK) {
            printf("%-30s | plate failed: %s\n", name, err.msg);
            break;
        }
        double t2 = plume_wall_seconds();
        tm = fmin(tm, t1 - t0), tp = fmin(tp, t2 - t1);
    }
    if (isfinite(tm) && isfinite(tp))
        printf("%-30s | %9ld | %9ld | %9ld | %10.2f | %10.2f | %6.2f | %.5g %.5g %.5g\n", name,
               (long)plume_cell_elements(c), (long)c->mesh->nv * 2, (long)info.dofs, 1e3 * tm, 1e3 * tp, tp / tm, D[0],
               D[4], D[8]);
    plume_cell_destroy(&c);
}

int main(void)
{
    plume_openmp_serial();
    printf("\nplume bench (bending): the plate cell (Morley, exact bending tensor) against the membrane cell\n"
           "(exact small-strain tensor) on the same cell; best of %d; plate/membrane is the cost ratio\n", REPS);
    printf("%-30s | %9s | %9s | %9s | %10s | %10s | %6s | %s\n", "layout", "elements", "2 nodes", "plate dofs",
           "membr. ms", "plate ms", "ratio", "D_long D_trans D_twist (N m)");
    plume_layout l;
    plume_layout_default(&l);
    row("strips, automatic (P2)", &l);
    l.e_rel = 0.25;
    row("strips, e-bar 0.25 (P2)", &l);
    l.order = 1;
    row("strips, e-bar 0.25 (P1)", &l);
    const double e[3] = {0.2, 0.1, 0.05};
    for (int k = 0; k < 3; k++) {
        plume_layout_default(&l);
        l.kind = PLUME_LAYOUT_BARBULES, l.ratio = 1.0, l.phi = 0.3, l.barbule_width = 1e-4, l.barbule_spacing = 8e-4;
        l.order = 1, l.e_rel = e[k];
        char name[64];
        snprintf(name, sizeof name, "barbules, e-bar %.2g (P1)", e[k]);
        row(name, &l);
    }
    l.order = 2, l.e_rel = 0.0;
    row("barbules, automatic (P2)", &l);
    return 0;
}
