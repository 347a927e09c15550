/* plume example: the tilted traction test of a vane with barbs at 45 degrees (include/plume/traction.h).
 * Build against the shared library (plume.pc carries its run path, so the program starts without
 * LD_LIBRARY_PATH; set PKG_CONFIG_PATH=PREFIX/lib/pkgconfig when PREFIX is not a system one):
 *     cc traction.c $(pkg-config --cflags --libs plume) -o traction
 * or against the static one (nothing of plume's to find at run time):
 *     cc traction.c $(pkg-config --cflags plume) $(pkg-config --variable=static_libs plume) -o traction */
#include <stdio.h>
#include <stdlib.h>

#include <plume/plume.h>

int main(void)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_vane vane;
    plume_vane_default(&vane);            /* E_xx = 1e4, E_yy = 1, G_xy = 1 Pa, h = 1 m, constraint on */
    if (plume_patch_mesh(1.0, 1.3, 45.0, 0.05, PLUME_PATCH_ALIGNED, 2, &mesh, &err) ||
        plume_problem_create(mesh->nv, 2, 1.3, &p, &err) ||
        plume_vane_add(p, mesh, &vane, &barbs, &nb, &err)) {
        fprintf(stderr, "setup: %s\n", err.msg);
        return 1;
    }
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = 1.0, o.ly = 1.3, o.h = vane.h;
    plume_traction_result r;
    if (plume_traction_run(mesh, p, barbs, nb, &o, &r, &err) != PLUME_OK) {
        fprintf(stderr, "traction: %s\n", err.msg);
        return 1;
    }
    for (plume_index k = 0; k < r.curve.n; k++)
        printf("%.4f %.6g %.6g\n", r.curve.strain[k], r.curve.stress[k], r.curve.wbar[k]);
    printf("converged: %d, iterations: %d\n", r.converged, r.newton_iterations);
    const int ok = r.converged;
    plume_traction_result_free(&r);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return ok ? 0 : 1;
}
