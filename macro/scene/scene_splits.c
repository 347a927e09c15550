/* plume: a scene's "splits" (docs/scene-format.md; docs/unzipping.md, "Splits in a scene"): barb
 * lines of the vane that split and zip again. The lines are opened in the scene's mesh when it is
 * loaded (macro/shell/split_lines.h), before anything selects its vertices, so that handles and
 * clamps see the copies; their links join the problem in scene_build.c. */
#include "internal/scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void plume_scene_splits_free(plume_scene *s)
{
    if (!s)
        return;
    free(s->split_weld);
    s->split_weld = NULL;
    if (!s->splits)
        return;
    if (s->splits->mesh == s->mesh)
        s->splits->mesh = NULL; /* the scene's mesh: freed with the scene */
    plume_split_lines_free(s->splits);
    free(s->splits);
    s->splits = NULL;
}

/* "materials": [name or id, ...] into split[nmat] (1: its triangles may split) */
static plume_status split_materials(const plume_json_ctx *c, json_t *js, const plume_scene *s, unsigned char *split)
{
    json_t *jm = json_object_get(js, "materials");
    if (!json_is_array(jm) || json_array_size(jm) == 0)
        return plume_json_bad(c, PLUME_EFORMAT, "splits.materials",
                              jm ? "must be a non-empty array of material names or ids" : "is missing: name the materials "
                              "whose barb lines may split (the vane's; never the rachis'), e.g. [\"vane\"]");
    for (size_t k = 0; k < json_array_size(jm); k++) {
        json_t *e = json_array_get(jm, k);
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subindex(kp, "splits.materials", k);
        int id = -1;
        if (json_is_integer(e) && json_integer_value(e) >= 0 && json_integer_value(e) < s->nmat)
            id = (int)json_integer_value(e);
        for (int m = 0; json_is_string(e) && m < s->nmat; m++)
            if (strcmp(s->mats[m].name, json_string_value(e)) == 0)
                id = m;
        if (id < 0)
            return plume_json_bad(c, PLUME_EINVAL, kp, "names no material (a \"name\" of materials, or an id from 0 to %d)",
                                  s->nmat - 1);
        split[id] = 1;
    }
    return PLUME_OK;
}

/* "law": {"from_moduli": "file.h5"} (apps/homogenize's separation law, "stiffness" optionally
 * replacing its stiffness) or {"strength", "stiffness", "capture"[, "slide"]}; a slide (the law's
 * opening past its peak) softens the links (split_lines.h) */
