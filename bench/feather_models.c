/* bench_feather --models: the shipped anisotropic feather at its three meshes (865, 11.4k and
 * 44.7k elements), bent by the shape operator, midedge and the hinge in one run, so that the
 * ratios compare like with like. Per mesh and model: the unknowns, the Hessian entries, CHOLMOD's
 * factor entries and flops, one factorisation's CPU time, the first step's wall time per Newton
 * iteration; and two accuracy figures, both of the vane's sag at mid-length out of the rachis'
 * plane: during the pull (the scene's first steps, the tip pulled sideways and up; with the tip
 * handle's reaction), and under gravity alone with both handles held at rest, settled.
 *
 * The pull's figure is read after the scene's first steps, not at the static equilibrium at the
 * pulled handles, so that the three models are compared on the scene as it runs (and the part
 * stays within minutes at 44.7k elements). */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../tests/plume_tree.h"
#include "feather_models.h"

#define NMODELS 3
#define VANE 0   /* the scene's material ids (data/feather/scene_anisotropic.json) */
#define RACHIS 1
#define TIP 1    /* its handles: 0 the base, 1 the tip */
/* the settling run under gravity: with steps of 1 s the inertia term (m / dt^2, about 1e-7 N/m a
 * vertex) is negligible against the vane's stiffness, so each step is the static equilibrium */
#define REST_DT 1.0
#define REST_STEPS 2

static const int models[NMODELS] = {PLUME_BENDING_SHAPE_OPERATOR, PLUME_BENDING_MIDEDGE, PLUME_BENDING_HINGE};

/* One line of the table. */
typedef struct {
    long elements, ndof, nfree, hessian;
    double lnz, flops;          /* CHOLMOD's counts */
    double factorise;           /* CPU s, best of 3 */
    double per_iteration;       /* wall s per Newton iteration of the first step */
    int iterations;             /* of the first step */
    int pull_iterations;        /* over the pull's steps */
    double pull_seconds;        /* wall */
    double pull_sag;            /* m, at the pull's last step */
    double reaction[3];         /* N: what the tip handle exerts on the feather then */
    double rest_sag, rest_uz;   /* m: under gravity, handles at rest: the sag, the edge point's displacement */
} model_row;

void feather_models_header(int steps)
{
    printf("\nplume bench (feather, bending models): the shipped anisotropic feather at its 3 meshes, every model in one run\n");
    printf("(unknowns: plume_problem_ndof, free: not prescribed; Hessian: its upper triangle's entries over the free "
           "unknowns; factor, flops: CHOLMOD's analysis of that pattern, AMD or METIS; factor: CPU ms of one "
           "factorisation, best of 3; s/iter: wall, first step; then the first %d steps of the pull: Newton "
           "iterations, wall s, the vane's edge point at mid-length out of the rachis' plane (mm), the tip handle's "
           "force on the feather (N); last, gravity alone with the handles at rest, settled: that sag and the point's "
           "vertical displacement (um))\n", steps);
    printf("%8s %-14s | %8s %8s %9s %9s %8s | %8s %7s %3s | %4s %6s %8s %7s %7s | %8s %8s\n", "elements", "bending",
           "unknowns", "free", "Hessian", "factor", "flops", "factor", "s/iter", "it", "it", "s", "sag mm", "F_tip_z",
           "|F_tip|", "sag um", "uz um");
}

/* The CPU seconds of one factorisation (best of 3) of the exact Hessian at the start state, shifted
 * until it succeeds, as measure_iteration in bench_feather.c, and CHOLMOD's factor entries and
 * flops of the ordering plume keeps (plume_chol_counts); NAN when it cannot. */
static double factorise_seconds(plume_problem *p, const plume_sparsity *hp, double *lnz, double *flops)
{
    *lnz = *flops = NAN;
    plume_err err = {{0}};
    plume_chol *chol = NULL;
    const plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p);
    double *u = malloc((size_t)n * sizeof *u), *values = malloc((size_t)hp->nnz * sizeof *values);
    double *lambda = calloc((size_t)m + 1, sizeof *lambda), best = NAN;
    if (!u || !values || !lambda || plume_chol_create(n, hp->colptr, hp->rowind, 0, &chol, &err) != PLUME_OK)
        goto done;
    plume_chol_counts(chol, lnz, flops);
    plume_problem_gather(p, u);
    plume_problem_hessian(p, u, 1.0, lambda, PLUME_HESSIAN_EXACT, values);
    double hmax = 0.0;
    for (plume_index c = 0; c < n; c++)
        hmax = fmax(hmax, fabs(values[hp->colptr[c + 1] - 1]));
    best = INFINITY;
    for (int r = 0; r < 3; r++) {
        double shift = 0.0, t0 = plume_cpu_seconds();
        while (plume_chol_factor(chol, values, shift) == PLUME_ESINGULAR && shift < hmax)
            shift = shift > 0.0 ? 10.0 * shift : 1e-8 * hmax;
        best = fmin(best, plume_cpu_seconds() - t0);
    }
done:
    plume_chol_destroy(&chol);
    free(u);
    free(values);
    free(lambda);
    return best;
}

