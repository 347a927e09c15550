/* plume (micro): the separation law of a barb line from the periodic cell of a layout with hooks
 * (docs/unzipping.md, "The macro law").
 *
 * The cell [0, a] x [0, d_B] has its barb along y = 0 .. w_B and one barbule from the barb's top
 * edge to y = d_B, where it meets the next barb: in the bonded cell its nodes there are periodic
 * images of the barb's bottom edge. Here they are opened: the barbule's triangles take copies of
 * them, free (periodic only along the barbs), and one hook holds each copy to its image. The cell
 * is then opened across the barbs, F = [1 0; 0 1 + e] (no stretch along the stiff barbs), the
 * hooks committed at every equilibrium as the traction loop does, and back again to find where
 * they catch. The traction across the barb line is (P_xy, P_yy), the cell's average membrane
 * stress on the line (N/m, force per barb length): only the hook crosses it, so its magnitude is the
 * hook's force per period, and the strength is that magnitude at the release. The hooked cell's
 * small-strain tensor (plume_separation_tensor) is measured on the same opened cell. */
#include "separation_cell.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/membrane.h"
#include "../lib/solve/options.h"
#include "cell_mesh.h"
#include "../lib/core/hooks.h"
#include "periodic.h"

/* The cell opened at its distal joins: its mesh and quadratic triangles with the copies, the
 * periodic map extended to them, and the hook's pairs. */
typedef struct {
    plume_cell cell;          /* mesh, quad, master, shift owned here */
    plume_index ncopy;        /* copies: vertices nv0 .. nv0 + ncopy - 1 */
    plume_index npairs;
    plume_index *pairs;       /* [2 npairs] (copy, image) */
} opened_cell;

static void opened_cell_free(opened_cell *o)
{
    plume_mesh_destroy(&o->cell.mesh);
    free(o->cell.quad.tri6);
    free(o->cell.quad.material);
    free(o->cell.quad.barb_dir);
    free(o->cell.master);
    free(o->cell.shift);
    free(o->pairs);
    memset(o, 0, sizeof *o);
}

static plume_index copy_of(const plume_index *copy, plume_index v)
{
    return copy[v] >= 0 ? copy[v] : v;
}

