/* plume: fitting macroscale moduli to traction curves with NLopt (micro/fit.h), and reading
 * measured curves from text files.
 *
 * Decisions (see the comments at each place):
 * - Search variables: ln E_xx, ln E_yy, ln G_xy (positive by construction, steps are relative)
 *   and nu_xy linearly in [-0.49, 0.49]. The model never sees a plane-stress tensor that is not
 *   positive definite (nu_xy^2 E_yy / E_xx >= 1): a free nu_xy is pulled back onto the limit with
 *   an exact penalty (see objective()); with nu_xy fixed the point is refused with a large misfit.
 * - NLopt sees the mean square of the relative misfits; the report gives its square root (the RMS
 *   of the header). The square is smooth at a zero-residual optimum where the RMS is a cone, which
 *   suits BOBYQA's quadratic models (measured on the synthetic test: see tests/test_fit.c).
 * - LN_BOBYQA for every dimension, 1 included (NLopt 2.7 accepts n = 1; Powell's original
 *   required n >= 2); if it refuses to start (NLOPT_INVALID_ARGS before any evaluation, as an
 *   older NLopt might for n = 1) the fit is rerun with LN_NELDERMEAD.
 * - Stopping: xtol_abs = xtol_rel on every variable (an absolute step in ln E is a relative step
 *   in E; nu_xy is of order one), and max_eval. */
#include "fit.h"
#include "../lib/core/opts.h"
#include "../lib/io/input_file.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <time.h>

#include <nlopt.h>

/* Misfit (RMS units) of an evaluation where the model is infeasible or the moduli are not
 * admissible; squared before it reaches NLopt. */
#define FIT_PENALTY 1e3
/* Relative misfit of a target point the model curve does not reach (a model run that stopped). */
#define FIT_MISSING 1.0
/* Half-width (log space) of the box around the start moduli: three decades each way. */
#define FIT_LOG_SPAN 6.907755278982137 /* ln(1e3) */
/* A target point at most this fraction of the model's end segment beyond the model's range is
 * extrapolated (grids that differ by half a step); the slack absorbs rounding of the strains. */
#define FIT_EXTRAP_FRACTION (0.5 * (1.0 + 1e-9))
/* Initial step: a factor 2 on the moduli, 0.05 on nu_xy. */
#define FIT_LOG_STEP 0.6931471805599453 /* ln(2) */
#define FIT_NU_STEP 0.05
#define FIT_NU_BOUND 0.49
/* Largest nu_xy^2 E_yy / E_xx the model is run at (1 would be a singular plane-stress tensor). */
#define FIT_PD_LIMIT 0.999
/* Denominator floor relative to the largest |stress| of the curve (header). */
#define FIT_STRESS_FLOOR 1e-3

void plume_fit_opts_default_sized(plume_fit_opts *o, size_t size)
{
    if (!o)
        return;
    static const plume_fit_opts full = {.size = sizeof full,
                                        .free_mask = PLUME_FIT_EYY | PLUME_FIT_GXY,
                                        .max_eval = 300,
                                        .xtol_rel = 1e-6,
                                        .min_strain = 1e-12};
    plume_opts_give(o, size, &full, sizeof full);
}

/* ------------------------------------------------------------------- objective ---- */

typedef struct {
    plume_fit_model model;
    void *ctx;
    const plume_curve *targets;
    int ncurves;
    const double *floor;  /* per curve: FIT_STRESS_FLOOR * max |target stress| */
    double min_strain;
    long npoints;         /* target points used (|strain| >= min_strain) */
    plume_ortho base;     /* start moduli: the fixed ones are taken from here */
    int which[4];         /* which[k]: modulus index (0 E_xx, 1 E_yy, 2 nu, 3 G_xy) of x[k] */
    unsigned n;
    nlopt_opt opt;        /* to force_stop on a model error */
    int evaluations;
    int feasible;         /* evaluations where every curve ran */
    int nu_free;
    double best_f;        /* best objective so far among feasible evaluations, */
    double best_ms;       /* its mean square misfit */
    plume_ortho best_m;   /* and the moduli the model ran at (nu_xy pulled back if needed) */
    plume_status status;  /* first model error (stops the fit) */
    plume_err cb_err;     /* the callback's message */
} fit_data;

