/* plume: the start of a contact scene checked before the first step (macro/scene/scene.h,
 * plume_scene_check_start). Barrier contact cannot start from crossed bodies: the barrier is
 * infinite there and every step fails its line search. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/contact/contact_broad.h"
#include "../../lib/core/rigid_motion.h"
#include "internal/scene_internal.h"

/* samples of the motion from the rest placement to the handles' placement at t = 0 */
#define START_PATH_SAMPLES 16

/* the name of triangle t's body: its object's, or "body N" (N its connected component) */
static void body_name(const plume_scene *s, const int *body, plume_index t, char *out, size_t n)
{
    for (int k = 0; k < s->nobjects; k++) {
        const plume_scene_object *o = s->objects + k;
        if (t >= o->t0 && t < o->t0 + o->nt) {
            snprintf(out, n, "'%s'", o->name);
            return;
        }
    }
    snprintf(out, n, "body %d", body[s->mesh->tri[3 * t]]);
}

/* positions at time t: the rest positions with every handle's vertices moved by its keyframes */
static void placed_at(const plume_scene *s, double t, double *x)
{
    const plume_mesh *m = s->mesh;
    memcpy(x, m->x, (size_t)(3 * m->nv) * sizeof *x);
    for (int h = 0; h < s->nhandles; h++) {
        const plume_handle *hd = s->handles + h;
        const plume_rigid_motion r = {hd->nkeys, hd->times, hd->offsets, hd->rotations, hd->pivot};
        for (plume_index i = 0; i < hd->nvertices; i++) {
            plume_index v = hd->vertices[i];
            plume_rigid_motion_apply(&r, t, m->x + 3 * v, x + 3 * v);
        }
    }
}

/* The first intersecting pair of triangles that counts for contact (different bodies, or any with
 * self contact) at positions x: *found 1 and the pair, else *found 0. */
static plume_status first_crossing(const plume_scene *s, const int *body, const double *x, plume_contact_pairs *pairs,
                                   int *found, plume_index *t1, plume_index *t2, plume_err *err)
{
    const plume_mesh *m = s->mesh;
    plume_contact_audit audit;
    *found = 0;
    plume_status st = plume_contact_count_intersections(m->nv, x, m->nt, m->tri, pairs, &audit, err);
    if (st != PLUME_OK)
        return st;
    for (plume_index k = 0; k < pairs->n && !*found; k++) {
        plume_index a = pairs->p[k].a, b = pairs->p[k].b;
        if ((s->contact.self_contact || body[m->tri[3 * a]] != body[m->tri[3 * b]]) &&
            !plume_scene_welded_neighbours(s, a, b))
            *found = 1, *t1 = a, *t2 = b;
    }
    return PLUME_OK;
}

plume_status plume_scene_check_start(const plume_scene *s, plume_err *err)
{
    if (!s || !s->mesh)
        return plume_err_set(err, PLUME_EINVAL, "scene: invalid arguments");
    if (!s->has_contact)
        return PLUME_OK;
    const plume_mesh *m = s->mesh;
    plume_status st = PLUME_OK;
    int *body = plume_scene_body_labels(s, err);
    double *x0 = malloc((size_t)(3 * m->nv + 1) * sizeof *x0), *x = malloc((size_t)(3 * m->nv + 1) * sizeof *x);
    plume_contact_pairs pairs = {0};
    if (!body || !x0 || !x) {
        st = plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        goto done;
    }
    placed_at(s, 0.0, x0);
    int moved = memcmp(x0, m->x, (size_t)(3 * m->nv) * sizeof *x0) != 0;
    /* the rest placement, then the way to the keyframes' placement at t = 0 (the first step makes
     * that jump), ending at it */
    for (int k = 0; k <= (moved ? START_PATH_SAMPLES : 0); k++) {
        double f = (double)k / START_PATH_SAMPLES;
        for (plume_index i = 0; i < 3 * m->nv; i++)
            x[i] = m->x[i] + f * (x0[i] - m->x[i]);
        int found;
        plume_index t1 = -1, t2 = -1;
        if ((st = first_crossing(s, body, x, &pairs, &found, &t1, &t2, err)) != PLUME_OK)
            goto done;
        if (!found)
            continue;
        char n1[160], n2[160];
        body_name(s, body, t1, n1, sizeof n1);
        body_name(s, body, t2, n2, sizeof n2);
        if (k == 0)
            st = plume_err_set(err, PLUME_EINVAL,
                               "%s: the bodies %s and %s intersect at rest (triangles %ld and %ld cross): barrier contact "
                               "cannot start from crossed bodies; move them apart (\"place\")",
                               s->path, n1, n2, (long)t1, (long)t2);
        else
            st = plume_err_set(err, PLUME_EINVAL,
                               "%s: the keyframes at t = 0 move the bodies away from their rest placement, and on "
                               "the way (%.0f %% of that jump) %s and %s intersect (triangles %ld and %ld cross): "
                               "start every keyframed motion at zero offset and rotation, or place the bodies where "
                               "the keyframes put them",
                               s->path, 100.0 * f, n1, n2, (long)t1, (long)t2);
        goto done;
    }
done:
    plume_contact_pairs_free(&pairs);
    free(body);
    free(x0);
    free(x);
    return st;
}
