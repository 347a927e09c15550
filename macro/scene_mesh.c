/* The mesh of a scene: from an OBJ file or from the feather mesher, and its constrained barb
 * edges (macro/internal/scene_internal.h). */
#include "internal/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/io/obj_read.h"
#include "feather_mesh.h"
#include "grid_mesh.h"
#include "patch_mesh.h"

/* mesh.barb_direction, normalised; (1, 0) when absent */
static plume_status barb_direction(const plume_json_ctx *c, json_t *m, double d[2])
{
    d[0] = 1.0, d[1] = 0.0;
    json_t *jd = json_object_get(m, "barb_direction");
    if (!jd)
        return PLUME_OK;
    plume_status st = plume_json_vector(c, jd, "mesh.barb_direction", 2, d);
    if (st != PLUME_OK)
        return st;
    double len = hypot(d[0], d[1]);
    if (!(len > 0.0))
        return plume_json_bad(c, PLUME_EINVAL, "mesh.barb_direction", "must be a non-zero vector");
    d[0] /= len, d[1] /= len;
    return PLUME_OK;
}

/* Mesh from an OBJ: x, y reference coordinates, material by group, constant barb direction.
 * *vertex_map gets, for every OBJ vertex (0-based), its mesh id or -1 if no face uses it. */
plume_status plume_scene_mesh_from_obj(const plume_json_ctx *c, json_t *m, plume_scene *s, plume_index **vertex_map,
                                  plume_index *nobj)
{
    static const char *const keys[] = {"obj", "materials_by_group", "barb_direction", NULL};
    plume_status st = plume_json_check_keys(c, m, "mesh", keys);
    if (st != PLUME_OK)
        return st;
    json_t *jo = json_object_get(m, "obj");
    if (!json_is_string(jo))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh.obj", "must be a file name");
    double d[2];
    if ((st = barb_direction(c, m, d)) != PLUME_OK)
        return st;
    char path[4096];
    plume_json_resolve(c, json_string_value(jo), path, sizeof path);
    plume_obj_data o;
    plume_err e2 = {{0}};
    if ((st = plume_obj_read(path, &o, &e2)) != PLUME_OK)
        return plume_json_bad(c, st, "mesh.obj", "(%s)", e2.msg);
    /* material of each group */
    int *gmat = calloc((size_t)o.ngroups + 1, sizeof *gmat);
    plume_index *map = malloc((size_t)(o.nv + 1) * sizeof *map);
    if (!gmat || !map) {
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    json_t *jg = json_object_get(m, "materials_by_group");
    if (jg) {
        if (!json_is_object(jg)) {
            st = plume_json_bad(c, PLUME_EFORMAT, "mesh.materials_by_group", "must be an object {\"group\": material id}");
            goto done;
        }
        const char *gname;
        json_t *gv;
        json_object_foreach(jg, gname, gv) {
            char kp[PLUME_JSON_KEY_MAX];
            plume_json_subkey(kp, "mesh.materials_by_group", gname);
            int g = 0;
            while (g < o.ngroups && strcmp(o.groups[g], gname) != 0)
                g++;
            if (g == o.ngroups) {
                st = plume_json_bad(c, PLUME_EINVAL, kp, "names a group that %s does not have (its g/o lines)", path);
                goto done;
            }
            double id = json_is_number(gv) ? json_number_value(gv) : -1.0;
            if (!json_is_number(gv) || id != floor(id) || id < 0 || id > 1e6) {
                st = plume_json_bad(c, PLUME_EINVAL, kp, "must be a material id (an integer >= 0)");
                goto done;
            }
            gmat[g] = (int)id;
        }
    }
    /* only vertices used by a face become mesh vertices */
    for (plume_index v = 0; v < o.nv; v++)
        map[v] = -1;
    for (plume_index k = 0; k < 3 * o.nf; k++)
        map[o.f[k]] = 0;
    plume_index nv = 0;
    for (plume_index v = 0; v < o.nv; v++)
        if (map[v] == 0)
            map[v] = nv++;
    if ((st = plume_mesh_create(nv, o.nf, 3, &s->mesh, NULL)) != PLUME_OK) {
        plume_err_set(c->err, st, "%s: out of memory", c->file);
        goto done;
    }
    plume_mesh *mesh = s->mesh;
    for (plume_index v = 0; v < o.nv; v++)
        if (map[v] >= 0) {
            mesh->X[2 * map[v]] = o.v[2 * v];
            mesh->X[2 * map[v] + 1] = o.v[2 * v + 1];
        }
    for (plume_index t = 0; t < o.nf; t++) {
        plume_index a = map[o.f[3 * t]], b = map[o.f[3 * t + 1]], cc = map[o.f[3 * t + 2]];
        const double *A = mesh->X + 2 * a, *B = mesh->X + 2 * b, *C = mesh->X + 2 * cc;
        double area2 = (B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0]);
        if (area2 < 0) { /* counter-clockwise in X, as plume_mesh expects */
            plume_index tmp = b;
            b = cc, cc = tmp;
        }
        mesh->tri[3 * t] = a, mesh->tri[3 * t + 1] = b, mesh->tri[3 * t + 2] = cc;
        mesh->material[t] = o.group[t] >= 0 ? gmat[o.group[t]] : 0;
        mesh->barb_dir[2 * t] = d[0];
        mesh->barb_dir[2 * t + 1] = d[1];
    }
    plume_mesh_reset_current(mesh);
    plume_err e3 = {{0}};
    if ((st = plume_mesh_build_topology(mesh, &e3)) != PLUME_OK) {
        st = plume_json_bad(c, st, "mesh.obj", "(%s): %s", path, e3.msg);
        goto done;
    }
    *vertex_map = map;
    *nobj = o.nv;
    map = NULL;
done:
    free(gmat);
    free(map);
    plume_obj_free(&o);
    return st;
}

