/* plume: the periodic plate cell problem (micro/cell_plate.h).
 *
 * Morley triangles: the deflection is quadratic on each triangle, its unknowns the three vertex
 * values and the three normal slopes at the edges' midpoints. The element is nonconforming but
 * passes the patch test and converges for Kirchhoff plates; its curvature is constant per
 * triangle, so a laminate of strips meshed along their boundaries is represented exactly. A
 * quadratic is reproduced exactly, so the macroscopic part 1/2 X^T kbar X contributes kbar to
 * every triangle and only the periodic fluctuation is discretised: per triangle the curvature is
 * kbar + B u, u its six fluctuation unknowns.
 *
 * Periodicity by construction: a vertex takes its master's unknown (micro/cell_mesh.h); an edge on
 * x = a or y = b takes the unknown of its translate on x = 0 or y = 0 (the cell mesh puts the same
 * coordinates on opposite sides, so midpoints match bit for bit). The slope unknown is along a
 * normal fixed by the edge's direction (translation invariant), each triangle seeing it with the
 * sign of its own outward normal. One vertex is anchored: the constant is the only periodic
 * fluctuation without energy. */
#include "cell_plate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/solve/cholesky.h"
#include "cell_linear.h"

void plume_plate_moduli_from_tensor(const double D[9], plume_plate_moduli *m)
{
    m->D_long = D[0];
    m->D_trans = D[4];
    m->D_coupling = 0.5 * (D[1] + D[3]);
    m->D_twist = D[8];
    m->D_16 = 0.5 * (D[2] + D[6]);
    m->D_26 = 0.5 * (D[5] + D[7]);
}

/* The Morley curvature operator of a triangle (vertices ccw, edge k from vertex k to k + 1):
 * kappa = (H_xx, H_yy, 2 H_xy) = B (w0, w1, w2, s0, s1, s2), s_k the slope along the edge's fixed
 * normal, which is sign[k] times the outward one. From Green's formula with the gradient linear
 * along each edge: A H_ab = sum_k l_k n_a g_b(M_k), the gradient at edge k's midpoint being
 * g = t (w_j - w_i) / l + n sign_k s_k (the tangential slope of a quadratic at the midpoint is
 * its secant). Returns the area. */
static double morley_B(const double *P0, const double *P1, const double *P2, const double sign[3], double B[3][6])
{
    const double *P[3] = {P0, P1, P2};
    double area = 0.5 * ((P1[0] - P0[0]) * (P2[1] - P0[1]) - (P2[0] - P0[0]) * (P1[1] - P0[1]));
    memset(B, 0, sizeof(double) * 18);
    for (int k = 0; k < 3; k++) {
        int i = k, j = (k + 1) % 3;
        double ex = P[j][0] - P[i][0], ey = P[j][1] - P[i][1], l = hypot(ex, ey);
        double t[2] = {ex / l, ey / l}, n[2] = {t[1], -t[0]}; /* outward for a ccw triangle */
        /* H_ab from the vertex values: n_a t_b (w_j - w_i) / A; from the slope: l sign n_a n_b / A */
        double Hw[2][2] = {{n[0] * t[0], n[0] * t[1]}, {n[1] * t[0], n[1] * t[1]}};
        double Hs[2][2] = {{n[0] * n[0], n[0] * n[1]}, {n[1] * n[0], n[1] * n[1]}};
        double vw[3] = {Hw[0][0], Hw[1][1], Hw[0][1] + Hw[1][0]};
        double vs[3] = {Hs[0][0], Hs[1][1], 2.0 * Hs[0][1]};
        for (int r = 0; r < 3; r++) {
            B[r][j] += vw[r] / area;
            B[r][i] -= vw[r] / area;
            B[r][3 + k] += l * sign[k] * vs[r] / area;
        }
    }
    return area;
}

/* The fixed normal of the edge p -> q: its direction made canonical (x > 0, or x = 0 and y > 0)
 * turned clockwise; returns +1 when it is the outward normal of a ccw triangle travelling p -> q. */
static double edge_sign(const double *p, const double *q)
{
    double ex = q[0] - p[0], ey = q[1] - p[1];
    return (ex > 0.0 || (ex == 0.0 && ey > 0.0)) ? 1.0 : -1.0;
}

typedef struct {
    double x, y;
    plume_index e;
} midpoint;

static int cmp_midpoint(const void *a, const void *b)
{
    const midpoint *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->y > q->y) - (p->y < q->y);
}