static plume_status open_cell(const plume_cell *c, opened_cell *o, plume_err *err)
{
    memset(o, 0, sizeof *o);
    const plume_mesh *m = c->mesh;
    const plume_index nv0 = m->nv;
    const double tol = 1e-9 * c->b;
    plume_index *copy = malloc((size_t)nv0 * sizeof *copy);
    if (!copy)
        return PLUME_ENOMEM;
    plume_index n = nv0;
    for (plume_index v = 0; v < nv0; v++)
        copy[v] = fabs(m->X[2 * v + 1] - c->b) < tol ? n++ : -1;
    o->ncopy = n - nv0;
    if (o->ncopy == 0) {
        free(copy);
        return plume_err_set(err, PLUME_EINVAL, "separation law: the cell has no barbule reaching the next barb");
    }
    plume_status st = plume_mesh_create(n, m->nt, 2, &o->cell.mesh, err);
    o->cell.master = malloc((size_t)n * sizeof *o->cell.master);
    o->cell.shift = malloc((size_t)(2 * n) * sizeof *o->cell.shift);
    o->pairs = malloc((size_t)(2 * o->ncopy) * sizeof *o->pairs);
    if (st != PLUME_OK || !o->cell.master || !o->cell.shift || !o->pairs) {
        free(copy);
        opened_cell_free(o);
        return st != PLUME_OK ? st : PLUME_ENOMEM;
    }
    plume_mesh *om = o->cell.mesh;
    for (plume_index v = 0; v < nv0; v++) {
        memcpy(om->X + 2 * v, m->X + 2 * v, 2 * sizeof(double));
        o->cell.master[v] = c->master[v];
        memcpy(o->cell.shift + 2 * v, c->shift + 2 * v, 2 * sizeof(double));
        if (copy[v] < 0)
            continue;
        const plume_index w = copy[v];
        memcpy(om->X + 2 * w, m->X + 2 * v, 2 * sizeof(double));
        /* the copy is periodic along the barbs only: its master is the copy of the node on y = d_B
         * at x - shift_x (itself when shift_x = 0) */
        const double sx = c->shift[2 * v];
        o->cell.shift[2 * w] = sx, o->cell.shift[2 * w + 1] = 0.0;
        o->cell.master[w] = w;
        if (sx != 0.0)
            for (plume_index u = 0; u < nv0; u++)
                if (copy[u] >= 0 && fabs(m->X[2 * u] - (m->X[2 * v] - sx)) < tol && c->shift[2 * u] == 0.0)
                    o->cell.master[w] = copy[u];
        if (o->cell.master[w] == w && sx != 0.0) {
            free(copy);
            opened_cell_free(o);
            return plume_err_set(err, PLUME_EINVAL, "separation law: node %ld on the cell's top edge has no image "
                                 "along the barbs", (long)v);
        }
        if (sx == 0.0) { /* one hook pair per physical node: the copy and the barb's image */
            o->pairs[2 * o->npairs] = w;
            o->pairs[2 * o->npairs + 1] = v;
            o->npairs++;
        }
    }
    plume_mesh_reset_current(om);
    for (plume_index t = 0; t < m->nt; t++) {
        int touches = 0;
        for (int k = 0; k < 3; k++)
            touches |= copy[m->tri[3 * t + k]] >= 0;
        if (touches && m->material[t] != PLUME_MAT_BARBULE) {
            free(copy);
            opened_cell_free(o);
            return plume_err_set(err, PLUME_EINVAL, "separation law: a barb triangle reaches the cell's top edge");
        }
        for (int k = 0; k < 3; k++)
            om->tri[3 * t + k] = copy_of(copy, m->tri[3 * t + k]);
        om->material[t] = m->material[t];
        memcpy(om->barb_dir + 2 * t, m->barb_dir + 2 * t, 2 * sizeof(double));
    }
    o->cell.order = c->order;
    o->cell.a = c->a;
    o->cell.b = c->b;
    o->cell.nmasters = 0;
    for (plume_index v = 0; v < n; v++)
        o->cell.nmasters += o->cell.master[v] == v;
    if (c->order == 2) {
        const plume_quadratic_mesh *q = &c->quad;
        plume_quadratic_mesh *oq = &o->cell.quad;
        oq->nt = q->nt;
        oq->tri6 = malloc((size_t)(6 * q->nt) * sizeof *oq->tri6);
        oq->material = malloc((size_t)q->nt * sizeof *oq->material);
        oq->barb_dir = malloc((size_t)(2 * q->nt) * sizeof *oq->barb_dir);
        if (!oq->tri6 || !oq->material || !oq->barb_dir) {
            free(copy);
            opened_cell_free(o);
            return PLUME_ENOMEM;
        }
        memcpy(oq->material, q->material, (size_t)q->nt * sizeof *oq->material);
        memcpy(oq->barb_dir, q->barb_dir, (size_t)(2 * q->nt) * sizeof *oq->barb_dir);
        for (plume_index k = 0; k < 6 * q->nt; k++)
            oq->tri6[k] = copy_of(copy, q->tri6[k]);
    }
    free(copy);
    return plume_mesh_build_topology(om, err);
}

/* The opened cell's problem: the membrane and the hook, each wrapped periodically; non-masters
 * and the anchor (the master at the origin) fixed. */
typedef struct {
    opened_cell oc;
    plume_hooks *hooks;       /* borrowed by the hook term; freed after the problem */
    plume_term hook;          /* that term (its keep saves and restores the hook's state) */
    plume_problem *p;
    plume_solver *s;
    plume_periodic *per[2];   /* membrane, hook */
    double *u, *grad, *xfull; /* xfull [2 nv]: every vertex, periodic images placed */
    double F[4];
    int iterations, solves;
} sep_cell;

static void sep_cell_free(sep_cell *c)
{
    plume_solver_destroy(&c->s);
    plume_problem_destroy(&c->p);
    plume_hooks_destroy(&c->hooks);
    opened_cell_free(&c->oc);
    free(c->u);
    free(c->grad);
    free(c->xfull);
}

