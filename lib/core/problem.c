#include "problem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "opts.h"

/* Where the element blocks of a term go in the Hessian values. Only the entries that land in the
 * upper triangle on free dofs are added (about half of each block), each value of the pattern at
 * most once per stencil, so the sums are those of a scan of the whole block, stencil after
 * stencil, whatever the order within a stencil.
 * - By vertex blocks (a stencil whose vertices are distinct and each free in all its dofs or in
 *   none): pairs bstart[s] .. bstart[s+1]-1, local vertices a = bab & 0xffff (the one with the
 *   smaller free index, the rows) and b = bab >> 16, b's first free index bcol. The pattern is a
 *   union of whole vertex blocks, so the d x d block sits in columns bcol + j at one offset:
 *   entry (i, j) at bpos + (colptr[bcol + j] - colptr[bcol]) + i, bpos the position of its
 *   (0, 0); a == b is a diagonal block, whose column bcol + j ends with rows bcol .. bcol + j.
 *   About 2 bytes of map per entry instead of 12: the scatter was bound by reading the map.
 * - Entry by entry (the others): entries start[s] .. start[s+1]-1 add block entry src[e]
 *   (row-major in the k x k block) to values[dst[e]]. */
typedef struct {
    plume_index *start;  /* [nstencil + 1] */
    unsigned *src;       /* [start[nstencil]] */
    plume_index *dst;    /* [start[nstencil]] */
    plume_index *bstart; /* [nstencil + 1] */
    unsigned *bab;       /* [bstart[nstencil]] */
    plume_index *bcol;   /* [bstart[nstencil]] */
    plume_index *bpos;   /* [bstart[nstencil]], -1 on a diagonal block */
} scatter_map;

/* A term or constraint set with its scatter maps into the free-dof structures. */
typedef struct {
    plume_term t;
    scatter_map hmap;
    double *blocks;    /* workspace: [nstencil*k*k], or a chunk's blocks with hess_range */
} term_slot;

typedef struct {
    plume_constraint c;
    plume_index *row;  /* [m] global constraint row or -1 (dropped: all of its dofs prescribed) */
    scatter_map hmap;
    plume_index *jmap; /* [m*k] position in the Jacobian triplets or -1 */
    double *g, *jac, *lam, *blocks; /* workspaces [m], [m*k], [m], [m*k*k] */
} cons_slot;

struct plume_problem {
    plume_index nv, ndof, nfree, ncons;
    int dim;
    double length_scale;
    int finalized;
    double *x;
    unsigned char *fixed;
    plume_index *free_of_dof; /* [ndof] free index or -1 */
    plume_index *dof_of_free; /* [nfree] */
    term_slot *terms;
    int nterms;
    cons_slot *cons;
    int ncsets;
    plume_index *colptr, *rowind, nnz; /* Hessian upper triangle, CSC */
    plume_index *scol, *srow;          /* the part of it from fixed stencils (terms without update,
                                          constraints, the diagonal): built once, merged with the
                                          changing terms' pairs at every rebuild */
    plume_index *smerged;              /* [scol[nfree]] where each entry of that part sits in the
                                          merged pattern: a rebuild moves the fixed stencils' scatter
                                          maps through it instead of searching the pattern again */
    plume_index jnnz, *jrow, *jcol;    /* Jacobian triplets */
    double *gradfull;                  /* [ndof] workspace */
    double *jtwork;                    /* [ndof] workspace for J^T lambda */
    double *dxfull;                    /* [ndof] workspace for a step on every dof */
    double force_scale;                /* max |grad f| over all dofs at the last gradient */
    double force_floor;                /* forces below this are round-off (set by finalize) */
    double *scale;                     /* [ncons] */
    plume_problem_timing timing;
};

/* A term with hess_range is assembled this many block entries at a time (256 kB of blocks): they are
 * scattered while still in the cache. Written whole, the blocks of shape-operator bending on the
 * wing (45 MB) went out to memory and back at every Hessian. */
#define HESS_CHUNK_ENTRIES 32768

/* Stencils of a term assembled per call of its hess_range, and the size of its blocks workspace. */
static plume_index term_chunk(const plume_term *t, size_t kk)
{
    if (!t->hess_range)
        return t->nstencil;
    const plume_index c = (plume_index)(HESS_CHUNK_ENTRIES / kk);
    return c < 1 ? 1 : c < t->nstencil ? c : t->nstencil;
}

static void scatter_map_free(scatter_map *m)
{
    free(m->start);
    free(m->src);
    free(m->dst);
    free(m->bstart);
    free(m->bab);
    free(m->bcol);
    free(m->bpos);
    m->start = m->dst = m->bstart = m->bcol = m->bpos = NULL;
    m->src = m->bab = NULL;
}

static double now(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void plume_problem_timing_get(const plume_problem *p, plume_problem_timing *t)
{
    if (!t)
        return;
    if (p)
        *t = p->timing;
    else
        memset(t, 0, sizeof *t);
}

plume_status plume_problem_create(plume_index nv, int dim, double length_scale, plume_problem **out,
                                  plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "problem: out is required");
    *out = NULL;
    if (nv <= 0 || (dim != 2 && dim != 3) || !(length_scale > 0.0) || !isfinite(length_scale))
        return plume_err_set(err, PLUME_EINVAL,
                             "problem: %ld vertices in dimension %d with length scale %g: needs vertices > 0, "
                             "dimension 2 or 3 and a finite length scale > 0",
                             (long)nv, dim, length_scale);
    plume_problem *p = calloc(1, sizeof *p);
    if (!p)
        return plume_err_set(err, PLUME_ENOMEM, "problem: out of memory");
    p->nv = nv;
    p->dim = dim;
    p->ndof = nv * dim;
    p->length_scale = length_scale;
    p->x = calloc((size_t)p->ndof, sizeof *p->x);
    p->fixed = calloc((size_t)p->ndof, 1);
    p->gradfull = calloc((size_t)p->ndof, sizeof *p->gradfull);
    p->jtwork = calloc((size_t)p->ndof, sizeof *p->jtwork);
    p->dxfull = calloc((size_t)p->ndof, sizeof *p->dxfull);
    if (!p->x || !p->fixed || !p->gradfull || !p->jtwork || !p->dxfull) {
        plume_problem_destroy(&p);
        return plume_err_set(err, PLUME_ENOMEM, "problem: out of memory for %ld vertices", (long)nv);
    }
    *out = p;
    return PLUME_OK;
}

void plume_problem_destroy(plume_problem **pp)
{
    if (!pp || !*pp)
        return;
    plume_problem *p = *pp;
    free(p->scol);
    free(p->srow);
    free(p->smerged);
    for (int i = 0; i < p->nterms; i++) {
        if (p->terms[i].t.destroy)
            p->terms[i].t.destroy(p->terms[i].t.ctx);
        scatter_map_free(&p->terms[i].hmap);
        free(p->terms[i].blocks);
    }
    for (int i = 0; i < p->ncsets; i++) {
        cons_slot *c = p->cons + i;
        if (c->c.destroy)
            c->c.destroy(c->c.ctx);
        free(c->row);
        scatter_map_free(&c->hmap);
        free(c->jmap);
        free(c->g);
        free(c->jac);
        free(c->lam);
        free(c->blocks);
    }
    free(p->terms);
    free(p->cons);
    free(p->x);
    free(p->fixed);
    free(p->free_of_dof);
    free(p->dof_of_free);
    free(p->colptr);
    free(p->rowind);
    free(p->jrow);
    free(p->jcol);
    free(p->gradfull);
    free(p->jtwork);
    free(p->dxfull);
    free(p->scale);
    free(p);
    *pp = NULL;
}

/* Grows a full-vector array of the problem from p->ndof to n entries, the new ones zero. */
static int grow_full(void **a, plume_index old, plume_index n, size_t size)
{
    char *g = realloc(*a, (size_t)n * size);
    if (!g)
        return 0;
    memset(g + (size_t)old * size, 0, (size_t)(n - old) * size);
    *a = g;
    return 1;
}

