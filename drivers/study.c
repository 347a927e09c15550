#include "study.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../include/plume/experiments.h"
#include "../lib/core/opts.h"

void plume_study_config_default_sized(plume_study_config *o, size_t size)
{
    plume_study_config full, *c = &full;
    memset(c, 0, sizeof *c);
    c->size = sizeof *c;
    c->lx = 1.0, c->ly = 1.3, c->h = 1.0;
    c->angle = 45.0;
    c->moduli.E_xx = 1e4, c->moduli.E_yy = 1.0, c->moduli.G_xy = 1.0, c->moduli.nu_xy = 0.0;
    c->kappa = 0.0;
    c->constraint = 1;
    c->mesh = PLUME_PATCH_ALIGNED;
    c->edge = 0.065;
    c->strain_max = 0.05;
    c->steps = 2;
    c->solver = PLUME_SOLVER_NEWTON;
    c->max_iter = 100;
    c->micro = 0;
    plume_layout_default(&c->layout);
    c->layout.h = c->h; /* a micro run's thickness is the study's */
    plume_opts_give(o, size, &full, sizeof full);
}

void plume_study_result_free(plume_study_result *r)
{
    if (!r)
        return;
    plume_curve_free(&r->curve);
    memset(r, 0, sizeof *r);
}

double plume_study_rel_error(double a, double ref)
{
    if (!isfinite(a) || !isfinite(ref))
        return NAN;
    return ref != 0.0 ? fabs(a - ref) / fabs(ref) : fabs(a - ref);
}

/* The vane of `c` meshed and set up; *barbs are its barb edges (inextensible with the constraint on). */
static plume_status build_vane(const plume_study_config *c, plume_mesh **mesh, plume_problem **p, plume_index **barbs,
                               plume_index *nb, plume_err *err)
{
    plume_vane vane;
    plume_vane_default(&vane);
    vane.moduli = c->moduli;
    vane.h = c->h;
    vane.kappa = c->kappa;
    vane.constraint = c->constraint;
    plume_status st = plume_vane_check(&vane, err);
    if (st == PLUME_OK)
        st = plume_patch_mesh(c->lx, c->ly, c->angle, c->edge, c->mesh, 2, mesh, err);
    if (st == PLUME_OK)
        st = plume_problem_create((*mesh)->nv, 2, fmax(c->lx, c->ly), p, err);
    if (st == PLUME_OK)
        st = plume_vane_add(*p, *mesh, &vane, barbs, nb, err);
    return st;
}

/* The micro specimen of `c`: the layout's thickness is the one the nominal stress divides by. */
static plume_status build_micro(const plume_study_config *c, plume_mesh **mesh, plume_problem **p, plume_err *err)
{
    if (!(fabs(c->h - c->layout.h) <= 1e-12 * fabs(c->h)))
        return plume_err_set(err, PLUME_EINVAL, "study: a micro run's h must equal layout.h (got %g and %g m)", c->h,
                             c->layout.h);
    return plume_micro_specimen(&c->layout, c->lx, c->ly, c->angle, mesh, p, err);
}

/* The study's reading of a traction run: the last point, the outcome, the mesh's size. The curve
 * moves from tr to r. */
static void take_result(const plume_study_config *c, const plume_mesh *mesh, plume_traction_result *tr,
                        plume_study_result *r)
{
    r->curve = tr->curve;
    memset(&tr->curve, 0, sizeof tr->curve);
    r->seconds = tr->seconds;
    r->iterations = tr->newton_iterations;
    r->converged = tr->converged;
    r->reason = tr->converged ? PLUME_REASON_CONVERGED : tr->failed_reason;
    r->elements = (long)(c->micro ? plume_micro_specimen_elements(&c->layout, mesh) : mesh->nt);
    r->vertices = (long)mesh->nv;
    plume_index n = r->curve.n;
    if (n > 0) {
        r->strain = r->curve.strain[n - 1];
        r->stress = r->curve.stress[n - 1];
        r->wbar = r->curve.wbar[n - 1];
    } else {
        r->strain = r->stress = r->wbar = NAN;
    }
    r->complete = n == (plume_index)c->steps + 1 && fabs(r->strain - c->strain_max) <= 1e-9 * c->strain_max;
}

plume_status plume_study_traction(const plume_study_config *given, plume_study_result *r, plume_err *err)
{
    if (!given || !r)
        return plume_err_set(err, PLUME_EINVAL, "study: invalid arguments");
    memset(r, 0, sizeof *r);
    plume_study_config full; /* the caller's config (as many bytes as it has) over the defaults */
    const plume_study_config *c = &full;
    plume_study_config_default(&full);
    if (plume_opts_take(&full, sizeof full, given, "plume_study_config", err) != PLUME_OK)
        return PLUME_EINVAL;
    if (!(c->steps >= 1) || !(c->max_iter >= 1) || !(c->strain_max > 0) || !isfinite(c->strain_max))
        return plume_err_set(err, PLUME_EINVAL, "study: steps and max_iter must be >= 1 and strain_max > 0 "
                             "(got %d, %d, %g)", c->steps, c->max_iter, c->strain_max);
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nb = 0;
    plume_traction_result tr;
    memset(&tr, 0, sizeof tr);
    plume_status st = c->micro ? build_micro(c, &mesh, &p, err) : build_vane(c, &mesh, &p, &barbs, &nb, err);
    if (st == PLUME_OK) {
        plume_traction_opts o;
        plume_solver_opts so;
        plume_traction_opts_default(&o);
        plume_solver_opts_default(&so);
        o.lx = c->lx, o.ly = c->ly, o.h = c->h;
        o.strain_max = c->strain_max;
        o.steps = c->steps;
        o.solver = c->solver;
        so.max_iter = c->max_iter;
        o.solver_opts = &so;
        /* the study reads the stress at strain_max, not the initial slope: the probe is solved with
         * the steps' tolerance, so that the times measure the models (the exact slope's probe costs
         * newton 2 -> 7 iterations at 1.2e5 triangles and a second symbolic analysis) */
        o.probe_tol_kkt = so.tol_kkt;
        o.progress = 0;
        st = plume_traction_run(mesh, p, barbs, nb, &o, &tr, err);
    }
    if (st == PLUME_OK)
        take_result(c, mesh, &tr, r);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return st;
}