static plume_status sep_cell_init(sep_cell *c, const plume_layout *l, const plume_cell *cell, plume_err *err)
{
    memset(c, 0, sizeof *c);
    c->F[0] = c->F[3] = 1.0;
    plume_status st = open_cell(cell, &c->oc, err);
    if (st != PLUME_OK)
        return st;
    const plume_cell *oc = &c->oc.cell;
    const plume_index nv = oc->mesh->nv;
    const plume_index first[2] = {0, c->oc.npairs};
    if ((st = plume_hooks_create(nv, 1, first, c->oc.pairs, &l->hooks, &c->hooks, err)) != PLUME_OK)
        return st;
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    plume_term membrane, wrapped[2];
    if ((st = plume_micro_membrane_term(oc->mesh, oc->order == 2 ? &oc->quad : NULL, mats, 2, &membrane, err)) != PLUME_OK)
        return st;
    if ((st = plume_periodic_term_create(oc, &membrane, &c->per[0], &wrapped[0], err)) != PLUME_OK)
        return st;
    plume_hooks_term(c->hooks, 0, &c->hook);
    if ((st = plume_periodic_term_create(oc, &c->hook, &c->per[1], &wrapped[1], err)) != PLUME_OK) {
        wrapped[0].destroy(wrapped[0].ctx);
        return st;
    }
    if ((st = plume_problem_create(nv, 2, fmax(oc->a, oc->b), &c->p, err)) != PLUME_OK) {
        wrapped[0].destroy(wrapped[0].ctx);
        wrapped[1].destroy(wrapped[1].ctx);
        return st;
    }
    st = plume_problem_add_term(c->p, &wrapped[0], err);
    plume_status st1 = plume_problem_add_term(c->p, &wrapped[1], err);
    if (st != PLUME_OK || st1 != PLUME_OK)
        return st != PLUME_OK ? st : st1;
    plume_periodic_hold(oc, c->p, err);
    if ((st = plume_problem_finalize(c->p, err)) != PLUME_OK)
        return st;
    plume_solver_opts so;
    plume_solver_opts_default(&so);
    plume_err why;
    if ((st = plume_solver_create(PLUME_SOLVER_NEWTON, c->p, &so, &c->s, &why)) != PLUME_OK)
        return plume_err_set(err, st, "separation law: cannot create the cell solver: %s", why.msg);
    const plume_index nf = plume_problem_nfree(c->p);
    c->u = malloc((size_t)nf * sizeof *c->u);
    c->grad = malloc((size_t)nf * sizeof *c->grad);
    c->xfull = malloc((size_t)(2 * nv) * sizeof *c->xfull);
    return c->u && c->grad && c->xfull ? PLUME_OK : PLUME_ENOMEM;
}

/* Solves at the average deformation gradient F (row-major; the previous fluctuation on the new
 * affine map) and returns the cell's average membrane stress P (N/m, row-major, both terms) and
 * energy (J); xfull holds every vertex. */
