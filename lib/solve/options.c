#include "options.h"

#include <string.h>

#include "../core/opts.h"

/* The defaults into a whole struct of this library's size. */
static void defaults(plume_solver_opts *o)
{
    memset(o, 0, sizeof *o); /* a field added later is never left undefined */
    o->size = sizeof *o;
    o->max_iter = 100;
    o->tol_kkt = 1e-9;
    o->tol_violation = 1e-10;
    o->tol_step = 1e-13;
    o->max_step = 100.0;
    o->kkt = PLUME_KKT_ELIMINATE;
    o->inertia_corrections = 1;
    o->inertia_max_shift = 1.0;
    o->line_search = PLUME_LS_FILTER;
    o->reuse_factorization = 1;
    o->reuse_rate = 0.25;
    o->kkt_refine = 1;
    o->verbose = 0;
    o->exact_hessian_first = 1;
    o->partial_projection = 1;
    o->trust_region = 0;
    o->curved_search = 1;
    o->stall_iterations = 0;
}

plume_status plume_solver_opts_take(plume_solver_opts *full, const plume_solver_opts *given, plume_err *err)
{
    defaults(full);
    return given ? plume_opts_take(full, sizeof *full, given, "plume_solver_opts", err) : PLUME_OK;
}

void plume_solver_opts_default_sized(plume_solver_opts *o, size_t size)
{
    plume_solver_opts full;
    defaults(&full);
    plume_opts_give(o, size, &full, sizeof full);
}

static const char *const globalization_names[] = {"curved_line_search", "line_search", "trust_region"};

plume_status plume_globalization_parse(const char *s, plume_globalization *out)
{
    for (int k = 0; s && k < 3; k++)
        if (strcmp(s, globalization_names[k]) == 0) {
            *out = (plume_globalization)k;
            return PLUME_OK;
        }
    return PLUME_EINVAL;
}

const char *plume_globalization_name(plume_globalization g)
{
    return (unsigned)g < 3 ? globalization_names[g] : "unknown";
}

void plume_solver_opts_set_globalization(plume_solver_opts *o, plume_globalization g)
{
    o->curved_search = g == PLUME_GLOBAL_CURVED_LINE_SEARCH;
    o->trust_region = g == PLUME_GLOBAL_TRUST_REGION;
}
