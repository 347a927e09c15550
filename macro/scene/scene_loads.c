/* Vertex selections, and what a static scene adds: clamps, supports, loads, moments and probes
 * (macro/scene/scene.h). */
#include "internal/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

plume_status plume_scene_select(const plume_json_ctx *c, json_t *obj, const char *where, const plume_scene *s,
                                const plume_index *map, plume_index nobj, plume_index *ids, plume_index *count)
{
    char kp[PLUME_JSON_KEY_MAX];
    plume_status st;
    const plume_mesh *m = s->mesh;
    json_t *jn = json_object_get(obj, "near"), *jv = json_object_get(obj, "vertices"), *jb = json_object_get(obj, "box");
    *count = 0;
    if ((jn != NULL) + (jv != NULL) + (jb != NULL) != 1)
        return plume_json_bad(c, PLUME_EFORMAT, where,
                              "needs exactly one selector: \"near\" (with \"radius\"), \"vertices\" or \"box\"");
    plume_index n = 0;
    double tol = 1e-12 * s->length;
    if (jn) {
        double p[2], r = -1.0;
        int have_r = 0;
        plume_json_subkey(kp, where, "near");
        if ((st = plume_json_vector(c, jn, kp, 2, p)) != PLUME_OK ||
            (st = plume_json_positive(c, obj, where, "radius", 0, 1, &r, &have_r)) != PLUME_OK)
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
            return plume_json_bad(c, PLUME_EINVAL, kp, "with radius %g selects no vertex (the nearest one, %ld, is %g m away)",
                                  r, (long)best, dbest);
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
    *count = n;
    return PLUME_OK;
}

/* mark[v] <- 1 for the vertices sharing an edge with a selected one (sel[v] != 0), not selected */
static plume_index second_row(const plume_mesh *m, const unsigned char *sel, unsigned char *mark)
{
    memset(mark, 0, (size_t)m->nv);
    for (plume_index e = 0; e < m->ne; e++) {
        plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
        if (sel[a] && !sel[b])
            mark[b] = 1;
        if (sel[b] && !sel[a])
            mark[a] = 1;
    }
    plume_index n = 0;
    for (plume_index v = 0; v < m->nv; v++)
        n += mark[v];
    return n;
}

typedef struct {
    const plume_json_ctx *c;
    plume_scene *s;
    const plume_index *map;
    plume_index nobj;
    plume_index *ids;        /* [nv] selection scratch */
    unsigned char *sel, *row; /* [nv] flags */
} static_parse;

/* selection of entry `where` into p->ids / p->sel; *n selected */
static plume_status select_into(static_parse *p, json_t *obj, const char *where, plume_index *n)
{
    plume_status st = plume_scene_select(p->c, obj, where, p->s, p->map, p->nobj, p->ids, n);
    if (st != PLUME_OK)
        return st;
    memset(p->sel, 0, (size_t)p->s->mesh->nv);
    for (plume_index k = 0; k < *n; k++)
        p->sel[p->ids[k]] = 1;
    return PLUME_OK;
}

/* One entry of a list: the object e at key path kp (an object, its keys checked). */
typedef plume_status (*entry_parser)(static_parse *p, json_t *e, const char *kp);

/* The list `key` of the scene: an array (else `array_msg`) of objects (else `object_msg`) whose
 * keys are among `keys`, each given to `one` with its key path ("key[k]"). */
static plume_status parse_list(static_parse *p, json_t *arr, const char *key, const char *array_msg,
                               const char *object_msg, const char *const *keys, entry_parser one)
{
    const plume_json_ctx *c = p->c;
    if (!json_is_array(arr))
        return plume_json_bad(c, PLUME_EFORMAT, key, "%s", array_msg);
    for (size_t k = 0; k < json_array_size(arr); k++) {
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subindex(kp, key, k);
        json_t *e = json_array_get(arr, k);
        plume_status st;
        if (!json_is_object(e))
            return plume_json_bad(c, PLUME_EFORMAT, kp, "%s", object_msg);
        if ((st = plume_json_check_keys(c, e, kp, keys)) != PLUME_OK || (st = one(p, e, kp)) != PLUME_OK)
            return st;
    }
    return PLUME_OK;
}

static const char *const clamp_keys[] = {"near", "radius", "vertices", "box", NULL};

static plume_status parse_clamp(static_parse *p, json_t *e, const char *kp)
{
    plume_scene *s = p->s;
    plume_status st;
    plume_index n;
    if ((st = select_into(p, e, kp, &n)) != PLUME_OK)
        return st;
    /* a clamp along the boundary holds rotations by the mirrored stencils of the shape-operator
     * bending (bit 2: its second row is held only with the hinge); one with no boundary edge holds
     * them through its second row whatever the bending (bit 4) */
    int on_edge = 0;
    for (plume_index ed = 0; ed < s->mesh->ne && !on_edge; ed++)
        on_edge = s->mesh->edge_tri[2 * ed + 1] < 0 && p->sel[s->mesh->edges[2 * ed]] &&
                  p->sel[s->mesh->edges[2 * ed + 1]];
    second_row(s->mesh, p->sel, p->row);
    const unsigned char rowbit = on_edge ? PLUME_CLAMP_ROW_EDGE : PLUME_CLAMP_ROW;
    for (plume_index v = 0; v < s->mesh->nv; v++)
        s->clamped[v] |= (unsigned char)(p->sel[v] ? PLUME_CLAMP_HELD : 0) | (unsigned char)(p->row[v] ? rowbit : 0);
    return PLUME_OK;
}

static const char *const load_keys[] = {"near", "radius", "vertices", "box", "force", "line_load", "moment", NULL};

static plume_status parse_load(static_parse *p, json_t *e, const char *kp)
{
    const plume_json_ctx *c = p->c;
    plume_scene *s = p->s;
    const plume_mesh *m = s->mesh;
    plume_status st;
    plume_index n;
    char kk[PLUME_JSON_KEY_MAX];
    json_t *jf = json_object_get(e, "force"), *jl = json_object_get(e, "line_load"), *jm = json_object_get(e, "moment");
    if ((jf != NULL) + (jl != NULL) + (jm != NULL) != 1)
        return plume_json_bad(c, PLUME_EFORMAT, kp, "needs exactly one of \"force\" [N], \"line_load\" [N/m] or \"moment\" [N m]");
    double v[3];
    plume_json_subkey(kk, kp, jf ? "force" : jl ? "line_load" : "moment");
    if ((st = plume_json_vector(c, jf ? jf : jl ? jl : jm, kk, 3, v)) != PLUME_OK ||
        (st = select_into(p, e, kp, &n)) != PLUME_OK)
        return st;
    if (jf) {
        for (plume_index k = 0; k < n; k++)
            for (int a = 0; a < 3; a++)
                s->force[3 * p->ids[k] + a] += v[a] / (double)n;
        return PLUME_OK;
    }
    if (jl) {
        double total = 0.0;
        for (plume_index ed = 0; ed < m->ne; ed++) {
            plume_index a = m->edges[2 * ed], b = m->edges[2 * ed + 1];
            if (m->edge_tri[2 * ed + 1] >= 0 || !p->sel[a] || !p->sel[b])
                continue;
            double l = hypot(m->X[2 * b] - m->X[2 * a], m->X[2 * b + 1] - m->X[2 * a + 1]);
            total += l;
            for (int q = 0; q < 3; q++) {
                s->force[3 * a + q] += 0.5 * l * v[q];
                s->force[3 * b + q] += 0.5 * l * v[q];
            }
        }
        if (!(total > 0.0))
            return plume_json_bad(c, PLUME_EINVAL, kp, "selects no boundary edge (a line load acts on boundary edges "
                                                       "whose two ends are selected)");
        return PLUME_OK;
    }
    double M = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(M > 0.0))
        return plume_json_bad(c, PLUME_EINVAL, kk, "must be a non-zero moment vector");
    plume_index nrow = second_row(m, p->sel, p->row);
    if (nrow == 0)
        return plume_json_bad(c, PLUME_EINVAL, kp, "selects an end with no second row (no vertex next to it)");
    plume_scene_moment *mo = s->moments + s->nmoments;
    mo->end = malloc((size_t)n * sizeof *mo->end);
    mo->row = malloc((size_t)nrow * sizeof *mo->row);
    if (!mo->end || !mo->row) {
        free(mo->end);
        free(mo->row);
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    }
    s->nmoments++;
    memcpy(mo->end, p->ids, (size_t)n * sizeof *mo->end);
    mo->nend = n;
    for (plume_index q = 0; q < m->nv; q++)
        if (p->row[q])
            mo->row[mo->nrow++] = q;
    for (int a = 0; a < 3; a++)
        mo->axis[a] = v[a] / M;
    mo->moment = M;
    return PLUME_OK;
}

