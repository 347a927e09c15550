/* plume: why a vane triangle of a feather mesh owns no barb edge (contract in macro/feather/feather_mesh.h).
 * It reads the mesh alone, so a caller (or a test) can classify any feather mesh and its barb list. */
#include <stdlib.h>

#include "feather_mesh.h"
#include "../shell/vane.h"

const char *plume_feather_uncovered_name(int reason)
{
    static const char *names[PLUME_FEATHER_UNCOVERED_REASONS] = {"rachis junction", "outline", "barb end", "other"};
    return reason >= 0 && reason < PLUME_FEATHER_UNCOVERED_REASONS ? names[reason] : NULL;
}

plume_status plume_feather_uncovered(const plume_mesh *m, const plume_index *barb_edges, plume_index nbarb,
                                     plume_index **tri, unsigned char **reason, plume_index *n, plume_err *err)
{
    if (tri)
        *tri = NULL;
    if (reason)
        *reason = NULL;
    if (!m || !n)
        return plume_err_set(err, PLUME_EINVAL, "feather uncovered: NULL mesh or count");
    *n = 0;
    if ((m->nt > 0 && (!m->edge_tri || !m->boundary || !m->material)) || nbarb < 0 || (nbarb > 0 && !barb_edges))
        return plume_err_set(err, PLUME_EINVAL, "feather uncovered: the mesh has no topology or the barb list is invalid");
    plume_status st = PLUME_OK;
    plume_index *unc = NULL, covered = 0, total = 0, *t_out = NULL;
    unsigned char *deg = calloc((size_t)m->nv + 1, 1), *strip = calloc((size_t)m->nv + 1, 1), *r_out = NULL;
    if (!deg || !strip) {
        st = plume_err_set(err, PLUME_ENOMEM, "feather uncovered: out of memory");
        goto cleanup;
    }
    for (plume_index k = 0; k < 2 * nbarb; k++) {
        plume_index v = barb_edges[k];
        if (v < 0 || v >= m->nv) {
            st = plume_err_set(err, PLUME_EINVAL, "feather uncovered: barb edge %ld names vertex %ld of %ld", (long)(k / 2),
                               (long)v, (long)m->nv);
            goto cleanup;
        }
        if (deg[v] < 255)
            deg[v]++;
    }
    for (plume_index t = 0; t < m->nt; t++)
        if (m->material[t] == PLUME_FEATHER_RACHIS)
            for (int k = 0; k < 3; k++)
                strip[m->tri[3 * t + k]] = 1;
    if ((st = plume_vane_barb_coverage(m, barb_edges, nbarb, PLUME_FEATHER_VANE, &covered, &total, &unc, err)) != PLUME_OK) {
        plume_err_set(err, st, "feather uncovered: %s", st == PLUME_ENOMEM ? "out of memory" : "invalid mesh");
        goto cleanup;
    }
    plume_index nu = total - covered;
    if (nu > 0) {
        t_out = malloc((size_t)nu * sizeof *t_out);
        r_out = malloc((size_t)nu);
        if (!t_out || !r_out) {
            st = plume_err_set(err, PLUME_ENOMEM, "feather uncovered: out of memory");
            goto cleanup;
        }
    }
    for (plume_index k = 0; k < nu; k++) {
        const plume_index *v = m->tri + 3 * unc[k];
        int has[PLUME_FEATHER_UNCOVERED_REASONS] = {0};
        for (int j = 0; j < 3; j++) {
            plume_index w = v[j];
            has[PLUME_FEATHER_UNCOVERED_RACHIS] |= strip[w] && deg[w] == 0;
            has[PLUME_FEATHER_UNCOVERED_OUTLINE] |= m->boundary[w] && deg[w] == 0;
            has[PLUME_FEATHER_UNCOVERED_BARB_END] |= !m->boundary[w] && !strip[w] && deg[w] == 1;
        }
        int r = PLUME_FEATHER_UNCOVERED_OTHER;
        for (int q = PLUME_FEATHER_UNCOVERED_OTHER - 1; q >= 0; q--)
            if (has[q])
                r = q;
        t_out[k] = unc[k];
        r_out[k] = (unsigned char)r;
    }
    *n = nu;
    if (tri)
        *tri = t_out, t_out = NULL;
    if (reason)
        *reason = r_out, r_out = NULL;
cleanup:
    free(deg);
    free(strip);
    free(unc);
    free(t_out);
    free(r_out);
    return st;
}
