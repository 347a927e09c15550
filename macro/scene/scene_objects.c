/* A scene's "objects" (macro/scene/scene.h): elastic shells (feathers, OBJ sheets, rectangles) placed
 * rigidly (scale, rotations, translation) with their own handles and attachments to kinematic
 * bodies, and kinematic bodies (3D OBJ surfaces following keyframed rigid motions), merged into one
 * mesh: the elastic objects' vertices and triangles first, in the list's order, then the kinematic
 * ones'. The elastic terms see only the elastic triangles (plume_scene.elastic); contact, inertia
 * and output see them all. */
#include "internal/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/io/obj_read.h"
#include "../../lib/core/rigid_motion.h"

static const double deg = 3.14159265358979323846 / 180.0;

/* y -> t + R(q) (scale y) */
typedef struct {
    double scale, q[4], t[3];
} placement;

static void place_point(const placement *pl, const double y[3], double out[3])
{
    double s[3] = {pl->scale * y[0], pl->scale * y[1], pl->scale * y[2]};
    plume_quat_rotate(pl->q, s, out);
    for (int a = 0; a < 3; a++)
        out[a] += pl->t[a];
}

/* [ax, ay, az, degrees] -> rotation vector (radians); a zero axis only with a zero angle */
static plume_status rotation_vector(const plume_json_ctx *c, const char *kp, const double r[4], double out[3])
{
    double n = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (r[3] != 0.0 && !(n > 0.0))
        return plume_json_bad(c, PLUME_EINVAL, kp, "rotates %g degrees about a zero axis", r[3]);
    for (int a = 0; a < 3; a++)
        out[a] = n > 0.0 ? r[a] / n * r[3] * deg : 0.0;
    return PLUME_OK;
}

/* "place": {"translate": [x, y, z], "rotate": [[ax, ay, az, degrees], ...], "scale": s} */
static plume_status parse_place(const plume_json_ctx *c, json_t *obj, const char *where, placement *pl)
{
    static const char *const keys[] = {"translate", "rotate", "scale", NULL};
    char kp[PLUME_JSON_KEY_MAX], kr[PLUME_JSON_KEY_MAX];
    plume_status st;
    pl->scale = 1.0;
    pl->q[0] = 1.0, pl->q[1] = pl->q[2] = pl->q[3] = 0.0;
    pl->t[0] = pl->t[1] = pl->t[2] = 0.0;
    json_t *jp = json_object_get(obj, "place");
    if (!jp)
        return PLUME_OK;
    plume_json_subkey(kp, where, "place");
    if (!json_is_object(jp))
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be an object {\"translate\": [x, y, z], \"rotate\": "
                                                    "[[ax, ay, az, degrees], ...], \"scale\": s}");
    if ((st = plume_json_check_keys(c, jp, kp, keys)) != PLUME_OK ||
        (st = plume_json_positive(c, jp, kp, "scale", 0, 0, &pl->scale, NULL)) != PLUME_OK)
        return st;
    json_t *v;
    plume_json_subkey(kr, kp, "translate");
    if ((v = json_object_get(jp, "translate")) && (st = plume_json_vector(c, v, kr, 3, pl->t)) != PLUME_OK)
        return st;
    plume_json_subkey(kr, kp, "rotate");
    if ((v = json_object_get(jp, "rotate"))) {
        if (!json_is_array(v))
            return plume_json_bad(c, PLUME_EFORMAT, kr, "must be an array of rotations [ax, ay, az, degrees], applied in order");
        for (size_t i = 0; i < json_array_size(v); i++) {
            char ki[PLUME_JSON_KEY_MAX];
            double r[4], rv[3], qi[4];
            plume_json_subindex(ki, kr, i);
            if ((st = plume_json_vector(c, json_array_get(v, i), ki, 4, r)) != PLUME_OK ||
                (st = rotation_vector(c, ki, r, rv)) != PLUME_OK)
                return st;
            plume_quat_from_rotvec(rv, qi);
            plume_quat_mul(qi, pl->q, pl->q); /* later rotations act after earlier ones */
        }
    }
    return PLUME_OK;
}

/* A kinematic body: its placed vertices, triangles and motion. */
typedef struct {
    const char *name; /* borrowed from the JSON */
    double *y;        /* [3 nv] */
    plume_index *tri; /* [3 nt] */
    plume_index nv, nt;
    int nkeys;
    double *times, *offsets, *rotations; /* [nkeys], [3 nkeys], [3 nkeys] */
    double pivot[3];
} kinematic_body;

