/* plume: rectangular traction specimens of a layout (micro/cell_mesh.h, plume_specimen_mesh).
 *
 * Frame: barbs along d = (sin a, cos a) (as macro/shell/patch_mesh.h), across them q = (-d_y, d_x), so
 * that (s, c) = (d.p, q.p) is the layout's barb frame (x, y) by a rotation (the membrane's
 * R = [d, d_perp] uses the same d_perp). Phase: a barb strip is centred on the rectangle's centre
 * (barb k covers c in c_mid + k d_B +- w_B / 2), and for barbule layouts a barbule of every gap is
 * centred there along the barbs: the specimen is symmetric under the half turn about its centre,
 * so its response has no artificial bias from where the pattern happens to start.
 *
 * Geometry: every strip boundary line clipped to the rectangle and every barbule side clipped to
 * it are constrained polylines with points <= e apart; a barbule side ends on a point of the barb
 * line it meets (the point is inserted in that line's polyline, so no two constraints cross away
 * from an input point, which the CGAL shim requires). Boundary points are shared exactly per side
 * and spaced <= e. CGAL refines to edges <= e. Then each triangle takes its material from its
 * centroid; for barbule layouts the triangles of the empty space are dropped, so are the pieces cut
 * loose by the rectangle that touch neither grip (y = 0, y = ly): a fragment that no load path
 * holds would leave the traction problem singular. Unused vertices are dropped and renumbered.
 *
 * Strip boundaries clipped to less than e/1000 (a line grazing a corner) are not constrained; the
 * triangles there still get their material from the centroid. */
#include "../lib/core/pslg.h"
#include "../include/plume/traction.h"
#include "cell_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/cdt.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Specimens above this many triangles (estimated as area / (0.43 e^2)) are refused. */
#define MAX_TRIANGLES 5e6
/* Clipped lines shorter than this fraction of e are not constrained. */
#define MIN_LINE_REL 1e-3

typedef plume_pslg geometry; /* lib/core/pslg.h */

/* A point of a line or a side, by its parameter along it. */
typedef struct {
    double t;
    plume_index id;
} tpoint;

typedef struct {
    tpoint *v;
    plume_index n, cap;
} tlist;

static int tlist_push(tlist *l, double t, plume_index id)
{
    if (l->n == l->cap) {
        plume_index cap = l->cap ? 2 * l->cap : 16;
        tpoint *v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v)
            return -1;
        l->v = v, l->cap = cap;
    }
    l->v[l->n].t = t, l->v[l->n].id = id;
    l->n++;
    return 0;
}