plume_status plume_problem_add_unknowns(plume_problem *p, plume_index n, plume_index *first, plume_err *err)
{
    if (!p || !first)
        return plume_err_set(err, PLUME_EINVAL, "problem: add_unknowns needs a problem and first");
    if (p->finalized)
        return plume_err_set(err, PLUME_EINVAL, "problem: unknowns are added before plume_problem_finalize");
    if (n <= 0)
        return plume_err_set(err, PLUME_EINVAL, "problem: %ld unknowns to add: needs at least 1", (long)n);
    const plume_index nd = p->ndof + n;
    if (!grow_full((void **)&p->x, p->ndof, nd, sizeof *p->x) || !grow_full((void **)&p->fixed, p->ndof, nd, 1) ||
        !grow_full((void **)&p->gradfull, p->ndof, nd, sizeof *p->gradfull) ||
        !grow_full((void **)&p->jtwork, p->ndof, nd, sizeof *p->jtwork) ||
        !grow_full((void **)&p->dxfull, p->ndof, nd, sizeof *p->dxfull))
        return plume_err_set(err, PLUME_ENOMEM, "problem: out of memory adding %ld unknowns", (long)n);
    *first = p->ndof;
    p->ndof = nd;
    return PLUME_OK;
}

/* The problem owns what it is given, also when it refuses it: free the context and return st
 * with the message `why`. */
static plume_status refuse(void (*destroy)(void *), void *ctx, plume_status st, plume_err *err, const char *why)
{
    if (destroy)
        destroy(ctx);
    return plume_err_set(err, st, "%s", why);
}

/* Grows an array of `count` slots of `size` bytes by one zeroed slot; NULL when memory runs out. */
static void *grow_slots(void *slots, int count, size_t size)
{
    char *g = realloc(slots, (size_t)(count + 1) * size);
    if (g)
        memset(g + (size_t)count * size, 0, size);
    return g;
}

plume_status plume_problem_add_term(plume_problem *p, const plume_term *given, plume_err *err)
{
    if (!p || !given)
        return plume_err_set(err, PLUME_EINVAL, "problem: add_term needs a problem and a term");
    plume_term full = {.size = sizeof full}; /* the caller's term (as many bytes as it has), the rest 0 */
    const plume_term *t = &full;
    if (plume_opts_take(&full, sizeof full, given, "plume_term", err) != PLUME_OK)
        return refuse(given->destroy, given->ctx, PLUME_EINVAL, err,
                      "problem: plume_term.size is 0: give it sizeof(plume_term) (the term is freed)");
    if (p->finalized)
        return refuse(t->destroy, t->ctx, PLUME_EINVAL, err,
                      "problem: terms are added before plume_problem_finalize (the term is freed)");
    if (!t->eval || t->arity <= 0 || t->nstencil < 0 || (t->nstencil && !t->stencil))
        return refuse(t->destroy, t->ctx, PLUME_EINVAL, err,
                      "problem: a term needs eval, arity > 0 and, with stencils, its stencil array (the term is "
                      "freed)");
    if (t->nextra < 0 || (t->nextra > 0 && ((t->nstencil && !t->extra) || t->update || t->padded)))
        return refuse(t->destroy, t->ctx, PLUME_EINVAL, err,
                      "problem: a term with extra unknowns needs nextra > 0, its extra array, and neither update "
                      "nor padded (the term is freed)");
    term_slot *ts = grow_slots(p->terms, p->nterms, sizeof *ts);
    if (!ts)
        return refuse(t->destroy, t->ctx, PLUME_ENOMEM, err, "problem: out of memory adding a term");
    p->terms = ts;
    ts[p->nterms++].t = *t;
    return PLUME_OK;
}

plume_status plume_problem_add_constraint(plume_problem *p, const plume_constraint *given, plume_err *err)
{
    if (!p || !given)
        return plume_err_set(err, PLUME_EINVAL, "problem: add_constraint needs a problem and a constraint set");
    plume_constraint full = {.size = sizeof full}; /* the caller's set (as many bytes as it has), the rest 0 */
    const plume_constraint *c = &full;
    if (plume_opts_take(&full, sizeof full, given, "plume_constraint", err) != PLUME_OK)
        return refuse(given->destroy, given->ctx, PLUME_EINVAL, err,
                      "problem: plume_constraint.size is 0: give it sizeof(plume_constraint) (the set is freed)");
    if (p->finalized)
        return refuse(c->destroy, c->ctx, PLUME_EINVAL, err,
                      "problem: constraints are added before plume_problem_finalize (the set is freed)");
    if (!c->eval || !c->hess || c->arity <= 0 || c->m < 0 || (c->m && (!c->stencil || !c->scale)))
        return refuse(c->destroy, c->ctx, PLUME_EINVAL, err,
                      "problem: a constraint set needs eval, hess, arity > 0 and, with constraints, its stencil "
                      "and scale arrays (the set is freed)");
    cons_slot *cs = grow_slots(p->cons, p->ncsets, sizeof *cs);
    if (!cs)
        return refuse(c->destroy, c->ctx, PLUME_ENOMEM, err, "problem: out of memory adding a constraint set");
    p->cons = cs;
    cs[p->ncsets++].c = *c;
    return PLUME_OK;
}

plume_status plume_problem_fix_dof(plume_problem *p, plume_index dof, plume_err *err)
{
    if (!p)
        return plume_err_set(err, PLUME_EINVAL, "problem: fix_dof needs a problem");
    if (p->finalized)
        return plume_err_set(err, PLUME_EINVAL, "problem: dofs are fixed before plume_problem_finalize");
    if (dof < 0 || dof >= p->ndof)
        return plume_err_set(err, PLUME_EINVAL, "problem: dof %ld out of [0, %ld) (vertex %ld, component %ld)",
                             (long)dof, (long)p->ndof, (long)(dof / p->dim), (long)(dof % p->dim));
    p->fixed[dof] = 1;
    return PLUME_OK;
}

/* (row, col) pair of the upper triangle, sorted column-major */
typedef struct {
    plume_index r, c;
} pair;

static int index_cmp(const void *a, const void *b)
{
    plume_index x = *(const plume_index *)a, y = *(const plume_index *)b;
    return x < y ? -1 : (x > y);
}

