#include "cell_linear.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/problem.h"
#include "../lib/solve/solver.h"
#include "periodic.h"

/* The linearised membrane over the cell: unknowns are displacements w (as "positions"); the
 * imposed macroscopic strain `ebar` (Voigt) is a parameter. Linear triangles (3 nodes, one point)
 * or quadratic ones (6 nodes, the 3-point rule: exact, the integrand B^T C B is quadratic). Per
 * element and quadrature point: the gradients of the shape functions and the weight times area
 * times thickness; per element the stiffness rotated to the cell frame. */
#define LIN_MAX_NODES 6
#define LIN_MAX_POINTS 3
typedef struct {
    plume_index nt;
    int na, nq;         /* nodes per element, quadrature points */
    plume_index *tri;   /* [na nt] */
    double *dN;         /* [nt nq na 2] shape-function gradients (dNx, dNy) */
    double *wA;         /* [nt nq] weight * area * thickness */
    double *C;          /* [9 nt] stiffness in the cell frame (Voigt, engineering shear) */
    double ebar[3];
} lin_ctx;

static void lin_destroy(void *ctx)
{
    lin_ctx *c = ctx;
    if (!c)
        return;
    free(c->tri);
    free(c->dN);
    free(c->wA);
    free(c->C);
    free(c);
}

/* strain (Voigt) at point q of element t: ebar + sym grad w */
static void tri_strain(const lin_ctx *c, plume_index t, int q, const double *w, double e[3])
{
    const double *g = c->dN + ((size_t)t * c->nq + q) * 2 * c->na;
    e[0] = c->ebar[0], e[1] = c->ebar[1], e[2] = c->ebar[2];
    for (int k = 0; k < c->na; k++) {
        const double *wk = w + 2 * c->tri[c->na * t + k];
        e[0] += wk[0] * g[2 * k];
        e[1] += wk[1] * g[2 * k + 1];
        e[2] += wk[0] * g[2 * k + 1] + wk[1] * g[2 * k];
    }
}

static plume_status lin_eval(void *ctx, int dim, const double *w, double *energy, double *grad, double *hblocks,
                             int project)
{
    (void)project; /* the energy is convex: blocks are PSD as they are */
    const lin_ctx *c = ctx;
    if (dim != 2)
        return PLUME_EINVAL;
    const int na = c->na, nd = 2 * na;
    for (plume_index t = 0; t < c->nt; t++) {
        const double *C = c->C + 9 * t;
        double *H = hblocks ? hblocks + (size_t)t * nd * nd : NULL;
        if (H)
            memset(H, 0, sizeof(double) * (size_t)(nd * nd));
        for (int q = 0; q < c->nq; q++) {
            const double *g = c->dN + ((size_t)t * c->nq + q) * 2 * na, wA = c->wA[(size_t)t * c->nq + q];
            double e[3], s[3];
            tri_strain(c, t, q, w, e);
            for (int i = 0; i < 3; i++)
                s[i] = C[3 * i] * e[0] + C[3 * i + 1] * e[1] + C[3 * i + 2] * e[2];
            if (energy)
                *energy += 0.5 * wA * (s[0] * e[0] + s[1] * e[1] + s[2] * e[2]);
            /* B maps the dofs to the Voigt strain: column (k, x) = (gx, 0, gy), (k, y) = (0, gy, gx) */
            double B[3][2 * LIN_MAX_NODES];
            for (int k = 0; k < na; k++) {
                double gx = g[2 * k], gy = g[2 * k + 1];
                B[0][2 * k] = gx, B[1][2 * k] = 0.0, B[2][2 * k] = gy;
                B[0][2 * k + 1] = 0.0, B[1][2 * k + 1] = gy, B[2][2 * k + 1] = gx;
            }
            if (grad)
                for (int a = 0; a < nd; a++)
                    grad[2 * c->tri[na * t + a / 2] + a % 2] += wA * (B[0][a] * s[0] + B[1][a] * s[1] + B[2][a] * s[2]);
            if (H) {
                for (int a = 0; a < nd; a++) {
                    double CB[3];
                    for (int i = 0; i < 3; i++)
                        CB[i] = C[3 * i] * B[0][a] + C[3 * i + 1] * B[1][a] + C[3 * i + 2] * B[2][a];
                    for (int b = 0; b < nd; b++)
                        H[nd * b + a] += wA * (B[0][b] * CB[0] + B[1][b] * CB[1] + B[2][b] * CB[2]);
                }
            }
        }
    }
    return PLUME_OK;
}