static int cmp_tpoint(const void *a, const void *b)
{
    const tpoint *x = a, *y = b;
    if (x->t != y->t)
        return x->t < y->t ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

/* A constrained line piece p(t) = o + t u (u unit), t in [tlo, thi] inside the rectangle. */
typedef struct {
    double o[2], u[2];
    double tlo, thi;
    int present;
    int has_end[2]; /* the end at tlo / thi is already in pts (a barbule end inside the rectangle) */
    tlist pts;
} line;

typedef struct {
    double lx, ly, tol, e;
    geometry g;
    tlist side[4]; /* 0 bottom (t = x), 1 right (t = y), 2 top (t = x), 3 left (t = y) */
} builder;

static double snap(double v, double lo, double hi, double tol)
{
    if (fabs(v - lo) <= tol)
        return lo;
    if (fabs(v - hi) <= tol)
        return hi;
    return v;
}

/* The id of the point at (x, y): on a side (within tol), the side's point within tol or a new one
 * registered on every side it lies on; inside, a new point. -1 on no memory. */
static plume_index add_point(builder *B, double x, double y)
{
    x = snap(x, 0.0, B->lx, B->tol);
    y = snap(y, 0.0, B->ly, B->tol);
    int on[4] = {y == 0.0, x == B->lx, y == B->ly, x == 0.0};
    for (int s = 0; s < 4; s++) {
        if (!on[s])
            continue;
        double t = s % 2 == 0 ? x : y;
        for (plume_index k = 0; k < B->side[s].n; k++)
            if (fabs(B->side[s].v[k].t - t) <= B->tol)
                return B->side[s].v[k].id;
    }
    plume_index id = plume_pslg_point(&B->g, x, y);
    if (id < 0)
        return -1;
    for (int s = 0; s < 4; s++)
        if (on[s] && tlist_push(&B->side[s], s % 2 == 0 ? x : y, id) < 0)
            return -1;
    return id;
}

/* Clips o + t u, t in [t0, t1], to the rectangle; returns 0 if nothing (or less than min_len) is left. */
static int clip(const builder *B, const double o[2], const double u[2], double t0, double t1, double min_len,
                double *tlo, double *thi)
{
    double lo = t0, hi = t1, size[2] = {B->lx, B->ly};
    for (int k = 0; k < 2; k++) {
        if (fabs(u[k]) < 1e-15) { /* parallel to this pair of sides: inside strictly, or skipped */
            if (o[k] <= B->tol || o[k] >= size[k] - B->tol)
                return 0;
            continue;
        }
        double ta = (0.0 - o[k]) / u[k], tb = (size[k] - o[k]) / u[k];
        lo = fmax(lo, fmin(ta, tb));
        hi = fmin(hi, fmax(ta, tb));
    }
    *tlo = lo, *thi = hi;
    return hi - lo > min_len;
}

/* Points along a line: its registered points plus its ends (on the rectangle's sides), sorted, gaps filled to <= e, joined by
 * constrained segments. */
static plume_status emit_line(builder *B, line *L)
{
    for (int end = 0; end < 2; end++) {
        if (L->has_end[end])
            continue;
        double t = end ? L->thi : L->tlo;
        plume_index id = add_point(B, L->o[0] + t * L->u[0], L->o[1] + t * L->u[1]);
        if (id < 0 || tlist_push(&L->pts, t, id) < 0)
            return PLUME_ENOMEM;
    }
    qsort(L->pts.v, (size_t)L->pts.n, sizeof *L->pts.v, cmp_tpoint);
    plume_index prev = -1;
    double tprev = 0.0;
    for (plume_index k = 0; k < L->pts.n; k++) {
        double t = L->pts.v[k].t;
        plume_index id = L->pts.v[k].id;
        if (id == prev)
            continue;
        if (prev >= 0) {
            long pieces = (long)ceil((t - tprev) / B->e - 1e-9);
            for (long j = 1; j < pieces; j++) {
                double tj = tprev + (t - tprev) * (double)j / (double)pieces;
                plume_index mid = plume_pslg_point(&B->g, L->o[0] + tj * L->u[0], L->o[1] + tj * L->u[1]);
                if (mid < 0 || plume_pslg_segment(&B->g, prev, mid) < 0)
                    return PLUME_ENOMEM;
                prev = mid;
            }
            if (plume_pslg_segment(&B->g, prev, id) < 0)
                return PLUME_ENOMEM;
        }
        prev = id, tprev = t;
    }
    return PLUME_OK;
}

/* corners, then points along each side so that no gap exceeds e */
static plume_status fill_sides(builder *B)
{
    double corners[4][2] = {{0, 0}, {B->lx, 0}, {B->lx, B->ly}, {0, B->ly}};
    for (int k = 0; k < 4; k++)
        if (add_point(B, corners[k][0], corners[k][1]) < 0)
            return PLUME_ENOMEM;
    for (int s = 0; s < 4; s++) {
        tlist *sd = &B->side[s];
        qsort(sd->v, (size_t)sd->n, sizeof *sd->v, cmp_tpoint);
        plume_index n0 = sd->n;
        for (plume_index k = 0; k + 1 < n0; k++) {
            double ta = sd->v[k].t, tb = sd->v[k + 1].t;
            long pieces = (long)ceil((tb - ta) / B->e - 1e-9);
            for (long j = 1; j < pieces; j++) {
                double t = ta + (tb - ta) * (double)j / (double)pieces;
                double x = s == 0 ? t : s == 1 ? B->lx : s == 2 ? t : 0.0;
                double y = s == 0 ? 0.0 : s == 1 ? t : s == 2 ? B->ly : t;
                if (plume_pslg_point(&B->g, x, y) < 0)
                    return PLUME_ENOMEM;
            }
        }
    }
    return PLUME_OK;
}

/* The pattern in the barb frame (see the file comment). */
typedef struct {
    double d[2], q[2];
    double w, dB, gap;
    double c0;       /* lower boundary of barb 0: c_mid - w / 2 */
    int barbules;
    double s0;       /* bottom-left corner of barbule 0 along the barbs */
    double sp, cot, L;
} pattern;

static double pmod(double v, double p)
{
    double r = fmod(v, p);
    return r < 0 ? r + p : r;
}

/* PLUME_MAT_BARB, PLUME_MAT_BARBULE, or -1 (empty) at p */
static int material_at(const pattern *P, double x, double y)
{
    double c = P->q[0] * x + P->q[1] * y, s = P->d[0] * x + P->d[1] * y;
    double u = pmod(c - P->c0, P->dB);
    if (u < P->w)
        return PLUME_MAT_BARB;
    if (!P->barbules)
        return PLUME_MAT_BARBULE;
    double yg = u - P->w; /* height in the gap */
    return pmod(s - (P->s0 + yg * P->cot), P->sp) < P->L ? PLUME_MAT_BARBULE : -1;
}


static plume_index find(plume_index *parent, plume_index i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Strip boundary lines and barbule sides as constrained polylines, then the sides. */
static plume_status build_geometry(builder *B, const pattern *P, line **lines_out, plume_index *nlines_out,
                                   plume_err *err)
{
    double corners[4][2] = {{0, 0}, {B->lx, 0}, {B->lx, B->ly}, {0, B->ly}};
    double cmin = INFINITY, cmax = -INFINITY, smin = INFINITY, smax = -INFINITY;
    for (int k = 0; k < 4; k++) {
        double c = P->q[0] * corners[k][0] + P->q[1] * corners[k][1];
        double s = P->d[0] * corners[k][0] + P->d[1] * corners[k][1];
        cmin = fmin(cmin, c), cmax = fmax(cmax, c), smin = fmin(smin, s), smax = fmax(smax, s);
    }
    double min_len = MIN_LINE_REL * B->e;
    /* barb k covers [c0 + k dB, c0 + k dB + w]; lines 2 (k - kmin) (lower) and 2 (k - kmin) + 1 (upper) */
    long kmin = (long)floor((cmin - P->c0) / P->dB) - 1, kmax = (long)ceil((cmax - P->c0) / P->dB) + 1;
    plume_index nbarb = 2 * (kmax - kmin + 1), nlines = nbarb;
    long jmin = 0, jmax = -1;
    if (P->barbules) {
        double lo = fmin(0.0, P->gap * P->cot), hi = fmax(0.0, P->gap * P->cot) + P->L;
        jmin = (long)floor((smin - hi - P->s0) / P->sp) - 1;
        jmax = (long)ceil((smax - lo - P->s0) / P->sp) + 1;
        /* every barbule is resolved, whatever e is: refuse patterns far finer than the elements */
        double nsides = 2.0 * (double)(kmax - kmin + 1) * (double)(jmax - jmin + 1);
        double per_side = fmax(1.0, P->gap * sqrt(1.0 + P->cot * P->cot) / B->e);
        if (!(nsides * per_side <= MAX_TRIANGLES))
            return plume_err_set(err, PLUME_EINVAL,
                                 "barbule_spacing = %g m gives ~%.3g barbule sides of ~%.3g elements each in the "
                                 "specimen (more than %g)",
                                 P->sp, nsides, per_side, MAX_TRIANGLES);
        nlines += 2 * (kmax - kmin + 1) * (jmax - jmin + 1);
    }
    line *lines = calloc((size_t)nlines, sizeof *lines);
    if (!lines)
        return PLUME_ENOMEM;
    *lines_out = lines, *nlines_out = nlines;
    for (long k = kmin; k <= kmax; k++)
        for (int up = 0; up < 2; up++) {
            line *L = lines + 2 * (k - kmin) + up;
            double c = P->c0 + (double)k * P->dB + (up ? P->w : 0.0);
            L->o[0] = c * P->q[0], L->o[1] = c * P->q[1];
            L->u[0] = P->d[0], L->u[1] = P->d[1];
            L->present = clip(B, L->o, L->u, -INFINITY, INFINITY, min_len, &L->tlo, &L->thi);
        }
    plume_index next = nbarb;
    for (long k = kmin; P->barbules && k < kmax; k++) {
        line *below = lines + 2 * (k - kmin) + 1, *above = lines + 2 * (k + 1 - kmin);
        double cb = P->c0 + (double)k * P->dB + P->w, ca = P->c0 + (double)(k + 1) * P->dB;
        for (long j = jmin; j <= jmax; j++)
            for (int side = 0; side < 2; side++) {
                line *L = lines + next++;
                /* from the bottom end (on `below`, at s = sb) to the top end (on `above`) */
                double sb = P->s0 + (double)j * P->sp + (side ? P->L : 0.0), st = sb + P->gap * P->cot;
                double A[2] = {cb * P->q[0] + sb * P->d[0], cb * P->q[1] + sb * P->d[1]};
                double Bt[2] = {ca * P->q[0] + st * P->d[0], ca * P->q[1] + st * P->d[1]};
                double len = hypot(Bt[0] - A[0], Bt[1] - A[1]);
                L->o[0] = A[0], L->o[1] = A[1];
                L->u[0] = (Bt[0] - A[0]) / len, L->u[1] = (Bt[1] - A[1]) / len;
                L->present = clip(B, L->o, L->u, 0.0, len, min_len, &L->tlo, &L->thi);
                if (!L->present)
                    continue;
                /* an end inside the rectangle is a point of the barb line it lies on */
                for (int end = 0; end < 2; end++) {
                    double t = end ? len : 0.0;
                    if (end ? L->thi < len : L->tlo > 0.0)
                        continue; /* clipped: that end is a boundary point, added by emit_line */
                    const double *p = end ? Bt : A;
                    plume_index id = add_point(B, p[0], p[1]);
                    line *barb = end ? above : below;
                    L->has_end[end] = 1;
                    if (id < 0 || tlist_push(&L->pts, t, id) < 0 ||
                        (barb->present && tlist_push(&barb->pts, end ? st : sb, id) < 0))
                        return PLUME_ENOMEM;
                }
            }
    }
    for (plume_index i = 0; i < next; i++)
        if (lines[i].present) {
            plume_status st = emit_line(B, lines + i);
            if (st != PLUME_OK)
                return st;
        }
    return fill_sides(B);
}

/* The checks of plume_specimen_mesh's layout, size and angle; the barb width *w and element edge *e. */
static plume_status check_specimen(const plume_layout *l, double lx, double ly, double angle_deg, double *w_out,
                                   double *e_out, plume_err *err)
{
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    if (!(lx > 0) || !(ly > 0) || !isfinite(lx) || !isfinite(ly))
        return plume_err_set(err, PLUME_EINVAL, "specimen size must be finite and > 0 (got lx = %g, ly = %g m)",
                             lx, ly);
    if (!(angle_deg >= 0.0 && angle_deg <= 180.0))
        return plume_err_set(err, PLUME_EINVAL, "barb angle must be in [0, 180] degrees (got %g)", angle_deg);
    double w = plume_layout_barb_width(l), e = plume_layout_element_edge(l, PLUME_MESH_SPECIMEN);
    if (!(w >= 1e-12 * l->d_B) || !(l->d_B - w >= 1e-12 * l->d_B))
        return plume_err_set(err, PLUME_EINVAL,
                             "phi = %g: the barb strip (%g m) or the gap (%g m) is below 1e-12 d_B: the mesh "
                             "cannot resolve it",
                             l->phi, w, l->d_B - w);
    double estimate = lx * ly / (0.43 * e * e);
    if (!(estimate <= MAX_TRIANGLES))
        return plume_err_set(err, PLUME_EINVAL,
                             "e_rel = %g gives elements of %g m: a %g x %g m specimen would need ~%.3g triangles "
                             "(more than %g)",
                             e / w, e, lx, ly, estimate, MAX_TRIANGLES);
    *w_out = w, *e_out = e;
    return PLUME_OK;
}

/* The layout's pattern over the lx x ly specimen with barbs at angle_deg, in phase with its centre
 * (see the file comment); w is the barb width. */
static void specimen_pattern(const plume_layout *l, double lx, double ly, double angle_deg, double w, pattern *P)
{
    memset(P, 0, sizeof *P);
    plume_barb_direction(angle_deg, P->d);
    P->q[0] = -P->d[1], P->q[1] = P->d[0];
    P->w = w, P->dB = l->d_B, P->gap = l->d_B - w;
    double mid[2] = {0.5 * lx, 0.5 * ly};
    P->c0 = P->q[0] * mid[0] + P->q[1] * mid[1] - 0.5 * w;
    P->barbules = l->kind == PLUME_LAYOUT_BARBULES;
    if (P->barbules) {
        double th = l->barbule_angle * M_PI / 180.0;
        P->sp = l->barbule_spacing;
        P->cot = cos(th) / sin(th);
        P->L = l->barbule_width / sin(th);
        /* the barbule of the gap above barb 0 has its centre (s0 + gap cot / 2 + L / 2) at mid */
        P->s0 = P->d[0] * mid[0] + P->d[1] * mid[1] - 0.5 * (P->gap * P->cot + P->L);
    }
}

/* Each triangle's material (mat[t], -1 for the dropped ones: empty space, and the pieces that touch
 * neither grip y = 0, y = ly), the new ids of the vertices kept (newid[v], -1 if dropped) and the
 * counts kept. A union-find of the kept triangles' vertices finds the pieces. */
static plume_status keep_held_pieces(const plume_cdt_output *cdt, const pattern *P, double ly, int *mat,
                                     plume_index *newid, plume_index *kept_out, plume_index *nv_out)
{
    plume_index np = cdt->npoints, nt = cdt->ntriangles;
    plume_index *parent = malloc((size_t)np * sizeof *parent);
    unsigned char *grip = calloc((size_t)np, 1);
    if (!parent || !grip) {
        free(parent);
        free(grip);
        return PLUME_ENOMEM;
    }
    for (plume_index i = 0; i < np; i++)
        parent[i] = i;
    for (plume_index t = 0; t < nt; t++) {
        const plume_index *v = cdt->triangles + 3 * t;
        double cx = 0, cy = 0;
        for (int k = 0; k < 3; k++)
            cx += cdt->points[2 * v[k]] / 3.0, cy += cdt->points[2 * v[k] + 1] / 3.0;
        mat[t] = material_at(P, cx, cy);
        if (mat[t] < 0)
            continue;
        plume_index r0 = find(parent, v[0]);
        for (int k = 1; k < 3; k++) {
            plume_index r = find(parent, v[k]);
            if (r != r0)
                parent[r] = r0;
        }
    }
    for (plume_index t = 0; t < nt; t++) /* a piece holds if one of its vertices is on a grip */
        for (int k = 0; mat[t] >= 0 && k < 3; k++) {
            plume_index v = cdt->triangles[3 * t + k];
            double y = cdt->points[2 * v + 1];
            if (y == 0.0 || y == ly)
                grip[find(parent, v)] = 1;
        }
    plume_index kept = 0, nv = 0;
    for (plume_index i = 0; i < np; i++)
        newid[i] = -1;
    for (plume_index t = 0; t < nt; t++) {
        if (mat[t] >= 0 && !grip[find(parent, cdt->triangles[3 * t])])
            mat[t] = -1;
        if (mat[t] < 0)
            continue;
        kept++;
        for (int k = 0; k < 3; k++) {
            plume_index v = cdt->triangles[3 * t + k];
            if (newid[v] < 0)
                newid[v] = nv++;
        }
    }
    free(parent);
    free(grip);
    *kept_out = kept, *nv_out = nv;
    return PLUME_OK;
}

/* The mesh of the kept triangles (mat[t] >= 0) renumbered by newid, barbs along d, topology built. */
static plume_status kept_mesh(const plume_cdt_output *cdt, const int *mat, const plume_index *newid, plume_index nv,
                              plume_index kept, const double d[2], plume_mesh **out, plume_err *err)
{
    plume_mesh *m = NULL;
    plume_status st = plume_mesh_create(nv, kept, 2, &m, err);
    if (st != PLUME_OK)
        return st;
    for (plume_index i = 0; i < cdt->npoints; i++)
        if (newid[i] >= 0)
            m->X[2 * newid[i]] = cdt->points[2 * i], m->X[2 * newid[i] + 1] = cdt->points[2 * i + 1];
    kept = 0;
    for (plume_index t = 0; t < cdt->ntriangles; t++) {
        if (mat[t] < 0)
            continue;
        for (int k = 0; k < 3; k++)
            m->tri[3 * kept + k] = newid[cdt->triangles[3 * t + k]];
        m->material[kept] = mat[t];
        m->barb_dir[2 * kept] = d[0], m->barb_dir[2 * kept + 1] = d[1];
        kept++;
    }
    plume_mesh_reset_current(m);
    if ((st = plume_mesh_build_topology(m, err)) != PLUME_OK) {
        plume_mesh_destroy(&m);
        return st;
    }
    *out = m;
    return PLUME_OK;
}

plume_status plume_specimen_mesh(const plume_layout *l, double lx, double ly, double angle_deg,
                                 plume_mesh **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "specimen mesh: out is NULL");
    *out = NULL;
    double w = 0.0, e = 0.0;
    plume_status st = check_specimen(l, lx, ly, angle_deg, &w, &e, err);
    if (st != PLUME_OK)
        return st;
    pattern P;
    specimen_pattern(l, lx, ly, angle_deg, w, &P);

    builder B;
    memset(&B, 0, sizeof B);
    B.lx = lx, B.ly = ly, B.e = e, B.tol = 1e-9 * fmax(lx, ly);
    line *lines = NULL;
    plume_index nlines = 0;
    plume_cdt_output cdt = {0};
    plume_index *newid = NULL;
    int *mat = NULL;
    if ((st = build_geometry(&B, &P, &lines, &nlines, err)) != PLUME_OK)
        goto cleanup;
    plume_cdt_input in;
    memset(&in, 0, sizeof in);
    in.npoints = B.g.n;
    in.points = B.g.p;
    in.nsegments = B.g.ns;
    in.segments = B.g.s;
    in.remove_exterior = 0;
    in.max_edge = e;
    if ((st = plume_cdt_triangulate(&in, &cdt, err)) != PLUME_OK)
        goto cleanup;

    mat = malloc((size_t)cdt.ntriangles * sizeof *mat);
    newid = malloc((size_t)cdt.npoints * sizeof *newid);
    if (!mat || !newid) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    plume_index kept = 0, nv = 0;
    if ((st = keep_held_pieces(&cdt, &P, ly, mat, newid, &kept, &nv)) != PLUME_OK)
        goto cleanup;
    if (kept == 0) {
        st = plume_err_set(err, PLUME_EINVAL,
                           "specimen mesh: no material left in the %g x %g m specimen at %g deg (every piece is "
                           "empty space or cut loose from both grips)",
                           lx, ly, angle_deg);
        goto cleanup;
    }
    st = kept_mesh(&cdt, mat, newid, nv, kept, P.d, out, err);
cleanup:
    if (st == PLUME_ENOMEM)
        plume_err_set(err, st, "specimen mesh: out of memory");
    plume_cdt_output_free(&cdt);
    for (plume_index i = 0; i < nlines; i++)
        free(lines[i].pts.v);
    free(lines);
    for (int s = 0; s < 4; s++)
        free(B.side[s].v);
    free(B.g.p);
    free(B.g.s);
    free(mat);
    free(newid);
    return st;
}