static plume_index find_entry(const plume_problem *p, plume_index r, plume_index c)
{
    plume_index lo = p->colptr[c], hi = p->colptr[c + 1] - 1;
    while (lo <= hi) {
        plume_index mid = lo + (hi - lo) / 2;
        if (p->rowind[mid] == r)
            return mid;
        if (p->rowind[mid] < r)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* The places of a stencil that hold its vertices: all of them, or with `padded` (plume_term's) those
 * before the trailing repeats of its first vertex. */
static int stencil_size(const plume_index *st, int arity, int padded)
{
    int n = arity;
    while (padded && n > 1 && st[n - 1] == st[0])
        n--;
    return n;
}

/* One stencil as the problem reads it: `arity` vertex places, the first `used` of them vertices
 * (the others padding), then `nextra` extra unknowns. Its block is k x k, k = arity*d + nextra:
 * place a < used*d is coordinate a % d of vertex st[a / d], place arity*d + j is extra j. */
typedef struct {
    const plume_index *st, *ex;
    int arity, used, nextra;
} stencil_view;

static stencil_view view_of(const plume_index *stencils, const plume_index *extras, int arity, int nextra, int padded,
                            plume_index s)
{
    stencil_view v = {stencils + s * arity, extras ? extras + s * nextra : NULL, arity, 0, extras ? nextra : 0};
    v.used = stencil_size(v.st, arity, padded);
    return v;
}

/* The places of a stencil's block that hold unknowns, counted without the padding. */
static int view_places(const stencil_view *v, int d) { return v->used * d + v->nextra; }

/* The block index of the i-th such place. */
static int view_slot(const stencil_view *v, int d, int i) { return i < v->used * d ? i : v->arity * d + (i - v->used * d); }

/* The full-vector index of the i-th such place. */
static plume_index view_dof(const stencil_view *v, int d, int i)
{
    return i < v->used * d ? v->st[i / d] * d + i % d : v->ex[i - v->used * d];
}

/* Adds the upper-triangle free pairs of one stencil to `pairs` (if non-NULL); returns their count.
 * A padded stencil's repeats of its first vertex add no pair that its first place does not. */
static plume_index stencil_pairs(const plume_problem *p, const stencil_view *v, pair *pairs)
{
    plume_index n = 0;
    const int d = p->dim, used = view_places(v, d);
    for (int a = 0; a < used; a++) {
        plume_index fa = p->free_of_dof[view_dof(v, d, a)];
        if (fa < 0)
            continue;
        for (int b = 0; b < used; b++) {
            plume_index fb = p->free_of_dof[view_dof(v, d, b)];
            if (fb < 0 || fa > fb)
                continue;
            if (pairs) {
                pairs[n].r = fa;
                pairs[n].c = fb;
            }
            n++;
        }
    }
    return n;
}

/* Whether stencil st (used places) is assembled by vertex blocks, and its count of vertex pairs
 * (upper, diagonal included): its vertices distinct, each free in all of its d dofs (consecutive
 * free indices) or in none, and every entry where the pattern's block structure puts it. */
static int stencil_blocked(const plume_problem *p, const plume_index *st, int used, int arity, plume_index *npairs)
{
    const int d = p->dim;
    *npairs = 0;
    if (arity > 0xffff)
        return 0;
    int nfree = 0;
    for (int a = 0; a < used; a++) {
        const plume_index f0 = p->free_of_dof[st[a] * d];
        for (int i = 1; i < d; i++) {
            const plume_index fi = p->free_of_dof[st[a] * d + i];
            if (f0 < 0 ? fi >= 0 : fi != f0 + i)
                return 0;
        }
        for (int b = 0; b < a; b++)
            if (st[b] == st[a])
                return 0;
        nfree += f0 >= 0;
    }
    for (int a = 0; a < used; a++) {
        const plume_index fa = p->free_of_dof[st[a] * d];
        for (int b = 0; b < used && fa >= 0; b++) {
            const plume_index fb = p->free_of_dof[st[b] * d];
            if (fb < fa)
                continue;
            const plume_index p0 = find_entry(p, fa, fb);
            for (int j = 0; j < d; j++)
                for (int i = 0; i < (a == b ? j + 1 : d); i++) {
                    const plume_index at = a == b ? p->colptr[fb + j + 1] - 1 - j + i
                                                  : p0 + (p->colptr[fb + j] - p->colptr[fb]) + i;
                    if (p0 < 0 || at != find_entry(p, fa + i, fb + j))
                        return 0;
                }
        }
    }
    *npairs = (plume_index)nfree * (nfree + 1) / 2;
    return 1;
}

/* The scatter map of n stencils of `arity` vertices (stencils [n*arity], padded as plume_term's
 * flag says) on the current pattern: by vertex blocks where stencil_blocked says so, otherwise
 * the entries stencil_pairs counts. A padded place's block entries are zero, and skipping them
 * leaves every sum as it was. */
static plume_status scatter_map_build(const plume_problem *p, const plume_index *stencils, int arity, int padded,
                                      const plume_index *extras, int nextra, plume_index n, scatter_map *m)
{
    const int d = p->dim, k = arity * d + (extras ? nextra : 0);
    memset(m, 0, sizeof *m);
    m->start = malloc((size_t)(n + 1) * sizeof *m->start);
    m->bstart = malloc((size_t)(n + 1) * sizeof *m->bstart);
    if (!m->start || !m->bstart) {
        scatter_map_free(m);
        return PLUME_ENOMEM;
    }
    m->start[0] = m->bstart[0] = 0;
    for (plume_index s = 0; s < n; s++) {
        const stencil_view v = view_of(stencils, extras, arity, nextra, padded, s);
        plume_index np = 0;
        const int blocked = v.nextra == 0 && stencil_blocked(p, v.st, v.used, arity, &np);
        m->start[s + 1] = m->start[s] + (blocked ? 0 : stencil_pairs(p, &v, NULL));
        m->bstart[s + 1] = m->bstart[s] + np;
    }
    const plume_index ne = m->start[n], nb = m->bstart[n];
    m->src = malloc((size_t)(ne + 1) * sizeof *m->src);
    m->dst = malloc((size_t)(ne + 1) * sizeof *m->dst);
    m->bab = malloc((size_t)(nb + 1) * sizeof *m->bab);
    m->bcol = malloc((size_t)(nb + 1) * sizeof *m->bcol);
    m->bpos = malloc((size_t)(nb + 1) * sizeof *m->bpos);
    if (!m->src || !m->dst || !m->bab || !m->bcol || !m->bpos) {
        scatter_map_free(m);
        return PLUME_ENOMEM;
    }
    for (plume_index s = 0; s < n; s++) {
        const stencil_view v = view_of(stencils, extras, arity, nextra, padded, s);
        const plume_index *st = v.st;
        const int used_v = v.used, used = view_places(&v, d);
        if (m->bstart[s + 1] > m->bstart[s]) {
            plume_index q = m->bstart[s];
            for (int a = 0; a < used_v; a++) {
                const plume_index fa = p->free_of_dof[st[a] * d];
                for (int b = 0; b < used_v && fa >= 0; b++) {
                    const plume_index fb = p->free_of_dof[st[b] * d];
                    if (fb < fa)
                        continue;
                    m->bab[q] = (unsigned)a | (unsigned)b << 16;
                    m->bcol[q] = fb;
                    m->bpos[q++] = a == b ? -1 : find_entry(p, fa, fb);
                }
            }
            continue;
        }
        plume_index e = m->start[s];
        for (int a = 0; a < used; a++) {
            plume_index fa = p->free_of_dof[view_dof(&v, d, a)];
            if (fa < 0)
                continue;
            for (int b = 0; b < used; b++) {
                plume_index fb = p->free_of_dof[view_dof(&v, d, b)];
                if (fb < 0 || fa > fb)
                    continue;
                m->src[e] = (unsigned)(view_slot(&v, d, a) * k + view_slot(&v, d, b));
                m->dst[e++] = find_entry(p, fa, fb);
            }
        }
    }
    return PLUME_OK;
}

static int stencil_ok(const plume_problem *p, const plume_index *st, plume_index n)
{
    for (plume_index i = 0; i < n; i++)
        if (st[i] < 0 || st[i] >= p->nv)
            return 0;
    return 1;
}

/* n extras, each an unknown after the vertices' coordinates */
static int extras_ok(const plume_problem *p, const plume_index *ex, plume_index n)
{
    for (plume_index i = 0; i < n; i++)
        if (ex[i] < p->nv * p->dim || ex[i] >= p->ndof)
            return 0;
    return 1;
}

/* Frees what finalize builds, so that a finalize that failed half-way can be called again. With
 * keep_fixed, the scatter maps of the fixed stencils (terms without update, constraints) stay: a
 * rebuild after a change of the changing terms' stencils moves them (build_structure). */
static void release_structure(plume_problem *p, int keep_fixed)
{
    free(p->free_of_dof);
    free(p->dof_of_free);
    free(p->colptr);
    free(p->rowind);
    free(p->jrow);
    free(p->jcol);
    free(p->scale);
    p->free_of_dof = p->dof_of_free = p->colptr = p->rowind = p->jrow = p->jcol = NULL;
    p->scale = NULL;
    for (int i = 0; i < p->nterms; i++) {
        if (!keep_fixed || p->terms[i].t.update) { /* a fixed term's blocks keep their size */
            scatter_map_free(&p->terms[i].hmap);
            free(p->terms[i].blocks);
            p->terms[i].blocks = NULL;
        }
    }
    if (!keep_fixed) {
        free(p->smerged);
        p->smerged = NULL;
    }
    for (int i = 0; i < p->ncsets; i++) {
        cons_slot *c = p->cons + i;
        free(c->row);
        if (!keep_fixed)
            scatter_map_free(&c->hmap);
        free(c->jmap);
        free(c->g);
        free(c->jac);
        free(c->lam);
        free(c->blocks);
        c->row = c->jmap = NULL;
        c->g = c->jac = c->lam = c->blocks = NULL;
    }
}

/* The pairs of stencil s of term t, and of constraint i of set c (stencil_pairs). */
static plume_index term_pairs(const plume_problem *p, const plume_term *t, plume_index s, pair *pairs)
{
    const stencil_view v = view_of(t->stencil, t->extra, t->arity, t->nextra, t->padded, s);
    return stencil_pairs(p, &v, pairs);
}

static plume_index constraint_pairs(const plume_problem *p, const plume_constraint *c, plume_index i, pair *pairs)
{
    const stencil_view v = view_of(c->stencil, NULL, c->arity, 0, 0, i);
    return stencil_pairs(p, &v, pairs);
}

/* Largest diagonal entry of the Hessian at the current x: a stiffness scale. */
static plume_status stiffness_scale(plume_problem *p, double *scale)
{
    double *values = malloc((size_t)(p->nnz + 1) * sizeof *values);
    if (!values)
        return PLUME_ENOMEM;
    p->finalized = 1; /* plume_problem_hessian requires it */
    plume_status st = plume_problem_hessian(p, NULL, 1.0, NULL, 0, values);
    p->finalized = 0;
    double s = 0.0;
    for (plume_index c = 0; c < p->nfree && st == PLUME_OK; c++)
        s = fmax(s, fabs(values[p->colptr[c + 1] - 1]));
    free(values);
    *scale = isfinite(s) ? s : 0.0;
    return st;
}

/* The free-dof map, constraint rows, Hessian pattern, scatter maps and Jacobian triplets from the
 * current stencils (finalize, and again when stencils change). */
/* The upper-triangle free pairs of the terms whose stencils change (changing = 1), or of everything
 * else: the fixed terms, the constraints and the diagonal (changing = 0). *out is malloc'ed. */
static plume_status collect_pairs(const plume_problem *p, int changing, pair **out, plume_index *n)
{
    plume_index np = changing ? 0 : p->nfree;
    for (int t = 0; t < p->nterms; t++)
        if ((p->terms[t].t.update != NULL) == changing)
            for (plume_index s = 0; s < p->terms[t].t.nstencil; s++)
                np += term_pairs(p, &p->terms[t].t, s, NULL);
    for (int s = 0; !changing && s < p->ncsets; s++)
        for (plume_index i = 0; i < p->cons[s].c.m; i++)
            np += constraint_pairs(p, &p->cons[s].c, i, NULL);
    pair *pairs = malloc((size_t)(np + 1) * sizeof *pairs);
    if (!pairs)
        return PLUME_ENOMEM;
    plume_index k = 0;
    for (int t = 0; t < p->nterms; t++)
        if ((p->terms[t].t.update != NULL) == changing)
            for (plume_index s = 0; s < p->terms[t].t.nstencil; s++)
                k += term_pairs(p, &p->terms[t].t, s, pairs + k);
    for (int s = 0; !changing && s < p->ncsets; s++)
        for (plume_index i = 0; i < p->cons[s].c.m; i++)
            k += constraint_pairs(p, &p->cons[s].c, i, pairs + k);
    for (plume_index i = 0; !changing && i < p->nfree; i++, k++) /* the diagonal: regularisation, KKT */
        pairs[k].r = pairs[k].c = i;
    *out = pairs;
    *n = k;
    return PLUME_OK;
}

/* n pairs as a CSC pattern over nfree columns, rows sorted and without repeats: a counting sort on
 * the column, then each column deduplicated (a mark per row) and sorted (a global qsort of every
 * pair was 14 % of a contact scene's run, which rebuilds the pattern whenever pairs change). */
static plume_status pairs_to_csc(plume_index nfree, const pair *pairs, plume_index n, plume_index **colptr,
                                 plume_index **rowind)
{
    plume_index *cp = calloc((size_t)nfree + 2, sizeof *cp), *ri = malloc((size_t)(n + 1) * sizeof *ri);
    plume_index *mark = malloc((size_t)(nfree + 1) * sizeof *mark);
    if (!cp || !ri || !mark) {
        free(cp);
        free(ri);
        free(mark);
        return PLUME_ENOMEM;
    }
    for (plume_index i = 0; i < n; i++)
        cp[pairs[i].c + 2]++;
    for (plume_index c = 0; c < nfree; c++)
        cp[c + 2] += cp[c + 1];
    for (plume_index i = 0; i < n; i++) /* cp[c + 1] is the fill position of column c */
        ri[cp[pairs[i].c + 1]++] = pairs[i].r;
    for (plume_index r = 0; r < nfree; r++)
        mark[r] = -1;
    plume_index u = 0;
    for (plume_index c = 0; c < nfree; c++) {
        plume_index lo = cp[c], hi = cp[c + 1], start = u;
        for (plume_index i = lo; i < hi; i++) /* u <= i: compaction never overtakes the reading */
            if (mark[ri[i]] != c) {
                mark[ri[i]] = c;
                ri[u++] = ri[i];
            }
        if (u - start > 32) {
            qsort(ri + start, (size_t)(u - start), sizeof *ri, index_cmp);
        } else {
            for (plume_index i = start + 1; i < u; i++) { /* insertion sort */
                plume_index r = ri[i], k = i;
                for (; k > start && ri[k - 1] > r; k--)
                    ri[k] = ri[k - 1];
                ri[k] = r;
            }
        }
        cp[c] = start; /* columns before c are final; c's bounds were read above */
    }
    cp[nfree] = u;
    free(mark);
    *colptr = cp;
    *rowind = ri;
    return PLUME_OK;
}

/* The fixed stencils' scatter maps, kept from the last build, moved to the new merged pattern:
 * old position -> entry of the fixed part (the old smerged inverted) -> new position. */
/* A fixed stencils' map to the merged pattern's new positions (a vertex block's other entries
 * follow from its first through the pattern's block structure, which the merge keeps). */
static void move_map(const plume_problem *p, scatter_map *m, plume_index n, const plume_index *fixed_of)
{
    for (plume_index e = 0; e < m->start[n]; e++)
        m->dst[e] = p->smerged[fixed_of[m->dst[e]]];
    for (plume_index q = 0; q < m->bstart[n]; q++)
        if (m->bpos[q] >= 0)
            m->bpos[q] = p->smerged[fixed_of[m->bpos[q]]];
}

static plume_status move_fixed_maps(plume_problem *p, plume_index old_nnz, const plume_index *old_smerged)
{
    const plume_index ns = p->scol[p->nfree];
    plume_index *fixed_of = malloc((size_t)(old_nnz + 1) * sizeof *fixed_of);
    if (!fixed_of)
        return PLUME_ENOMEM;
    for (plume_index j = 0; j < ns; j++)
        fixed_of[old_smerged[j]] = j;
    for (int t = 0; t < p->nterms; t++) {
        term_slot *ts = p->terms + t;
        if (ts->t.update)
            continue;
        move_map(p, &ts->hmap, ts->t.nstencil, fixed_of);
    }
    for (int s = 0; s < p->ncsets; s++)
        move_map(p, &p->cons[s].hmap, p->cons[s].c.m, fixed_of);
    free(fixed_of);
    return PLUME_OK;
}

static plume_status build_structure_with(plume_problem *p, int rebuild, plume_err *err);

/* A rebuild (the changing terms' stencils changed; the fixed part's pattern exists) keeps the
 * fixed stencils' scatter maps and moves them; a failed rebuild frees everything, so that the
 * next build starts from scratch. */
static plume_status build_structure(plume_problem *p, plume_err *err)
{
    const int rebuild = p->scol != NULL && p->smerged != NULL;
    plume_status st = build_structure_with(p, rebuild, err);
    if (st != PLUME_OK && rebuild)
        release_structure(p, 0);
    return st;
}

/* The free numbering of the coordinates (the fixed ones get -1) and its inverse. */
static plume_status number_free_dofs(plume_problem *p, plume_err *err)
{
    p->free_of_dof = malloc((size_t)p->ndof * sizeof *p->free_of_dof);
    if (!p->free_of_dof)
        return PLUME_ENOMEM;
    p->nfree = 0;
    for (plume_index i = 0; i < p->ndof; i++)
        p->free_of_dof[i] = p->fixed[i] ? -1 : p->nfree++;
    if (p->nfree == 0)
        return plume_err_set(err, PLUME_EINVAL, "problem has no free coordinate");
    p->dof_of_free = malloc((size_t)p->nfree * sizeof *p->dof_of_free);
    if (!p->dof_of_free)
        return PLUME_ENOMEM;
    for (plume_index i = 0; i < p->ndof; i++)
        if (p->free_of_dof[i] >= 0)
            p->dof_of_free[p->free_of_dof[i]] = i;
    return PLUME_OK;
}

/* Each constraint set's workspaces and rows: a row whose stencil is entirely prescribed is dropped
 * (-1); the others are numbered across the sets. */
static plume_status constraint_rows(plume_problem *p, plume_err *err)
{
    const int d = p->dim;
    p->ncons = 0;
    for (int s = 0; s < p->ncsets; s++) {
        cons_slot *c = p->cons + s;
        int k = c->c.arity * d;
        if (!stencil_ok(p, c->c.stencil, c->c.m * c->c.arity))
            return plume_err_set(err, PLUME_EINVAL, "constraint set '%s': vertex id out of range", c->c.name);
        c->row = malloc((size_t)(c->c.m + 1) * sizeof *c->row);
        c->g = calloc((size_t)(c->c.m + 1), sizeof *c->g);
        c->lam = calloc((size_t)(c->c.m + 1), sizeof *c->lam);
        c->jac = calloc((size_t)(c->c.m * k + 1), sizeof *c->jac);
        c->blocks = calloc((size_t)(c->c.m * k * k + 1), sizeof *c->blocks);
        c->jmap = malloc((size_t)(c->c.m * k + 1) * sizeof *c->jmap);
        if (!c->row || !c->g || !c->lam || !c->jac || !c->blocks || !c->jmap)
            return PLUME_ENOMEM;
        for (plume_index i = 0; i < c->c.m; i++) {
            int any_free = 0;
            for (int a = 0; a < k; a++)
                any_free |= p->free_of_dof[c->c.stencil[i * c->c.arity + a / d] * d + a % d] >= 0;
            c->row[i] = any_free ? p->ncons++ : -1;
        }
    }
    p->scale = malloc((size_t)(p->ncons + 1) * sizeof *p->scale);
    return p->scale ? PLUME_OK : PLUME_ENOMEM;
}

/* The Hessian pattern: the fixed stencils' part once (kept across rebuilds), then the changing
 * terms' pairs merged in; smerged maps each entry of the fixed part to its place in the merge. */
static plume_status hessian_pattern(plume_problem *p, plume_err *err)
{
    plume_status st = PLUME_OK;
    pair *pairs = NULL;
    plume_index npairs = 0, *dcol = NULL, *drow = NULL;
    for (int t = 0; t < p->nterms; t++) {
        term_slot *ts = p->terms + t;
        if (!stencil_ok(p, ts->t.stencil, ts->t.nstencil * ts->t.arity)) {
            st = plume_err_set(err, PLUME_EINVAL, "term '%s': vertex id out of range", ts->t.name);
            goto cleanup;
        }
        if (ts->t.nextra > 0 && !extras_ok(p, ts->t.extra, ts->t.nstencil * ts->t.nextra)) {
            st = plume_err_set(err, PLUME_EINVAL,
                               "term '%s': an extra unknown out of [%ld, %ld) (the unknowns after the vertices)",
                               ts->t.name, (long)(p->nv * p->dim), (long)p->ndof);
            goto cleanup;
        }
    }
    if (!p->scol) {
        if ((st = collect_pairs(p, 0, &pairs, &npairs)) != PLUME_OK ||
            (st = pairs_to_csc(p->nfree, pairs, npairs, &p->scol, &p->srow)) != PLUME_OK)
            goto cleanup;
        free(pairs);
        pairs = NULL;
    }
    if ((st = collect_pairs(p, 1, &pairs, &npairs)) != PLUME_OK ||
        (st = pairs_to_csc(p->nfree, pairs, npairs, &dcol, &drow)) != PLUME_OK)
        goto cleanup;
    p->colptr = malloc((size_t)(p->nfree + 1) * sizeof *p->colptr);
    p->rowind = malloc((size_t)(p->scol[p->nfree] + dcol[p->nfree] + 1) * sizeof *p->rowind);
    p->smerged = malloc((size_t)(p->scol[p->nfree] + 1) * sizeof *p->smerged);
    if (!p->colptr || !p->rowind || !p->smerged) {
        st = PLUME_ENOMEM;
        goto cleanup;
    }
    plume_index u = 0;
    for (plume_index c = 0; c < p->nfree; c++) { /* two sorted lists, merged without repeats */
        plume_index i = p->scol[c], ie = p->scol[c + 1], j = dcol[c], je = dcol[c + 1];
        p->colptr[c] = u;
        while (i < ie || j < je) {
            plume_index r = j >= je || (i < ie && p->srow[i] <= drow[j]) ? p->srow[i] : drow[j];
            p->rowind[u++] = r;
            while (i < ie && p->srow[i] == r)
                p->smerged[i++] = u - 1;
            while (j < je && drow[j] == r)
                j++;
        }
    }
    p->colptr[p->nfree] = u;
    p->nnz = u;
cleanup:
    free(pairs);
    free(dcol);
    free(drow);
    return st;
}

/* The terms' block workspaces and scatter maps (on a rebuild only the changing terms': the fixed
 * ones keep theirs, moved by move_fixed_maps). */
static plume_status term_maps(plume_problem *p, int rebuild)
{
    const int d = p->dim;
    for (int t = 0; t < p->nterms; t++) {
        term_slot *ts = p->terms + t;
        if (rebuild && !ts->t.update)
            continue; /* kept, its map moved */
        const size_t k = (size_t)(ts->t.arity * d + ts->t.nextra), kk = k * k;
        ts->blocks = malloc(((size_t)term_chunk(&ts->t, kk) * kk + 1) * sizeof *ts->blocks);
        if (!ts->blocks || scatter_map_build(p, ts->t.stencil, ts->t.arity, ts->t.padded, ts->t.extra, ts->t.nextra,
                                             ts->t.nstencil, &ts->hmap) != PLUME_OK)
            return PLUME_ENOMEM;
    }
    return PLUME_OK;
}

/* The constraints' Hessian maps (first build only), the Jacobian's triplets over the kept rows and
 * free coordinates with each stencil entry's place (jmap, -1 where none), and the rows' scales. */
static plume_status jacobian_triplets(plume_problem *p, int rebuild)
{
    const int d = p->dim;
    p->jnnz = 0;
    for (int s = 0; s < p->ncsets; s++) {
        cons_slot *c = p->cons + s;
        int k = c->c.arity * d;
        if (!rebuild && scatter_map_build(p, c->c.stencil, c->c.arity, 0, NULL, 0, c->c.m, &c->hmap) != PLUME_OK)
            return PLUME_ENOMEM;
        for (plume_index i = 0; i < c->c.m; i++) {
            for (int a = 0; a < k; a++)
                p->jnnz += c->row[i] >= 0 && p->free_of_dof[c->c.stencil[i * c->c.arity + a / d] * d + a % d] >= 0;
        }
    }
    p->jrow = malloc((size_t)(p->jnnz + 1) * sizeof *p->jrow);
    p->jcol = malloc((size_t)(p->jnnz + 1) * sizeof *p->jcol);
    if (!p->jrow || !p->jcol)
        return PLUME_ENOMEM;
    plume_index j = 0;
    for (int s = 0; s < p->ncsets; s++) {
        cons_slot *c = p->cons + s;
        int k = c->c.arity * d;
        for (plume_index i = 0; i < c->c.m; i++)
            for (int a = 0; a < k; a++) {
                plume_index f = p->free_of_dof[c->c.stencil[i * c->c.arity + a / d] * d + a % d];
                if (c->row[i] >= 0 && f >= 0) {
                    p->jrow[j] = c->row[i];
                    p->jcol[j] = f;
                    c->jmap[i * k + a] = j++;
                } else {
                    c->jmap[i * k + a] = -1;
                }
            }
        for (plume_index i = 0; i < c->c.m; i++)
            if (c->row[i] >= 0)
                p->scale[c->row[i]] = c->c.scale[i] > 0 ? c->c.scale[i] : 1.0;
    }
    return PLUME_OK;
}

/* The structure a problem is evaluated on: free numbering, constraint rows, the Hessian pattern,
 * the scatter maps and the Jacobian's triplets. What it allocates belongs to p (released by
 * release_structure, also after a failure). */
static plume_status build_structure_with(plume_problem *p, int rebuild, plume_err *err)
{
    const plume_index old_nnz = p->nnz;
    plume_index *old_smerged = rebuild ? p->smerged : NULL;
    release_structure(p, rebuild);
    p->smerged = NULL;
    plume_status st;
    if ((st = number_free_dofs(p, err)) == PLUME_OK && (st = constraint_rows(p, err)) == PLUME_OK &&
        (st = hessian_pattern(p, err)) == PLUME_OK &&
        (!rebuild || (st = move_fixed_maps(p, old_nnz, old_smerged)) == PLUME_OK) &&
        (st = term_maps(p, rebuild)) == PLUME_OK)
        st = jacobian_triplets(p, rebuild);
    free(old_smerged);
    return st;
}

plume_status plume_problem_finalize(plume_problem *p, plume_err *err)
{
    if (!p || p->finalized)
        return PLUME_EINVAL;
    plume_status st = build_structure(p, err);
    if (st != PLUME_OK)
        return st;
    /* round-off gradients of a stress-free state are ~1e-16 k L; measuring residuals against at
     * least 1e-6 k L makes the relative KKT test an absolute one of ~1e-15 k L there */
    double k;
    if ((st = stiffness_scale(p, &k)) != PLUME_OK)
        return plume_err_set(err, st, "problem: a term failed to evaluate at the initial state");
    p->force_floor = 1e-6 * k * p->length_scale;
    p->finalized = 1;
    return PLUME_OK;
}

plume_status plume_problem_lag_terms(plume_problem *p, const double *x)
{
    if (!p || !x)
        return PLUME_EINVAL;
    for (int t = 0; t < p->nterms; t++) {
        plume_term *tt = &p->terms[t].t;
        plume_status st = tt->lag ? tt->lag(tt->ctx, p->dim, x) : PLUME_OK;
        if (st != PLUME_OK)
            return st;
    }
    return PLUME_OK;
}

plume_status plume_problem_rebase_terms(plume_problem *p)
{
    if (!p)
        return PLUME_EINVAL;
    for (int t = 0; t < p->nterms; t++) {
        plume_term *tt = &p->terms[t].t;
        plume_status st = tt->rebase ? tt->rebase(tt->ctx, p->dim, p->x) : PLUME_OK;
        if (st != PLUME_OK)
            return st;
    }
    return PLUME_OK;
}

plume_status plume_problem_commit_terms(plume_problem *p, int may_cut, plume_commit_report *r, plume_err *err)
{
    if (!p || !r)
        return plume_err_set(err, PLUME_EINVAL, "problem: commit_terms: invalid arguments");
    memset(r, 0, sizeof *r);
    if (!p->finalized)
        return plume_err_set(err, PLUME_EINVAL, "problem: commit_terms before finalize");
    for (int t = 0; t < p->nterms; t++) {
        plume_term *tt = &p->terms[t].t;
        if (!tt->commit)
            continue;
        plume_commit_report one = {0};
        plume_status st = tt->commit(tt->ctx, p->dim, p->x, may_cut, &one);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "term '%s': commit failed (%s)", tt->name, plume_strerror(st));
        r->changed |= one.changed != 0;
        r->overshoot |= one.overshoot != 0;
        r->released += one.released;
        r->reengaged += one.reengaged;
        r->energy_drop += one.energy_drop;
    }
    return PLUME_OK;
}

plume_status plume_problem_keep_terms(plume_problem *p, int save, plume_err *err)
{
    if (!p)
        return plume_err_set(err, PLUME_EINVAL, "problem: keep_terms: no problem");
    for (int t = 0; t < p->nterms; t++) {
        plume_term *tt = &p->terms[t].t;
        plume_status st = tt->keep ? tt->keep(tt->ctx, save) : PLUME_OK;
        if (st != PLUME_OK)
            return plume_err_set(err, st, "term '%s': %s its state failed (%s)", tt->name,
                                 save ? "keeping" : "restoring", plume_strerror(st));
    }
    return PLUME_OK;
}

int plume_problem_commits(const plume_problem *p)
{
    for (int t = 0; p && t < p->nterms; t++)
        if (p->terms[t].t.commit)
            return 1;
    return 0;
}

const plume_term *plume_problem_term(const plume_problem *p, const char *name)
{
    for (int t = 0; p && name && t < p->nterms; t++)
        if (p->terms[t].t.name && strcmp(p->terms[t].t.name, name) == 0)
            return &p->terms[t].t;
    return NULL;
}

plume_status plume_problem_term_states(const plume_problem *p, const char *name, int *states, plume_index *n,
                                       plume_err *err)
{
    if (!p || !name || !n)
        return plume_err_set(err, PLUME_EINVAL, "term states: a problem, a term name and a count are required");
    const plume_term *t = plume_problem_term(p, name);
    if (!t || !t->states)
        return plume_err_set(err, PLUME_EINVAL, "term states: the problem has no term \"%s\"%s", name,
                             t ? " with states" : "");
    *n = t->nstencil;
    if (!states)
        return PLUME_OK;
    plume_status st = t->states(t->ctx, states);
    return st == PLUME_OK ? PLUME_OK : plume_err_set(err, st, "term states: \"%s\": %s", name, plume_strerror(st));
}

plume_index plume_problem_state_size(const plume_problem *p)
{
    plume_index n = 0;
    for (int t = 0; p && t < p->nterms; t++) {
        const plume_term *tt = &p->terms[t].t;
        if (tt->commit && !(tt->state_size && tt->state_get && tt->state_set))
            return -1;
        n += tt->state_size ? tt->state_size(tt->ctx) : 0;
    }
    return n;
}

void plume_problem_state_get(const plume_problem *p, double *s)
{
    for (int t = 0; p && t < p->nterms; t++) {
        const plume_term *tt = &p->terms[t].t;
        if (tt->state_size && tt->state_get) {
            tt->state_get(tt->ctx, s);
            s += tt->state_size(tt->ctx);
        }
    }
}

plume_status plume_problem_state_set(plume_problem *p, const double *s, plume_err *err)
{
    for (int t = 0; p && t < p->nterms; t++) {
        const plume_term *tt = &p->terms[t].t;
        if (!(tt->state_size && tt->state_set))
            continue;
        plume_status st = tt->state_set(tt->ctx, s);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "term '%s': its saved state is not one it can have (%s)", tt->name,
                                 plume_strerror(st));
        s += tt->state_size(tt->ctx);
    }
    return PLUME_OK;
}

const char *plume_problem_states_term(const plume_problem *p, int i)
{
    for (int t = 0; p && t < p->nterms; t++)
        if (p->terms[t].t.states && i-- == 0)
            return p->terms[t].t.name;
    return NULL;
}

void *plume_problem_term_ctx(const plume_problem *p, const char *name)
{
    const plume_term *t = plume_problem_term(p, name);
    return t ? t->ctx : NULL;
}

int plume_problem_rebases(const plume_problem *p)
{
    for (int t = 0; p && t < p->nterms; t++)
        if (p->terms[t].t.rebase)
            return 1;
    return 0;
}

plume_status plume_problem_update_terms(plume_problem *p, int *pattern_changed, plume_err *err)
{
    if (!p || !p->finalized || !pattern_changed)
        return PLUME_EINVAL;
    *pattern_changed = 0;
    for (int t = 0; t < p->nterms; t++) {
        plume_term *tt = &p->terms[t].t;
        if (!tt->update)
            continue;
        int changed = 0;
        const plume_index *stencil = tt->stencil;
        plume_index nstencil = tt->nstencil;
        plume_status st = tt->update(tt->ctx, p->dim, p->x, &stencil, &nstencil, &changed);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "term '%s': update failed (%s)", tt->name, plume_strerror(st));
        if (nstencil < 0 || (nstencil > 0 && !stencil))
            return plume_err_set(err, PLUME_EINVAL, "term '%s': update returned no stencils", tt->name);
        tt->stencil = stencil;
        tt->nstencil = nstencil;
        *pattern_changed |= changed != 0;
    }
    if (!*pattern_changed)
        return PLUME_OK;
    p->finalized = 0;
    plume_status st = build_structure(p, err);
    p->finalized = st == PLUME_OK;
    return st;
}