static plume_status sep_cell_solve_F(sep_cell *c, const double F[4], double P[4], double *energy, plume_err *err)
{
    const plume_cell *oc = &c->oc.cell;
    const plume_mesh *m = oc->mesh;
    double *x = plume_problem_x(c->p);
    for (plume_index v = 0; v < m->nv; v++)
        if (oc->master[v] == v) {
            const double X0 = m->X[2 * v], X1 = m->X[2 * v + 1];
            x[2 * v] += (F[0] - c->F[0]) * X0 + (F[1] - c->F[1]) * X1;
            x[2 * v + 1] += (F[2] - c->F[2]) * X0 + (F[3] - c->F[3]) * X1;
        }
    memcpy(c->F, F, sizeof c->F);
    for (int k = 0; k < 2; k++)
        plume_periodic_set_macro(c->per[k], F);
    plume_problem_gather(c->p, c->u);
    plume_solve_report rep;
    plume_status st = plume_solver_solve(c->s, c->u, NULL, &rep);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "separation law: solver error at F = [%g %g; %g %g] (%s)", F[0], F[1], F[2], F[3],
                             plume_strerror(st));
    c->iterations += rep.iterations;
    c->solves++;
    if (!rep.converged)
        return plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the cell did not converge at F = [%g %g; %g %g] "
                             "(%s after %d iterations)", F[0], F[1], F[2], F[3], plume_reason_name(rep.reason),
                             rep.iterations);
    if ((st = plume_problem_objective(c->p, c->u, energy, c->grad)) != PLUME_OK)
        return st;
    memset(P, 0, 4 * sizeof *P);
    for (int k = 0; k < 2; k++) {
        double Pk[4];
        plume_periodic_average_stress(c->per[k], Pk);
        for (int i = 0; i < 4; i++)
            P[i] += Pk[i];
    }
    for (plume_index v = 0; v < m->nv; v++) {
        const double *xm = x + 2 * oc->master[v], *s = oc->shift + 2 * v;
        c->xfull[2 * v] = xm[0] + F[0] * s[0] + F[1] * s[1];
        c->xfull[2 * v + 1] = xm[1] + F[2] * s[0] + F[3] * s[1];
    }
    return PLUME_OK;
}

/* Solves at opening e (F = [1 0; 0 1 + e]: no stretch along the stiff barbs, no shear) and returns
 * the traction across the barb line: its magnitude |(P_xy, P_yy)| (N/m) and its normal part P_yy.
 * Only the hook crosses the line, so the magnitude is the hook's force per period. */
static plume_status sep_cell_solve(sep_cell *c, double e, double *traction, double *normal, double *energy,
                                   plume_err *err)
{
    const double F[4] = {1.0, 0.0, 0.0, 1.0 + e};
    double P[4];
    plume_status st = sep_cell_solve_F(c, F, P, energy, err);
    if (st != PLUME_OK)
        return st;
    *traction = hypot(P[1], P[3]);
    *normal = P[3];
    return PLUME_OK;
}

/* The hook's load |F| / strength at the last solve. */
static double hook_load(const sep_cell *c)
{
    return plume_hooks_max_load(c->hooks, 2, c->xfull, NULL);
}

/* Where the hook first reaches its strength: secant steps on the hook's load, which grows almost
 * linearly with the opening, to a load in [1, 1 + PLUME_SEPARATION_LOAD_TOL]. */
#define PLUME_SEPARATION_LOAD_TOL 1e-4

