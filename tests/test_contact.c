/* The contact term in the solvers and the stepper: finite differences of the term, and a plate
 * dropped onto a fixed ground with the barrier (never an intersecting pair, checked by CGAL's
 * exact predicates in every frame) against the paper's penalty (which may pass through). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "term_fd.h"
#include "plume_tree.h"
#include "../lib/contact/contact.h"
#include "../lib/contact/contact_broad.h"
#include "../lib/sim/dynamics.h"

/* Bodies in one mesh: a fixed ground square 1 m x 1 m (body 0, material 0) at z = 0, then n
 * square plates (bodies 1..n, material 1) of the given sides, element edges and heights, centred
 * above it. */
typedef struct {
    plume_mesh *mesh;
    int *body;
    plume_index nground;
} two_bodies;

static int bodies_build(two_bodies *b, int n, const double *side, const double *z, const double *edge)
{
    memset(b, 0, sizeof *b);
    plume_mesh *part[4] = {NULL, NULL, NULL, NULL};
    plume_err err = {{0}};
    plume_index nv = 0, nt = 0;
    int ok = n >= 1 && n <= 3;
    for (int k = 0; ok && k <= n; k++) {
        double sk = k ? side[k - 1] : 1.0, ek = k ? edge[k - 1] : 0.25;
        ok = plume_patch_mesh(sk, sk, 0.0, ek, PLUME_PATCH_UNALIGNED, 3, &part[k], &err) == PLUME_OK;
        if (ok)
            nv += part[k]->nv, nt += part[k]->nt;
    }
    if (ok)
        ok = plume_mesh_create(nv, nt, 3, &b->mesh, &err) == PLUME_OK;
    plume_mesh *m = b->mesh;
    if (ok) {
        b->nground = part[0]->nv;
        b->body = malloc((size_t)nv * sizeof *b->body);
        plume_index v0 = 0, t0 = 0;
        for (int k = 0; k <= n; k++) {
            const plume_mesh *q = part[k];
            double shift = k ? 0.5 - 0.5 * side[k - 1] : 0.0, zk = k ? z[k - 1] : 0.0;
            for (plume_index w = 0; w < q->nv; w++) {
                plume_index v = v0 + w;
                m->X[2 * v] = q->X[2 * w] + shift;
                m->X[2 * v + 1] = q->X[2 * w + 1] + shift;
                m->x[3 * v] = m->X[2 * v], m->x[3 * v + 1] = m->X[2 * v + 1], m->x[3 * v + 2] = zk;
                b->body[v] = k;
            }
            for (plume_index u = 0; u < q->nt; u++) {
                for (int c = 0; c < 3; c++)
                    m->tri[3 * (t0 + u) + c] = q->tri[3 * u + c] + v0;
                m->material[t0 + u] = k > 0;
            }
            v0 += q->nv, t0 += q->nt;
        }
    }
    for (int k = 0; k < 4; k++)
        plume_mesh_destroy(&part[k]);
    return ok;
}

/* the ground and one plate of side `side` at height z0 */
static int two_bodies_build(two_bodies *b, double side, double z0, double edge)
{
    return bodies_build(b, 1, &side, &z0, &edge);
}

static void two_bodies_free(two_bodies *b)
{
    plume_mesh_destroy(&b->mesh);
    free(b->body);
}

/* the term's energy, gradient and exact Hessian against central differences, on a plate a
 * fraction of dhat above the ground, tilted so that point-triangle and edge-edge pairs of every
 * kind are active */