static void kinematic_free(kinematic_body *b)
{
    free(b->y);
    free(b->tri);
    free(b->times);
    free(b->offsets);
    free(b->rotations);
}

/* "kinematic": {"obj": file, "pivot": [x, y, z], "keyframes": [[t, dx, dy, dz(, ax, ay, az, deg)], ...]};
 * the pivot is in the scene's frame (after "place"), the keys' rotations turn about it. */
static plume_status parse_kinematic(const plume_json_ctx *c, json_t *jo, const char *where, kinematic_body *b)
{
    static const char *const keys[] = {"obj", "pivot", "keyframes", NULL};
    char kp[PLUME_JSON_KEY_MAX], kk[PLUME_JSON_KEY_MAX];
    plume_status st;
    placement pl;
    if ((st = parse_place(c, jo, where, &pl)) != PLUME_OK)
        return st;
    json_t *jk = json_object_get(jo, "kinematic");
    plume_json_subkey(kp, where, "kinematic");
    if (!json_is_object(jk))
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be an object {\"obj\": file, \"pivot\": [x, y, z], \"keyframes\": "
                                                    "[[t, dx, dy, dz, ax, ay, az, degrees], ...]}");
    if ((st = plume_json_check_keys(c, jk, kp, keys)) != PLUME_OK)
        return st;
    json_t *v = json_object_get(jk, "pivot");
    plume_json_subkey(kk, kp, "pivot");
    if (v && (st = plume_json_vector(c, v, kk, 3, b->pivot)) != PLUME_OK)
        return st;
    /* keyframes */
    plume_json_subkey(kk, kp, "keyframes");
    v = json_object_get(jk, "keyframes");
    if (!json_is_array(v) || json_array_size(v) < 1)
        return plume_json_bad(c, PLUME_EFORMAT, kk, "must be a non-empty array of [t, dx, dy, dz] or [t, dx, dy, dz, ax, ay, "
                                                    "az, degrees]");
    size_t nk = json_array_size(v);
    b->times = malloc(nk * sizeof *b->times);
    b->offsets = malloc(3 * nk * sizeof *b->offsets);
    b->rotations = malloc(3 * nk * sizeof *b->rotations);
    if (!b->times || !b->offsets || !b->rotations)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    b->nkeys = (int)nk;
    for (size_t k = 0; k < nk; k++) {
        char ki[PLUME_JSON_KEY_MAX];
        double row[8] = {0};
        json_t *e = json_array_get(v, k);
        plume_json_subindex(ki, kk, k);
        int n = json_is_array(e) && json_array_size(e) == 8 ? 8 : 4;
        if ((st = plume_json_vector(c, e, ki, n, row)) != PLUME_OK ||
            (st = rotation_vector(c, ki, row + 4, b->rotations + 3 * k)) != PLUME_OK)
            return st;
        if (k > 0 && !(row[0] > b->times[k - 1]))
            return plume_json_bad(c, PLUME_EINVAL, ki, "time %g is not after the previous keyframe's %g (times must increase)",
                                  row[0], b->times[k - 1]);
        b->times[k] = row[0];
        memcpy(b->offsets + 3 * k, row + 1, 3 * sizeof *row);
    }
    /* the surface: every vertex a face uses, placed */
    v = json_object_get(jk, "obj");
    plume_json_subkey(kk, kp, "obj");
    if (!json_is_string(v))
        return plume_json_bad(c, PLUME_EFORMAT, kk, "must be a file name (an OBJ triangle surface)");
    char path[4096];
    plume_json_resolve(c, json_string_value(v), path, sizeof path);
    plume_obj_data o;
    plume_err e2 = {{0}};
    if ((st = plume_obj_read(path, &o, &e2)) != PLUME_OK)
        return plume_json_bad(c, st, kk, "(%s)", e2.msg);
    plume_index *map = malloc((size_t)(o.nv + 1) * sizeof *map);
    b->tri = malloc((size_t)(3 * o.nf + 1) * sizeof *b->tri);
    b->y = malloc((size_t)(3 * o.nv + 1) * sizeof *b->y);
    if (!map || !b->tri || !b->y) {
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    if (o.nf < 1) {
        st = plume_json_bad(c, PLUME_EINVAL, kk, "(%s) has no faces", path);
        goto done;
    }
    for (plume_index i = 0; i < o.nv; i++)
        map[i] = -1;
    for (plume_index k = 0; k < 3 * o.nf; k++)
        map[o.f[k]] = 0;
    for (plume_index i = 0; i < o.nv; i++)
        if (map[i] == 0) {
            double y[3] = {o.v[2 * i], o.v[2 * i + 1], o.z[i]};
            map[i] = b->nv;
            place_point(&pl, y, b->y + 3 * b->nv++);
        }
    for (plume_index k = 0; k < 3 * o.nf; k++)
        b->tri[k] = map[o.f[k]];
    b->nt = o.nf;
done:
    free(map);
    plume_obj_free(&o);
    return st;
}

/* The merged mesh under construction. */
typedef struct {
    double *X, *x, *bd;
    plume_index *tri, *barb;
    int *mat;
    plume_index nv, nt, nbarb;
} merged;

static int grow(void **p, size_t n, size_t size)
{
    void *q = realloc(*p, (n + 1) * size);
    if (!q)
        return 0;
    *p = q;
    return 1;
}

/* A new handle of the scene (freed with it), with room for nids vertex ids in *ids when nids > 0. */
static plume_status add_handle(const plume_json_ctx *c, plume_scene *s, plume_index nids, plume_handle **h,
                               plume_index **ids)
{
    if (!grow((void **)&s->handles, (size_t)s->nhandles + 1, sizeof *s->handles))
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    *h = s->handles + s->nhandles++;
    memset(*h, 0, sizeof **h);
    if (nids > 0) {
        (*h)->vertices = *ids = malloc((size_t)nids * sizeof **ids);
        if (!*ids)
            return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    }
    return PLUME_OK;
}

/* A handle that moves like kinematic body b (its own copies of the keyframes). */
static plume_status follow(const plume_json_ctx *c, const kinematic_body *b, plume_index *ids, plume_index n, plume_handle *h)
{
    double *t = malloc((size_t)b->nkeys * sizeof *t), *off = malloc((size_t)(3 * b->nkeys) * sizeof *off),
           *rot = malloc((size_t)(3 * b->nkeys) * sizeof *rot);
    h->vertices = ids, h->nvertices = n;
    h->times = t, h->offsets = off, h->rotations = rot;
    if (!t || !off || !rot)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    h->nkeys = b->nkeys;
    memcpy(t, b->times, (size_t)b->nkeys * sizeof *t);
    memcpy(off, b->offsets, (size_t)(3 * b->nkeys) * sizeof *off);
    memcpy(rot, b->rotations, (size_t)(3 * b->nkeys) * sizeof *rot);
    memcpy(h->pivot, b->pivot, sizeof h->pivot);
    return PLUME_OK;
}

/* An elastic object's mesh into sub (map/nobj: an OBJ mesh's vertex map), parsed like the top-level
 * "mesh" with errors under the object's key (cc), its material ids checked against the scene's,
 * its size and its constrained edges. */
static plume_status object_mesh(const plume_json_ctx *c, const plume_json_ctx *cc, json_t *jo, const plume_scene *s,
                                const plume_scene_load_opts *o, plume_scene *sub, plume_index **map, plume_index *nobj)
{
    json_t *jm = json_object_get(jo, "mesh");
    if (!json_is_object(jm))
        return plume_json_bad(cc, PLUME_EFORMAT, "mesh", "must be an object {\"feather\": ...}, {\"obj\": ...} or "
                                                         "{\"rectangle\": ...}");
    int feather = json_object_get(jm, "feather") != NULL, rectangle = json_object_get(jm, "rectangle") != NULL;
    if (feather + rectangle + (json_object_get(jm, "obj") != NULL) != 1)
        return plume_json_bad(cc, PLUME_EFORMAT, "mesh", "needs one of \"obj\", \"feather\" or \"rectangle\"");
    plume_status st;
    if (feather)
        st = plume_scene_mesh_from_feather(cc, jm, sub, o);
    else if (rectangle)
        st = plume_scene_mesh_from_rectangle(cc, jm, sub, o);
    else
        st = plume_scene_mesh_from_obj(cc, jm, sub, map, nobj);
    if (st != PLUME_OK)
        return st;
    const plume_mesh *m = sub->mesh;
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] < 0 || m->material[t] >= s->nmat)
            return plume_json_bad(cc, PLUME_EINVAL, "mesh", "uses material %d (triangle %ld), but materials has %d entr%s",
                                  m->material[t], (long)t, s->nmat, s->nmat == 1 ? "y" : "ies");
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (plume_index i = 0; i < m->nv; i++)
        for (int a = 0; a < 2; a++)
            lo[a] = fmin(lo[a], m->X[2 * i + a]), hi[a] = fmax(hi[a], m->X[2 * i + a]);
    sub->length = hypot(hi[0] - lo[0], hi[1] - lo[1]);
    /* its split lines before its handles select (they see the copies) and before its barb edges */
    if ((st = plume_scene_parse_splits(cc, jo, sub)) != PLUME_OK)
        return st;
    return plume_scene_constrained_edges(sub, c->err);
}