/* At height y of the material space: the vane's free edge where it crosses y farthest in +x (P),
 * and the middle of the rachis' width (R), each interpolated linearly in the rest positions.
 * *uz = P's vertical displacement; *sag = P's distance from the rachis' tangent plane at R (the
 * plane of R's triangle, normal upward at rest), so that the rachis' own turning is left out.
 * 0 when the line misses either. */
static int sag_at(const plume_mesh *m, const double *x, double y, double *uz, double *sag)
{
    double best = -INFINITY, lo = INFINITY, hi = -INFINITY, xp[3] = {0, 0, 0};
    for (plume_index e = 0; e < m->ne; e++) {
        const plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1], t = m->edge_tri[2 * e];
        const double ya = m->X[2 * a + 1], yb = m->X[2 * b + 1];
        if (m->edge_tri[2 * e + 1] >= 0 || m->material[t] != VANE || (ya - y) * (yb - y) > 0.0 || ya == yb)
            continue;
        const double f = (y - ya) / (yb - ya), xe = (1 - f) * m->X[2 * a] + f * m->X[2 * b];
        if (xe > best) {
            best = xe;
            for (int c = 0; c < 3; c++)
                xp[c] = (1 - f) * x[3 * a + c] + f * x[3 * b + c];
        }
    }
    for (plume_index t = 0; t < m->nt; t++) /* the rachis' width along the line */
        for (int k = 0; k < 3 && m->material[t] == RACHIS; k++) {
            const plume_index a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            const double ya = m->X[2 * a + 1], yb = m->X[2 * b + 1];
            if ((ya - y) * (yb - y) > 0.0 || ya == yb)
                continue;
            const double xe = m->X[2 * a] + (y - ya) / (yb - ya) * (m->X[2 * b] - m->X[2 * a]);
            lo = fmin(lo, xe), hi = fmax(hi, xe);
        }
    const double px = 0.5 * (lo + hi);
    for (plume_index t = 0; t < m->nt && isfinite(best) && lo <= hi; t++) { /* the rachis triangle holding (px, y) */
        const plume_index *v = m->tri + 3 * t;
        const double *A = m->X + 2 * v[0], *B = m->X + 2 * v[1], *C = m->X + 2 * v[2];
        const double det = (B[0] - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (B[1] - A[1]);
        const double l1 = ((px - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (y - A[1])) / det;
        const double l2 = ((B[0] - A[0]) * (y - A[1]) - (px - A[0]) * (B[1] - A[1])) / det;
        if (m->material[t] != RACHIS || l1 < -1e-12 || l2 < -1e-12 || l1 + l2 > 1 + 1e-12)
            continue;
        const double *a = x + 3 * v[0], *b = x + 3 * v[1], *c = x + 3 * v[2];
        double e1[3], e2[3], xr[3];
        for (int k = 0; k < 3; k++)
            e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], xr[k] = (1 - l1 - l2) * a[k] + l1 * b[k] + l2 * c[k];
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        *uz = xp[2];
        *sag = ((xp[0] - xr[0]) * n[0] + (xp[1] - xr[1]) * n[1] + (xp[2] - xr[2]) * n[2]) / nn;
        return 1;
    }
    return 0;
}

/* The scene with this bending model (and, rest != 0, both handles held at their rest places), its
 * problem and stepper; 0 on failure (err says why). */
static int start(const char *scene, int model, int rest, plume_scene **s, plume_problem **p, plume_dynamics **d,
                 plume_err *err)
{
    if (plume_scene_load(scene, s, err) != PLUME_OK)
        return 0;
    (*s)->bending_model = model;
    for (int k = 0; rest && k < (*s)->nhandles; k++)
        (*s)->handles[k].nkeys = 1; /* the first keyframe only (the feather's: no offset) */
    if (rest)
        (*s)->dt = REST_DT;
    return plume_scene_dynamics(*s, p, d, err) == PLUME_OK;
}

/* The tip handle's force on the feather at the problem's state: minus the generalised forces on
 * its prescribed unknowns (plume_problem_forces); 0 on failure. */
static int tip_reaction(const plume_scene *s, plume_problem *p, const plume_dynamics *d, double out[3])
{
    plume_index m = 0;
    const double *lambda = plume_dynamics_multipliers(d, &m);
    double *force = calloc((size_t)plume_problem_ndof(p), sizeof *force);
    if (!force || plume_problem_forces(p, lambda, force) != PLUME_OK) {
        free(force);
        return 0;
    }
    const plume_handle *h = s->handles + TIP;
    out[0] = out[1] = out[2] = 0.0;
    for (plume_index i = 0; i < h->nvertices; i++)
        for (int a = 0; a < 3; a++)
            out[a] -= force[3 * h->vertices[i] + a];
    free(force);
    return 1;
}

static double mid_length(const plume_mesh *m)
{
    double lo = INFINITY, hi = -INFINITY;
    for (plume_index v = 0; v < m->nv; v++)
        lo = fmin(lo, m->X[2 * v + 1]), hi = fmax(hi, m->X[2 * v + 1]);
    return 0.5 * (lo + hi);
}