static int cmp_long(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

/* The plate problem of a cell: dofs, the per-triangle operators and stiffnesses, the matrix. */
typedef struct {
    plume_index nt, n;       /* triangles, unknowns */
    plume_index *dof;        /* [6 nt] unknown of each element dof, -1 for the anchor */
    double *B;               /* [18 nt] curvature operators */
    double *area;            /* [nt] */
    double *D;               /* [9 nt] plate stiffness in the cell frame */
    plume_index *colptr, *rowind; /* upper triangle, CSC */
    double *values;
} plate;

static void plate_free(plate *p)
{
    free(p->dof);
    free(p->B);
    free(p->area);
    free(p->D);
    free(p->colptr);
    free(p->rowind);
    free(p->values);
}

/* Edge of each triangle side (tri_edge[3 t + k], side k from vertex k to k + 1) from the mesh's
 * edge list and adjacency. */
static plume_status triangle_edges(const plume_mesh *m, plume_index *tri_edge, plume_err *err)
{
    for (plume_index t = 0; t < 3 * m->nt; t++)
        tri_edge[t] = -1;
    for (plume_index e = 0; e < m->ne; e++)
        for (int s = 0; s < 2; s++) {
            plume_index t = m->edge_tri[2 * e + s];
            if (t < 0)
                continue;
            for (int k = 0; k < 3; k++) {
                plume_index a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
                if ((a == m->edges[2 * e] && b == m->edges[2 * e + 1]) || (b == m->edges[2 * e] && a == m->edges[2 * e + 1]))
                    tri_edge[3 * t + k] = e;
            }
        }
    for (plume_index t = 0; t < 3 * m->nt; t++)
        if (tri_edge[t] < 0)
            return plume_err_set(err, PLUME_EINVAL, "plate cell: triangle %ld has a side without an edge (no topology?)",
                                 (long)(t / 3));
    return PLUME_OK;
}

/* The master of every edge: itself, or for an edge on x = a (both vertices shifted in x) or y = b
 * its translate by (-a, 0) or (0, -b), found by its midpoint. */
static plume_status edge_masters(const plume_cell *c, plume_index *master, plume_err *err)
{
    const plume_mesh *m = c->mesh;
    midpoint *mp = malloc((size_t)(m->ne + 1) * sizeof *mp);
    if (!mp)
        return plume_err_set(err, PLUME_ENOMEM, "plate cell: out of memory");
    for (plume_index e = 0; e < m->ne; e++) {
        const double *p = m->X + 2 * m->edges[2 * e], *q = m->X + 2 * m->edges[2 * e + 1];
        mp[e].x = 0.5 * (p[0] + q[0]), mp[e].y = 0.5 * (p[1] + q[1]), mp[e].e = e;
    }
    qsort(mp, (size_t)m->ne, sizeof *mp, cmp_midpoint);
    plume_status st = PLUME_OK;
    for (plume_index e = 0; e < m->ne && st == PLUME_OK; e++) {
        plume_index i = m->edges[2 * e], j = m->edges[2 * e + 1];
        const double *si = c->shift + 2 * i, *sj = c->shift + 2 * j;
        double sx = si[0] != 0.0 && sj[0] != 0.0 ? si[0] : 0.0, sy = si[1] != 0.0 && sj[1] != 0.0 ? si[1] : 0.0;
        master[e] = e;
        if (sx == 0.0 && sy == 0.0)
            continue;
        const double *p = m->X + 2 * i, *q = m->X + 2 * j;
        midpoint key = {0.5 * (p[0] + q[0]) - sx, 0.5 * (p[1] + q[1]) - sy, -1};
        const midpoint *hit = bsearch(&key, mp, (size_t)m->ne, sizeof *mp, cmp_midpoint);
        if (!hit)
            st = plume_err_set(err, PLUME_EINVAL, "plate cell: the boundary edge at (%g, %g) has no periodic image",
                               key.x + sx, key.y + sy);
        else
            master[e] = hit->e;
    }
    free(mp);
    return st;
}

/* Numbers the unknowns and fills the per-triangle data. */
static plume_status plate_setup(const plume_cell *c, const plume_membrane_material *mats, int nmat, plate *p,
                                plume_err *err)
{
    const plume_mesh *m = c->mesh;
    p->nt = m->nt;
    plume_index *tri_edge = malloc((size_t)(3 * m->nt + 1) * sizeof *tri_edge);
    plume_index *emaster = malloc((size_t)(m->ne + 1) * sizeof *emaster);
    plume_index *vnum = malloc((size_t)(m->nv + 1) * sizeof *vnum), *enumb = malloc((size_t)(m->ne + 1) * sizeof *enumb);
    p->dof = malloc((size_t)(6 * m->nt + 1) * sizeof *p->dof);
    p->B = malloc((size_t)(18 * m->nt + 1) * sizeof *p->B);
    p->area = malloc((size_t)(m->nt + 1) * sizeof *p->area);
    p->D = malloc((size_t)(9 * m->nt + 1) * sizeof *p->D);
    plume_status st = PLUME_OK;
    if (!tri_edge || !emaster || !vnum || !enumb || !p->dof || !p->B || !p->area || !p->D) {
        st = plume_err_set(err, PLUME_ENOMEM, "plate cell: out of memory");
        goto done;
    }
    if ((st = triangle_edges(m, tri_edge, err)) != PLUME_OK || (st = edge_masters(c, emaster, err)) != PLUME_OK)
        goto done;
    plume_index n = 0, anchor = c->master[0];
    for (plume_index v = 0; v < m->nv; v++)
        vnum[v] = (c->master[v] == v && v != anchor) ? n++ : -1;
    for (plume_index e = 0; e < m->ne; e++)
        enumb[e] = emaster[e] == e ? n++ : -1;
    p->n = n;
    for (plume_index t = 0; t < m->nt; t++) {
        int id = m->material[t];
        if (id < 0 || id >= nmat) {
            st = plume_err_set(err, PLUME_EINVAL, "plate cell: triangle %ld has material %d outside [0, %d)", (long)t, id,
                               nmat);
            goto done;
        }
        const plume_index *v = m->tri + 3 * t;
        const double *P[3] = {m->X + 2 * v[0], m->X + 2 * v[1], m->X + 2 * v[2]};
        double sign[3];
        for (int k = 0; k < 3; k++) {
            sign[k] = edge_sign(P[k], P[(k + 1) % 3]);
            p->dof[6 * t + k] = vnum[c->master[v[k]]];
            p->dof[6 * t + 3 + k] = enumb[emaster[tri_edge[3 * t + k]]];
        }
        p->area[t] = morley_B(P[0], P[1], P[2], sign, (double(*)[6])(p->B + 18 * t));
        if (!(p->area[t] > 0.0) || !isfinite(p->area[t])) {
            st = plume_err_set(err, PLUME_EINVAL, "plate cell: triangle %ld is degenerate or clockwise", (long)t);
            goto done;
        }
        /* D_i = h^3 / 12 Q_i in the cell frame */
        double Q[9], d[2] = {m->barb_dir[2 * t], m->barb_dir[2 * t + 1]}, dn = hypot(d[0], d[1]);
        double h = mats[id].h, s = h * h * h / 12.0;
        plume_membrane_stiffness(&mats[id], Q);
        for (int k = 0; k < 9; k++)
            Q[k] *= s;
        d[0] /= dn, d[1] /= dn;
        plume_cell_rotate_stiffness(Q, d, p->D + 9 * t);
    }
done:
    free(tri_edge);
    free(emaster);
    free(vnum);
    free(enumb);
    return st;
}

/* The pattern of the upper triangle (CSC, rows sorted) and the assembled values A B^T D B. */
static plume_status plate_assemble(plate *p, plume_err *err)
{
    size_t nk = 0;
    long *keys = malloc(((size_t)p->nt * 36 + 1) * sizeof *keys); /* col * n + row, row <= col */
    p->colptr = calloc((size_t)p->n + 1, sizeof *p->colptr);
    if (!keys || !p->colptr) {
        free(keys);
        return plume_err_set(err, PLUME_ENOMEM, "plate cell: out of memory");
    }
    for (plume_index t = 0; t < p->nt; t++)
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 6; b++) {
                plume_index r = p->dof[6 * t + a], c = p->dof[6 * t + b];
                if (r >= 0 && c >= 0 && r <= c)
                    keys[nk++] = (long)c * (long)p->n + (long)r;
            }
    qsort(keys, nk, sizeof *keys, cmp_long);
    size_t nnz = 0;
    for (size_t k = 0; k < nk; k++)
        if (k == 0 || keys[k] != keys[k - 1])
            keys[nnz++] = keys[k];
    p->rowind = malloc((nnz + 1) * sizeof *p->rowind);
    p->values = calloc(nnz + 1, sizeof *p->values);
    if (!p->rowind || !p->values) {
        free(keys);
        return plume_err_set(err, PLUME_ENOMEM, "plate cell: out of memory");
    }
    for (size_t k = 0; k < nnz; k++) {
        p->rowind[k] = (plume_index)(keys[k] % p->n);
        p->colptr[keys[k] / p->n + 1]++;
    }
    for (plume_index c = 0; c < p->n; c++)
        p->colptr[c + 1] += p->colptr[c];
    free(keys);
    for (plume_index t = 0; t < p->nt; t++) {
        const double *B = p->B + 18 * t, *D = p->D + 9 * t;
        double DB[3][6];
        for (int i = 0; i < 3; i++)
            for (int b = 0; b < 6; b++)
                DB[i][b] = D[3 * i] * B[b] + D[3 * i + 1] * B[6 + b] + D[3 * i + 2] * B[12 + b];
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 6; b++) {
                plume_index r = p->dof[6 * t + a], c = p->dof[6 * t + b];
                if (r < 0 || c < 0 || r > c)
                    continue;
                /* both (a, b) and (b, a) land on one stored entry when r == c with a != b: each adds once */
                double v = p->area[t] * (B[a] * DB[0][b] + B[6 + a] * DB[1][b] + B[12 + a] * DB[2][b]);
                plume_index lo = p->colptr[c], hi = p->colptr[c + 1] - 1;
                while (lo < hi) {
                    plume_index mid = (lo + hi) / 2;
                    if (p->rowind[mid] < r)
                        lo = mid + 1;
                    else
                        hi = mid;
                }
                p->values[lo] += v;
            }
    }
    return PLUME_OK;
}