/* Barb curves of one side: an array of polylines. */
static plume_status get_curves(const plume_json_ctx *c, json_t *doc, const char *name, plume_polyline **lines, double ***store,
                               int *n)
{
    *lines = NULL;
    *store = NULL;
    *n = 0;
    json_t *v = json_object_get(doc, name);
    if (!json_is_array(v) || json_array_size(v) < 1)
        return plume_json_bad(c, PLUME_EFORMAT, name, "must be an array of barb curves [[[x, y], ...], ...]");
    size_t nc = json_array_size(v);
    *lines = calloc(nc, sizeof **lines);
    *store = calloc(nc, sizeof **store);
    if (!*lines || !*store)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (size_t i = 0; i < nc; i++) {
        char ki[PLUME_JSON_KEY_MAX];
        plume_json_subindex(ki, name, i);
        plume_index np;
        plume_status st = plume_json_polyline(c, json_array_get(v, i), ki, &(*store)[i], &np);
        if (st != PLUME_OK)
            return st;
        (*lines)[i].n = np;
        (*lines)[i].p = (*store)[i];
        (*n)++;
    }
    return PLUME_OK;
}

/* What the feather mesher reads from a shape file (freed with feather_shape_free). */
typedef struct {
    double *outline, *rachis; /* [2 no], [2 nra] */
    double **left, **right;   /* each barb curve's points (nl, nr of them) */
    plume_polyline *lp, *rp;  /* the barb curves over left, right */
    int nl, nr;
    plume_index no, nra;
    double wb, wt; /* rachis widths at base and tip */
} feather_shape;

static void feather_shape_free(feather_shape *f)
{
    free(f->outline);
    free(f->rachis);
    for (int i = 0; f->left && i < f->nl; i++)
        free(f->left[i]);
    for (int i = 0; f->right && i < f->nr; i++)
        free(f->right[i]);
    free(f->left);
    free(f->right);
    free(f->lp);
    free(f->rp);
}

/* The shape file's text into sc, a context of its own so that its errors name it (its keys are its
 * own, its relative files are next to it); the caller frees sc->text. */
static plume_status open_shape(const plume_json_ctx *c, const char *shape_path, plume_json_ctx *sc)
{
    *sc = *c;
    sc->file = shape_path;
    sc->prefix = NULL; /* the shape file's keys are its own */
    plume_err e1 = {{0}};
    plume_status st = PLUME_OK;
    sc->text = plume_read_text(shape_path, &e1, "feather shape", &st);
    if (!sc->text)
        return plume_json_bad(c, st, "mesh.feather", "(%s)", e1.msg);
    const char *slash = strrchr(shape_path, '/');
    if (slash)
        snprintf(sc->dir, sizeof sc->dir, "%.*s", (int)(slash == shape_path ? 1 : slash - shape_path), shape_path);
    else
        sc->dir[0] = '\0';
    return PLUME_OK;
}