/* The object's split lines (sub->splits, its vertices from v0 on in the scene) join the scene's,
 * after those of earlier objects; every object that splits has one law (the scene's). */
static plume_status take_splits(const plume_json_ctx *cc, plume_scene *sub, plume_index v0, plume_scene *s)
{
    plume_split_lines *sl = sub->splits;
    if (!sl)
        return PLUME_OK;
    for (plume_index k = 0; k < 2 * sl->npairs; k++)
        sl->pairs[k] += v0;
    if (sl->mesh == sub->mesh)
        sl->mesh = NULL; /* the scene's merged mesh takes its place (merged_meshes) */
    if (!s->splits) {
        s->splits = sl;
        sub->splits = NULL;
        s->split_law = sub->split_law;
        memcpy(s->split_law_from, sub->split_law_from, sizeof s->split_law_from);
        return PLUME_OK;
    }
    const plume_separation_law *a = &s->split_law, *b = &sub->split_law;
    if (a->strength != b->strength || a->stiffness != b->stiffness || a->capture != b->capture)
        return plume_json_bad(cc, PLUME_EINVAL, "splits.law", "differs from an earlier object's (strength %g against %g "
                              "N/m, stiffness %g against %g N/m^2, capture %g against %g m): the objects of a scene "
                              "split by one law", b->strength, a->strength, b->stiffness, a->stiffness, b->capture,
                              a->capture);
    plume_split_lines *t = s->splits;
    const int nl = t->nlines + sl->nlines;
    const plume_index np = t->npairs + sl->npairs;
    double *offset = realloc(t->offset, (size_t)nl * sizeof *offset);
    if (offset)
        t->offset = offset;
    plume_index *first = realloc(t->first, (size_t)(nl + 1) * sizeof *first);
    if (first)
        t->first = first;
    plume_index *pairs = realloc(t->pairs, (size_t)(2 * np) * sizeof *pairs);
    if (pairs)
        t->pairs = pairs;
    double *length = realloc(t->length, (size_t)np * sizeof *length);
    if (length)
        t->length = length;
    if (!offset || !first || !pairs || !length)
        return plume_err_set(cc->err, PLUME_ENOMEM, "%s: out of memory", cc->file);
    for (int l = 0; l < sl->nlines; l++) {
        t->offset[t->nlines + l] = sl->offset[l];
        t->first[t->nlines + l + 1] = t->npairs + sl->first[l + 1];
    }
    memcpy(t->pairs + 2 * t->npairs, sl->pairs, (size_t)(2 * sl->npairs) * sizeof *t->pairs);
    memcpy(t->length + t->npairs, sl->length, (size_t)sl->npairs * sizeof *t->length);
    t->nlines = nl, t->npairs = np;
    return PLUME_OK;
}

