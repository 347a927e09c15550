/* plume: the flat interface's fit request (flat.h): macro moduli fitted to traction curves. */
#include "flat.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "internal/flat_common.h"

#define FLAT_MAX_TARGETS 16

/* fit request.start: the starting moduli (required), E_xx, E_yy and G_xy > 0. */
static plume_status get_fit_start(json_t *req, plume_ortho *start, plume_err *err)
{
    if (!json_object_get(req, "start"))
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"start\" (the starting moduli) is required");
    plume_status st = plume_flat_get_moduli(req, "fit", "start", start, err);
    if (st != PLUME_OK)
        return st;
    if (!(start->E_xx > 0.0 && start->E_yy > 0.0 && start->G_xy > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"start\" needs E_xx, E_yy and G_xy > 0");
    return PLUME_OK;
}

/* fit request.free: the names of the fitted moduli into *mask (left as it is without "free"). */
static plume_status get_fit_free(json_t *req, unsigned *mask, plume_err *err)
{
    json_t *jf = json_object_get(req, "free");
    if (!jf)
        return PLUME_OK;
    *mask = 0;
    size_t i;
    json_t *v;
    if (!json_is_array(jf))
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"free\" must be a list of modulus names");
    json_array_foreach(jf, i, v) {
        const char *s = json_is_string(v) ? json_string_value(v) : "";
        unsigned bit = strcmp(s, "E_xx") == 0 ? PLUME_FIT_EXX : strcmp(s, "E_yy") == 0 ? PLUME_FIT_EYY
                     : strcmp(s, "nu_xy") == 0 ? PLUME_FIT_NU : strcmp(s, "G_xy") == 0 ? PLUME_FIT_GXY : 0;
        if (!bit)
            return plume_err_set(err, PLUME_EINVAL, "fit request: \"free\"[%zu] must be E_xx, E_yy, nu_xy or G_xy", i);
        *mask |= bit;
    }
    if (!*mask)
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"free\" names no modulus");
    return PLUME_OK;
}

/* fit request.targets: the curves (curves[0 .. *nt), their arrays the caller's to free even on
 * failure), their barb angles and the largest last strain. */
static plume_status get_fit_targets(json_t *req, plume_curve *curves, double *angles, int *nt, double *strain_max,
                                    plume_err *err)
{
    json_t *jt = json_object_get(req, "targets");
    if (!json_is_array(jt) || json_array_size(jt) < 1 || json_array_size(jt) > FLAT_MAX_TARGETS)
        return plume_err_set(err, PLUME_EINVAL, "fit request: \"targets\" must be a list of 1 to %d curves",
                             FLAT_MAX_TARGETS);
    *strain_max = 0.0;
    for (size_t i = 0; i < json_array_size(jt); i++) {
        json_t *c = json_array_get(jt, i), *a = json_object_get(c, "angle"), *se = json_object_get(c, "strain"),
               *ss = json_object_get(c, "stress");
        size_t n = json_array_size(se);
        if (!json_is_object(c) || !json_is_number(a) || !json_is_array(se) || !json_is_array(ss) || n < 2 ||
            json_array_size(ss) != n)
            return plume_err_set(err, PLUME_EINVAL,
                                 "fit request: targets[%zu] needs \"angle\" and \"strain\", \"stress\" lists of equal "
                                 "length >= 2",
                                 i);
        angles[*nt] = json_number_value(a);
        if (!(angles[*nt] >= 0.0 && angles[*nt] <= 180.0))
            return plume_err_set(err, PLUME_EINVAL, "fit request: targets[%zu].angle must be in [0, 180] (got %g)", i,
                                 angles[*nt]);
        plume_curve *cv = &curves[(*nt)++];
        cv->n = (plume_index)n;
        cv->strain = calloc(n, sizeof(double)), cv->stress = calloc(n, sizeof(double));
        cv->wbar = calloc(n, sizeof(double)), cv->iterations = calloc(n, sizeof(double));
        cv->seconds = calloc(n, sizeof(double));
        if (!cv->strain || !cv->stress || !cv->wbar || !cv->iterations || !cv->seconds)
            return plume_err_set(err, PLUME_ENOMEM, "fit: out of memory");
        for (size_t k = 0; k < n; k++) {
            json_t *x = json_array_get(se, k), *y = json_array_get(ss, k);
            if (!json_is_number(x) || !json_is_number(y))
                return plume_err_set(err, PLUME_EINVAL, "fit request: targets[%zu] point %zu is not a number", i, k);
            cv->strain[k] = json_number_value(x), cv->stress[k] = json_number_value(y);
        }
        *strain_max = fmax(*strain_max, cv->strain[n - 1]);
    }
    return PLUME_OK;
}

plume_status plume_flat_fit(const char *request, char **result, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!result)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "fit: no result pointer"), &err, msg, nmsg);
    *result = NULL;
    static const char *const keys[] = {"targets", "start", "free", "max_eval", "xtol_rel", "lx", "ly", "thickness",
                                       "kappa", "constraint", "mesh", "edge", "steps", "solver", NULL};
    json_t *req;
    plume_status st = plume_flat_parse_request(request, "fit", keys, &req, &err);
    if (st != PLUME_OK)
        return plume_flat_finish(st, &err, msg, nmsg);
    plume_curve curves[FLAT_MAX_TARGETS];
    double angles[FLAT_MAX_TARGETS];
    memset(curves, 0, sizeof curves);
    int nt = 0;
    plume_flat_traction_setup t;
    plume_fit_opts fo;
    plume_fit_opts_default(&fo);
    plume_ortho start = {0.0, 0.0, 0.0, 0.0}, fit;
    double strain_max = 0.0;
    if ((st = plume_flat_get_traction_setup(req, "fit", &t, &err)) != PLUME_OK ||
        (st = plume_flat_get_int(req, "fit", "max_eval", &fo.max_eval, &err)) != PLUME_OK ||
        (st = plume_flat_get_number(req, "fit", "xtol_rel", &fo.xtol_rel, &err)) != PLUME_OK ||
        (st = get_fit_start(req, &start, &err)) != PLUME_OK || (st = get_fit_free(req, &fo.free_mask, &err)) != PLUME_OK ||
        (st = get_fit_targets(req, curves, angles, &nt, &strain_max, &err)) != PLUME_OK)
        goto done;
    plume_macro_model mm = {t.lx, t.ly, t.h, t.edge, t.mesh, t.constraint, t.kappa, strain_max, t.steps, nt, angles,
                            t.solver};
    plume_fit_report rep;
    if ((st = plume_fit_moduli(plume_macro_model_curve, &mm, curves, nt, &start, &fo, &fit, &rep, &err)) != PLUME_OK)
        goto done;
    st = plume_flat_emit(json_pack("{s:f, s:f, s:f, s:f, s:f, s:i, s:s, s:f}", "E_xx", fit.E_xx, "E_yy", fit.E_yy, "nu_xy",
                         fit.nu_xy, "G_xy", fit.G_xy, "residual", rep.residual, "evaluations", rep.evaluations, "stop",
                         rep.stop, "seconds", rep.seconds),
                         result, &err);
done:
    for (int k = 0; k < nt; k++)
        plume_curve_free(&curves[k]);
    json_decref(req);
    return plume_flat_finish(st, &err, msg, nmsg);
}