void plume_cell_rotate_stiffness(const double Cb[9], const double d[2], double C[9])
{
    double c = d[0], s = d[1];
    double T[9] = {c * c, s * s, c * s, s * s, c * c, -c * s, -2 * c * s, 2 * c * s, c * c - s * s};
    double CT[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            CT[3 * i + j] = Cb[3 * i] * T[j] + Cb[3 * i + 1] * T[3 + j] + Cb[3 * i + 2] * T[6 + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = T[i] * CT[j] + T[3 + i] * CT[3 + j] + T[6 + i] * CT[6 + j];
}

/* Gradients of the shape functions at barycentric point L of a triangle whose linear gradients
 * are gl[3][2]: linear (na 3) N_i = L_i; quadratic (na 6) corners L_i (2 L_i - 1), then the
 * midpoints of (0 1), (1 2), (2 0): 4 L_i L_j. */
static void shape_gradients(int na, const double L[3], const double gl[3][2], double *g)
{
    for (int i = 0; i < 3; i++)
        for (int d = 0; d < 2; d++)
            g[2 * i + d] = na == 3 ? gl[i][d] : (4.0 * L[i] - 1.0) * gl[i][d];
    if (na == 3)
        return;
    for (int k = 0; k < 3; k++) {
        int i = k, j = (k + 1) % 3;
        for (int d = 0; d < 2; d++)
            g[2 * (3 + k) + d] = 4.0 * (L[i] * gl[j][d] + L[j] * gl[i][d]);
    }
}

static plume_status lin_create(const plume_cell *cell, const plume_membrane_material *mats, int nmat,
                               plume_term *out, lin_ctx **handle, plume_err *err)
{
    const plume_mesh *m = cell->mesh;
    const int quadratic = cell->order == 2;
    lin_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return PLUME_ENOMEM;
    c->nt = quadratic ? cell->quad.nt : m->nt;
    c->na = quadratic ? 6 : 3;
    c->nq = quadratic ? 3 : 1;
    const plume_index *elements = quadratic ? cell->quad.tri6 : m->tri;
    const int *material = quadratic ? cell->quad.material : m->material;
    const double *barb_dir = quadratic ? cell->quad.barb_dir : m->barb_dir;
    c->tri = malloc((size_t)(c->na * c->nt + 1) * sizeof *c->tri);
    c->dN = malloc((size_t)(2 * c->na * c->nq * c->nt + 1) * sizeof *c->dN);
    c->wA = malloc((size_t)(c->nq * c->nt + 1) * sizeof *c->wA);
    c->C = malloc((size_t)(9 * c->nt + 1) * sizeof *c->C);
    if (!c->tri || !c->dN || !c->wA || !c->C) {
        lin_destroy(c);
        return PLUME_ENOMEM;
    }
    memcpy(c->tri, elements, (size_t)(c->na * c->nt) * sizeof *c->tri);
    /* the 3-point rule at (2/3, 1/6, 1/6) and its permutations (weights 1/3) for quadratic elements */
    static const double Lq[3][3] = {{2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};
    static const double L1[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
    for (plume_index t = 0; t < c->nt; t++) {
        int id = material[t];
        if (id < 0 || id >= nmat) {
            lin_destroy(c);
            return plume_err_set(err, PLUME_EINVAL, "cell: triangle %ld has material %d outside [0, %d)", (long)t, id, nmat);
        }
        const plume_index *v = elements + (size_t)c->na * t;
        const double *X0 = m->X + 2 * v[0], *X1 = m->X + 2 * v[1], *X2 = m->X + 2 * v[2];
        double a = X1[0] - X0[0], b = X2[0] - X0[0], cc = X1[1] - X0[1], dd = X2[1] - X0[1];
        double det = a * dd - b * cc;
        if (!(det > 0.0)) {
            lin_destroy(c);
            return plume_err_set(err, PLUME_EINVAL, "cell: triangle %ld is degenerate or clockwise", (long)t);
        }
        /* Dm^-1 = [dd -b; -cc a] / det; grad L1 = row 0, grad L2 = row 1, grad L0 = -(sum) */
        double gl[3][2] = {{-(dd - cc) / det, -(-b + a) / det}, {dd / det, -b / det}, {-cc / det, a / det}};
        for (int q = 0; q < c->nq; q++) {
            shape_gradients(c->na, quadratic ? Lq[q] : L1, (const double(*)[2])gl,
                            c->dN + ((size_t)t * c->nq + q) * 2 * c->na);
            c->wA[(size_t)t * c->nq + q] = 0.5 * det * mats[id].h / (double)c->nq;
        }
        double Cb[9], d[2] = {barb_dir[2 * t], barb_dir[2 * t + 1]}, n = hypot(d[0], d[1]);
        plume_membrane_stiffness(&mats[id], Cb);
        d[0] /= n, d[1] /= n;
        plume_cell_rotate_stiffness(Cb, d, c->C + 9 * t);
    }
    memset(out, 0, sizeof *out);
    out->name = "linear membrane";
    out->arity = c->na;
    out->nstencil = c->nt;
    out->stencil = c->tri;
    out->size = sizeof *out;
    out->eval = lin_eval;
    out->destroy = lin_destroy;
    out->ctx = c;
    *handle = c;
    return PLUME_OK;
}

/* The cell problem: the linear membrane (its context in *lc, owned by the problem) wrapped
 * periodically with a zero macroscopic part, the slave vertices and one anchor fixed (a rigid
 * translation), finalised. */
static plume_status periodic_cell_problem(const plume_cell *cell, const plume_membrane_material *mats, int nmat,
                                          lin_ctx **lc, plume_problem **p, plume_err *err)
{
    const plume_mesh *m = cell->mesh;
    plume_periodic *per = NULL;
    plume_term lin, wrapped;
    plume_status st = lin_create(cell, mats, nmat, &lin, lc, err);
    if (st != PLUME_OK)
        return st;
    if ((st = plume_periodic_term_create(cell, &lin, &per, &wrapped, err)) != PLUME_OK)
        return st;
    const double zero[4] = {0, 0, 0, 0};
    plume_periodic_set_macro(per, zero); /* w_v = w_master(v): the fluctuation is periodic */
    if ((st = plume_problem_create(m->nv, 2, fmax(cell->a, cell->b), p, err)) != PLUME_OK) {
        wrapped.destroy(wrapped.ctx);
        return st;
    }
    if ((st = plume_problem_add_term(*p, &wrapped, err)) != PLUME_OK)
        return st;
    plume_index anchor = cell->master[0]; /* rigid translation */
    for (plume_index v = 0; v < m->nv; v++)
        if (cell->master[v] != v || v == anchor) {
            plume_problem_fix_dof(*p, 2 * v, err);
            plume_problem_fix_dof(*p, 2 * v + 1, err);
        }
    return plume_problem_finalize(*p, err);
}

/* The area the stresses are averaged over. Every material has its own thickness: the area is
 * geometric, the stiffness A = sum h_i C_i (wA holds the thickness) is reported over h_ref (with one
 * thickness, the very same numbers as the area average of C_i e). A cell with empty space (explicit
 * barbules) averages over the whole cell, as the periodic wrapper's average stress does (the
 * vane's stiffness per unit area, not the material's); a full cell keeps its summed area, which is
 * a b up to round-off. */
static double averaging_area(const plume_cell *cell, const lin_ctx *lc, const plume_membrane_material *mats)
{
    const int *material = cell->order == 2 ? cell->quad.material : cell->mesh->material;
    double area = 0.0;
    for (plume_index t = 0; t < lc->nt; t++)
        for (int q = 0; q < lc->nq; q++)
            area += lc->wA[(size_t)t * lc->nq + q] / mats[material[t]].h;
    if (cell->a * cell->b - area > 1e-9 * cell->a * cell->b)
        area = cell->a * cell->b;
    return area;
}

/* The integral of the stress (over h_ref) of the solved fluctuation w, spread first from the
 * master vertices to every vertex (the wrapper's positions are the periodic fluctuation). */
static void stress_integral(const plume_cell *cell, const lin_ctx *lc, double h_ref, double *w, double avg[3])
{
    for (plume_index v = 0; v < cell->mesh->nv; v++)
        w[2 * v] = w[2 * cell->master[v]], w[2 * v + 1] = w[2 * cell->master[v] + 1];
    avg[0] = avg[1] = avg[2] = 0.0;
    for (plume_index t = 0; t < lc->nt; t++) {
        const double *Ct = lc->C + 9 * t;
        for (int q = 0; q < lc->nq; q++) {
            double e[3];
            tri_strain(lc, t, q, w, e);
            double a = lc->wA[(size_t)t * lc->nq + q] / h_ref;
            for (int i = 0; i < 3; i++)
                avg[i] += a * (Ct[3 * i] * e[0] + Ct[3 * i + 1] * e[1] + Ct[3 * i + 2] * e[2]);
        }
    }
}

plume_status plume_cell_linear_tensor(const plume_cell *cell, const plume_membrane_material *mats, int nmat,
                                      double h_ref, double C[9], int *iterations, plume_err *err)
{
    if (!cell || !mats || nmat < 1 || !C)
        return plume_err_set(err, PLUME_EINVAL, "cell tensor: invalid arguments");
    if (!(h_ref > 0.0) || !isfinite(h_ref))
        return plume_err_set(err, PLUME_EINVAL, "cell tensor: the reference thickness must be finite and > 0 (got %g m)",
                             h_ref);
    for (int k = 0; k < nmat; k++) {
        plume_status st = plume_membrane_material_check(&mats[k], err);
        if (st != PLUME_OK)
            return st;
    }
    const plume_mesh *m = cell->mesh;
    plume_problem *p = NULL;
    plume_solver *s = NULL;
    lin_ctx *lc = NULL;
    double *u = NULL;
    plume_status st = periodic_cell_problem(cell, mats, nmat, &lc, &p, err);
    if (st != PLUME_OK)
        goto done;
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    if ((st = plume_solver_create(PLUME_SOLVER_LINEARIZED, p, &so, &s, err)) != PLUME_OK)
        goto done;
    u = calloc((size_t)plume_problem_nfree(p), sizeof *u);
    if (!u) {
        st = PLUME_ENOMEM;
        goto done;
    }
    const double area = averaging_area(cell, lc, mats);
    if (iterations)
        *iterations = 0;
    double *w = plume_problem_x(p);
    for (int k = 0; k < 3; k++) {
        /* unit macroscopic strain k (engineering shear for k = 2), from w = 0: the energy is
         * quadratic, so the single Newton step is the exact minimiser */
        memset(lc->ebar, 0, sizeof lc->ebar);
        lc->ebar[k] = 1.0;
        memset(w, 0, (size_t)(2 * m->nv) * sizeof *w);
        memset(u, 0, (size_t)plume_problem_nfree(p) * sizeof *u);
        plume_solve_report rep;
        if ((st = plume_solver_solve(s, u, NULL, &rep)) != PLUME_OK)
            goto done;
        if (rep.reason != PLUME_REASON_SINGLE_STEP) {
            st = plume_err_set(err, PLUME_ESINGULAR, "cell tensor: the linear cell problem could not be solved (%s)",
                               plume_reason_name(rep.reason));
            goto done;
        }
        if (iterations)
            *iterations += rep.iterations;
        double avg[3];
        stress_integral(cell, lc, h_ref, w, avg);
        for (int i = 0; i < 3; i++)
            C[3 * i + k] = avg[i] / area;
    }
    for (int i = 0; i < 3; i++) /* symmetric up to round-off; make it exactly so */
        for (int j = i + 1; j < 3; j++)
            C[3 * i + j] = C[3 * j + i] = 0.5 * (C[3 * i + j] + C[3 * j + i]);
done:
    free(u);
    plume_solver_destroy(&s);
    plume_problem_destroy(&p);
    return st;
}