void test_contact_term_fd(void)
{
    for (int model = 0; model < 2; model++) {
        two_bodies b;
        CHECK(two_bodies_build(&b, 0.3, 0.0, 0.15));
        if (!b.mesh)
            return;
        plume_mesh *m = b.mesh;
        /* turned 0.3 rad in its plane and shifted (no vertex over a ground vertex or edge, where a
         * pair's closest feature switches and its energy is not twice differentiable), tilted and
         * lifted to heights 0.2..0.9 dhat */
        for (plume_index v = b.nground; v < m->nv; v++) {
            double px = m->X[2 * v] - 0.5, py = m->X[2 * v + 1] - 0.5;
            m->x[3 * v] = 0.5123 + cos(0.3) * px - sin(0.3) * py;
            m->x[3 * v + 1] = 0.4871 + sin(0.3) * px + cos(0.3) * py;
            m->x[3 * v + 2] = 1e-3 * (0.2 + 0.7 * (m->X[2 * v] - 0.35) / 0.3) + 1e-4 * (m->X[2 * v + 1] - 0.35);
        }
        plume_contact_term_opts o;
        plume_contact_term_opts_default(&o);
        o.pair.model = model ? PLUME_CONTACT_PENALTY : PLUME_CONTACT_BARRIER;
        o.pair.dhat = 1e-3;
        o.pair.stiffness = model ? 1e4 : 1.0;
        o.pair.project_psd = 0;
        plume_term t;
        plume_contact *h = NULL;
        plume_err err = {{0}};
        CHECK(plume_contact_term_create(m->nv, m->nt, m->tri, b.body, m->x, &o, &t, &h, &err) == PLUME_OK);
        int changed = 0;
        const plume_index *st = NULL;
        plume_index ns = 0;
        CHECK(t.update(t.ctx, 3, m->x, &st, &ns, &changed) == PLUME_OK && changed == 1 && ns > 0);
        t.stencil = st, t.nstencil = ns;
        double E = 0.0;
        CHECK(t.eval(t.ctx, 3, m->x, &E, NULL, NULL, 0) == PLUME_OK && E > 0.0);
        fprintf(stderr, "    %s: %ld candidate pairs, energy %.6g\n", model ? "penalty" : "barrier", (long)ns, E);
        term_fd_check(&t, m->nv, m->x, 1e-8, 1e-5, model ? "contact penalty" : "contact barrier");
        t.destroy(t.ctx);
        two_bodies_free(&b);
    }
}

typedef struct {
    int frames_checked, intersecting_frames;
    plume_index max_intersecting;
    double min_gap;       /* smallest plate height over the ground seen (m) */
    double final_height;  /* mean height of the last plate at the end */
    double min_distance;  /* smallest distance between non-adjacent primitives of different bodies */
    int converged;
    long step_limited;
    double energy_error;  /* the energy balance's error over the run (lib/sim/dynamics_energy.h) */
} drop_result;

/* n plates (membrane only; sides, heights and edges as bodies_build) released over the fixed
 * ground, the last one with downward speed v0, the others at rest */