static void x_to_moduli(const fit_data *d, const double *x, plume_ortho *m)
{
    *m = d->base;
    for (unsigned k = 0; k < d->n; k++) {
        switch (d->which[k]) {
        case 0: m->E_xx = exp(x[k]); break;
        case 1: m->E_yy = exp(x[k]); break;
        case 2: m->nu_xy = x[k]; break;
        default: m->G_xy = exp(x[k]); break;
        }
    }
}

/* nu_xy^2 E_yy / E_xx < 1 with positive moduli: the plane-stress tensor of docs/design.md is PD. */
static double pd_margin(const plume_ortho *m)
{
    return 1.0 - m->nu_xy * m->nu_xy * m->E_yy / m->E_xx;
}

/* Sum of squared relative misfits of target curve `t` against model curve `mc`. Model points
 * after the first non-finite one are ignored (a run that broke down); strains must then be
 * non-decreasing. A target point is interpolated linearly on the model segment that holds it,
 * extrapolated linearly from the end segment if it lies at most half that segment beyond the
 * model's range (grids that differ by rounding or half a step), and counted as FIT_MISSING if the
 * model curve stops short of it. Returns PLUME_EINVAL (message set) on an unsorted model curve. */
static plume_status curve_misfit(const fit_data *d, int ic, const plume_curve *mc, double *sum,
                                 plume_err *err)
{
    const plume_curve *t = &d->targets[ic];
    plume_index m = 0;
    if (mc->n > 0 && (!mc->strain || !mc->stress))
        return plume_err_set(err, PLUME_EINVAL,
                             "fit: the model returned curve %d with %ld points but no strain or "
                             "stress array", ic, (long)mc->n);
    while (m < mc->n && isfinite(mc->strain[m]) && isfinite(mc->stress[m]))
        m++;
    for (plume_index k = 1; k < m; k++)
        if (mc->strain[k] < mc->strain[k - 1])
            return plume_err_set(err, PLUME_EINVAL,
                                 "fit: the model's curve %d is not sorted by strain (point %ld: "
                                 "%g after %g)", ic, (long)k, mc->strain[k], mc->strain[k - 1]);
    /* first and last segments of positive length, for extrapolation */
    plume_index lo = 0, hi = m - 1;
    while (lo + 1 < m && !(mc->strain[lo + 1] > mc->strain[lo]))
        lo++;
    while (hi > 0 && !(mc->strain[hi] > mc->strain[hi - 1]))
        hi--;
    int usable = lo + 1 < m; /* some segment has positive length (then hi >= 1 too) */

    double s = 0.0;
    for (plume_index i = 0; i < t->n; i++) {
        double e = t->strain[i];
        if (fabs(e) < d->min_strain)
            continue;
        double denom = fabs(t->stress[i]) > d->floor[ic] ? fabs(t->stress[i]) : d->floor[ic];
        double r = FIT_MISSING;
        if (usable) {
            const double *xs = mc->strain, *ys = mc->stress;
            double y = NAN;
            plume_index a = -1;
            if (e < xs[0]) {
                if (xs[0] - e <= FIT_EXTRAP_FRACTION * (xs[lo + 1] - xs[lo]))
                    a = lo;
            } else if (e > xs[m - 1]) {
                if (e - xs[m - 1] <= FIT_EXTRAP_FRACTION * (xs[hi] - xs[hi - 1]))
                    a = hi - 1;
            } else {
                /* bisection keeps xs[l] <= e <= xs[u] */
                plume_index l = 0, u = m - 1;
                while (u - l > 1) {
                    plume_index mid = l + (u - l) / 2;
                    if (xs[mid] <= e)
                        l = mid;
                    else
                        u = mid;
                }
                if (xs[u] > xs[l])
                    a = l;
                else
                    y = ys[u]; /* e sits on a repeated strain: take the later point */
            }
            if (a >= 0) {
                double w = (e - xs[a]) / (xs[a + 1] - xs[a]);
                y = ys[a] + w * (ys[a + 1] - ys[a]);
            }
            if (!isnan(y)) {
                r = (y - t->stress[i]) / denom;
                if (!isfinite(r))
                    r = FIT_MISSING;
            }
        }
        s += r * r;
    }
    *sum = s;
    return PLUME_OK;
}

