/* plume: the periodic cell of a layout (micro/cell_mesh.h).
 *
 * The cell is meshed from a point set built here and triangulated without refinement
 * (max_edge = 0), so the vertices are exactly our points and the periodic pairs match bit for bit:
 * every row of points contains x = 0 and x = a, the same y values are used on both sides, and the
 * x values on y = b are also put on y = 0. Rows lie on y = 0, w_B, b (and in between), so the strip
 * boundary y = w_B is a row of points joined by constrained segments.
 *
 * Strips: a = 4 w_B (header); at least 3 elements along x so that no triangle joins a vertex to its
 * own periodic image. Barbules: a = barbule_spacing; the barb strip [0, a] x [0, w_B] is meshed
 * fully and the gap only inside the barbule parallelogram, centred in x (so it crosses neither
 * x = 0 nor x = a), whose outline is constrained; remove_exterior drops the empty space. */
#include "../lib/core/pslg.h"
#include "cell_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/cdt.h"
#include "../lib/core/membrane_p2.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Rows of a structured-ish grid are spaced by the height of an equilateral triangle of side e. */
#define ROW_HEIGHT(e) ((e) * 0.8660254037844386)
/* Cells above this many triangles (estimated from the grid) are refused. */
#define MAX_TRIANGLES 5e6
/* ceil(x - slack): a ratio that is an integer up to round-off does not get one more piece */
#define PIECES(x) ((long)ceil((x) - 1e-9))

typedef plume_pslg geometry; /* lib/core/pslg.h */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The x positions of a row: the uniform grid 0, a/nx, ..., a (shifted by half a step when `shift`,
 * keeping 0 and a), without the grid points closer than half a step to [lo, hi], plus the `nextra`
 * values `extra` (which lie in (0, a)); sorted. `out` holds nx + 2 + nextra values. Returns the
 * count. */
static long row_positions(double a, long nx, int shift, const double *extra, long nextra, double *out)
{
    double hx = a / (double)nx, lo = INFINITY, hi = -INFINITY;
    for (long k = 0; k < nextra; k++)
        lo = fmin(lo, extra[k]), hi = fmax(hi, extra[k]);
    long n = 0;
    out[n++] = 0.0;
    for (long i = shift ? 0 : 1; i < nx; i++) {
        double x = shift ? a * ((double)i + 0.5) / (double)nx : a * (double)i / (double)nx;
        if (nextra > 0 && x > lo - 0.5 * hx && x < hi + 0.5 * hx)
            continue;
        out[n++] = x;
    }
    out[n++] = a;
    for (long k = 0; k < nextra; k++)
        out[n++] = extra[k];
    qsort(out, (size_t)n, sizeof *out, cmp_double);
    return n;
}

/* Pushes a row of points at height y; joins them by segments when `constrain`. Returns the id of
 * the first point (the row's ids are consecutive) or -1 on no memory. */
static plume_index push_row(geometry *g, const double *xs, long n, double y, int constrain)
{
    plume_index first = g->n;
    for (long i = 0; i < n; i++) {
        if (plume_pslg_point(g, xs[i], y) < 0)
            return -1;
        if (constrain && i > 0 && plume_pslg_segment(g, first + i - 1, first + i) < 0)
            return -1;
    }
    return first;
}

/* Strips: rows at y = 0 .. w_B (ny1 intervals) and w_B .. b (ny2 intervals); the full hull is the
 * cell boundary, so the triangulation needs no exterior removal. */
static plume_status strips_geometry(double a, double w, double b, double e, geometry *g)
{
    long nx = PIECES(a / e);
    if (nx < 3)
        nx = 3;
    long ny1 = PIECES(w / ROW_HEIGHT(e)), ny2 = PIECES((b - w) / ROW_HEIGHT(e));
    if (ny1 < 1)
        ny1 = 1;
    if (ny2 < 1)
        ny2 = 1;
    double *xs = malloc((size_t)(nx + 2) * sizeof *xs);
    if (!xs)
        return PLUME_ENOMEM;
    plume_status st = PLUME_OK;
    for (long j = 0; j <= ny1 + ny2; j++) {
        double y = j == 0 ? 0.0
                 : j == ny1 ? w
                 : j == ny1 + ny2 ? b
                 : j < ny1 ? w * (double)j / (double)ny1
                           : w + (b - w) * (double)(j - ny1) / (double)ny2;
        int boundary_row = j == 0 || j == ny1 || j == ny1 + ny2;
        long band_row = j <= ny1 ? j : j - ny1; /* shifted rows alternate from each band's base */
        long n = row_positions(a, nx, !boundary_row && band_row % 2 == 1, NULL, 0, xs);
        if (push_row(g, xs, n, y, j == ny1) < 0) {
            st = PLUME_ENOMEM;
            break;
        }
    }
    free(xs);
    return st;
}