int plume_problem_limits_steps(const plume_problem *p)
{
    for (int t = 0; p && t < p->nterms; t++)
        if (p->terms[t].t.max_step)
            return 1;
    return 0;
}

/* min over the terms' max_step of the motion dx (full) from the current x */
static plume_status terms_max_step(plume_problem *p, const double *dx, double *alpha)
{
    *alpha = 1.0;
    for (int t = 0; t < p->nterms; t++) {
        plume_term *tt = &p->terms[t].t;
        if (!tt->max_step)
            continue;
        double a = 1.0;
        plume_status st = tt->max_step(tt->ctx, p->dim, p->x, dx, &a);
        if (st != PLUME_OK)
            return st;
        if (!(a >= 0.0)) /* NaN: no step is known to be safe */
            a = 0.0;
        *alpha = fmin(*alpha, fmin(a, 1.0));
    }
    return PLUME_OK;
}

plume_status plume_problem_max_step(plume_problem *p, const double *u, const double *du, double *alpha)
{
    if (!p || !p->finalized || !du || !alpha)
        return PLUME_EINVAL;
    *alpha = 1.0;
    plume_problem_scatter(p, u);
    if (!plume_problem_limits_steps(p))
        return PLUME_OK;
    memset(p->dxfull, 0, (size_t)p->ndof * sizeof *p->dxfull);
    for (plume_index i = 0; i < p->nfree; i++)
        p->dxfull[p->dof_of_free[i]] = du[i];
    return terms_max_step(p, p->dxfull, alpha);
}

