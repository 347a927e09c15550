/* plume: legacy VTK ASCII output of a triangle mesh state. */
#include "vtk.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* %.17g round-trips a double; non-finite values would make the file unreadable, so they are
 * written as NaN, which ParaView's reader accepts. */
static void put(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.17g", v);
    else
        fputs("nan", f);
}

plume_status plume_vtk_write(const char *path, const plume_mesh *m, const double *x, double t, plume_err *err)
{
    if (!path || !*path || !m || m->nv < 1 || m->nt < 0 || (m->dim != 2 && m->dim != 3))
        return plume_err_set(err, PLUME_EINVAL, "vtk: invalid arguments (path, mesh)");
    int dim = x ? 3 : m->dim;
    const double *pos = x ? x : m->x;
    size_t len = strlen(path) + 32;
    char *tmp = malloc(len);
    if (!tmp)
        return plume_err_set(err, PLUME_ENOMEM, "vtk '%s': out of memory", path);
    snprintf(tmp, len, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        plume_status s = plume_err_set(err, PLUME_EIO, "vtk '%s': cannot create '%s': %s", path, tmp, strerror(errno));
        free(tmp);
        return s;
    }
    fprintf(f, "# vtk DataFile Version 3.0\nplume frame t = %.17g s\nASCII\nDATASET UNSTRUCTURED_GRID\n", t);
    fputs("FIELD FieldData 1\nTIME 1 1 double\n", f);
    put(f, t);
    fprintf(f, "\nPOINTS %ld double\n", (long)m->nv);
    for (plume_index v = 0; v < m->nv; v++) {
        for (int a = 0; a < 3; a++) {
            if (a)
                fputc(' ', f);
            put(f, a < dim ? pos[dim * v + a] : 0.0);
        }
        fputc('\n', f);
    }
    fprintf(f, "CELLS %ld %ld\n", (long)m->nt, (long)(4 * m->nt));
    for (plume_index c = 0; c < m->nt; c++)
        fprintf(f, "3 %ld %ld %ld\n", (long)m->tri[3 * c], (long)m->tri[3 * c + 1], (long)m->tri[3 * c + 2]);
    fprintf(f, "CELL_TYPES %ld\n", (long)m->nt);
    for (plume_index c = 0; c < m->nt; c++)
        fputs("5\n", f); /* VTK_TRIANGLE */
    fprintf(f, "CELL_DATA %ld\nSCALARS material int 1\nLOOKUP_TABLE default\n", (long)m->nt);
    for (plume_index c = 0; c < m->nt; c++)
        fprintf(f, "%d\n", m->material[c]);
    fputs("VECTORS barb_direction double\n", f);
    for (plume_index c = 0; c < m->nt; c++) {
        put(f, m->barb_dir[2 * c]);
        fputc(' ', f);
        put(f, m->barb_dir[2 * c + 1]);
        fputs(" 0\n", f);
    }
    fprintf(f, "POINT_DATA %ld\nVECTORS displacement double\n", (long)m->nv);
    for (plume_index v = 0; v < m->nv; v++) {
        for (int a = 0; a < 3; a++) {
            double p = a < dim ? pos[dim * v + a] : 0.0, r = a < 2 ? m->X[2 * v + a] : 0.0;
            if (a)
                fputc(' ', f);
            put(f, p - r);
        }
        fputc('\n', f);
    }
    int bad = ferror(f);
    plume_status s = PLUME_OK;
    if (fclose(f) != 0 || bad)
        s = plume_err_set(err, PLUME_EIO, "vtk '%s': cannot write '%s': %s", path, tmp, strerror(errno));
    else if (rename(tmp, path) != 0)
        s = plume_err_set(err, PLUME_EIO, "vtk '%s': cannot rename '%s' over it: %s", path, tmp, strerror(errno));
    if (s != PLUME_OK)
        unlink(tmp);
    free(tmp);
    return s;
}