static void drop_plates(plume_contact_model model, double stiffness, double dhat, int n, const double *side,
                        const double *z, const double *edge, double v0, int frames, double dt, drop_result *r)
{
    memset(r, 0, sizeof *r);
    r->min_gap = r->min_distance = INFINITY;
    two_bodies b;
    CHECK(bodies_build(&b, n, side, z, edge));
    if (!b.mesh)
        return;
    plume_mesh *m = b.mesh;
    plume_problem *p = NULL;
    plume_err err = {{0}};
    CHECK(plume_problem_create(m->nv, 3, 1.0, &p, &err) == PLUME_OK);
    plume_membrane_material mats[2] = {{{1e6, 1e6, 0.3, 1e6 / 2.6}, 1e-3, 0.0, 0},
                                       {{1e6, 1e6, 0.3, 1e6 / 2.6}, 1e-3, 0.0, 0}};
    plume_term mt;
    CHECK(plume_membrane_term_create(m, 3, mats, 2, &mt, &err) == PLUME_OK && plume_problem_add_term(p, &mt, &err) == PLUME_OK);
    plume_contact_term_opts o;
    plume_contact_term_opts_default(&o);
    o.pair.model = model;
    o.pair.dhat = dhat;
    o.pair.stiffness = stiffness;
    plume_term ct;
    plume_contact *h = NULL;
    CHECK(plume_contact_term_create(m->nv, m->nt, m->tri, b.body, m->x, &o, &ct, &h, &err) == PLUME_OK &&
          plume_problem_add_term(p, &ct, &err) == PLUME_OK);
    memcpy(plume_problem_x(p), m->x, (size_t)(3 * m->nv) * sizeof(double));
    plume_index *ground = malloc((size_t)b.nground * sizeof *ground);
    for (plume_index v = 0; v < b.nground; v++)
        ground[v] = v;
    const double times[1] = {0.0}, offsets[3] = {0.0, 0.0, 0.0};
    plume_handle hd = {.nvertices = b.nground, .vertices = ground, .nkeys = 1, .times = times, .offsets = offsets};
    plume_dynamics_opts dop;
    plume_dynamics_opts_default(&dop);
    dop.dt = dt;
    const double rho[2] = {1.0, 1.0};
    plume_dynamics *d = NULL;
    CHECK(plume_dynamics_create(m, p, rho, 2, &hd, 1, &dop, &d, &err) == PLUME_OK);
    if (!d) {
        fprintf(stderr, "    %s\n", err.msg);
        goto done;
    }
    double *v = calloc((size_t)(3 * m->nv), sizeof *v);
    for (plume_index i = b.nground; i < m->nv; i++)
        v[3 * i + 2] = b.body[i] == n ? -v0 : 0.0;
    CHECK(plume_dynamics_set_state(d, 0.0, m->x, v, NULL, NULL) == PLUME_OK);
    free(v);
    plume_contact_pairs pairs = {0, 0, NULL};
    plume_contact_broad *measure = NULL;
    plume_contact_broad_opts bo;
    plume_contact_broad_opts_default(&bo);
    bo.self_contact = 0;
    CHECK(plume_contact_broad_create(m->nv, m->nt, m->tri, b.body, &bo, &measure, &err) == PLUME_OK);
    r->converged = 1;
    for (int f = 0; f < frames; f++) {
        plume_step_report rep;
        CHECK(plume_dynamics_advance(d, 0.0, &rep, NULL) == PLUME_OK);
        r->converged &= rep.converged;
        if (!rep.converged)
            fprintf(stderr, "    frame %d: not converged (%s), %d halvings, %d iterations\n", f,
                    plume_reason_name(rep.reason), rep.halvings, rep.iterations);
        r->step_limited += rep.step_limited;
        if (!rep.converged)
            break;
        const double *x = plume_dynamics_positions(d);
        plume_contact_audit audit;
        CHECK(plume_contact_count_intersections(m->nv, x, m->nt, m->tri, &pairs, &audit, &err) == PLUME_OK);
        r->frames_checked++;
        r->intersecting_frames += audit.intersecting > 0;
        if (audit.intersecting > r->max_intersecting)
            r->max_intersecting = audit.intersecting;
        double zmean = 0.0, dmin = INFINITY;
        plume_index nlast = 0;
        for (plume_index i = b.nground; i < m->nv; i++) {
            r->min_gap = fmin(r->min_gap, x[3 * i + 2]);
            if (b.body[i] == n)
                zmean += x[3 * i + 2], nlast++;
        }
        r->final_height = zmean / (double)nlast;
        CHECK(plume_contact_min_distance(measure, x, 10.0 * dhat, &dmin, &err) == PLUME_OK);
        r->min_distance = fmin(r->min_distance, dmin);
    }
    r->energy_error = plume_ledger_error(plume_dynamics_energy(d));
    plume_contact_broad_destroy(&measure);
    plume_contact_pairs_free(&pairs);
done:
    free(ground);
    plume_dynamics_destroy(&d);
    plume_problem_destroy(&p);
    two_bodies_free(&b);
}

/* A 0.5 m plate released at z0 with downward speed v0 over the fixed ground */
static void drop(plume_contact_model model, double stiffness, double dhat, double z0, double v0, int frames, double dt,
                 drop_result *r)
{
    const double side = 0.5, edge = 0.125;
    drop_plates(model, stiffness, dhat, 1, &side, &z0, &edge, v0, frames, dt, r);
}

void test_contact_drop_barrier_never_intersects(void)
{
    /* released 2 cm up, falling at 2 m/s: it reaches the ground in the first steps */
    drop_result r;
    drop(PLUME_CONTACT_BARRIER, 1e3, 1e-3, 0.02, 2.0, 30, 2.8e-3, &r);
    fprintf(stderr, "    barrier: %d frames, intersecting in %d, lowest vertex %.3g m, final mean height %.3g m, "
                    "%ld limited steps, energy balance error %.2e\n",
            r.frames_checked, r.intersecting_frames, r.min_gap, r.final_height, r.step_limited, r.energy_error);
    CHECK(r.converged && r.frames_checked == 30);
    CHECK(r.intersecting_frames == 0);
    /* it came within reach of the barrier, never touched, and was sent back up (implicit Euler
     * with a conservative barrier: a damped bounce) */
    CHECK(r.min_gap > 0.0 && r.min_gap < 2e-3 && r.final_height > r.min_gap);
    /* the bounce's energy: Simpson's rule halved where the barrier enters a step (one piece a step
     * left 5e-2) */
    CHECK(fabs(r.energy_error) < 1e-4);
}