static plume_status split_law(const plume_json_ctx *c, json_t *js, plume_scene *s)
{
    static const char *const keys[] = {"from_moduli", "strength", "stiffness", "capture", "slide", "note", NULL};
    json_t *jl = json_object_get(js, "law");
    if (!json_is_object(jl))
        return plume_json_bad(c, PLUME_EFORMAT, "splits.law",
                              "%s: {\"from_moduli\": \"file.h5\"} (the separation law apps/homogenize writes with the "
                              "moduli) or {\"strength\": N/m, \"stiffness\": N/m^2, \"capture\": m[, \"slide\": m]}",
                              jl ? "must be an object" : "is missing");
    plume_status st = plume_json_check_keys(c, jl, "splits.law", keys);
    if (st != PLUME_OK)
        return st;
    memset(&s->split_law, 0, sizeof s->split_law);
    json_t *jf = json_object_get(jl, "from_moduli");
    if (jf) {
        if (json_object_get(jl, "strength") || json_object_get(jl, "capture"))
            return plume_json_bad(c, PLUME_EINVAL, "splits.law", "takes \"from_moduli\" or the law's strength and "
                                  "capture, not both (\"stiffness\" may replace the file's)");
        if (json_object_get(jl, "slide"))
            return plume_json_bad(c, PLUME_EINVAL, "splits.law.slide", "comes with the file's law (its opening past "
                                  "the peak): give it with \"strength\", \"stiffness\" and \"capture\" only");
        if (!json_is_string(jf))
            return plume_json_bad(c, PLUME_EFORMAT, "splits.law.from_moduli", "must be the name of an HDF5 file with "
                                  "/moduli and its separation_* attributes (apps/homogenize on a layout with hooks)");
        plume_json_resolve(c, json_string_value(jf), s->split_law_from, sizeof s->split_law_from);
        plume_err e2 = {{0}};
        if ((st = plume_separation_read(s->split_law_from, &s->split_law, &e2)) != PLUME_OK)
            return plume_json_bad(c, st, "splits.law.from_moduli", "(%s): %s", json_string_value(jf), e2.msg);
        /* stiff lines for a vane whose membrane carries the hooks' compliance already (the hooked
         * tensor, docs/monoclinic-vane.md): the strength and capture stay the cell's */
        double k = 0.0;
        int given = 0;
        if ((st = plume_json_positive(c, jl, "splits.law", "stiffness", 0, 0, &k, &given)) != PLUME_OK)
            return st;
        if (given) { /* stiff lines: they keep the cell's energy under a softening branch */
            double h = 0.0;
            if ((st = plume_moduli_read_param(s->split_law_from, "thickness", &h, &e2)) != PLUME_OK || !(h > 0.0))
                return plume_json_bad(c, st != PLUME_OK ? st : PLUME_EINVAL, "splits.law.from_moduli",
                                      "(%s): %s", json_string_value(jf),
                                      st != PLUME_OK ? e2.msg : "its /moduli thickness must be > 0");
            plume_split_stiff_law(&s->split_law, k, h);
        }
        return PLUME_OK;
    }
    s->split_law_from[0] = '\0';
    if ((st = plume_json_positive(c, jl, "splits.law", "strength", 1, 0, &s->split_law.strength, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, jl, "splits.law", "stiffness", 1, 0, &s->split_law.stiffness, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, jl, "splits.law", "capture", 1, 1, &s->split_law.capture, NULL)) != PLUME_OK)
        return st;
    double slide = 0.0;
    if ((st = plume_json_positive(c, jl, "splits.law", "slide", 0, 1, &slide, NULL)) != PLUME_OK)
        return st;
    s->split_law.peak_opening = s->split_law.strength / s->split_law.stiffness;
    s->split_law.opening = s->split_law.peak_opening + slide; /* a slide softens the links (split_lines.h) */
    s->split_law.energy = NAN; /* per crack area needs the cell's thickness: unknown here */
    return PLUME_OK;
}

/* The barb direction shared by the triangles that may split (d, *straight = 1: straight lines
 * across the vane), or *straight = 0 where the barbs turn (a feather: lines along its barbs) */
static plume_status split_direction(const plume_json_ctx *c, const plume_mesh *m, const unsigned char *split,
                                    double d[2], int *straight)
{
    int found = 0;
    *straight = 1;
    for (plume_index t = 0; t < m->nt; t++) {
        if (!split[m->material[t]])
            continue;
        const double *b = m->barb_dir + 2 * t;
        if (!found)
            d[0] = b[0], d[1] = b[1], found = 1;
        else if (fabs(b[0] - d[0]) > 1e-9 || fabs(b[1] - d[1]) > 1e-9)
            *straight = 0;
    }
    if (!found)
        return plume_json_bad(c, PLUME_EINVAL, "splits.materials", "no triangle of the mesh has these materials");
    return PLUME_OK;
}

/* The lines' offsets n . X, n = (d_y, -d_x) as plume_split_lines_open takes them: "offsets" are
 * given along the barbs' left normal (-d_y, d_x) (y for barbs along x), so negated here; "lines"
 * spread evenly over the splitting triangles' span; *offsets malloc'ed */
