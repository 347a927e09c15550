/* plume (private, not installed): the v / f / g (and o) lines of an OBJ file, with each face's
 * group. Faces of more than three vertices are split into a fan; other statements (vt, vn, s,
 * usemtl, mtllib) are ignored. Errors name the file and line. */
#ifndef PLUME_INTERNAL_OBJ_READ_H
#define PLUME_INTERNAL_OBJ_READ_H

#include "../core/status.h"

typedef struct {
    double *v;             /* [2 nv] x, y */
    double *z;             /* [nv] z (0 when the line has none): kinematic bodies are 3D */
    plume_index nv, vcap;
    plume_index *f;        /* [3 nf] 0-based */
    int *group;            /* [nf] group id, -1 none */
    plume_index nf, fcap;
    char **groups;         /* group names */
    int ngroups;
} plume_obj_data;

/* Reads `path` into *o (owned by the caller: plume_obj_free). On error *o is empty. */
plume_status plume_obj_read(const char *path, plume_obj_data *o, plume_err *err);
void plume_obj_free(plume_obj_data *o);

#endif
