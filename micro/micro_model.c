#include "micro_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../lib/core/membrane.h"
#include "../lib/core/mesh_quadratic.h"
#include "../lib/core/opts.h"
#include "../lib/core/pslg.h"
#include "../lib/io/progress.h"
#include "cell_mesh.h"
#include "hook_mesh.h"

/* The specimen's problem on its (linear) mesh *mesh: the quadratic split when the layout asks for it
 * (*mesh then replaced by the split), and the two-material membrane term. */
static plume_status specimen_problem(const plume_layout *l, double lx, double ly, plume_mesh **mesh,
                                     plume_problem **p, plume_err *err)
{
    plume_status st;
    plume_quadratic_mesh quad = {0};
    if (l->order == 2) {
        /* the quadratic triangles' nodes are the split mesh's vertices: grips, reactions and output
         * see an ordinary mesh */
        if ((st = plume_mesh_quadratic(*mesh, &quad, err)) != PLUME_OK) {
            plume_mesh_destroy(mesh);
            return st;
        }
        plume_mesh_destroy(mesh);
        *mesh = quad.split;
        quad.split = NULL;
    }
    plume_membrane_material mats[2];
    plume_layout_materials(l, mats);
    plume_term term;
    if ((st = plume_problem_create((*mesh)->nv, 2, fmax(lx, ly), p, err)) != PLUME_OK ||
        (st = plume_micro_membrane_term(*mesh, l->order == 2 ? &quad : NULL, mats, 2, &term, err)) != PLUME_OK ||
        (st = plume_problem_add_term(*p, &term, err)) != PLUME_OK) {
        plume_problem_destroy(p);
        plume_mesh_destroy(mesh);
    }
    plume_quadratic_mesh_free(&quad);
    return st;
}

plume_status plume_micro_specimen(const plume_layout *l, double lx, double ly, double angle_deg,
                                  plume_mesh **mesh, plume_problem **p, plume_err *err)
{
    if (!l || !mesh || !p)
        return plume_err_set(err, PLUME_EINVAL, "micro specimen: invalid arguments");
    *mesh = NULL;
    *p = NULL;
    plume_status st = plume_layout_check(l, err);
    if (st != PLUME_OK)
        return st;
    if (l->kind == PLUME_LAYOUT_BARBULES && l->hooks.strength > 0.0)
        return plume_micro_specimen_hooked(l, lx, ly, angle_deg, &l->hooks, mesh, p, NULL, err);
    if ((st = plume_specimen_mesh(l, lx, ly, angle_deg, mesh, err)) != PLUME_OK)
        return st;
    return specimen_problem(l, lx, ly, mesh, p, err);
}

plume_status plume_micro_specimen_hooked(const plume_layout *l, double lx, double ly, double angle_deg,
                                         const plume_hook_law *law, plume_mesh **mesh, plume_problem **p,
                                         plume_hooks **hooks, plume_err *err)
{
    if (!l || !law || !mesh || !p)
        return plume_err_set(err, PLUME_EINVAL, "micro specimen with hooks: invalid arguments");
    *mesh = NULL, *p = NULL;
    if (hooks)
        *hooks = NULL;
    plume_hooks *made = NULL;
    plume_mesh *closed = NULL;
    plume_hook_mesh open = {0};
    plume_index *first = NULL, *pairs = NULL;
    plume_status st = plume_hook_law_check(law, err);
    if (st != PLUME_OK || (st = plume_layout_check(l, err)) != PLUME_OK ||
        (st = plume_specimen_mesh(l, lx, ly, angle_deg, &closed, err)) != PLUME_OK)
        return st;
    /* q: from a barb to the next one, as the specimen's barbules run (micro/specimen_mesh.c) */
    double d[2];
    plume_barb_direction(angle_deg, d);
    const double q[2] = {-d[1], d[0]};
    if ((st = plume_hook_mesh_open(closed, q, &open, err)) != PLUME_OK ||
        (l->order == 2 && open.nhooks > 0 && (st = plume_hook_mesh_quadratic_pairs(&open, &first, &pairs, err)) != PLUME_OK))
        goto done;
    *mesh = open.mesh; /* the problem is built on the opened mesh (split when quadratic) */
    open.mesh = NULL;
    if ((st = specimen_problem(l, lx, ly, mesh, p, err)) != PLUME_OK || open.nhooks == 0)
        goto done;
    if ((st = plume_hooks_create((*mesh)->nv, open.nhooks, first ? first : open.first, first ? pairs : open.pairs, law,
                                 &made, err)) != PLUME_OK)
        goto done;
    plume_term t;
    plume_hooks_term(made, 1, &t);
    st = plume_problem_add_term(*p, &t, err); /* the problem owns the hooks from here, even on failure */
    if (st == PLUME_OK && hooks)
        *hooks = made;
    made = NULL;
done:
    plume_hooks_destroy(&made);
    if (st != PLUME_OK) {
        plume_problem_destroy(p);
        plume_mesh_destroy(mesh);
    }
    plume_mesh_destroy(&closed);
    plume_hook_mesh_free(&open);
    free(first);
    free(pairs);
    return st;
}

plume_index plume_micro_specimen_elements(const plume_layout *l, const plume_mesh *mesh)
{
    return l->order == 2 ? mesh->nt / 4 : mesh->nt;
}

plume_status plume_micro_traction_convergence(const plume_layout *l, double lx, double ly, double angle_deg,
                                              const plume_traction_opts *o, const plume_traction_result *run,
                                              plume_micro_convergence *c, plume_err *err)
{
    if (!l || !o || !run || !c)
        return plume_err_set(err, PLUME_EINVAL, "micro convergence: invalid arguments");
    memset(c, 0, sizeof *c);
    c->stress_change = c->slope_change = -1.0;
    double t0 = plume_wall_seconds();
    plume_layout lc;
    plume_layout_refinement(l, PLUME_MESH_SPECIMEN, &lc);
    c->edge = plume_layout_element_edge(l, PLUME_MESH_SPECIMEN);
    c->refinement_edge = plume_layout_element_edge(&lc, PLUME_MESH_SPECIMEN);
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_traction_result r;
    memset(&r, 0, sizeof r);
    plume_status st = plume_micro_specimen(&lc, lx, ly, angle_deg, &mesh, &p, err);
    if (st != PLUME_OK)
        goto done;
    c->refinement_elements = plume_micro_specimen_elements(l, mesh);
    plume_traction_opts oc; /* the caller's options (as many bytes as it has) over the defaults */
    plume_traction_opts_default(&oc);
    if ((st = plume_opts_take(&oc, sizeof oc, o, "plume_traction_opts", err)) != PLUME_OK)
        goto done;
    oc.on_step = NULL;
    oc.on_step_user = NULL;
    oc.progress = 0;
    if ((st = plume_traction_run(mesh, p, NULL, 0, &oc, &r, err)) != PLUME_OK)
        goto done;
    c->converged = r.converged;
    if (r.converged) {
        plume_index n = r.curve.n < run->curve.n ? r.curve.n : run->curve.n;
        double smax = 0.0, d = 0.0;
        for (plume_index k = 0; k < n; k++) {
            smax = fmax(smax, fabs(run->curve.stress[k]));
            d = fmax(d, fabs(run->curve.stress[k] - r.curve.stress[k]));
        }
        c->stress_change = smax > 0.0 ? d / smax : 0.0;
        c->slope_change = fabs(run->initial_slope - r.initial_slope) / fmax(fabs(run->initial_slope), 1e-300);
    }
done:
    plume_traction_result_free(&r);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    c->seconds = plume_wall_seconds() - t0;
    return st;
}
