/* plume (macro): barb lines that split and zip again (split_lines.h; docs/unzipping.md). */
#include "split_lines.h"

#include "../../include/plume/traction.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "patch_mesh.h"

void plume_split_lines_free(plume_split_lines *s)
{
    if (!s)
        return;
    plume_mesh_destroy(&s->mesh);
    free(s->offset);
    free(s->first);
    free(s->pairs);
    free(s->length);
    memset(s, 0, sizeof *s);
}

typedef struct {
    double t;
    plume_index v;
} along;

static int cmp_along(const void *a, const void *b)
{
    const double x = ((const along *)a)->t, y = ((const along *)b)->t;
    return (x > y) - (x < y);
}

/* the smallest and largest offset n . X of the mesh's vertices */
static void offset_range(const plume_mesh *m, const double n[2], double *lo, double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (plume_index v = 0; v < m->nv; v++) {
        const double o = n[0] * m->X[2 * v] + n[1] * m->X[2 * v + 1];
        *lo = fmin(*lo, o), *hi = fmax(*hi, o);
    }
}

plume_status plume_split_lines_open(const plume_mesh *m, const double d[2], const double *c, int nc,
                                    plume_split_lines *out, plume_err *err)
{
    return plume_split_lines_open_held(m, d, c, nc, NULL, out, err);
}

plume_status plume_split_lines_open_held(const plume_mesh *m, const double d[2], const double *c, int nc,
                                         const unsigned char *held, plume_split_lines *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no output");
    memset(out, 0, sizeof *out);
    if (!m || (m->dim != 2 && m->dim != 3) || !m->edges || !d || nc < 1 || !c)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a mesh with its topology, a barb direction and "
                             "at least one offset are required");
    const double n[2] = {d[1], -d[0]};
    double lo, hi;
    offset_range(m, n, &lo, &hi);
    const double tol = 1e-9 * fmax(hi - lo, 1e-300);
    /* each requested offset snaps to the line of the nearest vertex offset */
    plume_status st = PLUME_OK;
    out->offset = malloc((size_t)nc * sizeof *out->offset);
    out->first = calloc((size_t)nc + 1, sizeof *out->first);
    int *side = calloc((size_t)m->nv, sizeof *side);      /* line + 1 of a vertex on an opened line */
    plume_index *copy = malloc((size_t)m->nv * sizeof *copy);
    along *row = malloc((size_t)m->nv * sizeof *row);
    out->pairs = malloc((size_t)(2 * m->nv) * sizeof *out->pairs);
    out->length = malloc((size_t)m->nv * sizeof *out->length);
    if (!out->offset || !out->first || !side || !copy || !row || !out->pairs || !out->length) {
        st = plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
        goto done;
    }
    for (plume_index v = 0; v < m->nv; v++)
        copy[v] = -1;
    plume_index nv = m->nv;
    for (int l = 0; l < nc; l++) {
        double best = INFINITY, at = 0.0;
        for (plume_index v = 0; v < m->nv; v++) {
            const double o = n[0] * m->X[2 * v] + n[1] * m->X[2 * v + 1];
            if (fabs(o - c[l]) < best)
                best = fabs(o - c[l]), at = o;
        }
        if (at <= lo + tol || at >= hi - tol) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: offset %g m lies on the mesh's edge (offsets run from "
                               "%g to %g m): a line that splits must cross the vane", c[l], lo, hi);
            goto done;
        }
        out->offset[l] = at;
        plume_index k = 0;
        for (plume_index v = 0; v < m->nv; v++)
            if (fabs(n[0] * m->X[2 * v] + n[1] * m->X[2 * v + 1] - at) <= tol) {
                if (side[v]) {
                    st = plume_err_set(err, PLUME_EINVAL, "split lines: offsets %g and %g m fall on the same line",
                                       c[side[v] - 1], c[l]);
                    goto done;
                }
                side[v] = l + 1;
                row[k].t = d[0] * m->X[2 * v] + d[1] * m->X[2 * v + 1];
                row[k++].v = v;
            }
        if (k < 2) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: no line of mesh edges at offset %g m", c[l]);
            goto done;
        }
        qsort(row, (size_t)k, sizeof *row, cmp_along);
        for (plume_index i = 0; i + 1 < k; i++)
            if (plume_mesh_edge(m, row[i].v, row[i + 1].v) < 0) {
                st = plume_err_set(err, PLUME_EINVAL, "split lines: the line at offset %g m is not a chain of mesh "
                                   "edges (vertices %ld and %ld): split lines need a mesh aligned with the barbs",
                                   at, (long)row[i].v, (long)row[i + 1].v);
                goto done;
            }
        plume_index f = out->first[l];
        for (plume_index i = 0; i < k; i++) {
            if (held && held[row[i].v]) { /* stays whole: the line ends there (a crack tip) */
                side[row[i].v] = 0;
                continue;
            }
            const double prev = i > 0 ? row[i].t - row[i - 1].t : 0.0, next = i + 1 < k ? row[i + 1].t - row[i].t : 0.0;
            copy[row[i].v] = nv;
            out->pairs[2 * f] = nv++;
            out->pairs[2 * f + 1] = row[i].v;
            out->length[f++] = 0.5 * (prev + next);
        }
        if (f == out->first[l]) {
            st = plume_err_set(err, PLUME_EINVAL, "split lines: no vertex of the line at offset %g m may split (each "
                               "touches a material that does not split)", at);
            goto done;
        }
        out->first[l + 1] = f;
    }
    out->nlines = nc;
    out->npairs = out->first[nc];
    if ((st = plume_mesh_create(nv, m->nt, m->dim, &out->mesh, err)) != PLUME_OK)
        goto done;
    plume_mesh *om = out->mesh;
    const int dim = m->dim;
    memcpy(om->X, m->X, (size_t)(2 * m->nv) * sizeof *om->X);
    memcpy(om->x, m->x, (size_t)(dim * m->nv) * sizeof *om->x);
    for (plume_index v = 0; v < m->nv; v++)
        if (copy[v] >= 0) {
            memcpy(om->X + 2 * copy[v], m->X + 2 * v, 2 * sizeof *om->X);
            memcpy(om->x + dim * copy[v], m->x + dim * v, (size_t)dim * sizeof *om->x);
        }
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *tv = m->tri + 3 * t;
        double cn = 0.0;
        for (int k = 0; k < 3; k++)
            cn += (n[0] * m->X[2 * tv[k]] + n[1] * m->X[2 * tv[k] + 1]) / 3.0;
        for (int k = 0; k < 3; k++) {
            const plume_index v = tv[k];
            /* ahead of the vertex's line: the copy */
            om->tri[3 * t + k] = side[v] && copy[v] >= 0 && cn > out->offset[side[v] - 1] ? copy[v] : v;
        }
        om->material[t] = m->material[t];
        memcpy(om->barb_dir + 2 * t, m->barb_dir + 2 * t, 2 * sizeof *om->barb_dir);
    }
    st = plume_mesh_build_topology(om, err);
