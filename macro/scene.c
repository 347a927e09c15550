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
    plume_mesh_destroy(&s->elastic);
    for (int k = 0; k < s->nobjects; k++)
        free(s->objects[k].name);
    free(s->objects);
    free(s->mats);
    for (int h = 0; h < s->nhandles; h++) {
        free((void *)s->handles[h].vertices);
        free((void *)s->handles[h].times);
        free((void *)s->handles[h].offsets);
        free((void *)s->handles[h].rotations);
    }
    free(s->handles);
    free(s->barb_edges);
    free(s->render);
    free(s->clamped);
    free(s->supported);
    free(s->force);
    for (int k = 0; k < s->nmoments; k++) {
        free(s->moments[k].end);
        free(s->moments[k].row);
    }
    free(s->moments);
    for (int k = 0; k < s->nprobes; k++) {
        free(s->probes[k].name);
        free(s->probes[k].vertices);
        free(s->probes[k].source);
    }
    free(s->probes);
    free(s);
    *ps = NULL;
}
/* One material entry. */
static plume_status parse_material(const plume_json_ctx *c, json_t *jm, const char *where, int need_density,
                                   plume_scene_material *out)
{
    static const char *const keys[] = {"membrane", "bending", "density", "constraint", NULL};
    static const char *const ortho[] = {"E_xx", "E_yy", "nu_xy", "G_xy", "thickness", "kappa", NULL};
    static const char *const iso[] = {"E", "nu", "thickness", "kappa", NULL};
    static const char *const bend2[] = {"D_long", "D_trans", "D_twist", "D_coupling", NULL};
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
        out->bending.D_coupling = mm->nu_xy * out->bending.D_trans; /* D_12 = nu_xy D_22 */
        out->bending.D_twist = mm->G_xy * h3 / 12.0;                /* D_66 = G t^3 / 12 */
    } else if (json_is_object(jb) && json_object_get(jb, "D")) {
        double D = 0.0;
        if ((st = plume_json_check_keys(c, jb, kp, bend1)) != PLUME_OK || (st = plume_json_positive(c, jb, kp, "D", 1, 1, &D, NULL)))
            return st;
        out->bending.D_long = out->bending.D_trans = D;
    } else if (json_is_object(jb)) {
        if ((st = plume_json_check_keys(c, jb, kp, bend2)) != PLUME_OK ||
            (st = plume_json_positive(c, jb, kp, "D_long", 1, 1, &out->bending.D_long, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_trans", 1, 1, &out->bending.D_trans, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_twist", 0, 1, &out->bending.D_twist, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_coupling", 0, 1, &out->bending.D_coupling, NULL)))
            return st;
    } else {
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be {\"D_long\", \"D_trans\"}, {\"D\"} or \"from_membrane\"");
    }
    if ((st = plume_json_positive(c, jm, where, "density", need_density, 0, &out->density, NULL)) != PLUME_OK)
        return st;
    json_t *jc = json_object_get(jm, "constraint");
    plume_json_subkey(kp, where, "constraint");
    if (jc && !json_is_boolean(jc))
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be true or false");
    out->constraint = jc ? json_is_true(jc) : 0;
    return PLUME_OK;
}

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

static plume_status parse_scene(plume_json_ctx *c, json_t *doc, plume_scene *s, const plume_scene_load_opts *o)
{
    static const char *const keys[] = {"mesh", "materials", "handles", "gravity", "dt", "duration", "solver",
                                       "max_halvings", "max_iter", "output_every", "render", "camera", "solve",
                                       "steps", "clamps", "supports", "loads", "probes", "bending_model", "contact",
                                       "objects", NULL};
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
    if ((v = json_object_get(doc, "solve"))) {
        const char *sv = json_is_string(v) ? json_string_value(v) : "";
        if (strcmp(sv, "static") != 0 && strcmp(sv, "dynamic") != 0)
            return plume_json_bad(c, PLUME_EINVAL, "solve", "must be \"static\" or \"dynamic\"");
        s->is_static = sv[0] == 's';
    }
    if ((v = json_object_get(doc, "bending_model"))) {
        const char *bv = json_is_string(v) ? json_string_value(v) : "";
        if (strcmp(bv, "hinge") != 0 && strcmp(bv, "shape_operator") != 0)
            return plume_json_bad(c, PLUME_EINVAL, "bending_model", "must be \"shape_operator\" or \"hinge\"");
        s->hinge_bending = bv[0] == 'h';
    }
    if ((v = json_object_get(doc, "contact")) && (st = plume_scene_parse_contact(c, v, s)) != PLUME_OK)
        return st;
    s->steps = 10;
    long steps = s->steps;
    if ((st = plume_json_int(c, doc, "", "steps", 1, 1000000, &steps)) != PLUME_OK)
        return st;
    s->steps = (int)steps;
    /* a static scene has no clock: dt and duration are optional (and unused) there */
    if ((st = plume_json_positive(c, doc, "", "dt", !s->is_static, 0, &s->dt, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, doc, "", "duration", !s->is_static, 0, &s->duration, NULL)) != PLUME_OK)
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
        if ((st = parse_material(c, json_array_get(jm, (size_t)k), kp, !s->is_static, s->mats + k)) != PLUME_OK)
            return st;
    }

    /* objects: many bodies, each meshed, placed and held on its own */
    json_t *objects = json_object_get(doc, "objects");
    if (objects) {
        if (json_object_get(doc, "mesh"))
            return plume_json_bad(c, PLUME_EFORMAT, "mesh", "cannot be given with \"objects\" (each object has its own)");
        if (json_object_get(doc, "handles"))
            return plume_json_bad(c, PLUME_EFORMAT, "handles", "cannot be given with \"objects\" (each object has its own "
                                                               "\"handles\" and \"attach\")");
        if (s->is_static)
            return plume_json_bad(c, PLUME_EINVAL, "objects", "are for dynamic scenes (\"solve\": \"static\" takes a \"mesh\")");
        if ((st = plume_scene_parse_objects(c, objects, s, o)) != PLUME_OK)
            return st;
        return plume_scene_parse_static(c, doc, s, NULL, 0);
    }

    /* mesh */
    json_t *mesh = json_object_get(doc, "mesh");
    if (!json_is_object(mesh))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh",
                              mesh ? "must be an object {\"obj\": ...}, {\"feather\": ...} or {\"rectangle\": ...}"
                                   : "is missing ({\"obj\": \"file.obj\"}, {\"feather\": \"shape.json\", ...} or "
                                     "{\"rectangle\": [lx, ly], ...})");
    int feather = json_object_get(mesh, "feather") != NULL, rectangle = json_object_get(mesh, "rectangle") != NULL;
    if (feather + rectangle + (json_object_get(mesh, "obj") != NULL) != 1)
        return plume_json_bad(c, PLUME_EFORMAT, "mesh", "needs one of \"obj\" (a triangle mesh), \"feather\" (a feather "
                                                        "shape file) or \"rectangle\" ([lx, ly])");
    if (o && (o->edge > 0.0 || o->pattern) && !feather && !rectangle)
        return plume_json_bad(c, PLUME_EINVAL, "mesh", "is an OBJ file: its edge and pattern cannot be overridden");
    if (o && o->pattern && !rectangle)
        return plume_json_bad(c, PLUME_EINVAL, "mesh", "is not a rectangle: only a rectangle has a pattern to override");
    if (feather)
        st = plume_scene_mesh_from_feather(c, mesh, s, o);
    else if (rectangle)
        st = plume_scene_mesh_from_rectangle(c, mesh, s, o);
    else
        st = plume_scene_mesh_from_obj(c, mesh, s, &map, &nobj);
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
            if ((st = plume_scene_parse_handle(c, json_array_get(jh, k), kp, s, map, nobj, s->handles + k)) != PLUME_OK)
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
    if ((st = plume_scene_parse_static(c, doc, s, map, nobj)) != PLUME_OK)
        goto done;
    st = plume_scene_constrained_edges(s, c->err);
done:
    free(map);
    return st;
}

plume_status plume_scene_load(const char *path, plume_scene **out, plume_err *err)
{
    return plume_scene_load_with(path, NULL, out, err);
}

plume_status plume_scene_load_with(const char *path, const plume_scene_load_opts *o, plume_scene **out,
                                   plume_err *err)
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
        st = parse_scene(&c, doc, s, o);
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