/* Runs the model on every curve at `m`; *ms is the mean square relative misfit. Returns PLUME_OK,
 * PLUME_EINFEASIBLE, or a model error (message in d->cb_err). */
static plume_status run_model(fit_data *d, const plume_ortho *m, double *ms)
{
    double sum = 0.0;
    for (int ic = 0; ic < d->ncurves; ic++) {
        plume_curve mc;
        memset(&mc, 0, sizeof mc);
        d->cb_err.msg[0] = '\0';
        plume_status s = d->model(d->ctx, m, ic, &mc, &d->cb_err);
        double cs = 0.0;
        if (s == PLUME_OK)
            s = curve_misfit(d, ic, &mc, &cs, &d->cb_err);
        plume_curve_free(&mc);
        if (s == PLUME_EINFEASIBLE)
            return s;
        if (s != PLUME_OK) {
            if (!d->cb_err.msg[0])
                plume_err_set(&d->cb_err, s, "fit: the model failed on curve %d (%s)", ic,
                              plume_strerror(s));
            return s;
        }
        sum += cs;
    }
    *ms = sum / (double)d->npoints;
    return PLUME_OK;
}

/* NLopt's objective: the mean square relative misfit (plus the PD penalty below). */
static double objective(unsigned n, const double *x, double *grad, void *data)
{
    (void)n;
    (void)grad; /* derivative-free algorithms only */
    fit_data *d = data;
    if (d->status != PLUME_OK) /* a model error already asked NLopt to stop */
        return HUGE_VAL;
    d->evaluations++;
    plume_ortho m;
    x_to_moduli(d, x, &m);

    double viol = 0.0;
    if (!(pd_margin(&m) >= 1.0 - FIT_PD_LIMIT)) {
        if (!d->nu_free) {
            /* nu_xy is fixed: refused without running the model, with a misfit that grows with
             * the violation so the search is pushed back */
            double v = FIT_PENALTY * (2.0 - pd_margin(&m));
            return v * v;
        }
        /* nu_xy is free: the model runs at nu_xy pulled back onto the PD limit and the distance
         * pulled back is added (an exact penalty). The objective stays continuous across the
         * limit, which BOBYQA's quadratic models need: with a large misfit there instead it stalled
         * on the limit when the optimum lies near it (test_fit_poisson: nu_xy 0.489 and E_yy 58 %
         * off, against the exact answer in 56 evaluations now). */
        double lim = sqrt(FIT_PD_LIMIT * m.E_xx / m.E_yy);
        viol = fabs(m.nu_xy) - lim;
        m.nu_xy = m.nu_xy > 0 ? lim : -lim;
    }
    double ms = 0.0;
    plume_status s = run_model(d, &m, &ms);
    if (s == PLUME_EINFEASIBLE)
        return FIT_PENALTY * FIT_PENALTY;
    if (s != PLUME_OK) {
        d->status = s;
        nlopt_force_stop(d->opt);
        return HUGE_VAL;
    }
    d->feasible++;
    double f = ms + viol;
    if (f < d->best_f) {
        d->best_f = f;
        d->best_ms = ms;
        d->best_m = m;
    }
    return f;
}

static const char *stop_text(nlopt_result r)
{
    switch (r) {
    case NLOPT_SUCCESS: return "success";
    case NLOPT_STOPVAL_REACHED: return "stopval reached";
    case NLOPT_FTOL_REACHED: return "ftol reached";
    case NLOPT_XTOL_REACHED: return "xtol reached";
    case NLOPT_MAXEVAL_REACHED: return "maxeval reached";
    case NLOPT_MAXTIME_REACHED: return "maxtime reached";
    case NLOPT_FAILURE: return "failure";
    case NLOPT_INVALID_ARGS: return "invalid arguments";
    case NLOPT_OUT_OF_MEMORY: return "out of memory";
    case NLOPT_ROUNDOFF_LIMITED: return "roundoff limited";
    case NLOPT_FORCED_STOP: return "forced stop";
    default: return "unknown NLopt result";
    }
}

static const char *alg_name(nlopt_algorithm a)
{
    return a == NLOPT_LN_BOBYQA ? "LN_BOBYQA" : "LN_NELDERMEAD";
}