static plume_status split_offsets(const plume_json_ctx *c, json_t *js, const plume_mesh *m, const unsigned char *split,
                                  const double d[2], double **offsets, int *n)
{
    json_t *jo = json_object_get(js, "offsets"), *jn = json_object_get(js, "lines");
    *offsets = NULL;
    if ((jo != NULL) == (jn != NULL))
        return plume_json_bad(c, PLUME_EINVAL, "splits", "needs one of \"offsets\" (each line's distance n . X across "
                              "the barbs, m) or \"lines\" (a number of lines spread evenly)");
    if (jo) {
        if (!json_is_array(jo) || json_array_size(jo) == 0 || json_array_size(jo) > 100000)
            return plume_json_bad(c, PLUME_EFORMAT, "splits.offsets", "must be a non-empty array of numbers (m)");
        *n = (int)json_array_size(jo);
        if (!(*offsets = malloc((size_t)*n * sizeof **offsets)))
            return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        plume_status st = plume_json_vector(c, jo, "splits.offsets", *n, *offsets);
        for (int k = 0; k < *n; k++)
            (*offsets)[k] = -(*offsets)[k];
        return st;
    }
    long lines = 0;
    plume_status st = plume_json_int(c, js, "splits", "lines", 1, 100000, &lines);
    if (st != PLUME_OK)
        return st;
    const double nn[2] = {d[1], -d[0]};
    double lo = INFINITY, hi = -INFINITY;
    for (plume_index t = 0; t < m->nt; t++)
        for (int k = 0; split[m->material[t]] && k < 3; k++) {
            const double *X = m->X + 2 * m->tri[3 * t + k];
            lo = fmin(lo, nn[0] * X[0] + nn[1] * X[1]), hi = fmax(hi, nn[0] * X[0] + nn[1] * X[1]);
        }
    *n = (int)lines;
    if (!(*offsets = malloc((size_t)*n * sizeof **offsets)))
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (int k = 0; k < *n; k++)
        (*offsets)[k] = lo + (hi - lo) * (double)(k + 1) / (double)(*n + 1);
    return PLUME_OK;
}

/* The capture must stay below the distance between neighbouring lines (a link would catch the
 * next line's lip) and below the mesh's shortest edge across a line (it would catch a lip that
 * never came back) */
static plume_status split_capture(const plume_json_ctx *c, const plume_split_lines *sl, const plume_mesh *m,
                                  double capture)
{
    double gap = INFINITY;
    for (int a = 0; a < sl->nlines; a++)
        for (int b = a + 1; b < sl->nlines; b++)
            if (isfinite(sl->offset[a]) && isfinite(sl->offset[b])) /* a feather's chains: the edges decide */
                gap = fmin(gap, fabs(sl->offset[a] - sl->offset[b]));
    for (plume_index e = 0; e < m->ne; e++) {
        const double *p = m->X + 2 * m->edges[2 * e], *q = m->X + 2 * m->edges[2 * e + 1];
        gap = fmin(gap, hypot(p[0] - q[0], p[1] - q[1]));
    }
    if (capture >= gap)
        return plume_json_bad(c, PLUME_EINVAL, "splits.law", "capture %g m is not below %g m, the smallest of the lines' "
                              "spacing and the mesh's edges: a released line would catch a lip it never met", capture, gap);
    return PLUME_OK;
}

