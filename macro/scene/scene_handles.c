/* The handles of a "mesh" scene (macro/scene/scene.h): selected vertices moved along keyframes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal/scene_internal.h"

/* One handle: its selector and keyframes. map/nobj translate OBJ vertex numbers (NULL: mesh ids). */
plume_status plume_scene_parse_handle(const plume_json_ctx *c, json_t *jh, const char *where, const plume_scene *s,
                                      const plume_index *map, plume_index nobj, plume_handle *h)
{
    static const char *const keys[] = {"near", "radius", "vertices", "box", "keyframes", NULL};
    char kp[PLUME_JSON_KEY_MAX];
    plume_status st;
    if (!json_is_object(jh))
        return plume_json_bad(c, PLUME_EFORMAT, where, "must be an object with a selector (near/radius, vertices or box) and keyframes");
    if ((st = plume_json_check_keys(c, jh, where, keys)) != PLUME_OK)
        return st;
    plume_index *ids = malloc((size_t)(s->mesh->nv + 1) * sizeof *ids), n = 0;
    if (!ids)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    h->vertices = ids;
    if ((st = plume_scene_select(c, jh, where, s, map, nobj, ids, &n)) != PLUME_OK)
        return st;
    h->nvertices = n;
    /* keyframes [[t, dx, dy, dz], ...], times increasing */
    plume_json_subkey(kp, where, "keyframes");
    json_t *jk = json_object_get(jh, "keyframes");
    if (!json_is_array(jk) || json_array_size(jk) < 1)
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be a non-empty array of [t, dx, dy, dz]");
    size_t nk = json_array_size(jk);
    double *times = malloc(nk * sizeof *times), *off = malloc(3 * nk * sizeof *off);
    h->times = times;
    h->offsets = off;
    if (!times || !off)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    h->nkeys = (int)nk;
    for (size_t k = 0; k < nk; k++) {
        char kk[PLUME_JSON_KEY_MAX];
        double row[4];
        plume_json_subindex(kk, kp, k);
        if ((st = plume_json_vector(c, json_array_get(jk, k), kk, 4, row)) != PLUME_OK)
            return st;
        if (k > 0 && !(row[0] > times[k - 1]))
            return plume_json_bad(c, PLUME_EINVAL, kk, "time %g is not after the previous keyframe's %g (times must increase)",
                       row[0], times[k - 1]);
        times[k] = row[0];
        off[3 * k] = row[1], off[3 * k + 1] = row[2], off[3 * k + 2] = row[3];
    }
    return PLUME_OK;
}

plume_status plume_scene_parse_handles(const plume_json_ctx *c, json_t *doc, plume_scene *s, const plume_index *map,
                                       plume_index nobj)
{
    plume_status st = PLUME_OK;
    const plume_mesh *m = s->mesh;
    json_t *jh = json_object_get(doc, "handles");
    if (!jh)
        return PLUME_OK;
    if (!json_is_array(jh))
        return plume_json_bad(c, PLUME_EFORMAT, "handles", "must be an array of handles");
    size_t nh = json_array_size(jh);
    s->handles = calloc(nh + 1, sizeof *s->handles);
    if (!s->handles)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (size_t k = 0; k < nh; k++) {
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subindex(kp, "handles", k);
        s->nhandles++;
        if ((st = plume_scene_parse_handle(c, json_array_get(jh, k), kp, s, map, nobj, s->handles + k)) != PLUME_OK)
            return st;
    }
    /* a vertex in two handles would follow two paths */
    int *owner = malloc((size_t)m->nv * sizeof *owner);
    if (!owner)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (plume_index i = 0; i < m->nv; i++)
        owner[i] = -1;
    for (int h = 0; h < s->nhandles && st == PLUME_OK; h++)
        for (plume_index i = 0; i < s->handles[h].nvertices; i++) {
            plume_index vtx = s->handles[h].vertices[i];
            if (owner[vtx] >= 0 && owner[vtx] != h) {
                char kp[PLUME_JSON_KEY_MAX];
                plume_json_subindex(kp, "handles", (size_t)h);
                st = plume_json_bad(c, PLUME_EINVAL, kp, "shares vertex %ld with handles[%d]: a vertex can follow one handle only",
                                    (long)vtx, owner[vtx]);
                break;
            }
            owner[vtx] = h;
        }
    free(owner);
    return st;
}