/* The outline: the scene's OBJ (jo), else the shape file's "outline_obj" (or an "outline" polyline). */
static plume_status shape_outline(const plume_json_ctx *c, const plume_json_ctx *sc, json_t *jo, json_t *doc,
                                  feather_shape *f)
{
    json_t *so = json_object_get(doc, "outline_obj"), *sp = json_object_get(doc, "outline");
    if (jo || so) {
        if (!jo && !json_is_string(so))
            return plume_json_bad(sc, PLUME_EFORMAT, "outline_obj", "must be a file name");
        char outline_path[4096];
        if (jo)
            plume_json_resolve(c, json_string_value(jo), outline_path, sizeof outline_path);
        else
            plume_json_resolve(sc, json_string_value(so), outline_path, sizeof outline_path);
        plume_err e2 = {{0}};
        plume_status st = plume_obj_outline(outline_path, &f->outline, &f->no, &e2);
        if (st != PLUME_OK)
            return plume_json_bad(jo ? c : sc, st, jo ? "mesh.outline" : "outline_obj", "(%s)", e2.msg);
        return PLUME_OK;
    }
    if (sp)
        return plume_json_polyline(sc, sp, "outline", &f->outline, &f->no);
    return plume_json_bad(c, PLUME_EFORMAT, "mesh.outline", "is missing (an OBJ file whose boundary is the feather outline; "
                                                            "or \"outline_obj\" in the shape file)");
}

/* The rachis: {"points", "width_base", "width_tip"}, or the flat form "rachis": [[x, y], ...] with
 * "rachis_width_base" and "rachis_width_tip". */
static plume_status shape_rachis(const plume_json_ctx *sc, json_t *doc, feather_shape *f)
{
    json_t *jr = json_object_get(doc, "rachis");
    plume_status st;
    if (json_is_object(jr)) {
        if ((st = plume_json_polyline(sc, json_object_get(jr, "points"), "rachis.points", &f->rachis, &f->nra)) != PLUME_OK ||
            (st = plume_json_positive(sc, jr, "rachis", "width_base", 1, 0, &f->wb, NULL)) != PLUME_OK ||
            (st = plume_json_positive(sc, jr, "rachis", "width_tip", 1, 0, &f->wt, NULL)) != PLUME_OK)
            return st;
    } else if ((st = plume_json_polyline(sc, jr, "rachis", &f->rachis, &f->nra)) != PLUME_OK ||
               (st = plume_json_positive(sc, doc, "", "rachis_width_base", 1, 0, &f->wb, NULL)) != PLUME_OK ||
               (st = plume_json_positive(sc, doc, "", "rachis_width_tip", 1, 0, &f->wt, NULL)) != PLUME_OK) {
        return st;
    }
    return PLUME_OK;
}

/* The feather mesher on shape f at target edge `edge`: s->mesh and its barb edges (filtered by
 * material later); errors name the scene file and the shape file. */
static plume_status mesh_shape(const plume_json_ctx *c, const char *shape_path, const feather_shape *f, double edge,
                               plume_scene *s)
{
    plume_feather_input in;
    memset(&in, 0, sizeof in);
    in.outline.n = f->no;
    in.outline.p = f->outline;
    in.rachis.n = f->nra;
    in.rachis.p = f->rachis;
    in.rachis_width_base = f->wb;
    in.rachis_width_tip = f->wt;
    in.nbarbs_left = f->nl;
    in.nbarbs_right = f->nr;
    in.barbs_left = f->lp;
    in.barbs_right = f->rp;
    in.edge = edge;
    plume_index *barbs = NULL, nbarb = 0;
    plume_err e3 = {{0}};
    plume_status st = plume_feather_mesh(&in, 3, &s->mesh, &barbs, &nbarb, &e3);
    if (st != PLUME_OK) {
        free(barbs);
        return plume_err_set(c->err, st, "%s: feather mesh from %s: %s", c->file, shape_path, e3.msg);
    }
    s->barb_edges = barbs;
    s->nbarb = nbarb;
    return PLUME_OK;
}

/* Mesh from the feather mesher: the shape file (data/feather/feather_shape.json: "rachis"
 * {"points", "width_base", "width_tip"}, "barbs_left", "barbs_right", "outline_obj", "edge"; the
 * flat form "rachis": [[x, y], ...] with "rachis_width_base"/"rachis_width_tip" is read too) and
 * the outline. The scene's "outline" and "edge" override the shape file's. Other keys of the shape
 * file (description, units, comments) are its author's business and are not checked. */