void test_contact_drop_penalty_passes_through(void)
{
    /* the paper's repulsion (Table 3 (b): thickness 1e-3 m, stiffness 1e11 J/m^2 over the plate's
     * ~4 kg/m^2 ... here 1 kg/m^2) on a fast fall: a step of 2.8 ms at 20 m/s moves 5.6 cm, far
     * more than the repulsion thickness, and nothing stops a vertex on the far side */
    drop_result r;
    drop(PLUME_CONTACT_PENALTY, 1e11, 1e-3, 0.02, 20.0, 5, 2.8e-3, &r);
    fprintf(stderr, "    penalty: %d frames, intersecting in %d (max %ld pairs), lowest vertex %.3g m\n",
            r.frames_checked, r.intersecting_frames, (long)r.max_intersecting, r.min_gap);
    CHECK(r.frames_checked > 0);
    CHECK(r.min_gap < 0.0); /* passed through the ground: what the barrier's CCD prevents */
    drop_result s;
    drop(PLUME_CONTACT_BARRIER, 1e3, 1e-3, 0.02, 20.0, 5, 2.8e-3, &s);
    fprintf(stderr, "    barrier, same fall: %d frames, intersecting in %d, lowest vertex %.3g m\n", s.frames_checked,
            s.intersecting_frames, s.min_gap);
    CHECK(s.converged && s.intersecting_frames == 0 && s.min_gap > 0.0);
}

/* bad input to the term: each error names what is wrong, and nothing is handed out */
static int create_fails(const plume_contact_term_opts *o, const int *body, const plume_index *tri, const char *needle)
{
    const double x[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const plume_index t[3] = {0, 1, 2};
    plume_term term;
    plume_contact *h = (plume_contact *)&term; /* any non-NULL value: create must reset it */
    plume_err err = {{0}};
    plume_status st = plume_contact_term_create(3, 1, tri ? tri : t, body, x, o, &term, &h, &err);
    int ok = st == PLUME_EINVAL && strstr(err.msg, needle) != NULL && h == NULL && term.ctx == NULL;
    if (!ok)
        fprintf(stderr, "    expected '%s', got %d: %s\n", needle, (int)st, err.msg);
    return ok;
}

void test_contact_term_bad_inputs(void)
{
    const int body[3] = {0, 0, 0};
    plume_contact_term_opts o;
    plume_contact_term_opts_default(&o);
    o.pair.dhat = 0.0;
    CHECK(create_fails(&o, body, NULL, "dhat > 0"));
    plume_contact_term_opts_default(&o);
    o.pair.stiffness = NAN;
    CHECK(create_fails(&o, body, NULL, "stiffness"));
    plume_contact_term_opts_default(&o);
    o.margin = -1.0;
    CHECK(create_fails(&o, body, NULL, "margin"));
    plume_contact_term_opts_default(&o);
    o.pair.model = (plume_contact_model)7;
    CHECK(create_fails(&o, body, NULL, "model barrier or penalty"));
    plume_contact_term_opts_default(&o);
    CHECK(create_fails(&o, NULL, NULL, "body ids"));
    const plume_index out_of_range[3] = {0, 1, 5};
    CHECK(create_fails(&o, body, out_of_range, "triangle 0: vertex id 5 out of range"));
    plume_term term;
    CHECK(plume_contact_term_create(3, 1, NULL, body, NULL, &o, &term, NULL, NULL) == PLUME_EINVAL);
    CHECK(strcmp(plume_contact_model_name(PLUME_CONTACT_BARRIER), "barrier") == 0 &&
          strcmp(plume_contact_model_name(PLUME_CONTACT_PENALTY), "penalty") == 0 &&
          strcmp(plume_contact_model_name((plume_contact_model)7), "unknown") == 0);
}

/* Two plates dropped onto each other: a 0.5 m plate released 2 mm over the ground, a 0.3 m one
 * 2 cm over it, falling at 2 m/s. Never an intersecting pair between any two of the three bodies,
 * and at the end the top plate rests on the lower one (within a few dhat of the ground). */
void test_contact_two_plates(void)
{
    const double side[2] = {0.5, 0.3}, z[2] = {0.002, 0.022}, edge[2] = {0.125, 0.1};
    drop_result r;
    drop_plates(PLUME_CONTACT_BARRIER, 1e3, 1e-3, 2, side, z, edge, 2.0, 40, 2.8e-3, &r);
    fprintf(stderr, "    two plates: %d frames, intersecting in %d, smallest distance %.3g m, lowest vertex %.3g m, "
                    "top plate's final mean height %.3g m, %ld limited steps\n",
            r.frames_checked, r.intersecting_frames, r.min_distance, r.min_gap, r.final_height, r.step_limited);
    CHECK(r.converged && r.frames_checked == 40);
    CHECK(r.intersecting_frames == 0);
    CHECK(r.min_distance > 0.0 && r.min_distance < 1e-3); /* they touched (within dhat), never crossed */
    CHECK(r.min_gap > 0.0);
    CHECK(r.final_height > 0.0 && r.final_height < 3e-3); /* on the lower plate, which is on the ground */
}

/* Self contact leaves out the pairs of one body already within reach at rest (a flat strip whose
 * triangles are narrower than dhat: every such pair would be pushed apart from the first step),
 * and still sees the pairs that come within reach later (the strip folded over itself). */
void test_contact_self_rest_pairs(void)
{
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 0.1, 0.0, 0.05, PLUME_PATCH_UNALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m)
        return;
    plume_contact_term_opts o;
    plume_contact_term_opts_default(&o);
    o.self_contact = 1;
    o.pair.dhat = 0.06; /* more than the triangles' heights */
    for (int pass = 0; pass < 2; pass++) {
        plume_term t;
        plume_contact *h = NULL;
        CHECK(plume_contact_term_create(m->nv, m->nt, m->tri, NULL, m->x, &o, &t, &h, &err) == PLUME_OK);
        if (!h)
            break;
        plume_contact_stats cs;
        plume_contact_term_stats(h, &cs);
        CHECK(cs.excluded > 0);
        double *x = malloc((size_t)(3 * m->nv) * sizeof *x);
        memcpy(x, m->x, (size_t)(3 * m->nv) * sizeof *x);
        if (pass == 1) /* fold the far half back over the near half, 1 cm above it */
            for (plume_index v = 0; v < m->nv; v++)
                if (x[3 * v] > 0.55)
                    x[3 * v] = 1.1 - x[3 * v], x[3 * v + 2] = 0.01;
        const plume_index *st = NULL;
        plume_index ns = 0;
        int changed = 0;
        double e = 0.0;
        CHECK(t.update(t.ctx, 3, x, &st, &ns, &changed) == PLUME_OK);
        CHECK(t.eval(t.ctx, 3, x, &e, NULL, NULL, 0) == PLUME_OK);
        if (pass == 0)
            CHECK(ns == 0 && e == 0.0); /* at rest: nothing pushes */
        else
            CHECK(ns > 0 && e > 0.0); /* folded: the halves repel */
        fprintf(stderr, "    %s: %ld rest pairs left out, %ld pairs in reach, energy %.3g\n", pass ? "folded" : "at rest",
                (long)cs.excluded, (long)ns, e);
        free(x);
        t.destroy(t.ctx);
    }
    plume_mesh_destroy(&m);
}

