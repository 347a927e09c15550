/* A barbule specimen opened at its distal joins (micro/hook_mesh.h): on a hand-made strip, the
 * join ahead along q is opened and the one behind is not; on the explicit-barbule specimen, every
 * triangle keeps its reference shape, the pairs coincide, only barbule triangles take the copies,
 * each join becomes two boundary edges, q and -q open disjoint joins, and the quadratic split's
 * midpoints are paired too. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../include/plume/homogenize.h"
#include "../lib/core/mesh_quadratic.h"
#include "../lib/core/pslg.h"
#include "../micro/hook_mesh.h"
#include "../include/plume/traction.h"

/* Barbule triangles on y in [0, 1], barb triangles on [1, 2]: one join, the edge y = 1. */
static plume_mesh *strip(plume_err *err)
{
    static const double X[12] = {0, 0, 1, 0, 0, 1, 1, 1, 0, 2, 1, 2};
    static const plume_index tri[12] = {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
    plume_mesh *m = NULL;
    if (plume_mesh_create(6, 4, 2, &m, err) != PLUME_OK)
        return NULL;
    memcpy(m->X, X, sizeof X);
    memcpy(m->tri, tri, sizeof tri);
    for (int t = 0; t < 4; t++) {
        m->material[t] = t < 2 ? PLUME_MAT_BARBULE : PLUME_MAT_BARB;
        m->barb_dir[2 * t] = 1.0, m->barb_dir[2 * t + 1] = 0.0;
    }
    plume_mesh_reset_current(m);
    if (plume_mesh_build_topology(m, err) != PLUME_OK)
        plume_mesh_destroy(&m);
    return m;
}

void test_micro_hook_mesh_strip(void)
{
    plume_err err = {{0}};
    plume_mesh *m = strip(&err);
    CHECK(m != NULL);
    if (!m)
        return;
    plume_hook_mesh h;
    const double up[2] = {0, 1}, down[2] = {0, -1};
    CHECK(plume_hook_mesh_open(m, up, &h, &err) == PLUME_OK);
    CHECK(h.nhooks == 1 && h.njoin == 1 && h.first[1] == 2 && h.mesh->nv == 8);
    /* the copies 6, 7 of vertices 2, 3 are the barbule triangles' */
    CHECK(h.pairs[0] == 6 && h.pairs[1] == 2 && h.pairs[2] == 7 && h.pairs[3] == 3);
    CHECK(h.mesh->tri[2] == 7 && h.mesh->tri[4] == 7 && h.mesh->tri[5] == 6 && h.mesh->tri[6] == 2);
    plume_index *first = NULL, *pairs = NULL;
    CHECK(plume_hook_mesh_quadratic_pairs(&h, &first, &pairs, &err) == PLUME_OK);
    CHECK(first && first[1] == 3 && pairs[4] >= h.mesh->nv && pairs[5] >= h.mesh->nv && pairs[4] != pairs[5]);
    free(first);
    free(pairs);
    plume_hook_mesh_free(&h);
    CHECK(plume_hook_mesh_open(m, down, &h, &err) == PLUME_OK);
    CHECK(h.nhooks == 0 && h.njoin == 0 && h.mesh->nv == 6);
    plume_hook_mesh_free(&h);
    CHECK(plume_hook_mesh_open(m, NULL, &h, &err) == PLUME_EINVAL);
    plume_mesh_destroy(&m);
}

static int boundary_edges(const plume_mesh *m)
{
    int n = 0;
    for (plume_index e = 0; e < m->ne; e++)
        n += m->edge_tri[2 * e + 1] < 0;
    return n;
}

void test_micro_hook_mesh_specimen(void)
{
    plume_layout l;
    plume_err err = {{0}};
    plume_layout_default(&l);
    CHECK(plume_layout_load_json("../data/layout_barbules_table3a.json", &l, &err) == PLUME_OK);
    const double angle = 45.0;
    double d[2];
    plume_barb_direction(angle, d);
    const double q[2] = {-d[1], d[0]}, mq[2] = {d[1], -d[0]}; /* from a barb to the next, and back */
    plume_mesh *m = NULL;
    CHECK(plume_specimen_mesh(&l, 4e-3, 5.2e-3, angle, &m, &err) == PLUME_OK);
    if (!m) {
        fprintf(stderr, "    %s\n", err.msg);
        return;
    }
    plume_hook_mesh h, back;
    CHECK(plume_hook_mesh_open(m, q, &h, &err) == PLUME_OK && plume_hook_mesh_open(m, mq, &back, &err) == PLUME_OK);
    printf("    specimen %ld vertices, %ld triangles: %d hooks over %ld join edges (%d behind)\n", (long)m->nv,
           (long)m->nt, h.nhooks, (long)h.njoin, back.nhooks);
    CHECK(h.nhooks >= 4 && back.nhooks >= 4 && h.mesh->nt == m->nt);
    CHECK(boundary_edges(h.mesh) == boundary_edges(m) + 2 * (int)h.njoin);
    /* each triangle keeps its vertices' reference positions and its material */
    int same = 1;
    for (plume_index t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            const plume_index v = m->tri[3 * t + k], w = h.mesh->tri[3 * t + k];
            same &= h.mesh->X[2 * w] == m->X[2 * v] && h.mesh->X[2 * w + 1] == m->X[2 * v + 1];
            same &= (w == v) || (w >= m->nv && m->material[t] == PLUME_MAT_BARBULE);
        }
    CHECK(same);
    /* pairs coincide; q and -q open disjoint joins (a barb's two sides) */
    for (plume_index p = 0; p < h.first[h.nhooks]; p++) {
        const plume_index c = h.pairs[2 * p], o = h.pairs[2 * p + 1];
        CHECK(c >= m->nv && o < m->nv && h.mesh->X[2 * c] == h.mesh->X[2 * o] &&
              h.mesh->X[2 * c + 1] == h.mesh->X[2 * o + 1]);
        for (plume_index r = 0; r < back.first[back.nhooks]; r++)
            CHECK(back.pairs[2 * r + 1] != o);
    }
    /* the quadratic split: the joins' midpoints are paired, coinciding too */
    plume_quadratic_mesh quad = {0};
    plume_index *first = NULL, *pairs = NULL;
    CHECK(plume_mesh_quadratic(h.mesh, &quad, &err) == PLUME_OK);
    CHECK(plume_hook_mesh_quadratic_pairs(&h, &first, &pairs, &err) == PLUME_OK);
    if (quad.split && first) {
        CHECK(first[h.nhooks] == h.first[h.nhooks] + h.njoin);
        for (plume_index p = 0; p < first[h.nhooks]; p++) {
            const plume_index c = pairs[2 * p], o = pairs[2 * p + 1];
            CHECK(c != o && quad.split->X[2 * c] == quad.split->X[2 * o] &&
                  quad.split->X[2 * c + 1] == quad.split->X[2 * o + 1]);
        }
    }
    free(first);
    free(pairs);
    plume_quadratic_mesh_free(&quad);
    plume_hook_mesh_free(&h);
    plume_hook_mesh_free(&back);
    plume_mesh_destroy(&m);
}