/* The object's "handles", added to the scene, selecting in the object's own mesh sub. */
static plume_status object_handles(const plume_json_ctx *c, const plume_json_ctx *cc, json_t *jo, plume_scene *s,
                                   const plume_scene *sub, const plume_index *map, plume_index nobj)
{
    json_t *jh = json_object_get(jo, "handles");
    if (jh && !json_is_array(jh))
        return plume_json_bad(cc, PLUME_EFORMAT, "handles", "must be an array of handles");
    plume_status st = PLUME_OK;
    for (size_t k = 0; jh && k < json_array_size(jh); k++) {
        char kp[PLUME_JSON_KEY_MAX];
        plume_handle *h;
        plume_json_subindex(kp, "handles", k);
        if ((st = add_handle(c, s, 0, &h, NULL)) != PLUME_OK ||
            (st = plume_scene_parse_handle(cc, json_array_get(jh, k), kp, sub, map, nobj, h)) != PLUME_OK)
            return st;
    }
    return st;
}

/* The object's "attach" (ja, not NULL): a handle of the vertices it selects in sub that follows the
 * kinematic body it names. */
static plume_status object_attach(const plume_json_ctx *c, const plume_json_ctx *cc, json_t *ja, plume_scene *s,
                                  const plume_scene *sub, const plume_index *map, plume_index nobj,
                                  const kinematic_body *kin, int nkin)
{
    static const char *const keys[] = {"to", "near", "radius", "vertices", "box", NULL};
    if (!json_is_object(ja))
        return plume_json_bad(cc, PLUME_EFORMAT, "attach", "must be an object {\"to\": kinematic object, selector}");
    plume_status st;
    if ((st = plume_json_check_keys(cc, ja, "attach", keys)) != PLUME_OK)
        return st;
    json_t *jt = json_object_get(ja, "to");
    const char *to = json_is_string(jt) ? json_string_value(jt) : NULL;
    int b = 0;
    while (to && b < nkin && strcmp(kin[b].name, to) != 0)
        b++;
    if (!to || b == nkin)
        return plume_json_bad(cc, PLUME_EINVAL, "attach.to", "must name a kinematic object (got %s%s%s)", to ? "\"" : "",
                              to ? to : "no name", to ? "\"" : "");
    plume_index *ids = NULL, n = 0;
    plume_handle *h;
    if ((st = add_handle(c, s, sub->mesh->nv + 1, &h, &ids)) != PLUME_OK ||
        (st = plume_scene_select(cc, ja, "attach", sub, map, nobj, ids, &n)) != PLUME_OK ||
        (st = follow(c, kin + b, ids, n, h)) != PLUME_OK)
        return st;
    return PLUME_OK;
}