static const char *const probe_keys[] = {"name", "near", "radius", "vertices", "box", "reference", "source", NULL};

static plume_status parse_probe(static_parse *p, json_t *e, const char *kp, plume_scene_probe *pr)
{
    const plume_json_ctx *c = p->c;
    plume_status st;
    char kk[PLUME_JSON_KEY_MAX];
    json_t *jn = json_object_get(e, "name"), *jr = json_object_get(e, "reference"), *js = json_object_get(e, "source");
    plume_json_subkey(kk, kp, "name");
    if (!json_is_string(jn) || !*json_string_value(jn))
        return plume_json_bad(c, PLUME_EFORMAT, kk, jn ? "must be a non-empty string" : "is missing (a name for the report)");
    plume_json_subkey(kk, kp, "source");
    if (js && !json_is_string(js))
        return plume_json_bad(c, PLUME_EFORMAT, kk, "must be a string (where the reference comes from)");
    plume_index n;
    if ((st = select_into(p, e, kp, &n)) != PLUME_OK)
        return st;
    if (jr) { /* three numbers, any of them null: a reference for some components only */
        plume_json_subkey(kk, kp, "reference");
        if (!json_is_array(jr) || json_array_size(jr) != 3)
            return plume_json_bad(c, PLUME_EFORMAT, kk, "must be an array of 3 numbers (null for a component "
                                                        "without a reference)");
        for (int a = 0; a < 3; a++) {
            json_t *v = json_array_get(jr, (size_t)a);
            if (json_is_null(v)) {
                pr->reference[a] = NAN;
                continue;
            }
            if (!json_is_number(v) || !isfinite(json_number_value(v)))
                return plume_json_bad(c, PLUME_EFORMAT, kk, "must be an array of 3 finite numbers or nulls");
            pr->reference[a] = json_number_value(v);
            pr->has_reference |= 1 << a;
        }
        if (!pr->has_reference)
            return plume_json_bad(c, PLUME_EFORMAT, kk, "has no number: give at least one component");
    }
    pr->name = strdup(json_string_value(jn));
    pr->source = js ? strdup(json_string_value(js)) : NULL;
    pr->vertices = malloc((size_t)n * sizeof *pr->vertices);
    if (!pr->name || (js && !pr->source) || !pr->vertices)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    memcpy(pr->vertices, p->ids, (size_t)n * sizeof *pr->vertices);
    pr->n = n;
    return PLUME_OK;
}