plume_status plume_separation_law_of(const plume_layout *l, plume_separation_law *out, plume_err *err)
{
    if (!l || !out)
        return plume_err_set(err, PLUME_EINVAL, "separation law: a layout and an output are required");
    memset(out, 0, sizeof *out);
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    if (l->kind != PLUME_LAYOUT_BARBULES || !(l->hooks.strength > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "separation law: the layout needs explicit barbules held by hooks "
                             "(\"layout\": \"barbules\" and hook_strength > 0)");
    plume_cell *cell = NULL;
    if ((st = plume_cell_mesh(l, &cell, err)) != PLUME_OK)
        return st;
    sep_cell c;
    st = sep_cell_init(&c, l, cell, err);
    const double b = cell->b, a = cell->a, h = l->h;
    plume_cell_destroy(&cell);
    double T = 0.0, Tn = 0.0, E = 0.0, e = 0.0, work = 0.0, eprev = 0.0;
    /* 1. up to the strength: a first small opening, then secant steps on the hook's load */
    const double e0 = 1e-3 * l->hooks.opening / b;
    if (st == PLUME_OK)
        st = sep_cell_solve(&c, e = e0, &T, &Tn, &E, err);
    double load = st == PLUME_OK ? hook_load(&c) : 0.0, load_prev = 0.0;
    for (int it = 0; st == PLUME_OK && !(load >= 1.0 && load <= 1.0 + PLUME_SEPARATION_LOAD_TOL); it++) {
        if (it == 50 || !(load > load_prev)) {
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook's load (%g of its strength at opening "
                               "strain %g) does not reach the strength", load, e);
            break;
        }
        const double target = 1.0 + 0.5 * PLUME_SEPARATION_LOAD_TOL;
        const double slope = (load - load_prev) / (e - (it == 0 ? 0.0 : eprev));
        const double enext = e + (target - load) / slope;
        if (load < 1.0) { /* accepted: work along the elastic branch */
            eprev = e, load_prev = load;
        }
        if ((st = sep_cell_solve(&c, enext, &T, &Tn, &E, err)) != PLUME_OK)
            break;
        e = enext;
        load = hook_load(&c);
    }
    /* the path so far is elastic: the work per barb length is the energy per barb length; the
     * hook's own opening across the line is its pairs' mean gap along y. The strength is the
     * traction's magnitude: the hook lets go at its strength whatever the direction of its pull,
     * and a leaning barbule pulls it askew (with the shear held, P_xy is half of P_yy for
     * data/layout_hooks.json), so the line's traction at the release is one hook's strength per
     * period in every mode, the macro link's criterion. */
    if (st == PLUME_OK) {
        out->strength = T;
        out->peak_opening = e * b;
        work = E / a;
        double gap = 0.0;
        for (plume_index p = 0; p < c.oc.npairs; p++)
            gap += c.xfull[2 * c.oc.pairs[2 * p + 1] + 1] - c.xfull[2 * c.oc.pairs[2 * p] + 1];
        gap /= (double)c.oc.npairs;
        if (!(gap > 0.0))
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook has not opened at its strength "
                               "(mean gap %g m)", gap);
        else
            out->stiffness = Tn / gap;
    }
    /* 2. let go, and keep opening until the hook has cleared the capture distance (a hook held at
     * exactly its strength, which no commit lets go, is pulled on by 1/1000 of its opening). A slide
     * is crossed in 40 steps: each loads the hook beyond its strength, the commit slides it back and
     * the cell is solved again. The work is summed between admissible states (every hook within its
     * strength), the states a slide passes through; the strength is the largest of their
     * tractions. */
    const double slide_step = (l->hooks.slide > 0.0 ? l->hooks.slide / 40.0 : 1e-3 * l->hooks.opening) / b;
    const double free_step = (2.0 * l->hooks.capture + l->hooks.opening + l->hooks.slide) / 10.0 / b;
    const double e_clear = (2.0 * l->hooks.capture + l->hooks.opening + l->hooks.slide) / b + e;
    double T_adm = Tn, e_adm = e; /* the work is the normal traction's along the opening */
    int released = 0;
    for (int guard = 0; st == PLUME_OK; guard++) {
        plume_hooks_events ev;
        if ((st = plume_hooks_commit(c.hooks, 2, c.xfull, PLUME_HOOKS_ALL, &ev, err)) != PLUME_OK)
            break;
        if (ev.released && !released) /* the step that lets go: its work up to here */
            work += 0.5 * (T_adm + Tn) * (e - e_adm) * b;
        if (ev.released || ev.slid) { /* the change solved again at the same opening */
            if ((st = sep_cell_solve(&c, e, &T, &Tn, &E, err)) != PLUME_OK)
                break;
            if (ev.released && !released) {
                released = 1;
                out->opening = e * b;
                out->energy = (work - E / a) / h;
            }
            continue;
        }
        if (!released) { /* admissible */
            work += 0.5 * (T_adm + Tn) * (e - e_adm) * b; /* per barb length */
            T_adm = Tn, e_adm = e;
            out->strength = fmax(out->strength, T);
        }
        if (released && e >= e_clear)
            break;
        if (guard == 100000) {
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook has not let go at opening %g m", e * b);
            break;
        }
        const double step = released ? free_step : slide_step;
        if ((st = sep_cell_solve(&c, e + step, &T, &Tn, &E, err)) != PLUME_OK)
            break;
        e += step;
    }
    /* 3. back until the hook catches again: steps of a tenth of the capture distance, and the step
     * that catches it undone and halved down to 1/1000 of it (the released cell holds no load, so
     * an undone step leaves nothing behind) */
    if (st == PLUME_OK && l->hooks.capture > 0.0) {
        double down = 0.1 * l->hooks.capture / b;
        const double finest = 1e-3 * l->hooks.capture / b;
        while (st == PLUME_OK && e > 0.0) {
            const double enext = fmax(e - down, 0.0);
            if ((st = sep_cell_solve(&c, enext, &T, &Tn, &E, err)) != PLUME_OK)
                break;
            c.hook.keep(c.hook.ctx, 1);
            plume_hooks_events ev;
            if ((st = plume_hooks_commit(c.hooks, 2, c.xfull, PLUME_HOOKS_ALL, &ev, err)) != PLUME_OK)
                break;
            if (!ev.reengaged) {
                e = enext;
                continue;
            }
            if (down <= finest) {
                out->capture = enext * b;
                break;
            }
            c.hook.keep(c.hook.ctx, 0);
            down *= 0.5;
        }
        if (st == PLUME_OK && !(out->capture > 0.0))
            st = plume_err_set(err, PLUME_EINFEASIBLE, "separation law: the hook did not catch again on closing "
                               "(capture %g m)", l->hooks.capture);
    }
    out->cell_hooks = 1;
    out->cell_length = a;
    out->solves = c.solves;
    out->newton_iterations = c.iterations;
    sep_cell_free(&c);
    if (st != PLUME_OK)
        memset(out, 0, sizeof *out);
    return st;
}