/* The object's handles (s->handles[h0..]) over its nv vertices: refused if a vertex is in two of
 * them (it would follow two paths), then renumbered to the merged mesh (from v0). */
static plume_status own_handles(const plume_json_ctx *c, const plume_json_ctx *cc, plume_scene *s, int h0,
                                plume_index nv, int has_attach, plume_index v0)
{
    plume_index *owner = malloc((size_t)(nv + 1) * sizeof *owner);
    if (!owner)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (plume_index i = 0; i < nv; i++)
        owner[i] = -1;
    plume_status st = PLUME_OK;
    for (int h = h0; h < s->nhandles && st == PLUME_OK; h++) {
        plume_index *ids = (plume_index *)s->handles[h].vertices;
        for (plume_index i = 0; i < s->handles[h].nvertices; i++) {
            if (owner[ids[i]] >= 0 && owner[ids[i]] != h) {
                st = plume_json_bad(cc, PLUME_EINVAL, has_attach && h == s->nhandles - 1 ? "attach" : "handles",
                                    "shares vertex %ld with another handle of the object: a vertex can follow one handle only",
                                    (long)ids[i]);
                break;
            }
            owner[ids[i]] = h;
        }
        for (plume_index i = 0; st == PLUME_OK && i < s->handles[h].nvertices; i++)
            ids[i] += v0;
    }
    free(owner);
    return st;
}

/* Appends the object's mesh and barb edges (sub) to mg, placed by pl. */
static plume_status append_placed(const plume_json_ctx *c, const plume_scene *sub, const placement *pl, merged *mg)
{
    const plume_mesh *m = sub->mesh;
    const plume_index v0 = mg->nv;
    if (!grow((void **)&mg->X, (size_t)(2 * (mg->nv + m->nv)), sizeof *mg->X) ||
        !grow((void **)&mg->x, (size_t)(3 * (mg->nv + m->nv)), sizeof *mg->x) ||
        !grow((void **)&mg->tri, (size_t)(3 * (mg->nt + m->nt)), sizeof *mg->tri) ||
        !grow((void **)&mg->bd, (size_t)(2 * (mg->nt + m->nt)), sizeof *mg->bd) ||
        !grow((void **)&mg->mat, (size_t)(mg->nt + m->nt), sizeof *mg->mat) ||
        !grow((void **)&mg->barb, (size_t)(2 * (mg->nbarb + sub->nbarb)), sizeof *mg->barb))
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (plume_index i = 0; i < m->nv; i++) {
        double y[3] = {m->X[2 * i], m->X[2 * i + 1], 0.0};
        mg->X[2 * (v0 + i)] = pl->scale * y[0];
        mg->X[2 * (v0 + i) + 1] = pl->scale * y[1];
        place_point(pl, y, mg->x + 3 * (v0 + i));
    }
    for (plume_index t = 0; t < m->nt; t++) {
        for (int k = 0; k < 3; k++)
            mg->tri[3 * (mg->nt + t) + k] = m->tri[3 * t + k] + v0;
        mg->bd[2 * (mg->nt + t)] = m->barb_dir[2 * t];
        mg->bd[2 * (mg->nt + t) + 1] = m->barb_dir[2 * t + 1];
        mg->mat[mg->nt + t] = m->material[t];
    }
    for (plume_index k = 0; k < 2 * sub->nbarb; k++)
        mg->barb[2 * mg->nbarb + k] = sub->barb_edges[k] + v0;
    mg->nv += m->nv, mg->nt += m->nt, mg->nbarb += sub->nbarb;
    return PLUME_OK;
}