plume_status plume_problem_max_motion(plume_problem *p, const double *dx, double *alpha)
{
    if (!p || !p->finalized || !dx || !alpha)
        return PLUME_EINVAL;
    for (plume_index i = 0; i < p->ndof; i++)
        if (!isfinite(dx[i]))
            return PLUME_EINVAL;
    return terms_max_step(p, dx, alpha);
}

int plume_problem_dim(const plume_problem *p) { return p->dim; }
plume_index plume_problem_nvert(const plume_problem *p) { return p->nv; }
plume_index plume_problem_ndof(const plume_problem *p) { return p ? p->ndof : 0; }
plume_index plume_problem_nfree(const plume_problem *p) { return p->nfree; }
plume_index plume_problem_ncons(const plume_problem *p) { return p->ncons; }
double plume_problem_length_scale(const plume_problem *p) { return p->length_scale; }
int plume_problem_is_fixed(const plume_problem *p, plume_index dof) { return p->fixed[dof]; }
double plume_problem_force_scale(const plume_problem *p) { return fmax(p->force_scale, p->force_floor); }
double *plume_problem_x(plume_problem *p) { return p->x; }

void plume_problem_gather(const plume_problem *p, double *u)
{
    for (plume_index i = 0; i < p->nfree; i++)
        u[i] = p->x[p->dof_of_free[i]];
}

