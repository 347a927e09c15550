/* plume: the feather mesher's state (macro/feather/internal/feather_mesher.h): its output vertices and
 * constrained segments, the geometric segments (outline pieces, strip sides, barb edges) in a grid
 * of their own, the anchors that split outline edges, and the proximity queries the walks make on
 * them (what a barb may not come near, cross or snap to). The design, steps and decisions, is the
 * comment at the top of macro/feather/feather_mesh.c. */
#include <stdlib.h>

#include "internal/feather_mesher.h"

int plume_fm_add_seg(fm *f, const double *a, const double *b, plume_index v0, plume_index v1, int kind, int side,
                     plume_index tag, double t0, double t1)
{
    if (f->ns == f->scap) {
        plume_index cap = f->scap ? 2 * f->scap : 1024;
        fseg *s = realloc(f->s, (size_t)cap * sizeof *s);
        if (!s)
            return -1;
        f->s = s;
        unsigned *stp = realloc(f->stamp, (size_t)cap * sizeof *stp);
        if (!stp)
            return -1;
        f->stamp = stp, f->scap = cap;
    }
    fseg *s = f->s + f->ns;
    s->a[0] = a[0], s->a[1] = a[1], s->b[0] = b[0], s->b[1] = b[1];
    s->v0 = v0, s->v1 = v1, s->kind = kind, s->side = side, s->tag = tag, s->t0 = t0, s->t1 = t1;
    f->stamp[f->ns] = 0;
    if (plume_bins_add(&f->sg, f->ns, a[0], a[1], b[0], b[1]) < 0)
        return -1;
    f->ns++;
    return 0;
}

/* New output vertex, registered in the point grid; its id or -1 (no memory). */
plume_index plume_fm_add_vertex(fm *f, const double *p)
{
    plume_index id = plume_pslg_point(&f->g, p[0], p[1]);
    if (id < 0 || plume_bins_add(&f->pg, id, p[0], p[1], p[0], p[1]) < 0)
        return -1;
    return id;
}

/* A constrained edge between vertices (side or barb). */
int plume_fm_add_constraint(fm *f, plume_index v0, plume_index v1, int kind, int side, plume_index tag)
{
    if (plume_pslg_segment(&f->g, v0, v1) < 0)
        return -1;
    if (kind == SEG_BARB) {
        if (f->nbarb_seg == f->barb_cap) {
            plume_index cap = f->barb_cap ? 2 * f->barb_cap : 256;
            plume_index *b = realloc(f->barb_seg, (size_t)cap * sizeof *b);
            if (!b)
                return -1;
            f->barb_seg = b, f->barb_cap = cap;
        }
        f->barb_seg[f->nbarb_seg++] = f->g.ns - 1;
    }
    return plume_fm_add_seg(f, f->g.p + 2 * v0, f->g.p + 2 * v1, v0, v1, kind, side, tag, 0, 0);
}

/* A vertex on outline edge `edge` at parameter t (snapped to an edge end closer than `snap`). */
plume_index plume_fm_outline_vertex(fm *f, plume_index edge, double t, double snap)
{
    plume_index j = (edge + 1) % f->no;
    const double *a = f->o + 2 * edge, *b = f->o + 2 * j;
    double len = norm2(b[0] - a[0], b[1] - a[1]);
    if (t * len < snap || (1 - t) * len < snap) {
        plume_index v = t * len < snap ? edge : j;
        if (!f->outline_used[v] &&
            plume_bins_add(&f->pg, v, f->o[2 * v], f->o[2 * v + 1], f->o[2 * v], f->o[2 * v + 1]) < 0)
            return -1;
        f->outline_used[v] = 1;
        return v;
    }
    double p[2] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
    plume_index id = plume_fm_add_vertex(f, p);
    if (id < 0)
        return -1;
    if (f->nanc == f->anccap) {
        plume_index cap = f->anccap ? 2 * f->anccap : 256;
        anchor *an = realloc(f->anc, (size_t)cap * sizeof *an);
        if (!an)
            return -1;
        f->anc = an, f->anccap = cap;
    }
    f->anc[f->nanc].edge = edge, f->anc[f->nanc].t = t, f->anc[f->nanc].id = id;
    f->nanc++;
    return id;
}

/* The outline vertex a snapped end would use, or -1 (not snapped). */
plume_index plume_fm_snap_target(const fm *f, plume_index edge, double t, double snap)
{
    plume_index j = (edge + 1) % f->no;
    const double *a = f->o + 2 * edge, *b = f->o + 2 * j;
    double len = norm2(b[0] - a[0], b[1] - a[1]);
    if (t * len < snap)
        return edge;
    if ((1 - t) * len < snap)
        return j;
    return -1;
}

/* Earliest crossing of p->q with the outline: 1 and t along pq, the edge and its parameter. */
int plume_fm_outline_cross(const fm *f, const double *p, const double *q, double *t, plume_index *edge, double *u)
{
    int found = 0;
    double best = INFINITY;
    FOR_CELLS(&f->sg, p[0], p[1], q[0], q[1], nd)
    {
        const fseg *s = f->s + f->sg.item[nd];
        if (s->kind != SEG_OUTLINE)
            continue;
        double tt, uu;
        if (seg_intersect(p, q, s->a, s->b, &tt, &uu) && tt < best) {
            best = tt, found = 1;
            *t = tt, *edge = s->tag, *u = s->t0 + uu * (s->t1 - s->t0);
        }
    }
    return found;
}

/* Any segment of one of the kinds (bit mask) within r of p, ignoring those incident to vertex `skip`. */
int plume_fm_near_segment(const fm *f, const double *p, double r, unsigned kinds, plume_index skip)
{
    FOR_CELLS(&f->sg, p[0] - r, p[1] - r, p[0] + r, p[1] + r, nd)
    {
        const fseg *s = f->s + f->sg.item[nd];
        if (!(kinds & (1u << s->kind)) || (skip >= 0 && (s->v0 == skip || s->v1 == skip)))
            continue;
        if (seg_dist(p, s->a, s->b, NULL) < r)
            return 1;
    }
    return 0;
}

/* Any constrained (side, barb) segment crossing or within r of ab, ignoring those incident to `skip`. */
int plume_fm_blocked(const fm *f, const double *a, const double *b, double r, plume_index skip)
{
    FOR_CELLS(&f->sg, fmin(a[0], b[0]) - r, fmin(a[1], b[1]) - r, fmax(a[0], b[0]) + r, fmax(a[1], b[1]) + r, nd)
    {
        const fseg *s = f->s + f->sg.item[nd];
        if ((s->kind != SEG_SIDE && s->kind != SEG_BARB) || (skip >= 0 && (s->v0 == skip || s->v1 == skip)))
            continue;
        if (segseg_dist(a, b, s->a, s->b) <= r)
            return 1;
    }
    return 0;
}

/* Any vertex within r of segment ab (a point when a == b), ignoring `skip`. */
int plume_fm_near_vertex(const fm *f, const double *a, const double *b, double r, plume_index skip)
{
    FOR_CELLS(&f->pg, fmin(a[0], b[0]) - r, fmin(a[1], b[1]) - r, fmax(a[0], b[0]) + r, fmax(a[1], b[1]) + r, nd)
    {
        plume_index v = f->pg.item[nd];
        if (v == skip)
            continue;
        if (seg_dist(f->g.p + 2 * v, a, b, NULL) < r)
            return 1;
    }
    return 0;
}