/* The pull: sizes, counts and a factorisation at the start, then `steps` steps of the scene (the
 * first one timed per iteration), the sag and the tip's reaction at the last; 0 on failure. */
static int pull_part(const char *scene, int model, int steps, model_row *r)
{
    plume_err err = {{0}};
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    int ok = 0, k = 0;
    double uz;
    if (!start(scene, model, 0, &s, &p, &d, &err))
        goto done;
    plume_sparsity hp = plume_problem_hessian_pattern(p);
    r->elements = (long)s->mesh->nt;
    r->ndof = (long)plume_problem_ndof(p);
    r->nfree = (long)plume_problem_nfree(p);
    r->hessian = (long)hp.nnz;
    r->factorise = factorise_seconds(p, &hp, &r->lnz, &r->flops);
    for (; k < steps; k++) {
        plume_step_report rep;
        if (plume_dynamics_advance(d, 0.0, &rep, &err) != PLUME_OK || !rep.converged)
            goto done;
        if (k == 0 && rep.iterations > 0)
            r->iterations = rep.iterations, r->per_iteration = rep.seconds / rep.iterations;
        r->pull_iterations += rep.iterations;
        r->pull_seconds += rep.seconds;
    }
    ok = sag_at(s->mesh, plume_problem_x(p), mid_length(s->mesh), &uz, &r->pull_sag) &&
         tip_reaction(s, p, d, r->reaction);
done:
    if (!ok)
        printf("%s, %s bending: the pull failed at step %d%s%s\n", scene, plume_scene_bending_name(model), k + 1,
               err.msg[0] ? ": " : "", err.msg);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return ok;
}

/* Gravity alone, both handles at rest: REST_STEPS steps of REST_DT, the sag at the last; 0 on failure. */
static int rest_part(const char *scene, int model, model_row *r)
{
    plume_err err = {{0}};
    plume_scene *s = NULL;
    plume_problem *p = NULL;
    plume_dynamics *d = NULL;
    int ok = start(scene, model, 1, &s, &p, &d, &err);
    for (int k = 0; ok && k < REST_STEPS; k++) {
        plume_step_report rep;
        ok = plume_dynamics_advance(d, 0.0, &rep, &err) == PLUME_OK && rep.converged;
    }
    ok = ok && sag_at(s->mesh, plume_problem_x(p), mid_length(s->mesh), &r->rest_uz, &r->rest_sag);

    if (!ok)
        printf("%s, %s bending: settling under gravity failed%s%s\n", scene, plume_scene_bending_name(model),
               err.msg[0] ? ": " : "", err.msg);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    plume_scene_destroy(&s);
    return ok;
}

static void print_row(const model_row *r, int model)
{
    printf("%8ld %-14s | %8ld %8ld %9ld %9.3e %8.2e | %8.1f %7.3f %3d | %4d %6.1f %8.4f %7.3f %7.3f | %8.2f %8.2f\n",
           r->elements, plume_scene_bending_name(model), r->ndof, r->nfree, r->hessian, r->lnz, r->flops,
           1e3 * r->factorise, r->per_iteration, r->iterations, r->pull_iterations, r->pull_seconds, 1e3 * r->pull_sag,
           r->reaction[2],
           sqrt(r->reaction[0] * r->reaction[0] + r->reaction[1] * r->reaction[1] + r->reaction[2] * r->reaction[2]),
           1e6 * r->rest_sag, 1e6 * r->rest_uz);
}

void feather_models(const char *const *scenes, int n, int steps)
{
    feather_models_header(steps);
    for (int i = 0; i < n; i++) {
        model_row rows[NMODELS];
        for (int k = 0; k < NMODELS; k++) {
            model_row *r = rows + k;
            memset(r, 0, sizeof *r);
            r->per_iteration = r->factorise = r->pull_sag = r->rest_sag = r->rest_uz = NAN;
            r->reaction[0] = r->reaction[1] = r->reaction[2] = NAN;
            pull_part(scenes[i], models[k], steps, r);
            rest_part(scenes[i], models[k], r);
            print_row(r, models[k]);
            fflush(stdout);
        }
        const model_row *sh = rows, *me = rows + 1, *hi = rows + 2;
        printf("%8ld over midedge   | shape: Hessian %.2f, factor %.2f, flops %.2f, factorise %.2f, s/iter %.2f, "
               "sag pulled %.2f, at rest %.2f | hinge: Hessian %.2f, factor %.2f, flops %.2f, factorise %.2f, s/iter "
               "%.2f, sag pulled %.2f, at rest %.2f\n",
               me->elements, (double)sh->hessian / me->hessian, sh->lnz / me->lnz, sh->flops / me->flops,
               sh->factorise / me->factorise, sh->per_iteration / me->per_iteration, sh->pull_sag / me->pull_sag,
               sh->rest_sag / me->rest_sag, (double)hi->hessian / me->hessian, hi->lnz / me->lnz, hi->flops / me->flops,
               hi->factorise / me->factorise, hi->per_iteration / me->per_iteration, hi->pull_sag / me->pull_sag,
               hi->rest_sag / me->rest_sag);
    }
}