done:
    free(side);
    free(copy);
    free(row);
    if (st != PLUME_OK)
        plume_split_lines_free(out);
    return st;
}

double plume_split_softening(const plume_separation_law *law)
{
    const double d0 = law->strength / law->stiffness, slide = law->opening - law->peak_opening;
    if (!(law->peak_opening > 0.0) || !(slide > 1e-9 * d0) || !isfinite(slide))
        return 1.0;
    return 1.0 + 2.0 * slide / d0;
}

void plume_split_stiff_law(plume_separation_law *law, double stiffness, double h)
{
    const double energy = law->energy * h; /* J/m: the cell's, per length of line */
    const double slide = fmax(law->opening - law->peak_opening, 0.0);
    law->stiffness = stiffness;
    law->peak_opening = law->strength / stiffness;
    /* the plateau that holds that energy above the stiff link's own triangle (at least the cell's
     * slide): plume_split_softening turns it into the bilinear law of the same energy */
    law->opening = law->peak_opening + fmax(slide, energy / law->strength - 0.5 * law->peak_opening);
}

plume_status plume_split_lines_add(plume_problem *p, const plume_split_lines *s, const plume_separation_law *law,
                                   plume_hooks **hooks, plume_err *err)
{
    if (hooks)
        *hooks = NULL;
    if (!p || !s || !s->mesh || !law || s->npairs < 1)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a problem, opened lines and a law are required");
    if (!(law->strength > 0.0) || !(law->stiffness > 0.0) || !(law->capture >= 0.0) || !isfinite(law->strength) ||
        !isfinite(law->stiffness) || !isfinite(law->capture))
        return plume_err_set(err, PLUME_EINVAL, "split lines: the separation law needs strength > 0 (got %g N/m), "
                             "stiffness > 0 (got %g N/m^2) and capture >= 0 (got %g m)", law->strength, law->stiffness,
                             law->capture);
    /* one hook per pair, of the law per unit length, scaled by the pair's length */
    const plume_hook_law per_length = {.strength = law->strength, .opening = law->strength / law->stiffness,
                                       .slide = 0.0, .capture = law->capture};
    plume_index *first = malloc((size_t)(s->npairs + 1) * sizeof *first);
    if (!first)
        return plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
    for (plume_index k = 0; k <= s->npairs; k++)
        first[k] = k;
    plume_hooks *h = NULL;
    plume_status st = plume_hooks_create(s->mesh->nv, (int)s->npairs, first, s->pairs, &per_length, &h, err);
    free(first);
    if (st == PLUME_OK) {
        plume_hooks_set_overshoot(h, PLUME_SPLIT_OVERSHOOT);
        plume_hooks_set_seating(h, PLUME_SPLIT_SEATING * law->capture);
        plume_hooks_set_softening(h, plume_split_softening(law));
    }
    for (plume_index k = 0; st == PLUME_OK && k < s->npairs; k++)
        if (plume_hooks_set_scale(h, (int)k, s->length[k]) != PLUME_OK)
            st = plume_err_set(err, PLUME_EINVAL, "split lines: pair %ld has no length along its line", (long)k);
    if (st != PLUME_OK) {
        plume_hooks_destroy(&h);
        return st;
    }
    plume_term t;
    plume_hooks_term(h, 1, &t);
    t.name = "splits";
    if ((st = plume_problem_add_term(p, &t, err)) == PLUME_OK && hooks)
        *hooks = h; /* the problem owns it, also on failure */
    return st;
}