void plume_problem_scatter(plume_problem *p, const double *u)
{
    if (!u)
        return;
    for (plume_index i = 0; i < p->nfree; i++)
        p->x[p->dof_of_free[i]] = u[i];
}

/* grad f over all dofs into p->gradfull; *f total energy */
static plume_status full_gradient(plume_problem *p, double *f)
{
    const double t0 = now();
    memset(p->gradfull, 0, (size_t)p->ndof * sizeof *p->gradfull);
    *f = 0.0;
    p->timing.objective_calls++;
    for (int t = 0; t < p->nterms; t++) {
        plume_status st = p->terms[t].t.eval(p->terms[t].t.ctx, p->dim, p->x, f, p->gradfull, NULL, 0);
        if (st != PLUME_OK) {
            p->timing.objective_seconds += now() - t0;
            return st;
        }
    }
    double s = 0.0;
    for (plume_index i = 0; i < p->ndof; i++)
        s = fmax(s, fabs(p->gradfull[i]));
    p->force_scale = s;
    p->timing.objective_seconds += now() - t0;
    return PLUME_OK;
}

plume_status plume_problem_objective(plume_problem *p, const double *u, double *f, double *grad)
{
    if (!p || !p->finalized || !f)
        return PLUME_EINVAL;
    plume_problem_scatter(p, u);
    if (!grad) {
        const double t0 = now();
        plume_status st = PLUME_OK;
        *f = 0.0;
        p->timing.objective_calls++;
        for (int t = 0; t < p->nterms && st == PLUME_OK; t++)
            st = p->terms[t].t.eval(p->terms[t].t.ctx, p->dim, p->x, f, NULL, NULL, 0);
        p->timing.objective_seconds += now() - t0;
        return st;
    }
    plume_status st = full_gradient(p, f);
    if (st != PLUME_OK)
        return st;
    for (plume_index i = 0; i < p->nfree; i++)
        grad[i] = p->gradfull[p->dof_of_free[i]];
    return PLUME_OK;
}