plume_status plume_cell_plate_tensor(const plume_cell *cell, const plume_membrane_material *mats, int nmat,
                                     double D[9], plume_cell_plate_info *info, plume_err *err)
{
    if (!cell || !cell->mesh || !cell->master || !cell->shift || !mats || nmat < 1 || !D)
        return plume_err_set(err, PLUME_EINVAL, "plate cell: invalid arguments");
    for (int k = 0; k < nmat; k++) {
        plume_status st = plume_membrane_material_check(&mats[k], err);
        if (st != PLUME_OK)
            return st;
    }
    if (!cell->mesh->edges || !cell->mesh->edge_tri)
        return plume_err_set(err, PLUME_EINVAL, "plate cell: the cell mesh has no topology");
    plate p;
    memset(&p, 0, sizeof p);
    plume_chol *chol = NULL;
    double *rhs = NULL, *u = NULL;
    plume_status st = plate_setup(cell, mats, nmat, &p, err);
    if (st != PLUME_OK || (st = plate_assemble(&p, err)) != PLUME_OK)
        goto done;
    if (info) {
        info->elements = p.nt;
        info->dofs = p.n;
        info->nnz = p.colptr[p.n];
    }
    rhs = malloc((size_t)(p.n + 1) * sizeof *rhs);
    u = malloc((size_t)(p.n + 1) * sizeof *u);
    if (!rhs || !u) {
        st = plume_err_set(err, PLUME_ENOMEM, "plate cell: out of memory");
        goto done;
    }
    if ((st = plume_chol_create(p.n, p.colptr, p.rowind, 0, &chol, err)) != PLUME_OK)
        goto done;
    if ((st = plume_chol_factor(chol, p.values, 0.0)) != PLUME_OK) {
        st = plume_err_set(err, st, "plate cell: the plate cell matrix is not positive definite (%s)", plume_strerror(st));
        goto done;
    }
    /* the average is over the whole cell, empty space included (explicit barbules): moduli per
     * unit area of vane */
    double area = cell->a * cell->b;
    for (int k = 0; k < 3; k++) {
        /* unit macroscopic curvature k: K u = -sum A B^T D kbar, then the average moment */
        memset(rhs, 0, (size_t)p.n * sizeof *rhs);
        for (plume_index t = 0; t < p.nt; t++) {
            const double *B = p.B + 18 * t, *Dt = p.D + 9 * t;
            for (int a = 0; a < 6; a++) {
                plume_index r = p.dof[6 * t + a];
                if (r >= 0)
                    rhs[r] -= p.area[t] * (B[a] * Dt[k] + B[6 + a] * Dt[3 + k] + B[12 + a] * Dt[6 + k]);
            }
        }
        if ((st = plume_chol_solve(chol, rhs, u)) != PLUME_OK) {
            st = plume_err_set(err, st, "plate cell: the solve failed (%s)", plume_strerror(st));
            goto done;
        }
        double avg[3] = {0, 0, 0};
        for (plume_index t = 0; t < p.nt; t++) {
            const double *B = p.B + 18 * t, *Dt = p.D + 9 * t;
            double kap[3] = {0, 0, 0};
            kap[k] = 1.0;
            for (int a = 0; a < 6; a++) {
                plume_index r = p.dof[6 * t + a];
                if (r >= 0)
                    for (int i = 0; i < 3; i++)
                        kap[i] += B[6 * i + a] * u[r];
            }
            for (int i = 0; i < 3; i++)
                avg[i] += p.area[t] * (Dt[3 * i] * kap[0] + Dt[3 * i + 1] * kap[1] + Dt[3 * i + 2] * kap[2]);
        }
        for (int i = 0; i < 3; i++)
            D[3 * i + k] = avg[i] / area;
    }
    for (int i = 0; i < 3; i++) /* symmetric up to round-off; make it exactly so */
        for (int j = i + 1; j < 3; j++)
            D[3 * i + j] = D[3 * j + i] = 0.5 * (D[3 * i + j] + D[3 * j + i]);
done:
    plume_chol_destroy(&chol);
    free(rhs);
    free(u);
    plate_free(&p);
    return st;
}
