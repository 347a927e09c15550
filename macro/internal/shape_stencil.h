/* plume (private, not installed): the stencil search of the shape-operator bending term
 * (macro/shape_bending.c, whose top comment gives the method). A triangle T whose natural stencil
 * (the vertices opposite its edges) is missing or poorly conditioned gets three vertices from its
 * rings that make the quadratic fit of its heights well conditioned: the search is here, the fit
 * and the term in shape_bending.c. */
#ifndef PLUME_MACRO_INTERNAL_SHAPE_STENCIL_H
#define PLUME_MACRO_INTERNAL_SHAPE_STENCIL_H

#include "../../lib/core/mesh.h"

/* Row-normalised determinant s(M) (shape_bending.c's top comment) above which a complete natural stencil is kept, and
 * below which no stencil is accepted at all. s is affine-invariant (barycentric coordinates
 * are): every regular lattice, right-triangle or equilateral, has s = 0.77 inside; below 1e-3
 * height errors would be amplified a thousandfold. */
#define SHAPE_GOOD_STENCIL 0.1
#define SHAPE_MIN_STENCIL 1e-3

/* Rings searched for replacement stencil vertices, nearest first. */
#define SHAPE_MAX_RING 3

/* Candidates tried from one ring: at most this many, the nearest to T's centroid in each of
 * SHAPE_CANDIDATE_SECTORS directions, both measured with T mapped to an equilateral triangle
 * (shape_stencil.c, ring_candidates). The search tries every triple, so its cost is the cube of
 * this; without the bound a fan of k triangles round one vertex cost about k^4 (2.3 s for
 * k = 100). Regular meshes' 2-rings hold fewer, so their stencils are the unbounded search's. */
#define SHAPE_MAX_CANDIDATES 32
#define SHAPE_CANDIDATE_SECTORS 8

/* the determinant of a 3x3 matrix */
static inline double det3(double M[3][3])
{
    return M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
           M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
}

/* Reference data of one triangle: barycentric gradients g[3][2] and the map
 * X -> (lambda_0, lambda_1, lambda_2). */
typedef struct {
    double X0[2], g[3][2];
    double det; /* 2 A, signed */
} ref_tri;

static inline void barycentric(const ref_tri *R, const double *P, double lam[3])
{
    const double dx = P[0] - R->X0[0], dy = P[1] - R->X0[1];
    lam[1] = R->g[1][0] * dx + R->g[1][1] * dy;
    lam[2] = R->g[2][0] * dx + R->g[2][1] * dy;
    lam[0] = 1.0 - lam[1] - lam[2];
}

/* Row k of M: (q_0, q_1, q_2)(P), q_j = lambda_{j+1} lambda_{j+2} */
static inline void fit_row(const ref_tri *R, const double *P, double row[3])
{
    double l[3];
    barycentric(R, P, l);
    row[0] = l[1] * l[2];
    row[1] = l[2] * l[0];
    row[2] = l[0] * l[1];
}

/* Workspace of the stencil search (allocated once per create). */
typedef struct {
    plume_index *vstart, *vtri; /* vertex -> triangles CSR */
    plume_index *mark;          /* [nv] stamp of the last search that saw the vertex */
    plume_index *ring;          /* candidate vertices */
    plume_index cap, nring;
    plume_index stamp;
    struct near_cand { double d; plume_index v, at; int rank, sector; } *near; /* [near_cap]: ring_candidates' sort */
    plume_index near_cap;
    plume_index cand[SHAPE_MAX_CANDIDATES];
    int phase; /* >= 0: rings grow through triangles of this material only (phase-aware stencils);
                  -1: through every triangle. Set by the caller before each search. */
} search_ws;

/* Where the stencil's points are in the reference plane: mesh vertices, except the ghost slots
 * (gp[k] != NULL), which sit at the mirror image of T's own vertex. */
typedef struct {
    const double *gp[3];
} ghost_ref;

/* The search's workspace over mesh m: its vertex -> triangles map and marks (W zeroed first).
 * Returns 0, or -1 when memory runs out (W then holds what to free). */
int plume_shape_search_init(search_ws *W, const plume_mesh *m);
void plume_shape_search_free(search_ws *W);

/* Chooses p[3] for triangle t (natural opposite vertices in p, -1 where the edge is on the
 * boundary; ghost slots, gr->gp[k] != NULL, are kept whatever happens). Returns the chosen
 * stencil's s(M) (0 if none was found), or -1 on allocation failure. */
double plume_shape_choose_stencil(const plume_mesh *m, plume_index t, const ref_tri *R, const ghost_ref *gr, search_ws *W,
                            plume_index p[3]);

#endif