static const char *const support_keys[] = {"near", "radius", "vertices", "box", "fix", "symmetry", NULL};

static plume_status parse_support(static_parse *p, json_t *e, const char *kp)
{
    const plume_json_ctx *c = p->c;
    char kf[PLUME_JSON_KEY_MAX];
    plume_json_subkey(kf, kp, "fix");
    json_t *jf = json_object_get(e, "fix");
    plume_status st;
    plume_index n;
    if (!jf)
        return plume_json_bad(c, PLUME_EFORMAT, kp, "needs \"fix\": the coordinates it holds (\"x\", \"y\", \"z\" "
                                                    "or several, e.g. \"xz\")");
    const char *f = json_is_string(jf) ? json_string_value(jf) : "";
    unsigned char bits = 0;
    for (const char *q = f; *q; q++) {
        unsigned char b = *q == 'x' ? 1 : *q == 'y' ? 2 : *q == 'z' ? 4 : 0;
        if (!b || (bits & b)) {
            bits = 0;
            break;
        }
        bits |= b;
    }
    if (!bits)
        return plume_json_bad(c, PLUME_EINVAL, kf, "must name the held coordinates once each, from x, y and z "
                                                   "(e.g. \"y\" or \"xz\")");
    /* "symmetry": true, the plane normal to the one held coordinate (midedge bending holds the
     * directors of its edges in it) */
    char ks[PLUME_JSON_KEY_MAX];
    plume_json_subkey(ks, kp, "symmetry");
    json_t *jsym = json_object_get(e, "symmetry");
    if (jsym && !json_is_boolean(jsym))
        return plume_json_bad(c, PLUME_EFORMAT, ks, "must be true or false");
    const int sym = json_is_true(jsym);
    if (sym && bits != 1 && bits != 2 && bits != 4)
        return plume_json_bad(c, PLUME_EINVAL, ks, "needs \"fix\" to name one coordinate, the plane's normal (it names "
                                                   "\"%s\")", f);
    if ((st = select_into(p, e, kp, &n)) != PLUME_OK)
        return st;
    for (plume_index q = 0; q < n; q++)
        p->s->supported[p->ids[q]] |= (unsigned char)(bits | (sym ? bits << 3 : 0));
    return PLUME_OK;
}