/* ---- the public face (include/plume/traction.h) ---- */
struct plume_splits {
    plume_split_lines lines;
};

plume_status plume_splits_open(const plume_mesh *m, double angle_deg, int nlines, plume_splits **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no output");
    *out = NULL;
    if (!m || m->dim != 2 || !m->edges)
        return plume_err_set(err, PLUME_EINVAL, "split lines: a planar mesh with its topology is required");
    if (nlines < 1)
        return plume_err_set(err, PLUME_EINVAL, "split lines: the number of lines must be >= 1 (got %d)", nlines);
    if (!(angle_deg >= 0.0 && angle_deg <= 180.0))
        return plume_err_set(err, PLUME_EINVAL, "split lines: the barb angle must be in [0, 180] (got %g)", angle_deg);
    double d[2];
    plume_patch_barb_direction(angle_deg, d);
    const double n[2] = {d[1], -d[0]};
    double lo, hi;
    offset_range(m, n, &lo, &hi);
    double *c = malloc((size_t)nlines * sizeof *c);
    plume_splits *s = calloc(1, sizeof *s);
    if (!c || !s) {
        free(c);
        free(s);
        return plume_err_set(err, PLUME_ENOMEM, "split lines: out of memory");
    }
    for (int k = 0; k < nlines; k++)
        c[k] = lo + (hi - lo) * (double)(k + 1) / (double)(nlines + 1);
    plume_status st = plume_split_lines_open(m, d, c, nlines, &s->lines, err);
    free(c);
    if (st != PLUME_OK) {
        free(s);
        return st;
    }
    *out = s;
    return PLUME_OK;
}

const plume_mesh *plume_splits_mesh(const plume_splits *s)
{
    return s ? s->lines.mesh : NULL;
}

long plume_splits_pairs(const plume_splits *s)
{
    return s ? (long)s->lines.npairs : 0;
}

plume_status plume_splits_add(plume_problem *p, const plume_splits *s, const plume_separation_law *law, plume_err *err)
{
    if (!s)
        return plume_err_set(err, PLUME_EINVAL, "split lines: no lines");
    return plume_split_lines_add(p, &s->lines, law, NULL, err);
}

void plume_splits_destroy(plume_splits **s)
{
    if (!s || !*s)
        return;
    plume_split_lines_free(&(*s)->lines);
    free(*s);
    *s = NULL;
}