plume_status plume_scene_mesh_from_feather(const plume_json_ctx *c, json_t *m, plume_scene *s,
                                           const plume_scene_load_opts *o)
{
    static const char *const keys[] = {"feather", "outline", "edge", NULL};
    plume_status st = plume_json_check_keys(c, m, "mesh", keys);
    if (st != PLUME_OK)
        return st;
    json_t *jf = json_object_get(m, "feather"), *jo = json_object_get(m, "outline");
    if (!json_is_string(jf))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh.feather", "must be a file name (the feather shape JSON)");
    if (jo && !json_is_string(jo))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh.outline", "must be a file name (an OBJ mesh whose boundary is the outline)");
    double edge = 0.0;
    int have_edge = 0;
    if ((st = plume_json_positive(c, m, "mesh", "edge", 0, 0, &edge, &have_edge)) != PLUME_OK)
        return st;
    if (o && o->edge > 0.0)
        edge = o->edge, have_edge = 1;
    char shape_path[4096];
    plume_json_resolve(c, json_string_value(jf), shape_path, sizeof shape_path);
    plume_json_ctx sc;
    if ((st = open_shape(c, shape_path, &sc)) != PLUME_OK)
        return st;
    json_error_t je;
    json_t *doc = json_loads(sc.text, JSON_REJECT_DUPLICATES, &je);
    feather_shape f;
    memset(&f, 0, sizeof f);
    if (!doc) {
        st = plume_err_set(c->err, PLUME_EFORMAT, "%s:%d:%d: %s", shape_path, je.line, je.column, je.text);
        goto done;
    }
    if (!json_is_object(doc)) {
        st = plume_err_set(c->err, PLUME_EFORMAT, "%s: expected a JSON object", shape_path);
        goto done;
    }
    if (!have_edge) {
        if (!json_object_get(doc, "edge")) {
            st = plume_json_bad(c, PLUME_EFORMAT, "mesh.edge", "is missing (the target edge length, m; the shape file has none)");
            goto done;
        }
        if ((st = plume_json_positive(&sc, doc, "", "edge", 1, 0, &edge, NULL)) != PLUME_OK)
            goto done;
    }
    if ((st = shape_outline(c, &sc, jo, doc, &f)) != PLUME_OK || (st = shape_rachis(&sc, doc, &f)) != PLUME_OK ||
        (st = get_curves(&sc, doc, "barbs_left", &f.lp, &f.left, &f.nl)) != PLUME_OK ||
        (st = get_curves(&sc, doc, "barbs_right", &f.rp, &f.right, &f.nr)) != PLUME_OK)
        goto done;
    st = mesh_shape(c, shape_path, &f, edge, s);
done:
    json_decref(doc);
    free(sc.text);
    feather_shape_free(&f);
    return st;
}


/* The constrained barb edges: edges along the barb direction of an adjacent triangle whose
 * material is constrained. For the feather the mesher's list is the candidate set; for an OBJ
 * mesh every edge is a candidate (same test as plume_vane_barb_edges, tolerance 1e-6). */