/* An elastic object: its mesh (parsed like the top-level "mesh", errors under its key), placement,
 * handles and attachments, appended to mg; its vertices become v0 = mg->nv on. */
static plume_status parse_elastic(const plume_json_ctx *c, json_t *jo, const char *where, plume_scene *s,
                                  const plume_scene_load_opts *o, const kinematic_body *kin, int nkin, merged *mg)
{
    plume_json_ctx cc = *c;
    cc.prefix = where;
    plume_scene sub;
    memset(&sub, 0, sizeof sub);
    sub.path = s->path;
    sub.nmat = s->nmat;
    sub.mats = s->mats;
    sub.is_static = s->is_static;
    sub.has_contact = s->has_contact;
    sub.contact = s->contact;
    plume_index *map = NULL, nobj = 0;
    placement pl;
    plume_status st;
    int h0 = s->nhandles;
    if ((st = parse_place(c, jo, where, &pl)) != PLUME_OK)
        return st;
    /* handles and the attachment select in the object's own reference (before "place") */
    json_t *ja = json_object_get(jo, "attach");
    if ((st = object_mesh(c, &cc, jo, s, o, &sub, &map, &nobj)) != PLUME_OK ||
        (st = object_handles(c, &cc, jo, s, &sub, map, nobj)) != PLUME_OK ||
        (ja && (st = object_attach(c, &cc, ja, s, &sub, map, nobj, kin, nkin)) != PLUME_OK) ||
        (st = own_handles(c, &cc, s, h0, sub.mesh->nv, ja != NULL, mg->nv)) != PLUME_OK)
        goto done;
    const plume_index v0 = mg->nv;
    if ((st = append_placed(c, &sub, &pl, mg)) == PLUME_OK)
        st = take_splits(&cc, &sub, v0, s);
done:
    free(map);
    plume_scene_splits_free(&sub);
    plume_mesh_destroy(&sub.mesh);
    free(sub.barb_edges);
    return st;
}

static plume_status copy_mesh_part(const merged *mg, plume_index nt, plume_mesh **out, plume_err *err)
{
    plume_status st = plume_mesh_create(mg->nv, nt, 3, out, err);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "scene: out of memory");
    plume_mesh *m = *out;
    memcpy(m->X, mg->X, (size_t)(2 * mg->nv) * sizeof *m->X);
    memcpy(m->x, mg->x, (size_t)(3 * mg->nv) * sizeof *m->x);
    memcpy(m->tri, mg->tri, (size_t)(3 * nt) * sizeof *m->tri);
    memcpy(m->barb_dir, mg->bd, (size_t)(2 * nt) * sizeof *m->barb_dir);
    memcpy(m->material, mg->mat, (size_t)nt * sizeof *m->material);
    return PLUME_OK;
}

/* The objects' heads, before any mesh: each an object with known keys, a unique non-empty name and
 * exactly one of "mesh" and "kinematic" (a kinematic one with no handles or attach); the kinematic
 * bodies parsed into kin[0 .. *nkin) (attachments refer to them by name). */
