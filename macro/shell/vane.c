#include "vane.h"

#include <math.h>
#include <stdlib.h>

#include "../../lib/core/edge_length.h"

void plume_vane_default(plume_vane *v)
{
    v->moduli.E_xx = 1e4;
    v->moduli.E_yy = 1.0;
    v->moduli.nu_xy = 0.0;
    v->moduli.G_xy = 1.0;
    v->h = 1.0;
    v->kappa = 0.0;
    v->constraint = 1;
    v->align_tol = 1e-6;
}

plume_membrane_material plume_vane_material(const plume_vane *v)
{
    plume_membrane_material mat = {.moduli = v->moduli, .h = v->h, .kappa = v->kappa};
    return mat;
}

plume_status plume_vane_check(const plume_vane *v, plume_err *err)
{
    plume_membrane_material mat = plume_vane_material(v);
    return plume_membrane_material_check(&mat, err);
}

plume_status plume_vane_barb_edges(const plume_mesh *m, double align_tol, plume_index **edges, plume_index *n,
                                   plume_err *err)
{
    if (!edges || !n)
        return plume_err_set(err, PLUME_EINVAL, "barb edges: edges and n are required");
    *edges = NULL;
    *n = 0;
    if (!m || (m->ne > 0 && (!m->edges || !m->edge_tri)))
        return plume_err_set(err, PLUME_EINVAL, "barb edges: %s", m ? "the mesh's topology is not built "
                                                                     "(plume_mesh_build_topology)" : "no mesh");
    if (!(align_tol >= 0.0))
        return plume_err_set(err, PLUME_EINVAL, "barb edges: align_tol must be >= 0 (got %g)", align_tol);
    plume_index *e = malloc((size_t)(2 * m->ne + 1) * sizeof *e);
    if (!e)
        return plume_err_set(err, PLUME_ENOMEM, "barb edges: out of memory");
    plume_index k = 0;
    for (plume_index i = 0; i < m->ne; i++) {
        plume_index a = m->edges[2 * i], b = m->edges[2 * i + 1];
        double ex = m->X[2 * b] - m->X[2 * a], ey = m->X[2 * b + 1] - m->X[2 * a + 1];
        double len = hypot(ex, ey);
        int aligned = 0;
        for (int s = 0; s < 2 && !aligned; s++) {
            plume_index t = m->edge_tri[2 * i + s];
            if (t < 0)
                continue;
            const double *d = m->barb_dir + 2 * t;
            aligned = fabs(ex * d[1] - ey * d[0]) <= align_tol * len * hypot(d[0], d[1]);
        }
        if (aligned) {
            e[2 * k] = a;
            e[2 * k + 1] = b;
            k++;
        }
    }
    *edges = e;
    *n = k;
    return PLUME_OK;
}

static int cmp_pair(const void *p, const void *q)
{
    const plume_index *a = p, *b = q;
    if (a[0] != b[0])
        return (a[0] > b[0]) - (a[0] < b[0]);
    return (a[1] > b[1]) - (a[1] < b[1]);
}