/* Barbules: the barb strip rows, then the barbule rows; every outline piece is constrained. */
static plume_status barbules_geometry(const plume_layout *l, double a, double w, double b, double e,
                                      geometry *g, plume_err *err)
{
    double th = l->barbule_angle * M_PI / 180.0, gap = b - w;
    double cot = cos(th) / sin(th), L = l->barbule_width / sin(th);
    double extent = gap * fabs(cot) + L, margin = 0.5 * (a - extent);
    if (!(margin > 1e-12 * b))
        return plume_err_set(err, PLUME_EINVAL,
                             "cell too small for its layout: the barbule spans %g m along the barbs, leaving "
                             "%g m of the barbule_spacing %g m: too little to mesh",
                             extent, a - extent, a);
    double x0 = margin - fmin(0.0, gap * cot); /* bottom-left corner on y = w_B */
    double xt0 = x0 + gap * cot;                /* top-left corner on y = b */
    long nw = PIECES(L / e), ns = PIECES(gap / sin(th) / e);
    if (nw < 1)
        nw = 1;
    if (ns < 1)
        ns = 1;
    long nx = PIECES(a / e);
    if (nx < 3)
        nx = 3;
    long ny1 = PIECES(w / ROW_HEIGHT(e));
    if (ny1 < 1)
        ny1 = 1;
    plume_status st = PLUME_OK;
    double *xb = malloc((size_t)(nw + 1) * sizeof *xb), *xt = malloc((size_t)(nw + 1) * sizeof *xt);
    double *xs = malloc((size_t)(nx + nw + 4) * sizeof *xs);
    plume_index *left = malloc((size_t)(ns + 1) * sizeof *left), *right = malloc((size_t)(ns + 1) * sizeof *right);
    plume_index *col0 = malloc((size_t)(ny1 + 1) * sizeof *col0), *cola = malloc((size_t)(ny1 + 1) * sizeof *cola);
    if (!xb || !xt || !xs || !left || !right || !col0 || !cola) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    /* The top end's x values are computed once and used on y = b and (as its images) on y = 0. */
    for (long i = 0; i <= nw; i++) {
        xb[i] = x0 + L * (double)i / (double)nw;
        xt[i] = xt0 + L * (double)i / (double)nw;
    }
    /* barb strip: row 0 (hull, with the top end's images), interior rows, row w_B (with the bottom end) */
    for (long j = 0; j <= ny1; j++) {
        double y = j == 0 ? 0.0 : j == ny1 ? w : w * (double)j / (double)ny1;
        long n = j == 0     ? row_positions(a, nx, 0, xt, nw + 1, xs)
               : j == ny1 ? row_positions(a, nx, 0, xb, nw + 1, xs)
                          : row_positions(a, nx, j % 2 == 1, NULL, 0, xs);
        plume_index first = push_row(g, xs, n, y, j == 0 || j == ny1);
        if (first < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
        col0[j] = first, cola[j] = first + n - 1;
        if (j == ny1) { /* the barbule's bottom corners are points of this row */
            for (long i = 0; i < n; i++) {
                if (xs[i] == xb[0])
                    left[0] = first + i;
                if (xs[i] == xb[nw])
                    right[0] = first + i;
            }
        }
    }
    for (long j = 0; j < ny1; j++)
        if (plume_pslg_segment(g, col0[j], col0[j + 1]) < 0 || plume_pslg_segment(g, cola[j], cola[j + 1]) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
    /* barbule rows r = 1 .. ns; the last one is y = b exactly, with the x values xt */
    for (long r = 1; r <= ns; r++) {
        double y = r == ns ? b : w + gap * (double)r / (double)ns;
        double xl = x0 + (y - w) * cot;
        for (long i = 0; i <= nw; i++)
            xs[i] = r == ns ? xt[i] : xl + L * (double)i / (double)nw;
        plume_index first = push_row(g, xs, nw + 1, y, r == ns);
        if (first < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
        left[r] = first, right[r] = first + nw;
    }
    for (long r = 0; r < ns; r++)
        if (plume_pslg_segment(g, left[r], left[r + 1]) < 0 || plume_pslg_segment(g, right[r], right[r + 1]) < 0) {
            st = PLUME_ENOMEM;
            goto cleanup;
        }
cleanup:
    free(xb);
    free(xt);
    free(xs);
    free(left);
    free(right);
    free(col0);
    free(cola);
    return st;
}

/* vertex ids sorted by (x, y) for exact periodic look-ups */
typedef struct {
    const double *X;
    plume_index v;
} vkey;

static int cmp_xy(const double *p, const double *q)
{
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return (p[1] > q[1]) - (p[1] < q[1]);
}

static int cmp_vkey(const void *a, const void *b)
{
    return cmp_xy(((const vkey *)a)->X, ((const vkey *)b)->X);
}

/* Masters and shifts: x = a maps to x = 0 (same y), y = b to y = 0 (same x), both to the corner. */
static plume_status periodic_pairs(plume_cell *c, plume_err *err)
{
    const plume_mesh *m = c->mesh;
    plume_status st = PLUME_OK;
    vkey *keys = malloc((size_t)m->nv * sizeof *keys);
    if (!keys)
        return PLUME_ENOMEM;
    for (plume_index v = 0; v < m->nv; v++)
        keys[v].X = m->X + 2 * v, keys[v].v = v;
    qsort(keys, (size_t)m->nv, sizeof *keys, cmp_vkey);
    plume_index on_left = 0, on_right = 0;
    c->nmasters = 0;
    for (plume_index v = 0; v < m->nv; v++) {
        const double *X = m->X + 2 * v;
        double target[2] = {X[0] == c->a ? 0.0 : X[0], X[1] == c->b ? 0.0 : X[1]};
        on_left += X[0] == 0.0;
        on_right += X[0] == c->a;
        plume_index master = v;
        if (target[0] != X[0] || target[1] != X[1]) {
            vkey key = {target, -1};
            const vkey *hit = bsearch(&key, keys, (size_t)m->nv, sizeof *keys, cmp_vkey);
            if (!hit) {
                st = plume_err_set(err, PLUME_EDEP,
                                   "cell mesh: vertex %ld at (%.17g, %.17g) on the %s side has no periodic "
                                   "partner at (%.17g, %.17g) (internal error)",
                                   (long)v, X[0], X[1], X[0] == c->a ? "x = a" : "y = b", target[0], target[1]);
                goto cleanup;
            }
            master = hit->v;
        }
        c->master[v] = master;
        c->shift[2 * v] = X[0] - m->X[2 * master];
        c->shift[2 * v + 1] = X[1] - m->X[2 * master + 1];
        c->nmasters += master == v;
    }
    if (on_left != on_right)
        st = plume_err_set(err, PLUME_EDEP,
                           "cell mesh: %ld vertices on x = 0 but %ld on x = a: the sides do not pair (internal "
                           "error)",
                           (long)on_left, (long)on_right);
cleanup:
    free(keys);
    return st;
}

plume_status plume_cell_mesh(const plume_layout *l, plume_cell **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "cell mesh: out is NULL");
    *out = NULL;
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    double w = plume_layout_barb_width(l), b = l->d_B, e = plume_layout_element_edge(l, PLUME_MESH_CELL);
    if (!(w >= 1e-12 * b) || !(b - w >= 1e-12 * b))
        return plume_err_set(err, PLUME_EINVAL,
                             "phi = %g: the barb strip (%g m) or the gap (%g m) is below 1e-12 d_B: the mesh "
                             "cannot resolve it",
                             l->phi, w, b - w);
    double a = l->kind == PLUME_LAYOUT_STRIPS ? 4.0 * w : l->barbule_spacing;
    double estimate = 2.0 * (a / e + 4.0) * (b / ROW_HEIGHT(e) + 4.0);
    if (!(estimate <= MAX_TRIANGLES))
        return plume_err_set(err, PLUME_EINVAL,
                             "e_rel = %g gives elements of %g m: the %g x %g m cell would need ~%.3g triangles "
                             "(more than %g)",
                             l->e_rel, e, a, b, estimate, MAX_TRIANGLES);
    geometry g = {0};
    plume_cdt_output cdt = {0};
    plume_cell *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->b = b;
    plume_cdt_input in = {0};
    c->a = a;
    if (l->kind == PLUME_LAYOUT_STRIPS) {
        st = strips_geometry(c->a, w, b, e, &g);
        in.remove_exterior = 0;
    } else {
        st = barbules_geometry(l, c->a, w, b, e, &g, err);
        in.remove_exterior = 1;
    }
    if (st != PLUME_OK)
        goto cleanup;
    in.npoints = g.n;
    in.points = g.p;
    in.nsegments = g.ns;
    in.segments = g.s;
    in.max_edge = 0.0; /* no Steiner points: the periodic pairs stay exact */
    if ((st = plume_cdt_triangulate(&in, &cdt, err)) != PLUME_OK)
        goto cleanup;
    if (cdt.npoints != g.n) {
        st = plume_err_set(err, PLUME_EDEP, "cell mesh: the triangulation added %ld points (internal error)",
                           (long)(cdt.npoints - g.n));
        goto cleanup;
    }
    if ((st = plume_mesh_create(cdt.npoints, cdt.ntriangles, 2, &c->mesh, err)) != PLUME_OK)
        goto cleanup;
    plume_mesh *m = c->mesh;
    memcpy(m->X, cdt.points, (size_t)(2 * cdt.npoints) * sizeof *m->X);
    memcpy(m->tri, cdt.triangles, (size_t)(3 * cdt.ntriangles) * sizeof *m->tri);
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        double yc = (m->X[2 * v[0] + 1] + m->X[2 * v[1] + 1] + m->X[2 * v[2] + 1]) / 3.0;
        m->material[t] = yc < w ? PLUME_MAT_BARB : PLUME_MAT_BARBULE;
        m->barb_dir[2 * t] = 1.0, m->barb_dir[2 * t + 1] = 0.0;
    }
    plume_mesh_reset_current(m);
    if ((st = plume_mesh_build_topology(m, err)) != PLUME_OK)
        goto cleanup;
    c->order = l->order;
    if (l->order == 2) {
        if ((st = plume_mesh_quadratic(m, &c->quad, err)) != PLUME_OK)
            goto cleanup;
        plume_mesh_destroy(&c->mesh);
        m = c->mesh = c->quad.split;
        c->quad.split = NULL;
    }
    c->master = malloc((size_t)m->nv * sizeof *c->master);
    c->shift = malloc((size_t)(2 * m->nv) * sizeof *c->shift);
    if (!c->master || !c->shift) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    if ((st = periodic_pairs(c, err)) != PLUME_OK)
        goto cleanup;
    *out = c;
    c = NULL;
cleanup:
    if (st == PLUME_ENOMEM)
        plume_err_set(err, st, "cell mesh: out of memory");
    plume_cell_destroy(&c);
    plume_cdt_output_free(&cdt);
    free(g.p);
    free(g.s);
    return st;
}

void plume_cell_destroy(plume_cell **c)
{
    if (!c || !*c)
        return;
    plume_mesh_destroy(&(*c)->mesh);
    plume_quadratic_mesh_free(&(*c)->quad);
    free((*c)->master);
    free((*c)->shift);
    free(*c);
    *c = NULL;
}

plume_index plume_cell_elements(const plume_cell *c)
{
    return c->order == 2 ? c->quad.nt : c->mesh->nt;
}

plume_status plume_micro_membrane_term(const plume_mesh *mesh, const plume_quadratic_mesh *quad,
                                       const plume_membrane_material *mats, int nmat, plume_term *out,
                                       plume_err *err)
{
    if (!quad || !quad->tri6)
        return plume_membrane_term_create(mesh, 2, mats, nmat, out, err);
    return plume_membrane_p2_term_create(mesh->X, mesh->nv, quad->tri6, quad->nt, quad->material, quad->barb_dir,
                                         mats, nmat, out, err);
}

const plume_mesh *plume_cell_mesh_of(const plume_cell *cell)
{
    return cell ? cell->mesh : NULL;
}