static plume_status parse_heads(const plume_json_ctx *c, json_t *v, kinematic_body *kin, int *nkin)
{
    static const char *const keys[] = {"name", "mesh", "kinematic", "place", "handles", "attach", "splits", NULL};
    plume_status st;
    for (size_t k = 0; k < json_array_size(v); k++) {
        char kp[PLUME_JSON_KEY_MAX], kn[PLUME_JSON_KEY_MAX];
        json_t *jo = json_array_get(v, k);
        plume_json_subindex(kp, "objects", k);
        if (!json_is_object(jo))
            return plume_json_bad(c, PLUME_EFORMAT, kp, "must be an object");
        if ((st = plume_json_check_keys(c, jo, kp, keys)) != PLUME_OK)
            return st;
        json_t *jn = json_object_get(jo, "name");
        plume_json_subkey(kn, kp, "name");
        if (!json_is_string(jn) || !*json_string_value(jn))
            return plume_json_bad(c, PLUME_EFORMAT, kn, jn ? "must be a non-empty string" : "is missing (every object has a name)");
        for (size_t j = 0; j < k; j++)
            if (strcmp(json_string_value(json_object_get(json_array_get(v, j), "name")), json_string_value(jn)) == 0)
                return plume_json_bad(c, PLUME_EINVAL, kn, "\"%s\" is also the name of objects[%zu]", json_string_value(jn), j);
        int is_kin = json_object_get(jo, "kinematic") != NULL;
        if (is_kin == (json_object_get(jo, "mesh") != NULL))
            return plume_json_bad(c, PLUME_EFORMAT, kp, "needs exactly one of \"mesh\" (an elastic shell) and \"kinematic\" "
                                                        "(a rigid body moved by keyframes)");
        if (is_kin && (json_object_get(jo, "handles") || json_object_get(jo, "attach") || json_object_get(jo, "splits")))
            return plume_json_bad(c, PLUME_EINVAL, kp, "is kinematic: its keyframes move all of it (no handles, attach or "
                                  "splits)");
        if (is_kin) {
            kin[*nkin].name = json_string_value(jn);
            if ((st = parse_kinematic(c, jo, kp, kin + (*nkin)++)) != PLUME_OK)
                return st;
        }
    }
    return PLUME_OK;
}

/* The elastic objects, in the list's order, appended to mg and recorded in s->objects. */
static plume_status add_elastic_objects(const plume_json_ctx *c, json_t *v, plume_scene *s, const plume_scene_load_opts *o,
                                        const kinematic_body *kin, int nkin, merged *mg)
{
    for (size_t k = 0; k < json_array_size(v); k++) {
        json_t *jo = json_array_get(v, k);
        if (json_object_get(jo, "kinematic"))
            continue;
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subindex(kp, "objects", k);
        plume_scene_object *ob = s->objects + s->nobjects;
        ob->v0 = mg->nv, ob->t0 = mg->nt;
        if (!(ob->name = strdup(json_string_value(json_object_get(jo, "name")))))
            return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        s->nobjects++;
        plume_status st = parse_elastic(c, jo, kp, s, o, kin, nkin, mg);
        if (st != PLUME_OK)
            return st;
        ob->nv = mg->nv - ob->v0, ob->nt = mg->nt - ob->t0;
    }
    return PLUME_OK;
}

/* Kinematic body kb appended to mg (held by a handle that follows its keyframes) and recorded in
 * s->objects. */
static plume_status add_kinematic_object(const plume_json_ctx *c, const kinematic_body *kb, plume_scene *s, merged *mg)
{
    plume_scene_object *ob = s->objects + s->nobjects;
    ob->v0 = mg->nv, ob->t0 = mg->nt, ob->nv = kb->nv, ob->nt = kb->nt, ob->kinematic = 1;
    if (!(ob->name = strdup(kb->name)) ||
        !grow((void **)&mg->X, (size_t)(2 * (mg->nv + kb->nv)), sizeof *mg->X) ||
        !grow((void **)&mg->x, (size_t)(3 * (mg->nv + kb->nv)), sizeof *mg->x) ||
        !grow((void **)&mg->tri, (size_t)(3 * (mg->nt + kb->nt)), sizeof *mg->tri) ||
        !grow((void **)&mg->bd, (size_t)(2 * (mg->nt + kb->nt)), sizeof *mg->bd) ||
        !grow((void **)&mg->mat, (size_t)(mg->nt + kb->nt), sizeof *mg->mat)) {
        free(ob->name);
        ob->name = NULL;
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    }
    s->nobjects++;
    plume_index *ids = NULL;
    plume_handle *h;
    plume_status st;
    if ((st = add_handle(c, s, kb->nv, &h, &ids)) != PLUME_OK)
        return st;
    for (plume_index i = 0; i < kb->nv; i++) {
        ids[i] = mg->nv + i;
        /* no flat reference: X is the projection, used by nothing elastic */
        mg->X[2 * (mg->nv + i)] = kb->y[3 * i], mg->X[2 * (mg->nv + i) + 1] = kb->y[3 * i + 1];
        memcpy(mg->x + 3 * (mg->nv + i), kb->y + 3 * i, 3 * sizeof *mg->x);
    }
    if ((st = follow(c, kb, ids, kb->nv, h)) != PLUME_OK)
        return st;
    for (plume_index t = 0; t < kb->nt; t++) {
        for (int a = 0; a < 3; a++)
            mg->tri[3 * (mg->nt + t) + a] = kb->tri[3 * t + a] + mg->nv;
        mg->bd[2 * (mg->nt + t)] = 1.0, mg->bd[2 * (mg->nt + t) + 1] = 0.0;
        mg->mat[mg->nt + t] = 0; /* a density for the (fixed) vertices' lumped mass; no energy */
    }
    mg->nv += kb->nv, mg->nt += kb->nt;
    return PLUME_OK;
}