/* the next probe of the scene (its array is allocated for the whole list) */
static plume_status parse_next_probe(static_parse *p, json_t *e, const char *kp)
{
    return parse_probe(p, e, kp, p->s->probes + p->s->nprobes++);
}

plume_status plume_scene_parse_static(const plume_json_ctx *c, json_t *doc, plume_scene *s, const plume_index *map,
                                      plume_index nobj)
{
    const plume_mesh *m = s->mesh;
    static_parse p = {c, s, map, nobj, NULL, NULL, NULL};
    plume_status st = PLUME_OK;
    json_t *jc = json_object_get(doc, "clamps"), *jl = json_object_get(doc, "loads"), *jp = json_object_get(doc, "probes");
    json_t *js = json_object_get(doc, "supports");
    if (!s->is_static) {
        const char *key = jc ? "clamps" : js ? "supports" : jl ? "loads" : "steps";
        if (jc || js || jl || json_object_get(doc, "steps"))
            return plume_json_bad(c, PLUME_EINVAL, key, "belongs to a static scene (add \"solve\": \"static\"; a dynamic "
                                                        "scene moves through its handles and gravity)");
    }
    p.ids = malloc((size_t)(m->nv + 1) * sizeof *p.ids);
    p.sel = calloc((size_t)m->nv + 1, 1);
    p.row = calloc((size_t)m->nv + 1, 1);
    if (!p.ids || !p.sel || !p.row) {
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    if (s->is_static) {
        s->clamped = calloc((size_t)m->nv + 1, 1);
        s->supported = calloc((size_t)m->nv + 1, 1);
        s->force = calloc((size_t)(3 * m->nv + 1), sizeof *s->force);
        if (!s->clamped || !s->supported || !s->force) {
            st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
            goto done;
        }
        if (jc && (st = parse_list(&p, jc, "clamps", "must be an array of vertex selections",
                                   "must be an object with a selector (near/radius, vertices or box)", clamp_keys,
                                   parse_clamp)) != PLUME_OK)
            goto done;
        if (js && (st = parse_list(&p, js, "supports", "must be an array of {selector, \"fix\": \"xyz\"}",
                                   "must be an object with a selector and \"fix\"", support_keys, parse_support)) !=
                      PLUME_OK)
            goto done;
        if (jl) {
            if (!(s->moments = calloc(json_array_size(jl) + 1, sizeof *s->moments))) {
                st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
                goto done;
            }
            if ((st = parse_list(&p, jl, "loads", "must be an array of loads",
                                 "must be an object: a selector and one of force, line_load, moment", load_keys,
                                 parse_load)) != PLUME_OK)
                goto done;
        }
        int held = s->nhandles > 0;
        for (plume_index v = 0; v < m->nv && !held; v++)
            held = s->clamped[v] & PLUME_CLAMP_HELD;
        if (!held) {
            st = plume_json_bad(c, PLUME_EINVAL, "clamps", "%s: a static scene needs a clamp or a handle (nothing holds "
                                                           "it, so rigid motions are free)",
                                jc ? "select no vertex" : "are missing");
            goto done;
        }
    }
    if (jp) {
        if (!(s->probes = calloc(json_array_size(jp) + 1, sizeof *s->probes))) {
            st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
            goto done;
        }
        if ((st = parse_list(&p, jp, "probes", "must be an array of probes",
                             "must be an object {\"name\", selector, \"reference\"}", probe_keys, parse_next_probe)) !=
            PLUME_OK)
            goto done;
    }
done:
    free(p.ids);
    free(p.sel);
    free(p.row);
    return st;
}

void plume_scene_probe_displacement(const plume_scene *s, int k, const double *x, double u[3])
{
    u[0] = u[1] = u[2] = 0.0;
    if (!s || !x || k < 0 || k >= s->nprobes) {
        u[0] = u[1] = u[2] = NAN;
        return;
    }
    const plume_scene_probe *pr = s->probes + k;
    for (plume_index i = 0; i < pr->n; i++) {
        plume_index v = pr->vertices[i];
        u[0] += x[3 * v] - s->mesh->X[2 * v];
        u[1] += x[3 * v + 1] - s->mesh->X[2 * v + 1];
        u[2] += x[3 * v + 2];
    }
    for (int a = 0; a < 3; a++)
        u[a] /= (double)pr->n;
}