plume_sparsity plume_problem_hessian_pattern(const plume_problem *p)
{
    plume_sparsity s = {p->nfree, p->nnz, p->colptr, p->rowind};
    return s;
}

plume_sparsity plume_problem_fixed_pattern(const plume_problem *p)
{
    plume_sparsity s = {p->nfree, p->scol ? p->scol[p->nfree] : 0, p->scol, p->srow};
    return s;
}

/* Scatters the blocks of stencils first .. first + n - 1 (blocks: stencil first's first, k x k). */
static void scatter_blocks(const plume_problem *p, double *values, const scatter_map *m, plume_index first,
                           plume_index n, const double *blocks, int k, double w)
{
    const unsigned *src = m->src;
    const plume_index *dst = m->dst, *cp = p->colptr;
    const int d = p->dim;
    const size_t kk = (size_t)k * (size_t)k;
    for (plume_index s = first; s < first + n; s++) {
        const double *b = blocks + (size_t)(s - first) * kk;
        for (plume_index e = m->start[s], ee = m->start[s + 1]; e < ee; e++)
            values[dst[e]] += w * b[src[e]];
        for (plume_index q = m->bstart[s], qe = m->bstart[s + 1]; q < qe; q++) {
            const unsigned ab = m->bab[q], a = ab & 0xffff, c = ab >> 16;
            const plume_index f = m->bcol[q], p0 = m->bpos[q];
            const double *blk = b + (size_t)(d * a) * k + d * c;
            if (a == c) {
                for (int j = 0; j < d; j++) {
                    double *top = values + cp[f + j + 1] - 1 - j;
                    for (int i = 0; i <= j; i++)
                        top[i] += w * blk[i * k + j];
                }
            } else {
                for (int j = 0; j < d; j++) {
                    double *col = values + p0 + (cp[f + j] - cp[f]);
                    for (int i = 0; i < d; i++)
                        col[i] += w * blk[i * k + j];
                }
            }
        }
    }
}

