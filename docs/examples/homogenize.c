/* plume example: a barb layout homogenised into the macroscale moduli (include/plume/homogenize.h),
 * written to an HDF5 file and read back (include/plume/curves.h), as apps/homogenize does.
 *   homogenize LAYOUT.json OUT.h5
 * Build against the installed library:
 *   cc -std=c11 homogenize.c $(pkg-config --cflags --libs plume) -o homogenize */
#include <stdio.h>

#include <plume/plume.h>

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: homogenize LAYOUT.json OUT.h5\n");
        return 2;
    }
    plume_openmp_serial();
    plume_err err = {{0}};
    plume_layout layout;
    plume_layout_default(&layout);
    if (plume_layout_load_json(argv[1], &layout, &err) != PLUME_OK) {
        fprintf(stderr, "homogenize: %s\n", err.msg);
        return 1;
    }
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.steps = 2; /* short cell curves: the moduli are what this example is after */
    plume_homog_result r;
    if (plume_homogenize(&layout, &o, &r, &err) != PLUME_OK) {
        fprintf(stderr, "homogenize: %s\n", err.msg);
        return 1;
    }
    printf("membrane: E_xx %.6g Pa, E_yy %.6g Pa, nu_xy %.4g, G_xy %.6g Pa (%ld elements)\n", r.moduli.E_xx,
           r.moduli.E_yy, r.moduli.nu_xy, r.moduli.G_xy, (long)r.elements);
    printf("bending: D_long %.6g N m, D_trans %.6g N m, D_twist %.6g N m\n", r.bending.D_long, r.bending.D_trans,
           r.bending.D_twist);
    plume_ortho back;
    int ok = plume_moduli_write(argv[2], &r.moduli, "docs/examples/homogenize.c", &err) == PLUME_OK &&
             plume_moduli_read(argv[2], &back, &err) == PLUME_OK && back.E_xx == r.moduli.E_xx &&
             back.E_yy == r.moduli.E_yy && back.nu_xy == r.moduli.nu_xy && back.G_xy == r.moduli.G_xy;
    if (!ok && err.msg[0])
        fprintf(stderr, "homogenize: %s\n", err.msg);
    plume_homog_result_free(&r);
    printf("homogenize example: %s\n", ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}
