/* plume: the stencil search of the shape-operator bending term (macro/shell/internal/shape_stencil.h;
 * the method in macro/shell/shape_bending.c's top comment). */
#include "internal/shape_stencil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


int plume_shape_search_init(search_ws *W, const plume_mesh *m)
{
    const plume_index nv = m->nv, nt = m->nt;
    memset(W, 0, sizeof *W);
    W->vstart = calloc((size_t)(nv + 2), sizeof *W->vstart);
    W->vtri = malloc((size_t)(3 * nt + 1) * sizeof *W->vtri);
    W->mark = malloc((size_t)(nv + 1) * sizeof *W->mark);
    if (!W->vstart || !W->vtri || !W->mark)
        return -1;
    for (plume_index v = 0; v < nv; v++)
        W->mark[v] = -1;
    W->phase = -1;
    /* vertex -> triangles (CSR) */
    for (plume_index t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            W->vstart[m->tri[3 * t + k] + 2]++;
    for (plume_index v = 0; v < nv; v++)
        W->vstart[v + 2] += W->vstart[v + 1];
    for (plume_index t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            W->vtri[W->vstart[m->tri[3 * t + k] + 1]++] = t;
    return 0;
}

void plume_shape_search_free(search_ws *W)
{
    free(W->vstart);
    free(W->vtri);
    free(W->mark);
    free(W->ring);
    free(W->near);
    memset(W, 0, sizeof *W);
}

/* s(M), the row-normalised determinant (shape_bending.c's top comment) */
static double stencil_quality(double M[3][3])
{
    const double r0 = sqrt(M[0][0] * M[0][0] + M[0][1] * M[0][1] + M[0][2] * M[0][2]);
    const double r1 = sqrt(M[1][0] * M[1][0] + M[1][1] * M[1][1] + M[1][2] * M[1][2]);
    const double r2 = sqrt(M[2][0] * M[2][0] + M[2][1] * M[2][1] + M[2][2] * M[2][2]);
    const double den = r0 * r1 * r2;
    return den > 0.0 && isfinite(den) ? fabs(det3(M)) / den : 0.0;
}

static int ring_push(search_ws *W, plume_index v)
{
    if (W->mark[v] == W->stamp)
        return 1;
    W->mark[v] = W->stamp;
    if (W->nring == W->cap) {
        const plume_index cap = 2 * W->cap + 16;
        plume_index *r = realloc(W->ring, (size_t)cap * sizeof *r);
        if (!r)
            return 0;
        W->ring = r;
        W->cap = cap;
    }
    W->ring[W->nring++] = v;
    return 1;
}

/* Grows W->ring (which starts with T's vertices) by one ring: every vertex of a triangle incident
 * to a vertex already in it (of material W->phase if that is >= 0). Returns 0 on allocation
 * failure. */
static int ring_grow(search_ws *W, const plume_mesh *m)
{
    const plume_index n0 = W->nring;
    for (plume_index r = 0; r < n0; r++) {
        const plume_index v = W->ring[r];
        for (plume_index s = W->vstart[v]; s < W->vstart[v + 1]; s++)
            for (int k = 0; k < 3 && (W->phase < 0 || m->material[W->vtri[s]] == W->phase); k++)
                if (!ring_push(W, m->tri[3 * W->vtri[s] + k]))
                    return 0;
    }
    return 1;
}

static const double *slot_point(const plume_mesh *m, const ghost_ref *gr, const plume_index p[3], int k)
{
    return gr && gr->gp[k] ? gr->gp[k] : m->X + 2 * p[k];
}

/* Score of a stencil: s(M) over the farthest vertex's distance to T's centroid in T's longest
 * edges (>= some positive constant). *quality gets s(M). */
static double stencil_score(const ref_tri *R, const plume_mesh *m, const ghost_ref *gr, const plume_index p[3],
                            const double cen[2], double edge, double *quality)
{
    double M[3][3], far = 0.0;
    /* a point on one of T's vertices, or on another point (a split line's copy and its original
     * share a reference position): its row of M vanishes or repeats, which s(M), normalising the
     * rows, does not see (measured: a fit inverse of 9e15 and a bending stiffness of 1e32) */
    for (int k = 0; k < 3; k++) {
        const double *P = slot_point(m, gr, p, k);
        double lam[3];
        barycentric(R, P, lam);
        for (int j = 0; j < 3; j++) {
            const double *Q = slot_point(m, gr, p, j);
            if ((fabs(lam[j] - 1.0) <= 1e-9 && fabs(lam[(j + 1) % 3]) <= 1e-9 && fabs(lam[(j + 2) % 3]) <= 1e-9) ||
                (j < k && hypot(P[0] - Q[0], P[1] - Q[1]) <= 1e-9 * edge)) {
                *quality = 0.0;
                return 0.0;
            }
        }
    }
    for (int k = 0; k < 3; k++) {
        const double *P = slot_point(m, gr, p, k);
        fit_row(R, P, M[k]);
        far = fmax(far, hypot(P[0] - cen[0], P[1] - cen[1]) / edge);
    }
    *quality = stencil_quality(M);
    return *quality / fmax(far, 1e-300);
}

static int near_cmp(const void *a, const void *b)
{
    const struct near_cand *x = a, *y = b;
    if (x->rank != y->rank)
        return x->rank < y->rank ? -1 : 1;
    if (x->d != y->d)
        return x->d < y->d ? -1 : 1;
    return (x->at > y->at) - (x->at < y->at);
}

static int at_cmp(const void *a, const void *b)
{
    const struct near_cand *x = a, *y = b;
    return (x->at > y->at) - (x->at < y->at);
}

/* The candidates of the current ring (W->ring without T's three vertices): all of them if they
 * are at most SHAPE_MAX_CANDIDATES, else that many taken round the compass: the nearest to T's
 * centroid in each of SHAPE_CANDIDATE_SECTORS angular sectors, then the second nearest in each,
 * and so on. Angles and distances are those of the plane mapped affinely so that T is
 * equilateral, since s(M) is affine-invariant: the nearest alone can all lie near one line (a
 * fan's rim, for a thin triangle), and a quadratic fit needs points spread round T. Returned in ring order (the order the unbounded search tried them in) in *C and
 * *nc. Returns 0 on allocation failure. */
static int ring_candidates(search_ws *W, const plume_mesh *m, const ref_tri *R, const plume_index **C,
                           plume_index *nc)
{
    const plume_index n = W->nring - 3;
    if (n <= SHAPE_MAX_CANDIDATES) {
        *C = W->ring + 3;
        *nc = n;
        return 1;
    }
    if (W->near_cap < n) {
        struct near_cand *q = realloc(W->near, (size_t)n * sizeof *q);
        if (!q)
            return 0;
        W->near = q;
        W->near_cap = n;
    }
    int in_sector[SHAPE_CANDIDATE_SECTORS];
    for (int k = 0; k < SHAPE_CANDIDATE_SECTORS; k++)
        in_sector[k] = 0;
    for (plume_index i = 0; i < n; i++) {
        const plume_index v = W->ring[3 + i];
        /* T mapped to an equilateral triangle, its centroid at the origin */
        double l[3];
        barycentric(R, m->X + 2 * v, l);
        const double dx = l[1] - l[2], dy = (2.0 * l[0] - l[1] - l[2]) / 1.7320508075688772;
        const double turn = atan2(dy, dx) / (2.0 * 3.14159265358979323846) + 0.5; /* [0, 1] */
        const int sec = (int)(turn * SHAPE_CANDIDATE_SECTORS);
        W->near[i] = (struct near_cand){hypot(dx, dy), v, i, 0,
                                        sec < 0 ? 0 : sec >= SHAPE_CANDIDATE_SECTORS ? SHAPE_CANDIDATE_SECTORS - 1 : sec};
    }
    /* rank in its sector by distance, then take by rank */
    qsort(W->near, (size_t)n, sizeof *W->near, near_cmp); /* all ranks 0: by distance */
    for (plume_index i = 0; i < n; i++)
        W->near[i].rank = in_sector[W->near[i].sector]++;
    qsort(W->near, (size_t)n, sizeof *W->near, near_cmp);
    qsort(W->near, SHAPE_MAX_CANDIDATES, sizeof *W->near, at_cmp);
    for (plume_index i = 0; i < SHAPE_MAX_CANDIDATES; i++)
        W->cand[i] = W->near[i].v;
    *C = W->cand;
    *nc = SHAPE_MAX_CANDIDATES;
    return 1;
}

double plume_shape_choose_stencil(const plume_mesh *m, plume_index t, const ref_tri *R, const ghost_ref *gr, search_ws *W,
                            plume_index p[3])
{
    const plume_index *tv = m->tri + 3 * t;
    double cen[2] = {0.0, 0.0}, edge = 0.0;
    for (int k = 0; k < 3; k++) {
        const double *A = m->X + 2 * tv[k], *B = m->X + 2 * tv[(k + 1) % 3];
        cen[0] += A[0] / 3.0;
        cen[1] += A[1] / 3.0;
        edge = fmax(edge, hypot(B[0] - A[0], B[1] - A[1]));
    }
    int nmiss = 0, miss[3], nfree = 0, freeslot[3];
    for (int k = 0; k < 3; k++) {
        if (p[k] < 0)
            miss[nmiss++] = k;
        if (!gr->gp[k])
            freeslot[nfree++] = k;
    }
    double q = 0.0;
    if (nmiss == 0) {
        stencil_score(R, m, gr, p, cen, edge, &q);
        if (q >= SHAPE_GOOD_STENCIL || nfree == 0)
            return q;
    }
    const plume_index nat[3] = {p[0], p[1], p[2]};
    double best = -1.0, bestq = 0.0;
    plume_index bp[3] = {-1, -1, -1};
    W->stamp++;
    W->nring = 0;
    for (int k = 0; k < 3; k++)
        if (!ring_push(W, tv[k]))
            return -1.0;
    for (int ring = 1; ring <= SHAPE_MAX_RING; ring++) {
        if (!ring_grow(W, m))
            return -1.0;
        /* candidates: the ring without T's vertices (ring[0..2]), its nearest if many */
        const plume_index *C;
        plume_index nc;
        if (!ring_candidates(W, m, R, &C, &nc))
            return -1.0;
        for (int full = 0; full < 2; full++) {
            /* first only the missing slots (natural and ghost vertices kept), then every
             * non-ghost slot anew */
            if (full == 0 && nmiss == 0)
                continue;
            if (full == 1 && bestq >= SHAPE_GOOD_STENCIL)
                break;
            const int ns = full ? nfree : nmiss;
            int slot[3];
            for (int k = 0; k < ns; k++)
                slot[k] = full ? freeslot[k] : miss[k];
            /* combinations i0 < i1 < i2 of candidates for the ns slots */
            plume_index idx[3] = {0, 1, 2};
            if (nc < ns)
                continue;
            for (;;) {
                plume_index c[3] = {nat[0], nat[1], nat[2]};
                int ok = 1;
                for (int k = 0; k < ns; k++)
                    c[slot[k]] = C[idx[k]];
                for (int k = 0; k < ns; k++)
                    for (int j = 0; j < 3; j++)
                        if (j != slot[k] && !gr->gp[j] && c[j] == c[slot[k]])
                            ok = 0;
                if (ok) {
                    double qq;
                    const double sc = stencil_score(R, m, gr, c, cen, edge, &qq);
                    if (qq >= SHAPE_MIN_STENCIL && sc > best) {
                        best = sc;
                        bestq = qq;
                        memcpy(bp, c, sizeof bp);
                    }
                }
                /* next combination */
                int k = ns - 1;
                while (k >= 0 && idx[k] == nc - ns + k)
                    k--;
                if (k < 0)
                    break;
                idx[k]++;
                for (int j = k + 1; j < ns; j++)
                    idx[j] = idx[j - 1] + 1;
            }
        }
        if (bestq >= SHAPE_GOOD_STENCIL)
            break;
    }
    if (bp[0] < 0)
        return nmiss == 0 ? q : 0.0;
    memcpy(p, bp, sizeof bp);
    return bestq;
}
