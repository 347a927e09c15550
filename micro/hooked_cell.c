/* plume (micro): the periodic cell of a layout opened at its barbules' distal joins and held there by
 * a hook (micro/hooked_cell.h). */
#include "hooked_cell.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/membrane.h"
#include "../lib/solve/options.h"

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

void plume_hooked_cell_free(plume_hooked_cell *c)
{
    plume_solver_destroy(&c->s);
    plume_problem_destroy(&c->p);
    plume_hooks_destroy(&c->hooks);
    opened_cell_free(&c->oc);
    free(c->u);
    free(c->grad);
    free(c->xfull);
}

plume_status plume_hooked_cell_init(plume_hooked_cell *c, const plume_layout *l, const char *what, plume_err *err)
{
    memset(c, 0, sizeof *c);
    c->F[0] = c->F[3] = 1.0;
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    if (l->kind != PLUME_LAYOUT_BARBULES || !(l->hooks.strength > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "%s: the layout needs explicit barbules held by hooks (\"layout\": "
                             "\"barbules\" and hook_strength > 0)", what);
    plume_cell *cell = NULL;
    if ((st = plume_cell_mesh(l, &cell, err)) != PLUME_OK)
        return st;
    st = open_cell(cell, &c->oc, err);
    plume_cell_destroy(&cell);
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
plume_status plume_hooked_cell_solve_F(plume_hooked_cell *c, const double F[4], double P[4], double *energy, plume_err *err)
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
        return plume_err_set(err, st, "hooked cell: solver error at F = [%g %g; %g %g] (%s)", F[0], F[1], F[2], F[3],
                             plume_strerror(st));
    c->iterations += rep.iterations;
    c->solves++;
    if (!rep.converged)
        return plume_err_set(err, PLUME_EINFEASIBLE, "hooked cell: the cell did not converge at F = [%g %g; %g %g] "
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
plume_status plume_hooked_cell_open(plume_hooked_cell *c, double e, double *traction, double *normal, double *energy,
                                   plume_err *err)
{
    const double F[4] = {1.0, 0.0, 0.0, 1.0 + e};
    double P[4];
    plume_status st = plume_hooked_cell_solve_F(c, F, P, energy, err);
    if (st != PLUME_OK)
        return st;
    *traction = hypot(P[1], P[3]);
    *normal = P[3];
    return PLUME_OK;
}

/* The hook's load |F| / strength at the last solve. */
double plume_hooked_cell_load(const plume_hooked_cell *c)
{
    return plume_hooks_max_load(c->hooks, 2, c->xfull, NULL);
}