/* The scene's mesh from mg, its elastic part (the first nt_elastic triangles) for the elastic terms
 * when there are kinematic bodies, its barb edges (taken from mg) and its size. */
static plume_status merged_meshes(const plume_json_ctx *c, merged *mg, plume_index nt_elastic, int nkin, plume_scene *s)
{
    plume_err e2 = {{0}};
    plume_status st;
    if ((st = copy_mesh_part(mg, mg->nt, &s->mesh, c->err)) != PLUME_OK)
        return st;
    if ((st = plume_mesh_build_topology_rigid(s->mesh, nt_elastic, &e2)) != PLUME_OK)
        return plume_json_bad(c, st, "objects", "do not make a valid mesh: %s", e2.msg);
    if (nkin > 0) {
        if ((st = copy_mesh_part(mg, nt_elastic, &s->elastic, c->err)) != PLUME_OK)
            return st;
        if ((st = plume_mesh_build_topology(s->elastic, &e2)) != PLUME_OK)
            return plume_json_bad(c, st, "objects", "do not make a valid mesh: %s", e2.msg);
    }
    s->barb_edges = mg->barb, s->nbarb = mg->nbarb;
    mg->barb = NULL;
    if (s->splits) {
        s->splits->mesh = s->mesh; /* the lines' mesh is the scene's (not theirs to free) */
        if ((st = plume_scene_splits_weld(s, c->err)) != PLUME_OK)
            return st;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (plume_index i = 0; i < mg->nv; i++)
        for (int a = 0; a < 3; a++)
            lo[a] = fmin(lo[a], mg->x[3 * i + a]), hi[a] = fmax(hi[a], mg->x[3 * i + a]);
    s->length = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    return PLUME_OK;
}

plume_status plume_scene_parse_objects(const plume_json_ctx *c, json_t *v, plume_scene *s, const plume_scene_load_opts *o)
{
    if (!json_is_array(v) || json_array_size(v) < 1)
        return plume_json_bad(c, PLUME_EFORMAT, "objects", "must be a non-empty array of objects ({\"name\", \"mesh\", "
                                                           "\"place\", ...} or {\"name\", \"kinematic\", ...})");
    size_t n = json_array_size(v);
    kinematic_body *kin = calloc(n, sizeof *kin);
    merged mg;
    memset(&mg, 0, sizeof mg);
    s->objects = calloc(n, sizeof *s->objects);
    plume_status st = PLUME_OK;
    int nkin = 0;
    if (!kin || !s->objects) {
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    /* names and kinds first, then the elastic objects in order, then the kinematic ones */
    if ((st = parse_heads(c, v, kin, &nkin)) != PLUME_OK || (st = add_elastic_objects(c, v, s, o, kin, nkin, &mg)) != PLUME_OK)
        goto done;
    plume_index nt_elastic = mg.nt;
    if (nt_elastic == 0) {
        st = plume_json_bad(c, PLUME_EINVAL, "objects", "has no elastic object (one with a \"mesh\"): nothing to simulate");
        goto done;
    }
    for (int b = 0; b < nkin; b++)
        if ((st = add_kinematic_object(c, kin + b, s, &mg)) != PLUME_OK)
            goto done;
    st = merged_meshes(c, &mg, nt_elastic, nkin, s);
done:
    for (int b = 0; kin && b < nkin; b++)
        kinematic_free(kin + b);
    free(kin);
    free(mg.X);
    free(mg.x);
    free(mg.bd);
    free(mg.tri);
    free(mg.barb);
    free(mg.mat);
    return st;
}
