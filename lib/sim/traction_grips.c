/* plume: the traction sample's grips and sides (traction_grips.h). */
#include "traction_grips.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static plume_index uf_find(plume_index *parent, plume_index i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

void plume_traction_grips_free(plume_traction_grips *g)
{
    free(g->top);
    free(g->left);
    free(g->right);
    free(g->bottom_flag);
    free(g->top_flag);
}

typedef struct {
    double y;
    plume_index v;
} keyed_vertex;

static int by_y(const void *a, const void *b)
{
    double ya = ((const keyed_vertex *)a)->y, yb = ((const keyed_vertex *)b)->y;
    return (ya > yb) - (ya < yb);
}

/* sorts vertex ids by reference Y (qsort has no context argument, so sort keyed copies) */
static plume_status sort_by_y(const double *X, plume_index *v, plume_index n)
{
    keyed_vertex *k = malloc((size_t)(n + 1) * sizeof *k);
    if (!k)
        return PLUME_ENOMEM;
    for (plume_index i = 0; i < n; i++)
        k[i].y = X[2 * v[i] + 1], k[i].v = v[i];
    qsort(k, (size_t)n, sizeof *k, by_y);
    for (plume_index i = 0; i < n; i++)
        v[i] = k[i].v;
    free(k);
    return PLUME_OK;
}

plume_status plume_traction_grips_find(const plume_mesh *m, double lx, double ly, double peel, double top_free,
                                       plume_traction_grips *g, plume_err *err)
{
    double tol = 1e-9 * fmax(lx, ly);
    memset(g, 0, sizeof *g);
    g->lx = lx, g->peel = peel;
    size_t nv = (size_t)m->nv;
    g->top = malloc(nv * sizeof *g->top);
    g->left = malloc(nv * sizeof *g->left);
    g->right = malloc(nv * sizeof *g->right);
    g->bottom_flag = calloc(nv, 1);
    g->top_flag = calloc(nv, 1);
    if (!g->top || !g->left || !g->right || !g->bottom_flag || !g->top_flag)
        return PLUME_ENOMEM;
    plume_index nbottom = 0;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (plume_index v = 0; v < m->nv; v++) {
        double X = m->X[2 * v], Y = m->X[2 * v + 1];
        xmin = fmin(xmin, X), xmax = fmax(xmax, X), ymin = fmin(ymin, Y), ymax = fmax(ymax, Y);
        if (fabs(Y) <= tol)
            g->bottom_flag[v] = 1, nbottom++;
        if (fabs(Y - ly) <= tol && X >= top_free * lx - tol)
            g->top_flag[v] = 1, g->top[g->ntop++] = v;
        if (fabs(X) <= tol)
            g->left[g->nleft++] = v;
        if (fabs(X - lx) <= tol)
            g->right[g->nright++] = v;
    }
    if (fabs(xmin) > tol || fabs(xmax - lx) > tol || fabs(ymin) > tol || fabs(ymax - ly) > tol)
        return plume_err_set(err, PLUME_EINVAL,
                             "traction: mesh bounding box [%g, %g] x [%g, %g] does not match the sample %g x %g m",
                             xmin, xmax, ymin, ymax, lx, ly);
    if (nbottom < 2 || g->ntop < 2 || g->nleft < 2 || g->nright < 2)
        return plume_err_set(err, PLUME_EINVAL, "traction: mesh has too few vertices on the sample's edges");
    plume_status st = sort_by_y(m->X, g->left, g->nleft);
    return st == PLUME_OK ? sort_by_y(m->X, g->right, g->nright) : st;
}

/* trapezoidal integral over y of u_x along a side, vertices sorted by Y */
double plume_traction_side_integral(const plume_mesh *m, const double *x, int dim, const plume_index *v,
                                    plume_index n)
{
    double s = 0.0;
    for (plume_index k = 0; k + 1 < n; k++) {
        double ua = x[dim * v[k]] - m->X[2 * v[k]], ub = x[dim * v[k + 1]] - m->X[2 * v[k + 1]];
        s += 0.5 * (ua + ub) * (m->X[2 * v[k + 1] + 1] - m->X[2 * v[k] + 1]);
    }
    return s;
}

/* The y-reaction on the moving grip as the virtual work of the generalised forces `force` over
 * the field w = Y/ly on the y-dofs (1 on the top grip, 0 on the bottom one): the grip's reaction
 * plus sum_free w r, r the residual of equilibrium, so the two agree at equilibrium. Why the
 * probe uses it: at 1e-6 strain the forces are so small that the round-off of the stiff barbs'
 * membrane stress (E_xx times a barb strain at round-off, ~1e-16 |x| / edge, that the multipliers
 * of the final iterate do not match) is a visible part of them. The grip's sum takes that noise
 * whole from the elements along the grip; here each element's contribution is weighted by the
 * change of w across it, ~edge/ly. Measured on the tilted vane (E_xx/E_yy = 1e4, edge 0.01, 3e4
 * triangles), five converged solves of the same probe (newton, ipopt, three tolerances): the
 * slope spreads over 1e-5 Pa by the grip's sum, over 3e-8 Pa by this one. */
double plume_traction_reaction_virtual_work(const plume_mesh *m, const plume_traction_grips *g, const double *force,
                                            int dim, double ly)
{
    double F = 0.0;
    for (plume_index v = 0; v < m->nv; v++) {
        const double s = plume_traction_grip_shape(g, m->X[2 * v]);
        double w = g->top_flag[v] ? s : g->bottom_flag[v] ? 0.0 : s * m->X[2 * v + 1] / ly;
        F += w * force[dim * v + 1];
    }
    return F;
}

/* barbs spanning both grips cannot stretch: union-find over the rigid edges, PLUME_EINFEASIBLE
 * when a top grip vertex is joined to a bottom one */
plume_status plume_traction_barbs_stretch_check(const plume_mesh *mesh, const plume_traction_grips *g,
                                                const plume_index *rigid_edges, plume_index nrigid, plume_err *err)
{
    if (nrigid == 0)
        return PLUME_OK;
    plume_index *parent = malloc((size_t)mesh->nv * sizeof *parent);
    if (!parent)
        return PLUME_ENOMEM;
    for (plume_index v = 0; v < mesh->nv; v++)
        parent[v] = v;
    for (plume_index e = 0; e < nrigid; e++)
        parent[uf_find(parent, rigid_edges[2 * e])] = uf_find(parent, rigid_edges[2 * e + 1]);
    unsigned char *root_bottom = calloc((size_t)mesh->nv, 1);
    if (!root_bottom) {
        free(parent);
        return PLUME_ENOMEM;
    }
    for (plume_index v = 0; v < mesh->nv; v++)
        if (g->bottom_flag[v])
            root_bottom[uf_find(parent, v)] = 1;
    plume_index culprit = -1;
    for (plume_index k = 0; k < g->ntop && culprit < 0; k++)
        if (root_bottom[uf_find(parent, g->top[k])])
            culprit = g->top[k];
    free(root_bottom);
    free(parent);
    if (culprit >= 0)
        return plume_err_set(err, PLUME_EINFEASIBLE,
                             "traction: inextensible barbs span both grips (e.g. the barb through (%g, %g) m), "
                             "so the sample cannot stretch: take the constraint off the barbs (the vane's "
                             "constraint 0), or choose a barb angle whose barbs leave through the free sides",
                             mesh->X[2 * culprit], mesh->X[2 * culprit + 1]);
    return PLUME_OK;
}