plume_status plume_scene_constrained_edges(plume_scene *s, plume_err *err)
{
    const plume_mesh *m = s->mesh;
    unsigned char *keep = calloc((size_t)m->ne + 1, 1);
    /* edges sorted by (i, j) for lookups of the mesher's list */
    plume_index *order = malloc((size_t)(m->ne + 1) * sizeof *order);
    if (!keep || !order) {
        free(keep);
        free(order);
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    const double tol = 1e-6;
    for (plume_index e = 0; e < m->ne; e++) {
        plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
        double ex = m->X[2 * b] - m->X[2 * a], ey = m->X[2 * b + 1] - m->X[2 * a + 1], len = hypot(ex, ey);
        for (int k = 0; k < 2; k++) {
            plume_index t = m->edge_tri[2 * e + k];
            if (t < 0 || !s->mats[m->material[t]].constraint)
                continue;
            const double *d = m->barb_dir + 2 * t;
            /* the mesher's edges are barb edges by construction; others must be aligned */
            if (s->barb_edges || fabs(ex * d[1] - ey * d[0]) <= tol * len * hypot(d[0], d[1]))
                keep[e] |= 1;
        }
    }
    if (s->barb_edges) { /* only the mesher's barb edges are candidates */
        unsigned char *listed = calloc((size_t)m->ne + 1, 1);
        if (!listed) {
            free(keep);
            free(order);
            return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        }
        /* mesh->edges hold i < j; find each listed pair by a scan of the vertex's edges */
        plume_index *start = calloc((size_t)m->nv + 2, sizeof *start);
        if (!start) {
            free(listed);
            free(keep);
            free(order);
            return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        }
        for (plume_index e = 0; e < m->ne; e++)
            start[m->edges[2 * e] + 1]++;
        for (plume_index v = 0; v < m->nv; v++)
            start[v + 1] += start[v];
        plume_index *fill = calloc((size_t)m->nv + 1, sizeof *fill);
        if (!fill) {
            free(start);
            free(listed);
            free(keep);
            free(order);
            return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        }
        for (plume_index e = 0; e < m->ne; e++) {
            plume_index a = m->edges[2 * e];
            order[start[a] + fill[a]++] = e;
        }
        for (plume_index k = 0; k < s->nbarb; k++) {
            plume_index a = s->barb_edges[2 * k], b = s->barb_edges[2 * k + 1];
            if (a > b) {
                plume_index t = a;
                a = b, b = t;
            }
            if (a < 0 || b >= m->nv)
                continue;
            for (plume_index q = start[a]; q < start[a + 1]; q++)
                if (m->edges[2 * order[q] + 1] == b)
                    listed[order[q]] = 1;
        }
        for (plume_index e = 0; e < m->ne; e++)
            keep[e] &= listed[e];
        free(fill);
        free(start);
        free(listed);
    }
    free(order);
    plume_index n = 0;
    for (plume_index e = 0; e < m->ne; e++)
        n += keep[e] ? 1 : 0;
    plume_index *out = malloc((size_t)(2 * n + 1) * sizeof *out);
    if (!out) {
        free(keep);
        return plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
    }
    n = 0;
    for (plume_index e = 0; e < m->ne; e++)
        if (keep[e]) {
            out[2 * n] = m->edges[2 * e];
            out[2 * n + 1] = m->edges[2 * e + 1];
            n++;
        }
    free(keep);
    free(s->barb_edges);
    s->barb_edges = out;
    s->nbarb = n;
    return PLUME_OK;
}

/* Mesh of a rectangle ("mesh": {"rectangle": [lx, ly], "edge", "pattern", "barb_direction"});
 * o (may be NULL) overrides the edge and the pattern. */
plume_status plume_scene_mesh_from_rectangle(const plume_json_ctx *c, json_t *m, plume_scene *s,
                                             const plume_scene_load_opts *o)
{
    static const char *const keys[] = {"rectangle", "edge", "pattern", "barb_direction", NULL};
    plume_status st = plume_json_check_keys(c, m, "mesh", keys);
    if (st != PLUME_OK)
        return st;
    double size[2], edge = 0.0, d[2];
    if ((st = plume_json_vector(c, json_object_get(m, "rectangle"), "mesh.rectangle", 2, size)) != PLUME_OK)
        return st;
    if (!(size[0] > 0.0 && size[1] > 0.0))
        return plume_json_bad(c, PLUME_EINVAL, "mesh.rectangle", "must be [lx, ly] with lx, ly > 0 (got [%g, %g])", size[0],
                              size[1]);
    if ((st = plume_json_positive(c, m, "mesh", "edge", 1, 0, &edge, NULL)) != PLUME_OK)
        return st;
    if (o && o->edge > 0.0)
        edge = o->edge;
    if ((st = barb_direction(c, m, d)) != PLUME_OK)
        return st;
    json_t *jp = json_object_get(m, "pattern");
    if (jp && !json_is_string(jp))
        return plume_json_bad(c, PLUME_EFORMAT, "mesh.pattern", "must be \"grid\", \"delaunay\" or \"aligned\"");
    const char *pattern = o && o->pattern ? o->pattern : jp ? json_string_value(jp) : "grid";
    plume_err e2 = {{0}};
    if (strcmp(pattern, "grid") == 0) {
        long nx = lround(size[0] / edge), ny = lround(size[1] / edge);
        st = plume_grid_mesh(size[0], size[1], nx < 1 ? 1 : nx, ny < 1 ? 1 : ny, d, 3, &s->mesh, &e2);
    } else if (strcmp(pattern, "delaunay") == 0 || strcmp(pattern, "aligned") == 0) {
        /* the patch mesher measures the barb angle from y toward +x, in [0, 180] */
        double angle = atan2(d[0], d[1]) * 180.0 / 3.14159265358979323846;
        if (angle < 0.0)
            angle += 180.0;
        st = plume_patch_mesh(size[0], size[1], angle, edge,
                              pattern[0] == 'd' ? PLUME_PATCH_UNALIGNED : PLUME_PATCH_ALIGNED, 3, &s->mesh, &e2);
        if (st == PLUME_OK && pattern[0] == 'd') /* the mesher's barb field; the scene's direction rules */
            for (plume_index t = 0; t < s->mesh->nt; t++)
                s->mesh->barb_dir[2 * t] = d[0], s->mesh->barb_dir[2 * t + 1] = d[1];
    } else {
        return plume_json_bad(c, PLUME_EINVAL, "mesh.pattern", "must be \"grid\", \"delaunay\" or \"aligned\" (got \"%s\")",
                              pattern);
    }
    if (st != PLUME_OK)
        return plume_json_bad(c, st, "mesh", "could not be meshed: %s", e2.msg);
    return PLUME_OK;
}
