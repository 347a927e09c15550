/* plume: bending moduli fitted by the fitter of the membrane moduli (include/plume/fit.h's
 * plume_fit_bending_moduli). The fitter searches four quantities, the first, second and fourth
 * positive (in log space) and the third in (-1, 1) (linearly): the plate's D_long, D_trans and
 * D_twist, and its coupling as D_coupling / sqrt(D_long D_trans), which keeps the plate positive
 * definite wherever the search goes. The packing stays in this file: the caller's model sees
 * bending moduli in N m, never moduli in Pa that hold them. */
#include <math.h>

#include "../include/plume/fit.h"

/* The plate's moduli in the fitter's four places (and back). */
static void pack(const plume_bending_material *b, plume_ortho *m)
{
    const double g = sqrt(b->D_long * b->D_trans);
    m->E_xx = b->D_long, m->E_yy = b->D_trans, m->G_xy = b->D_twist;
    m->nu_xy = g > 0.0 ? b->D_coupling / g : 0.0;
}

static void unpack(const plume_ortho *m, plume_bending_material *b)
{
    b->D_long = m->E_xx, b->D_trans = m->E_yy, b->D_twist = m->G_xy;
    b->D_coupling = m->nu_xy * sqrt(m->E_xx * m->E_yy);
}

typedef struct {
    plume_fit_bending_model model;
    void *ctx;
} bending_adapter;

static plume_status adapted_model(void *vctx, const plume_ortho *m, int icurve, plume_curve *out, plume_err *err)
{
    const bending_adapter *a = vctx;
    plume_bending_material b = {0};
    unpack(m, &b);
    return a->model(a->ctx, &b, icurve, out, err);
}

plume_status plume_fit_bending_moduli(plume_fit_bending_model model, void *ctx, const plume_curve *targets, int ncurves,
                                      const plume_bending_material *start, const plume_fit_opts *o,
                                      plume_bending_material *result, plume_fit_report *rep, plume_err *err)
{
    if (!model || !start || !result)
        return plume_err_set(err, PLUME_EINVAL, "fit: the bending model, start and result are required");
    if (!(start->D_long > 0.0 && start->D_trans > 0.0 && start->D_twist > 0.0) ||
        !(start->D_coupling * start->D_coupling < start->D_long * start->D_trans))
        return plume_err_set(err, PLUME_EINVAL,
                             "fit: the start plate must be positive definite (D_long, D_trans, D_twist > 0 and "
                             "D_coupling^2 < D_long D_trans; got %g, %g, %g and %g N m)",
                             start->D_long, start->D_trans, start->D_twist, start->D_coupling);
    bending_adapter a = {model, ctx};
    plume_ortho s, fit;
    pack(start, &s);
    plume_status st = plume_fit_moduli(adapted_model, &a, targets, ncurves, &s, o, &fit, rep, err);
    if (st == PLUME_OK)
        unpack(&fit, result);
    return st;
}