/* The opened cell with its hooks engaged, strained by +-PLUME_SEPARATION_TENSOR_STRAIN in each
 * Voigt component: the hooks are linear springs, so central differences leave only the geometric
 * nonlinearity's second order (1e-12 relative). */
#define PLUME_SEPARATION_TENSOR_STRAIN 1e-6

plume_status plume_separation_tensor(const plume_layout *l, double C[9], plume_err *err)
{
    if (!l || !C)
        return plume_err_set(err, PLUME_EINVAL, "hooked cell tensor: a layout and an output are required");
    memset(C, 0, 9 * sizeof *C);
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    if (l->kind != PLUME_LAYOUT_BARBULES || !(l->hooks.strength > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "hooked cell tensor: the layout needs explicit barbules held by hooks "
                             "(\"layout\": \"barbules\" and hook_strength > 0)");
    plume_cell *cell = NULL;
    if ((st = plume_cell_mesh(l, &cell, err)) != PLUME_OK)
        return st;
    sep_cell c;
    st = sep_cell_init(&c, l, cell, err);
    plume_cell_destroy(&cell);
    const double eps = PLUME_SEPARATION_TENSOR_STRAIN;
    for (int j = 0; j < 3 && st == PLUME_OK; j++) {
        double Pv[2][3];
        for (int side = 0; side < 2 && st == PLUME_OK; side++) {
            const double d = side ? -eps : eps;
            /* E11, E22, and 2E12 = d with a symmetric gradient (no rotation) */
            const double F[4] = {1.0 + (j == 0 ? d : 0.0), j == 2 ? 0.5 * d : 0.0, j == 2 ? 0.5 * d : 0.0,
                                 1.0 + (j == 1 ? d : 0.0)};
            double P[4], E;
            if ((st = sep_cell_solve_F(&c, F, P, &E, err)) == PLUME_OK)
                Pv[side][0] = P[0], Pv[side][1] = P[3], Pv[side][2] = 0.5 * (P[1] + P[2]);
        }
        for (int i = 0; st == PLUME_OK && i < 3; i++)
            C[3 * i + j] = (Pv[0][i] - Pv[1][i]) / (2.0 * eps) / l->h;
    }
    sep_cell_free(&c);
    if (st != PLUME_OK) {
        memset(C, 0, 9 * sizeof *C);
        return st;
    }
    for (int i = 0; i < 3; i++) /* symmetric to the differences' rounding */
        for (int j = i + 1; j < 3; j++)
            C[3 * i + j] = C[3 * j + i] = 0.5 * (C[3 * i + j] + C[3 * j + i]);
    return PLUME_OK;
}