int plume_problem_has_partial_projection(const plume_problem *p)
{
    if (!p)
        return 0;
    for (int t = 0; t < p->nterms; t++)
        if (p->terms[t].t.partial_projection)
            return 1;
    for (int s = 0; s < p->ncsets; s++)
        if (p->cons[s].c.partial_projection)
            return 1;
    return 0;
}

plume_status plume_problem_hessian(plume_problem *p, const double *u, double obj_factor,
                                   const double *lambda, int project, double *values)
{
    if (!p || !p->finalized || !values)
        return PLUME_EINVAL;
    plume_problem_scatter(p, u);
    p->timing.hessian_calls++;
    double t0 = now(), t1;
    memset(values, 0, (size_t)p->nnz * sizeof *values);
    int d = p->dim;
    for (int t = 0; t < p->nterms; t++) {
        term_slot *ts = p->terms + t;
        int pj = project == PLUME_HESSIAN_PARTIAL ? ts->t.partial_projection : project != 0;
        const int k = ts->t.arity * d + ts->t.nextra;
        const size_t kk = (size_t)k * (size_t)k;
        const plume_index chunk = term_chunk(&ts->t, kk);
        plume_index first = 0;
        do { /* once with no stencils, as eval always was */
            const plume_index n = ts->t.nstencil - first < chunk ? ts->t.nstencil - first : chunk;
            plume_status st = ts->t.hess_range ? ts->t.hess_range(ts->t.ctx, d, p->x, first, n, ts->blocks, pj)
                                               : ts->t.eval(ts->t.ctx, d, p->x, NULL, NULL, ts->blocks, pj);
            t1 = now();
            p->timing.hessian_eval_seconds += t1 - t0;
            if (st != PLUME_OK)
                return st;
            scatter_blocks(p, values, &ts->hmap, first, n, ts->blocks, k, obj_factor);
            t0 = now();
            p->timing.hessian_scatter_seconds += t0 - t1;
            first += n;
        } while (first < ts->t.nstencil);
    }
    if (!lambda)
        return PLUME_OK;
    for (int s = 0; s < p->ncsets; s++) {
        cons_slot *c = p->cons + s;
        for (plume_index i = 0; i < c->c.m; i++)
            c->lam[i] = c->row[i] >= 0 ? lambda[c->row[i]] : 0.0;
        int pj = project == PLUME_HESSIAN_PARTIAL ? c->c.partial_projection : project != 0;
        plume_status st = c->c.hess(c->c.ctx, d, p->x, c->lam, c->blocks, pj);
        t1 = now();
        p->timing.hessian_eval_seconds += t1 - t0;
        if (st != PLUME_OK)
            return st;
        scatter_blocks(p, values, &c->hmap, 0, c->c.m, c->blocks, c->c.arity * d, 1.0);
        t0 = now();
        p->timing.hessian_scatter_seconds += t0 - t1;
    }
    return PLUME_OK;
}

plume_status plume_problem_constraints(plume_problem *p, const double *u, double *g, double *max_rel)
{
    if (!p || !p->finalized)
        return PLUME_EINVAL;
    plume_problem_scatter(p, u);
    double mx = 0.0;
    const double t0 = now();
    p->timing.constraint_calls++;
    for (int s = 0; s < p->ncsets; s++) {
        cons_slot *c = p->cons + s;
        plume_status st = c->c.eval(c->c.ctx, p->dim, p->x, c->g, NULL);
        if (st != PLUME_OK) {
            p->timing.constraint_seconds += now() - t0;
            return st;
        }
        for (plume_index i = 0; i < c->c.m; i++) {
            if (c->row[i] < 0)
                continue;
            if (g)
                g[c->row[i]] = c->g[i];
            double r = fabs(c->g[i]) / p->scale[c->row[i]];
            if (!(r <= mx))
                mx = r; /* NaN propagates */
        }
    }
    if (max_rel)
        *max_rel = mx;
    p->timing.constraint_seconds += now() - t0;
    return PLUME_OK;
}

void plume_problem_jacobian_pattern(const plume_problem *p, plume_index *nnz,
                                    const plume_index **rows, const plume_index **cols)
{
    *nnz = p->jnnz;
    *rows = p->jrow;
    *cols = p->jcol;
}

plume_status plume_problem_jacobian(plume_problem *p, const double *u, double *values)
{
    if (!p || !p->finalized || (!values && p->jnnz))
        return PLUME_EINVAL;
    plume_problem_scatter(p, u);
    const double t0 = now();
    p->timing.constraint_calls++;
    plume_status st = PLUME_OK;
    for (int s = 0; s < p->ncsets && st == PLUME_OK; s++) {
        cons_slot *c = p->cons + s;
        st = c->c.eval(c->c.ctx, p->dim, p->x, c->g, c->jac);
        if (st != PLUME_OK)
            break;
        plume_index n = c->c.m * c->c.arity * p->dim;
        for (plume_index i = 0; i < n; i++)
            if (c->jmap[i] >= 0)
                values[c->jmap[i]] = c->jac[i];
    }
    p->timing.constraint_seconds += now() - t0;
    return st;
}

/* force[dof] += sum_c lambda_c dg_c/dx_dof over all dofs (prescribed included) */
static plume_status add_jt_lambda(plume_problem *p, const double *lambda, double *force)
{
    int d = p->dim;
    for (int s = 0; s < p->ncsets; s++) {
        cons_slot *c = p->cons + s;
        int k = c->c.arity * d;
        plume_status st = c->c.eval(c->c.ctx, d, p->x, c->g, c->jac);
        if (st != PLUME_OK)
            return st;
        for (plume_index i = 0; i < c->c.m; i++) {
            if (c->row[i] < 0)
                continue;
            double l = lambda[c->row[i]];
            for (int a = 0; a < k; a++)
                force[c->c.stencil[i * c->c.arity + a / d] * d + a % d] += l * c->jac[i * k + a];
        }
    }
    return PLUME_OK;
}

plume_status plume_problem_energy_forces(plume_problem *p, const double *lambda, double *energy, double *force)
{
    if (!p || !p->finalized || !force)
        return PLUME_EINVAL;
    double f;
    plume_status st = full_gradient(p, &f);
    if (st != PLUME_OK)
        return st;
    if (energy)
        *energy = f;
    memcpy(force, p->gradfull, (size_t)p->ndof * sizeof *force);
    return lambda ? add_jt_lambda(p, lambda, force) : PLUME_OK;
}

plume_status plume_problem_forces(plume_problem *p, const double *lambda, double *force)
{
    return plume_problem_energy_forces(p, lambda, NULL, force);
}

plume_status plume_problem_kkt_residual(plume_problem *p, const double *u, const double *lambda,
                                        double *rel_residual)
{
    if (!p || !p->finalized || !rel_residual)
        return PLUME_EINVAL;
    plume_problem_scatter(p, u);
    double f;
    plume_status st = full_gradient(p, &f);
    if (st != PLUME_OK)
        return st;
    double gmax = 0.0, jmax = 0.0, rmax = 0.0;
    for (plume_index i = 0; i < p->nfree; i++)
        gmax = fmax(gmax, fabs(p->gradfull[p->dof_of_free[i]]));
    if (lambda && p->ncons) {
        /* r = grad f + J^T lambda; J^T lambda alone = r - grad f */
        double *jt = p->jtwork;
        memset(jt, 0, (size_t)p->ndof * sizeof *jt);
        st = add_jt_lambda(p, lambda, jt);
        for (plume_index i = 0; i < p->nfree && st == PLUME_OK; i++) {
            plume_index dof = p->dof_of_free[i];
            jmax = fmax(jmax, fabs(jt[dof]));
            rmax = fmax(rmax, fabs(jt[dof] + p->gradfull[dof]));
        }
        if (st != PLUME_OK)
            return st;
    } else {
        rmax = gmax;
    }
    double ref = fmax(plume_problem_force_scale(p), fmax(gmax, jmax));
    *rel_residual = ref > 0.0 ? rmax / ref : 0.0;
    if (!isfinite(gmax) || !isfinite(rmax))
        *rel_residual = NAN;
    return PLUME_OK;
}