plume_status plume_vane_barb_coverage(const plume_mesh *m, const plume_index *barb_edges, plume_index nbarb,
                                      int material, plume_index *covered, plume_index *total,
                                      plume_index **uncovered, plume_err *err)
{
    if (uncovered)
        *uncovered = NULL;
    if (!m || !covered || !total || nbarb < 0 || (nbarb > 0 && !barb_edges))
        return plume_err_set(err, PLUME_EINVAL, "barb coverage: a mesh, the outputs and %ld barb edges (>= 0, "
                                                "with their array) are required", (long)nbarb);
    *covered = *total = 0;
    if ((m->ne > 0 && !m->edges) || (m->nt > 0 && !m->edge_tri))
        return plume_err_set(err, PLUME_EINVAL,
                             "barb coverage: the mesh's topology is not built (plume_mesh_build_topology)");
    plume_status st = PLUME_OK;
    plume_index *keys = malloc((size_t)(2 * nbarb + 2) * sizeof *keys);
    unsigned char *own = calloc((size_t)m->nt + 1, 1);
    if (!keys || !own) {
        st = plume_err_set(err, PLUME_ENOMEM, "barb coverage: out of memory");
        goto cleanup;
    }
    for (plume_index e = 0; e < nbarb; e++) {
        plume_index a = barb_edges[2 * e], b = barb_edges[2 * e + 1];
        if (a < 0 || b < 0 || a >= m->nv || b >= m->nv) {
            st = plume_err_set(err, PLUME_EINVAL, "barb coverage: barb edge %ld (%ld, %ld) names a vertex out of "
                               "[0, %ld)", (long)e, (long)a, (long)b, (long)m->nv);
            goto cleanup;
        }
        keys[2 * e] = a < b ? a : b;
        keys[2 * e + 1] = a < b ? b : a;
    }
    qsort(keys, (size_t)nbarb, 2 * sizeof *keys, cmp_pair);
    for (plume_index i = 0; i < m->ne; i++) {
        plume_index key[2] = {m->edges[2 * i], m->edges[2 * i + 1]}; /* i < j by construction */
        if (nbarb > 0 && bsearch(key, keys, (size_t)nbarb, 2 * sizeof *keys, cmp_pair))
            for (int s = 0; s < 2; s++)
                if (m->edge_tri[2 * i + s] >= 0)
                    own[m->edge_tri[2 * i + s]] = 1;
    }
    plume_index n = 0, c = 0;
    for (plume_index t = 0; t < m->nt; t++)
        if (material < 0 || m->material[t] == material)
            n++, c += own[t];
    if (uncovered && c < n) {
        if (!(*uncovered = malloc((size_t)(n - c) * sizeof **uncovered))) {
            st = plume_err_set(err, PLUME_ENOMEM, "barb coverage: out of memory");
            goto cleanup;
        }
        plume_index k = 0;
        for (plume_index t = 0; t < m->nt; t++)
            if ((material < 0 || m->material[t] == material) && !own[t])
                (*uncovered)[k++] = t;
    }
    *covered = c;
    *total = n;
cleanup:
    free(keys);
    free(own);
    return st;
}

plume_status plume_vane_add(plume_problem *p, const plume_mesh *m, const plume_vane *v,
                            plume_index **barb_edges, plume_index *nbarb, plume_err *err)
{
    return plume_vane_add_tensor(p, m, v, NULL, barb_edges, nbarb, err);
}

plume_status plume_vane_add_tensor(plume_problem *p, const plume_mesh *m, const plume_vane *v, const double C[9],
                                   plume_index **barb_edges, plume_index *nbarb, plume_err *err)
{
    if (barb_edges)
        *barb_edges = NULL;
    if (nbarb)
        *nbarb = 0;
    plume_status st = plume_vane_check(v, err);
    if (st != PLUME_OK)
        return st;
    plume_membrane_material mat = plume_vane_material(v);
    plume_term term;
    if ((st = plume_membrane_term_create_tensor(m, plume_problem_dim(p), &mat, C, 1, &term, err)) != PLUME_OK)
        return st;
    if ((st = plume_problem_add_term(p, &term, err)) != PLUME_OK)
        return st;
    if (!v->constraint)
        return PLUME_OK;
    plume_index *edges = NULL, n = 0;
    if ((st = plume_vane_barb_edges(m, v->align_tol, &edges, &n, err)) != PLUME_OK)
        return st;
    plume_constraint c;
    if ((st = plume_edge_length_create(edges, n, m->X, m->nv, &c, err)) == PLUME_OK)
        st = plume_problem_add_constraint(p, &c, err);
    if (st == PLUME_OK && barb_edges) {
        *barb_edges = edges;
        *nbarb = n;
    } else {
        free(edges);
    }
    return st;
}
