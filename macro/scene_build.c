/* plume: the problem and stepper of a loaded scene (scene.h). */
#include "scene.h"

#include <stdlib.h>
#include <string.h>

#include "../lib/edge_length.h"
#include "../lib/membrane.h"

plume_status plume_scene_dynamics(const plume_scene *s, plume_problem **pp, plume_dynamics **pd, plume_err *err)
{
    if (!s || !s->mesh || !pp || !pd)
        return plume_err_set(err, PLUME_EINVAL, "scene: invalid arguments");
    *pp = NULL;
    *pd = NULL;
    const plume_mesh *m = s->mesh;
    plume_problem *p = NULL;
    plume_membrane_material *mm = malloc((size_t)s->nmat * sizeof *mm);
    plume_bending_material *bm = malloc((size_t)s->nmat * sizeof *bm);
    double *rho = malloc((size_t)s->nmat * sizeof *rho);
    plume_status st = PLUME_ENOMEM;
    if (!mm || !bm || !rho || (st = plume_problem_create(m->nv, 3, s->length, &p)) != PLUME_OK) {
        plume_err_set(err, st, "scene: out of memory");
        goto fail;
    }
    int bending = 0;
    for (int k = 0; k < s->nmat; k++) {
        mm[k] = s->mats[k].membrane;
        bm[k] = s->mats[k].bending;
        rho[k] = s->mats[k].density;
        bending |= bm[k].D_long > 0.0 || bm[k].D_trans > 0.0;
    }
    plume_term term;
    if ((st = plume_membrane_term_create(m, 3, mm, s->nmat, &term, err)) != PLUME_OK ||
        (st = plume_problem_add_term(p, &term)) != PLUME_OK)
        goto fail;
    if (bending && ((st = plume_bending_term_create(m, bm, s->nmat, NULL, &term, err)) != PLUME_OK ||
                    (st = plume_problem_add_term(p, &term)) != PLUME_OK))
        goto fail;
    if (s->nbarb > 0) {
        plume_constraint con;
        if ((st = plume_edge_length_create(s->barb_edges, s->nbarb, m->X, m->nv, &con, err)) != PLUME_OK ||
            (st = plume_problem_add_constraint(p, &con)) != PLUME_OK)
            goto fail;
    }
    memcpy(plume_problem_x(p), m->x, (size_t)(3 * m->nv) * sizeof(double));
    plume_dynamics_opts o;
    plume_dynamics_opts_default(&o);
    o.dt = s->dt;
    memcpy(o.gravity, s->gravity, sizeof o.gravity);
    o.max_halvings = s->max_halvings;
    o.solver = s->solver;
    o.solver_opts.max_iter = s->max_iter;
    o.solver_opts.verbose = s->verbose;
    if ((st = plume_dynamics_create(m, p, rho, s->nmat, s->handles, s->nhandles, &o, pd, err)) != PLUME_OK)
        goto fail;
    *pp = p;
    free(mm);
    free(bm);
    free(rho);
    return PLUME_OK;
fail:
    plume_problem_destroy(&p);
    free(mm);
    free(bm);
    free(rho);
    return st;
}