static double now_seconds(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One NLopt run with `alg` from x (in/out). Returns NLopt's result; *created is 0 if NLopt could
 * not even allocate the optimiser. */
static nlopt_result run_nlopt(nlopt_algorithm alg, fit_data *d, const double *lb, const double *ub,
                              const double *step, const double *xtol, int max_eval, double *x,
                              int *created)
{
    double fbest = HUGE_VAL;
    nlopt_opt opt = nlopt_create(alg, d->n);
    *created = opt != NULL;
    if (!opt)
        return NLOPT_OUT_OF_MEMORY;
    nlopt_result r = nlopt_set_min_objective(opt, objective, d);
    if (r > 0)
        r = nlopt_set_lower_bounds(opt, lb);
    if (r > 0)
        r = nlopt_set_upper_bounds(opt, ub);
    if (r > 0)
        r = nlopt_set_initial_step(opt, step);
    if (r > 0)
        r = nlopt_set_xtol_abs(opt, xtol);
    if (r > 0)
        r = nlopt_set_maxeval(opt, max_eval);
    if (r > 0) {
        d->opt = opt;
        r = nlopt_optimize(opt, x, &fbest);
        d->opt = NULL;
    }
    nlopt_destroy(opt);
    return r;
}

/* Checks one target curve; returns PLUME_OK or PLUME_EINVAL with a message. */
static plume_status check_target(const plume_curve *c, int ic, plume_err *err)
{
    if (c->n < 2)
        return plume_err_set(err, PLUME_EINVAL, "fit: target curve %d has %ld point(s); at least 2 "
                             "are needed", ic, (long)c->n);
    if (!c->strain || !c->stress)
        return plume_err_set(err, PLUME_EINVAL, "fit: target curve %d has no strain or stress array",
                             ic);
    for (plume_index i = 0; i < c->n; i++)
        if (!isfinite(c->strain[i]) || !isfinite(c->stress[i]))
            return plume_err_set(err, PLUME_EINVAL, "fit: target curve %d, point %ld: non-finite "
                                 "value (strain %g, stress %g)", ic, (long)i, c->strain[i],
                                 c->stress[i]);
    return PLUME_OK;
}

/* The checks of plume_fit_moduli's arguments, options, start moduli and target curves. */
static plume_status check_fit_inputs(plume_fit_model model, const plume_curve *targets, int ncurves,
                                     const plume_ortho *start, const plume_fit_opts *o, const plume_ortho *result,
                                     plume_err *err)
{
    if (!model)
        return plume_err_set(err, PLUME_EINVAL, "fit: no model callback");
    if (!start || !result)
        return plume_err_set(err, PLUME_EINVAL, "fit: no %s moduli", !start ? "start" : "result");
    if (ncurves <= 0)
        return plume_err_set(err, PLUME_EINVAL, "fit: %d target curves; at least one is needed",
                             ncurves);
    if (!targets)
        return plume_err_set(err, PLUME_EINVAL, "fit: no target curves (NULL)");
    if (o->free_mask == 0 ||
        (o->free_mask & ~(unsigned)(PLUME_FIT_EXX | PLUME_FIT_EYY | PLUME_FIT_NU | PLUME_FIT_GXY)))
        return plume_err_set(err, PLUME_EINVAL, "fit: free_mask 0x%x must be a non-empty "
                             "combination of PLUME_FIT_EXX, _EYY, _NU, _GXY", o->free_mask);
    if (o->max_eval < 1)
        return plume_err_set(err, PLUME_EINVAL, "fit: max_eval %d must be at least 1", o->max_eval);
    if (!(o->xtol_rel > 0.0) || !isfinite(o->xtol_rel))
        return plume_err_set(err, PLUME_EINVAL, "fit: xtol_rel %g must be finite and > 0",
                             o->xtol_rel);
    if (!(o->min_strain >= 0.0) || !isfinite(o->min_strain))
        return plume_err_set(err, PLUME_EINVAL, "fit: min_strain %g must be finite and >= 0",
                             o->min_strain);
    const double mv[3] = {start->E_xx, start->E_yy, start->G_xy};
    const char *mn[3] = {"E_xx", "E_yy", "G_xy"};
    for (int i = 0; i < 3; i++)
        if (!(mv[i] > 0.0) || !isfinite(mv[i]))
            return plume_err_set(err, PLUME_EINVAL, "fit: start %s = %g must be finite and > 0",
                                 mn[i], mv[i]);
    if (!isfinite(start->nu_xy) || !(pd_margin(start) > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "fit: start nu_xy = %g is not admissible "
                             "(need nu_xy^2 E_yy/E_xx < 1)", start->nu_xy);
    if ((o->free_mask & PLUME_FIT_NU) && fabs(start->nu_xy) > FIT_NU_BOUND)
        return plume_err_set(err, PLUME_EINVAL, "fit: start nu_xy = %g is outside the search "
                             "range [-%g, %g] of a free nu_xy", start->nu_xy, FIT_NU_BOUND,
                             FIT_NU_BOUND);
    for (int ic = 0; ic < ncurves; ic++) {
        const plume_status s = check_target(&targets[ic], ic, err);
        if (s != PLUME_OK)
            return s;
    }
    return PLUME_OK;
}

/* Each target curve's stress floor (floor_[ic], FIT_STRESS_FLOOR of its largest |stress|) and the
 * number of target points used (|strain| >= min_strain) into *npoints. */
static plume_status target_floors(const plume_curve *targets, int ncurves, double min_strain, double *floor_,
                                  long *npoints, plume_err *err)
{
    for (int ic = 0; ic < ncurves; ic++) {
        const plume_curve *c = &targets[ic];
        double mx = 0.0;
        long used = 0;
        for (plume_index i = 0; i < c->n; i++) {
            mx = fmax(mx, fabs(c->stress[i]));
            used += fabs(c->strain[i]) >= min_strain;
        }
        if (used > 0 && !(mx > 0.0))
            return plume_err_set(err, PLUME_EINVAL, "fit: target curve %d has only zero stresses; "
                                 "its relative misfit is undefined", ic);
        floor_[ic] = FIT_STRESS_FLOOR * mx;
        *npoints += used;
    }
    if (*npoints == 0)
        return plume_err_set(err, PLUME_EINVAL, "fit: no target point has |strain| >= min_strain = %g",
                             min_strain);
    return PLUME_OK;
}

/* The search space: the free moduli of o->free_mask into d->which and d->n, with their start x,
 * bounds, initial steps and tolerances (log space for the moduli, linear for nu_xy). */
static void search_space(fit_data *d, const plume_ortho *start, const plume_fit_opts *o, double x[4], double lb[4],
                         double ub[4], double step[4], double xtol[4])
{
    static const unsigned bits[4] = {PLUME_FIT_EXX, PLUME_FIT_EYY, PLUME_FIT_NU, PLUME_FIT_GXY};
    const double v[4] = {start->E_xx, start->E_yy, start->nu_xy, start->G_xy};
    for (int i = 0; i < 4; i++) {
        if (!(o->free_mask & bits[i]))
            continue;
        unsigned k = d->n++;
        d->which[k] = i;
        if (i == 2) {
            x[k] = v[i];
            lb[k] = -FIT_NU_BOUND;
            ub[k] = FIT_NU_BOUND;
            step[k] = FIT_NU_STEP;
        } else {
            x[k] = log(v[i]);
            lb[k] = x[k] - FIT_LOG_SPAN;
            ub[k] = x[k] + FIT_LOG_SPAN;
            step[k] = FIT_LOG_STEP;
        }
        xtol[k] = o->xtol_rel;
    }
}

/* What the search ended with, as a status: the model's error, NLopt's own failures, or no feasible
 * evaluation at all. */
static plume_status fit_outcome(const fit_data *d, nlopt_result r, nlopt_algorithm alg, plume_err *err)
{
    if (d->status != PLUME_OK)
        return plume_err_set(err, d->status, "%s", d->cb_err.msg);
    if (r == NLOPT_OUT_OF_MEMORY)
        return plume_err_set(err, PLUME_ENOMEM, "fit: NLopt (%s) ran out of memory", alg_name(alg));
    /* roundoff-limited still carries a useful best point (NLopt's documentation); other
     * failures before any evaluation are NLopt's */
    if (r < 0 && r != NLOPT_ROUNDOFF_LIMITED && d->evaluations == 0)
        return plume_err_set(err, PLUME_EDEP, "fit: NLopt %s failed to start: %s", alg_name(alg),
                             stop_text(r));
    if (d->feasible == 0)
        return plume_err_set(err, PLUME_EINFEASIBLE, "fit: the model was infeasible at every one of "
                             "the %d evaluated moduli", d->evaluations);
    return PLUME_OK;
}

/* `o` and `rep` may be NULL (defaults, no report). On error *result is left unchanged. */
plume_status plume_fit_moduli(plume_fit_model model, void *ctx, const plume_curve *targets, int ncurves,
                              const plume_ortho *start, const plume_fit_opts *o, plume_ortho *result,
                              plume_fit_report *rep, plume_err *err)
{
    double t0 = now_seconds();
    plume_status s = PLUME_OK;
    double *floor_ = NULL;
    plume_fit_opts def; /* the caller's options (as many bytes as it has) over the defaults */
    plume_fit_opts_default(&def);
    if (o && plume_opts_take(&def, sizeof def, o, "plume_fit_opts", err) != PLUME_OK)
        return PLUME_EINVAL;
    o = &def;
    if (rep) {
        memset(rep, 0, sizeof *rep);
        rep->residual = NAN;
        snprintf(rep->stop, sizeof rep->stop, "not started");
    }
    if ((s = check_fit_inputs(model, targets, ncurves, start, o, result, err)) != PLUME_OK)
        return s;

    fit_data d;
    memset(&d, 0, sizeof d);
    floor_ = malloc((size_t)ncurves * sizeof *floor_);
    if (!floor_)
        return plume_err_set(err, PLUME_ENOMEM, "fit: out of memory for %d curves", ncurves);
    if ((s = target_floors(targets, ncurves, o->min_strain, floor_, &d.npoints, err)) != PLUME_OK)
        goto cleanup;
    d.model = model;
    d.ctx = ctx;
    d.targets = targets;
    d.ncurves = ncurves;
    d.floor = floor_;
    d.min_strain = o->min_strain;
    d.base = *start;
    d.best_f = HUGE_VAL;
    d.nu_free = (o->free_mask & PLUME_FIT_NU) != 0;
    double x[4], lb[4], ub[4], step[4], xtol[4];
    search_space(&d, start, o, x, lb, ub, step, xtol);

    /* BOBYQA, or Nelder-Mead from the same start where BOBYQA refuses the problem before evaluating */
    double x0[4];
    memcpy(x0, x, sizeof x);
    int created = 0;
    nlopt_algorithm alg = NLOPT_LN_BOBYQA;
    nlopt_result r = run_nlopt(alg, &d, lb, ub, step, xtol, o->max_eval, x, &created);
    if (r == NLOPT_INVALID_ARGS && d.evaluations == 0 && created) {
        alg = NLOPT_LN_NELDERMEAD;
        memcpy(x, x0, sizeof x);
        r = run_nlopt(alg, &d, lb, ub, step, xtol, o->max_eval, x, &created);
    }
    if (rep) {
        rep->evaluations = d.evaluations;
        rep->nlopt_result = (int)r;
        snprintf(rep->stop, sizeof rep->stop, "%s", stop_text(r));
        rep->residual = d.feasible > 0 ? sqrt(d.best_ms) : NAN;
    }
    if ((s = fit_outcome(&d, r, alg, err)) != PLUME_OK)
        goto cleanup;
    *result = d.best_m;

cleanup:
    free(floor_);
    if (rep)
        rep->seconds = now_seconds() - t0;
    return s;
}

/* ------------------------------------------------------------------ text curves ---- */

static const char *skip_blank(const char *p)
{
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\v' || *p == '\f')
        p++;
    return p;
}

/* Parses "a b", "a,b", "a , b", "a\tb" (nothing else on the line). Returns 2 on success, 0 if the
 * first token is not a number, 1 otherwise. */
static int parse_pair(const char *line, double *a, double *b)
{
    const char *p = skip_blank(line);
    char *end;
    errno = 0;
    *a = strtod(p, &end);
    if (end == p)
        return 0;
    p = skip_blank(end);
    if (*p == ',')
        p = skip_blank(p + 1);
    else if (p == end) /* no separator between the numbers */
        return 1;
    const char *q = p;
    *b = strtod(q, &end);
    if (end == q)
        return 1;
    p = skip_blank(end);
    return *p == '\0' ? 2 : 1;
}

/* Appends one point, growing the arrays geometrically. */
static int push_point(double **st, double **ss, size_t *n, size_t *cap, double a, double b)
{
    if (*n == *cap) {
        size_t nc = *cap ? 2 * *cap : 64;
        double *t1 = realloc(*st, nc * sizeof *t1);
        if (!t1)
            return 0;
        *st = t1;
        double *t2 = realloc(*ss, nc * sizeof *t2);
        if (!t2)
            return 0;
        *ss = t2;
        *cap = nc;
    }
    (*st)[*n] = a;
    (*ss)[*n] = b;
    (*n)++;
    return 1;
}

plume_status plume_curve_read_text(const char *path, plume_curve *out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "curve text file: no output curve");
    memset(out, 0, sizeof *out);
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "curve text file: empty path");

    plume_status s = PLUME_OK;
    double *st = NULL, *ss = NULL;
    size_t n = 0, cap = 0;
    char *line = NULL;
    size_t linecap = 0;
    long lineno = 0;
    int seen_content = 0; /* a header may only be the first non-comment line */
    FILE *f = plume_input_fopen(path, "r", NULL, err);
    if (!f)
        return PLUME_EIO;
    ssize_t len;
    while ((len = getline(&line, &linecap, f)) >= 0) {
        lineno++;
        if ((size_t)len != strlen(line)) {
            s = plume_err_set(err, PLUME_EFORMAT, "%s:%ld: NUL byte in a text file", path, lineno);
            goto cleanup;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        line[strcspn(line, "\n")] = '\0';
        if (*skip_blank(line) == '\0')
            continue;
        double a = 0.0, b = 0.0;
        int k = parse_pair(line, &a, &b);
        if (k != 2 && !seen_content) {
            const char *p = skip_blank(line);
            if (isalpha((unsigned char)*p)) { /* a header line of words, once, before the data */
                seen_content = 1;
                continue;
            }
        }
        seen_content = 1;
        if (k != 2) {
            s = plume_err_set(err, PLUME_EFORMAT, "%s:%ld: expected two numbers (strain, stress)",
                              path, lineno);
            goto cleanup;
        }
        if (!isfinite(a) || !isfinite(b)) {
            s = plume_err_set(err, PLUME_EFORMAT, "%s:%ld: non-finite value (strain %g, stress %g)",
                              path, lineno, a, b);
            goto cleanup;
        }
        if (n > 0 && a < st[n - 1]) {
            s = plume_err_set(err, PLUME_EFORMAT, "%s:%ld: strain %g is below the previous %g; "
                              "strains must be non-decreasing", path, lineno, a, st[n - 1]);
            goto cleanup;
        }
        if (!push_point(&st, &ss, &n, &cap, a, b)) {
            s = plume_err_set(err, PLUME_ENOMEM, "%s:%ld: out of memory", path, lineno);
            goto cleanup;
        }
    }
    if (ferror(f)) {
        int e = errno;
        s = plume_err_set(err, PLUME_EIO, "%s: read error: %s", path, strerror(e));
        goto cleanup;
    }
    if (n < 2) {
        s = plume_err_set(err, PLUME_EFORMAT, "%s: %zu data point(s); at least 2 are needed", path,
                          n);
        goto cleanup;
    }
    out->wbar = calloc(n, sizeof *out->wbar);
    out->iterations = calloc(n, sizeof *out->iterations);
    out->seconds = calloc(n, sizeof *out->seconds);
    if (!out->wbar || !out->iterations || !out->seconds) {
        s = plume_err_set(err, PLUME_ENOMEM, "%s: out of memory for %zu points", path, n);
        goto cleanup;
    }
    out->strain = st;
    out->stress = ss;
    out->n = (plume_index)n;
    st = ss = NULL;

cleanup:
    free(line);
    fclose(f);
    free(st);
    free(ss);
    if (s != PLUME_OK)
        plume_curve_free(out);
    return s;
}