/* plume_contact_min_distance searches within cap / 5 first and widens to cap when nothing is that
 * close: two parallel triangles of two bodies at gaps below cap / 5, between cap / 5 and cap, and
 * beyond cap give the gap itself (to round-off), or cap. */
void test_contact_min_distance_stages(void)
{
    const plume_index tri[6] = {0, 1, 2, 3, 4, 5};
    const int body[6] = {0, 0, 0, 1, 1, 1};
    const double cap = 1e-2, gaps[5] = {5e-4, 1.9e-3, 2.1e-3, 7e-3, 1.5e-2};
    plume_contact_broad *b = NULL;
    plume_contact_broad_opts bo;
    plume_contact_broad_opts_default(&bo);
    plume_err err = {{0}};
    CHECK(plume_contact_broad_create(6, 2, tri, body, &bo, &b, &err) == PLUME_OK);
    for (int k = 0; b && k < 5; k++) {
        /* the upper triangle smaller, inside the lower one's shadow: the gap is a point-triangle distance */
        const double x[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.1, 0.1, gaps[k], 0.3, 0.1, gaps[k], 0.1, 0.3, gaps[k]};
        double d = -1.0;
        CHECK(plume_contact_min_distance(b, x, cap, &d, &err) == PLUME_OK);
        const double expect = fmin(gaps[k], cap);
        fprintf(stderr, "    gap %.4g m: min distance %.6g m (cap %g)\n", gaps[k], d, cap);
        CHECK(fabs(d - expect) <= 1e-12);
    }
    plume_contact_broad_destroy(&b);
}