plume_status plume_scene_parse_splits(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    static const char *const keys[] = {"offsets", "lines", "every", "materials", "law", "note", NULL};
    json_t *js = json_object_get(doc, "splits");
    if (!js)
        return PLUME_OK;
    if (!json_is_object(js))
        return plume_json_bad(c, PLUME_EFORMAT, "splits", "must be an object {\"materials\", \"offsets\" or \"lines\", "
                              "\"law\"}");
    plume_status st = plume_json_check_keys(c, js, "splits", keys);
    if (st != PLUME_OK)
        return st;
    if (s->is_static)
        return plume_json_bad(c, PLUME_EINVAL, "splits", "are for dynamic scenes: a line lets go and catches between "
                              "time steps");
    if (s->has_contact && !s->contact.self_contact)
        return plume_json_bad(c, PLUME_EINVAL, "splits", "with \"contact\" need \"self\": true: a line's two "
                              "lips are one body's, and only self contact keeps them apart once they let go (where "
                              "they coincide, as neighbours do, they do not touch: docs/unzipping.md)");
    const plume_mesh *m = s->mesh;
    unsigned char *split = calloc((size_t)s->nmat + 1, 1), *held = calloc((size_t)m->nv + 1, 1);
    double *offsets = NULL, d[2] = {1.0, 0.0};
    int n = 0, straight = 1;
    plume_split_lines *sl = calloc(1, sizeof *sl);
    if (!split || !held || !sl) {
        st = plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
        goto done;
    }
    if ((st = split_materials(c, js, s, split)) != PLUME_OK ||
        (st = split_direction(c, m, split, d, &straight)) != PLUME_OK || (st = split_law(c, js, s)) != PLUME_OK)
        goto done;
    if (straight && json_object_get(js, "every")) {
        st = plume_json_bad(c, PLUME_EINVAL, "splits.every", "is for a feather's barbs; straight barbs take "
                            "\"offsets\" or \"lines\"");
        goto done;
    }
    /* a vertex that touches a material that does not split stays whole: the rachis never splits */
    for (plume_index t = 0; t < m->nt; t++)
        for (int k = 0; !split[m->material[t]] && k < 3; k++)
            held[m->tri[3 * t + k]] = 1;
    plume_err e2 = {{0}};
    if (!straight) { /* a feather: along its barbs */
        if ((st = plume_scene_split_chains(c, js, s, split, held, sl)) != PLUME_OK)
            goto done;
    } else if ((st = split_offsets(c, js, m, split, d, &offsets, &n)) != PLUME_OK) {
        goto done;
    } else if ((st = plume_split_lines_open_held(m, d, offsets, n, held, sl, &e2)) != PLUME_OK) {
        st = plume_json_bad(c, st, json_object_get(js, "offsets") ? "splits.offsets" : "splits.lines",
                            "%s (offsets here are n . X with n = (%g, %g); the scene's are along (%g, %g))", e2.msg,
                            d[1], -d[0], -d[1], d[0]);
        goto done;
    }
    if ((st = split_capture(c, sl, m, s->split_law.capture)) != PLUME_OK) {
        plume_split_lines_free(sl);
        goto done;
    }
    plume_mesh_destroy(&s->mesh);
    s->mesh = sl->mesh; /* the opened mesh is the scene's from now on */
    s->splits = sl;
    sl = NULL;
    /* the mesher's barb edges: the lips' own too; the weld (an object's is made again for the scene) */
    if ((st = plume_scene_split_barb_edges(s, s->splits, c->err)) == PLUME_OK)
        st = plume_scene_splits_weld(s, c->err);
done:
    free(split);
    free(held);
    free(offsets);
    free(sl);
    return st;
}

plume_status plume_scene_add_splits(const plume_scene *s, plume_problem *p, plume_err *err)
{
    if (!s->splits)
        return PLUME_OK;
    return plume_split_lines_add(p, s->splits, &s->split_law, NULL, err);
}

/* A new array (nv) of the vertex each vertex stands for with the lines welded shut (a copy's
 * original; itself otherwise), or NULL with err set */
static plume_index *scene_weld(const plume_scene *s, plume_err *err)
{
    const plume_index nv = s->mesh->nv;
    plume_index *weld = malloc((size_t)(nv + 1) * sizeof *weld);
    if (!weld) {
        plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        return NULL;
    }
    for (plume_index v = 0; v < nv; v++)
        weld[v] = v;
    for (plume_index k = 0; s->splits && k < s->splits->npairs; k++)
        weld[s->splits->pairs[2 * k]] = s->splits->pairs[2 * k + 1];
    return weld;
}

int plume_scene_welded_neighbours(const plume_scene *s, plume_index t1, plume_index t2)
{
    const plume_index *w = s->split_weld;
    if (!w)
        return 0;
    const plume_index *a = s->mesh->tri + 3 * t1, *b = s->mesh->tri + 3 * t2;
    for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++)
            if (w[a[j]] == w[b[k]])
                return 1;
    return 0;
}

plume_status plume_scene_splits_weld(plume_scene *s, plume_err *err)
{
    free(s->split_weld);
    s->split_weld = scene_weld(s, err);
    return s->split_weld ? PLUME_OK : PLUME_ENOMEM;
}
