/* plume: reading and validating a shell scene from JSON (format in scene.h and README.md); the
 * mesh is read in scene_mesh.c, the problem built in scene_build.c. */
#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal/scene_internal.h"

void plume_scene_destroy(plume_scene **ps)
{
    if (!ps || !*ps)
        return;
    plume_scene *s = *ps;
    free(s->path);
    plume_mesh_destroy(&s->mesh);
    free(s->mats);
    for (int h = 0; h < s->nhandles; h++) {
        free((void *)s->handles[h].vertices);
        free((void *)s->handles[h].times);
        free((void *)s->handles[h].offsets);
    }
    free(s->handles);
    free(s->barb_edges);
    free(s->render);
    free(s);
    *ps = NULL;
}
/* One material entry. */
static plume_status parse_material(const plume_json_ctx *c, json_t *jm, const char *where, plume_scene_material *out)
{
    static const char *const keys[] = {"membrane", "bending", "density", "constraint", NULL};
    static const char *const ortho[] = {"E_xx", "E_yy", "nu_xy", "G_xy", "thickness", "kappa", NULL};
    static const char *const iso[] = {"E", "nu", "thickness", "kappa", NULL};
    static const char *const bend2[] = {"D_long", "D_trans", NULL};
    static const char *const bend1[] = {"D", NULL};
    char kp[PLUME_JSON_KEY_MAX];
    plume_status st;
    if (!json_is_object(jm))
        return plume_json_bad(c, PLUME_EFORMAT, where, "must be an object with membrane, bending, density, constraint");
    if ((st = plume_json_check_keys(c, jm, where, keys)) != PLUME_OK)
        return st;
    memset(out, 0, sizeof *out);
    plume_membrane_material *mm = &out->membrane;
    plume_json_subkey(kp, where, "membrane");
    json_t *mem = json_object_get(jm, "membrane");
    if (!json_is_object(mem))
        return plume_json_bad(c, PLUME_EFORMAT, kp,
                   mem ? "must be an object {E_xx, E_yy, nu_xy, G_xy, thickness, kappa} or {E, nu, thickness, kappa}"
                       : "is missing (an object {E_xx, E_yy, nu_xy, G_xy, thickness, kappa} or {E, nu, thickness, kappa})");
    if (json_object_get(mem, "E")) {
        double E = 0.0, nu = 0.0;
        if ((st = plume_json_check_keys(c, mem, kp, iso)) != PLUME_OK || (st = plume_json_positive(c, mem, kp, "E", 1, 0, &E, NULL)) ||
            (st = plume_json_number(c, mem, kp, "nu", 0, &nu, NULL)))
            return st;
        if (!(nu > -1.0 && nu < 0.5)) {
            char kn[PLUME_JSON_KEY_MAX];
            plume_json_subkey(kn, kp, "nu");
            return plume_json_bad(c, PLUME_EINVAL, kn, "must be in (-1, 0.5) (got %g)", nu);
        }
        mm->E_xx = mm->E_yy = E;
        mm->nu_xy = nu;
        mm->G_xy = E / (2.0 * (1.0 + nu));
    } else {
        if ((st = plume_json_check_keys(c, mem, kp, ortho)) != PLUME_OK ||
            (st = plume_json_positive(c, mem, kp, "E_xx", 1, 0, &mm->E_xx, NULL)) ||
            (st = plume_json_positive(c, mem, kp, "E_yy", 1, 0, &mm->E_yy, NULL)) ||
            (st = plume_json_number(c, mem, kp, "nu_xy", 0, &mm->nu_xy, NULL)) ||
            (st = plume_json_positive(c, mem, kp, "G_xy", 1, 0, &mm->G_xy, NULL)))
            return st;
    }
    if ((st = plume_json_positive(c, mem, kp, "thickness", 1, 0, &mm->h, NULL)) ||
        (st = plume_json_positive(c, mem, kp, "kappa", 0, 1, &mm->kappa, NULL)))
        return st;
    plume_err e2 = {{0}};
    if ((st = plume_membrane_material_check(mm, &e2)) != PLUME_OK)
        return plume_json_bad(c, st, kp, "is not a valid material: %s", e2.msg);

    /* bending: explicit, or that of a plate of the membrane's moduli and thickness */
    plume_json_subkey(kp, where, "bending");
    json_t *jb = json_object_get(jm, "bending");
    if (!jb || (json_is_string(jb) && strcmp(json_string_value(jb), "from_membrane") == 0)) {
        double nu_yx = mm->nu_xy * mm->E_yy / mm->E_xx, h3 = mm->h * mm->h * mm->h;
        double den = 12.0 * (1.0 - mm->nu_xy * nu_yx);
        out->bending.D_long = mm->E_xx * h3 / den;
        out->bending.D_trans = mm->E_yy * h3 / den;
    } else if (json_is_object(jb) && json_object_get(jb, "D")) {
        double D = 0.0;
        if ((st = plume_json_check_keys(c, jb, kp, bend1)) != PLUME_OK || (st = plume_json_positive(c, jb, kp, "D", 1, 1, &D, NULL)))
            return st;
        out->bending.D_long = out->bending.D_trans = D;
    } else if (json_is_object(jb)) {
        if ((st = plume_json_check_keys(c, jb, kp, bend2)) != PLUME_OK ||
            (st = plume_json_positive(c, jb, kp, "D_long", 1, 1, &out->bending.D_long, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_trans", 1, 1, &out->bending.D_trans, NULL)))
            return st;
    } else {
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be {\"D_long\", \"D_trans\"}, {\"D\"} or \"from_membrane\"");
    }
    if ((st = plume_json_positive(c, jm, where, "density", 1, 0, &out->density, NULL)) != PLUME_OK)
        return st;
    json_t *jc = json_object_get(jm, "constraint");
    plume_json_subkey(kp, where, "constraint");
    if (jc && !json_is_boolean(jc))
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be true or false");
    out->constraint = jc ? json_is_true(jc) : 0;
    return PLUME_OK;
}

/* One handle: its selector and keyframes. map/nobj translate OBJ vertex numbers (NULL: mesh ids). */
static plume_status parse_handle(const plume_json_ctx *c, json_t *jh, const char *where, const plume_scene *s,
                                 const plume_index *map, plume_index nobj, plume_handle *h)
{
    static const char *const keys[] = {"near", "radius", "vertices", "box", "keyframes", NULL};
    char kp[PLUME_JSON_KEY_MAX];
    plume_status st;
    if (!json_is_object(jh))
        return plume_json_bad(c, PLUME_EFORMAT, where, "must be an object with a selector (near/radius, vertices or box) and keyframes");
    if ((st = plume_json_check_keys(c, jh, where, keys)) != PLUME_OK)
        return st;
    const plume_mesh *m = s->mesh;
    json_t *jn = json_object_get(jh, "near"), *jv = json_object_get(jh, "vertices"), *jb = json_object_get(jh, "box");
    if ((jn != NULL) + (jv != NULL) + (jb != NULL) != 1)
        return plume_json_bad(c, PLUME_EFORMAT, where, "needs exactly one selector: \"near\" (with \"radius\"), \"vertices\" or \"box\"");
    plume_index *ids = malloc((size_t)(m->nv + 1) * sizeof *ids), n = 0;
    if (!ids)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    h->vertices = ids;
    double tol = 1e-12 * s->length;
    if (jn) {
        double p[2], r = -1.0;
        int have_r = 0;
        plume_json_subkey(kp, where, "near");
        if ((st = plume_json_vector(c, jn, kp, 2, p)) != PLUME_OK ||
            (st = plume_json_positive(c, jh, where, "radius", 0, 1, &r, &have_r)) != PLUME_OK)
            return st;
        plume_index best = 0;
        double dbest = INFINITY;
        for (plume_index v = 0; v < m->nv; v++) {
            double dist = hypot(m->X[2 * v] - p[0], m->X[2 * v + 1] - p[1]);
            if (dist < dbest)
                dbest = dist, best = v;
            if (have_r && dist <= r + tol)
                ids[n++] = v;
        }
        if (!have_r) /* no radius: the nearest vertex */
            ids[n++] = best;
        if (n == 0)
            return plume_json_bad(c, PLUME_EINVAL, kp,
                       "with radius %g selects no vertex (the nearest one, %ld, is %g m away)", r, (long)best, dbest);
    } else if (jb) {
        double b[4];
        plume_json_subkey(kp, where, "box");
        if ((st = plume_json_vector(c, jb, kp, 4, b)) != PLUME_OK)
            return st;
        if (!(b[2] >= b[0] && b[3] >= b[1]))
            return plume_json_bad(c, PLUME_EINVAL, kp, "must be [x_min, y_min, x_max, y_max] with min <= max");
        for (plume_index v = 0; v < m->nv; v++) {
            double x = m->X[2 * v], y = m->X[2 * v + 1];
            if (x >= b[0] - tol && x <= b[2] + tol && y >= b[1] - tol && y <= b[3] + tol)
                ids[n++] = v;
        }
        if (n == 0)
            return plume_json_bad(c, PLUME_EINVAL, kp, "selects no vertex");
    } else {
        plume_json_subkey(kp, where, "vertices");
        if (!json_is_array(jv) || json_array_size(jv) < 1)
            return plume_json_bad(c, PLUME_EFORMAT, kp, "must be a non-empty array of vertex ids");
        plume_index limit = map ? nobj : m->nv;
        for (size_t i = 0; i < json_array_size(jv); i++) {
            json_t *e = json_array_get(jv, i);
            double d = json_is_number(e) ? json_number_value(e) : -1.0;
            if (!json_is_number(e) || d != floor(d) || d < 0 || d >= (double)limit)
                return plume_json_bad(c, PLUME_EINVAL, kp, "entry %zu must be a vertex id in [0, %ld)", i, (long)limit);
            plume_index id = map ? map[(plume_index)d] : (plume_index)d;
            if (id < 0)
                return plume_json_bad(c, PLUME_EINVAL, kp, "entry %zu: OBJ vertex %ld belongs to no face", i, (long)d);
            int dup = 0;
            for (plume_index k = 0; k < n && !dup; k++)
                dup = ids[k] == id;
            if (!dup)
                ids[n++] = id;
        }
    }
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
static plume_status parse_scene(plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    static const char *const keys[] = {"mesh", "materials", "handles", "gravity", "dt", "duration", "solver",
                                       "max_halvings", "max_iter", "output_every", "render", "camera", NULL};
    plume_status st;
    plume_index *map = NULL, nobj = 0;
    if (!json_is_object(doc))
        return plume_err_set(c->err, PLUME_EFORMAT, "%s: expected a JSON object at the top level", c->file);
    if ((st = plume_json_check_keys(c, doc, "", keys)) != PLUME_OK)
        return st;

    /* run settings first: cheap, and their errors need no mesh */
    s->gravity[0] = s->gravity[1] = 0.0;
    s->gravity[2] = -9.81;
    s->solver = PLUME_SOLVER_NEWTON;
    s->max_halvings = 6;
    s->max_iter = 100;
    s->output_every = 1;
    s->camera[0] = 60.0;
    s->camera[1] = 30.0;
    json_t *v;
    if ((v = json_object_get(doc, "gravity")) && (st = plume_json_vector(c, v, "gravity", 3, s->gravity)) != PLUME_OK)
        return st;
    if ((st = plume_json_positive(c, doc, "", "dt", 1, 0, &s->dt, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, doc, "", "duration", 1, 0, &s->duration, NULL)) != PLUME_OK)
        return st;
    if ((v = json_object_get(doc, "solver"))) {
        if (!json_is_string(v) || plume_solver_kind_parse(json_string_value(v), &s->solver) != PLUME_OK)
            return plume_json_bad(c, PLUME_EINVAL, "solver", "must be \"newton\", \"ipopt\" or \"linearized\" (got %s%s%s)",
                       json_is_string(v) ? "\"" : "", json_is_string(v) ? json_string_value(v) : "a non-string",
                       json_is_string(v) ? "\"" : "");
    }
    long lv = s->max_halvings;
    if ((st = plume_json_int(c, doc, "", "max_halvings", 0, 30, &lv)) != PLUME_OK)
        return st;
    s->max_halvings = (int)lv;
    lv = s->max_iter;
    if ((st = plume_json_int(c, doc, "", "max_iter", 1, 100000, &lv)) != PLUME_OK)
        return st;
    s->max_iter = (int)lv;
    lv = s->output_every;
    if ((st = plume_json_int(c, doc, "", "output_every", 1, 1000000, &lv)) != PLUME_OK)
        return st;
    s->output_every = (int)lv;
    if ((v = json_object_get(doc, "render"))) {
        if (!json_is_array(v))
            return plume_json_bad(c, PLUME_EFORMAT, "render", "must be an array of frame indices");
        s->render = malloc((json_array_size(v) + 1) * sizeof *s->render);
        if (!s->render)
            return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        for (size_t i = 0; i < json_array_size(v); i++) {
            json_t *e = json_array_get(v, i);
            double d = json_is_number(e) ? json_number_value(e) : -1.0;
            if (!json_is_number(e) || d != floor(d) || d < 0 || d > 1e9) {
                char kp[PLUME_JSON_KEY_MAX];
                plume_json_subindex(kp, "render", i);
                return plume_json_bad(c, PLUME_EINVAL, kp, "must be a frame index (an integer >= 0)");
            }
            s->render[s->nrender++] = (long)d;
        }
    }
    if ((v = json_object_get(doc, "camera"))) {
        static const char *const ck[] = {"rot_x", "rot_z", NULL};
        if (!json_is_object(v))
            return plume_json_bad(c, PLUME_EFORMAT, "camera", "must be an object {\"rot_x\": deg, \"rot_z\": deg}");
        if ((st = plume_json_check_keys(c, v, "camera", ck)) != PLUME_OK ||
            (st = plume_json_number(c, v, "camera", "rot_x", 0, &s->camera[0], NULL)) != PLUME_OK ||
            (st = plume_json_number(c, v, "camera", "rot_z", 0, &s->camera[1], NULL)) != PLUME_OK)
            return st;
        if (!(s->camera[0] >= 0.0 && s->camera[0] <= 180.0))
            return plume_json_bad(c, PLUME_EINVAL, "camera.rot_x", "must be in [0, 180] degrees (got %g)", s->camera[0]);
        if (!(s->camera[1] >= 0.0 && s->camera[1] <= 360.0))
            return plume_json_bad(c, PLUME_EINVAL, "camera.rot_z", "must be in [0, 360] degrees (got %g)", s->camera[1]);
    }

    /* materials */
    json_t *jm = json_object_get(doc, "materials");
    if (!json_is_array(jm) || json_array_size(jm) < 1)
        return plume_json_bad(c, PLUME_EFORMAT, "materials", jm ? "must be a non-empty array of materials (indexed by material id)"
                                                     : "is missing (an array of materials indexed by material id)");
    s->nmat = (int)json_array_size(jm);
    s->mats = calloc((size_t)s->nmat, sizeof *s->mats);
    if (!s->mats)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (int k = 0; k < s->nmat; k++) {
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subindex(kp, "materials", (size_t)k);
        if ((st = parse_material(c, json_array_get(jm, (size_t)k), kp, s->mats + k)) != PLUME_OK)
            return st;
    }

    /* mesh */
    json_t *mesh = json_object_get(doc, "mesh");
    if (!json_is_object(mesh))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh", mesh ? "must be an object {\"obj\": ...} or {\"feather\": ...}"
                                                  : "is missing ({\"obj\": \"file.obj\"} or {\"feather\": \"shape.json\", ...})");
    int feather = json_object_get(mesh, "feather") != NULL;
    if (!feather && !json_object_get(mesh, "obj"))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh", "needs \"obj\" (a triangle mesh) or \"feather\" (a feather shape file)");
    st = feather ? plume_scene_mesh_from_feather(c, mesh, s) : plume_scene_mesh_from_obj(c, mesh, s, &map, &nobj);
    if (st != PLUME_OK)
        goto done;
    const plume_mesh *m = s->mesh;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (plume_index i = 0; i < m->nv; i++)
        for (int a = 0; a < 2; a++)
            lo[a] = fmin(lo[a], m->X[2 * i + a]), hi[a] = fmax(hi[a], m->X[2 * i + a]);
    s->length = hypot(hi[0] - lo[0], hi[1] - lo[1]);
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] < 0 || m->material[t] >= s->nmat) {
            st = plume_json_bad(c, PLUME_EINVAL, feather ? "materials" : "mesh.materials_by_group",
                     "%s: triangle %ld has material %d, but materials has %d entr%s (ids 0 to %d)",
                     feather ? "the feather mesh uses material 0 (vane) and 1 (rachis)" : "material id without a material",
                     (long)t, m->material[t], s->nmat, s->nmat == 1 ? "y" : "ies", s->nmat - 1);
            goto done;
        }

    /* handles */
    json_t *jh = json_object_get(doc, "handles");
    if (jh) {
        if (!json_is_array(jh)) {
            st = plume_json_bad(c, PLUME_EFORMAT, "handles", "must be an array of handles");
            goto done;
        }
        size_t nh = json_array_size(jh);
        s->handles = calloc(nh + 1, sizeof *s->handles);
        if (!s->handles) {
            st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
            goto done;
        }
        for (size_t k = 0; k < nh; k++) {
            char kp[PLUME_JSON_KEY_MAX];
            plume_json_subindex(kp, "handles", k);
            s->nhandles++;
            if ((st = parse_handle(c, json_array_get(jh, k), kp, s, map, nobj, s->handles + k)) != PLUME_OK)
                goto done;
        }
        /* a vertex in two handles would follow two paths */
        int *owner = malloc((size_t)m->nv * sizeof *owner);
        if (!owner) {
            st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
            goto done;
        }
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
        if (st != PLUME_OK)
            goto done;
    }
    st = plume_scene_constrained_edges(s, c->err);
done:
    free(map);
    return st;
}

plume_status plume_scene_load(const char *path, plume_scene **out, plume_err *err)
{
    if (!path || !*path || !out)
        return plume_err_set(err, PLUME_EINVAL, "scene: no file given");
    *out = NULL;
    plume_json_ctx c;
    memset(&c, 0, sizeof c);
    c.file = path;
    c.err = err;
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(c.dir, sizeof c.dir, "%.*s", (int)(slash == path ? 1 : slash - path), path);
    plume_status st;
    c.text = plume_read_text(path, err, "scene", &st);
    if (!c.text)
        return st;
    json_error_t je;
    json_t *doc = json_loads(c.text, JSON_REJECT_DUPLICATES, &je);
    if (!doc) {
        free(c.text);
        return plume_err_set(err, PLUME_EFORMAT, "%s:%d:%d: %s", path, je.line, je.column, je.text);
    }
    plume_scene *s = calloc(1, sizeof *s);
    st = PLUME_ENOMEM;
    if (s && (s->path = malloc(strlen(path) + 1)) != NULL) {
        memcpy(s->path, path, strlen(path) + 1);
        st = parse_scene(&c, doc, s);
    } else {
        plume_err_set(err, st, "%s: out of memory", path);
    }
    json_decref(doc);
    free(c.text);
    if (st != PLUME_OK) {
        plume_scene_destroy(&s);
        return st;
    }
    *out = s;
    return PLUME_OK;
}
