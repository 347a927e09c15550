/* Tests of micro/fit.c: fitting moduli to curves with NLopt against closed-form model callbacks
 * (exact answers known), model errors and infeasible points, bad inputs, and the text curve reader
 * (scratch files in a mkdtemp directory under /tmp, removed by each test). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "../micro/fit.h"

/* ------------------------------------------------------------- synthetic model ---- */

/* Closed-form "traction curves" of the moduli:
 *   curve 0: E_yy e + 0.3 G_xy e^2
 *   curve 1: G_xy e (1 + e) + 0.1 E_yy e
 *   curve 2: (1 + nu_xy) E_yy e
 * evaluated at the target's own strains (as an app runs traction at the measured steps), so the
 * fitter's interpolation is exact and the true moduli give a zero misfit. */
typedef struct {
    const plume_curve *targets;
    int calls;              /* callback calls (one per curve per evaluation) */
    int fail_at;            /* if > 0: this call returns fail_status with a message */
    plume_status fail_status;
    double infeasible_G;    /* if > 0: G_xy above it is reported infeasible */
    int always_infeasible;
    int infeasible_hits;
    int not_pd_seen;        /* moduli handed to the model with a non-PD plane-stress tensor */
    int at_pd_limit;        /* ... with nu_xy^2 E_yy / E_xx within 1e-9 of the fitter's 0.999 */
} synth;

static double synth_stress(const plume_ortho *m, int ic, double e)
{
    switch (ic) {
    case 0: return m->E_yy * e + 0.3 * m->G_xy * e * e;
    case 1: return m->G_xy * e * (1.0 + e) + 0.1 * m->E_yy * e;
    default: return (1.0 + m->nu_xy) * m->E_yy * e;
    }
}

static int alloc_curve(plume_curve *c, plume_index n)
{
    c->n = n;
    c->strain = calloc((size_t)n, sizeof(double));
    c->stress = calloc((size_t)n, sizeof(double));
    c->wbar = calloc((size_t)n, sizeof(double));
    c->iterations = calloc((size_t)n, sizeof(double));
    c->seconds = calloc((size_t)n, sizeof(double));
    return c->strain && c->stress && c->wbar && c->iterations && c->seconds;
}

static plume_status synth_model(void *ctx, const plume_ortho *m, int ic, plume_curve *out, plume_err *err)
{
    synth *s = ctx;
    s->calls++;
    double pd = m->nu_xy * m->nu_xy * m->E_yy / m->E_xx;
    if (pd >= 1.0)
        s->not_pd_seen++;
    if (fabs(pd - 0.999) < 1e-9)
        s->at_pd_limit++;
    if (s->fail_at > 0 && s->calls == s->fail_at)
        return plume_err_set(err, s->fail_status, "synthetic model: disk failure at call %d", s->calls);
    if (s->always_infeasible || (s->infeasible_G > 0 && m->G_xy > s->infeasible_G)) {
        s->infeasible_hits++;
        return plume_err_set(err, PLUME_EINFEASIBLE, "synthetic model: did not converge");
    }
    const plume_curve *t = &s->targets[ic];
    if (!alloc_curve(out, t->n))
        return plume_err_set(err, PLUME_ENOMEM, "synthetic model: out of memory");
    for (plume_index i = 0; i < t->n; i++) {
        out->strain[i] = t->strain[i];
        out->stress[i] = synth_stress(m, ic, t->strain[i]);
    }
    return PLUME_OK;
}

/* Target curves 0..ncurves-1 from moduli `m`, strains 0, 0.005, ..., 0.05 (the 0 point is skipped
 * by the fitter's min_strain). */
static void make_targets(plume_curve *t, int ncurves, const plume_ortho *m)
{
    for (int ic = 0; ic < ncurves; ic++) {
        memset(&t[ic], 0, sizeof t[ic]);
        alloc_curve(&t[ic], 11);
        for (int i = 0; i < 11; i++) {
            t[ic].strain[i] = 0.005 * i;
            t[ic].stress[i] = synth_stress(m, ic, t[ic].strain[i]);
        }
    }
}

static void free_targets(plume_curve *t, int ncurves)
{
    for (int ic = 0; ic < ncurves; ic++)
        plume_curve_free(&t[ic]);
}

static const plume_ortho truth = {1e8, 3.2e4, 0.3, 1.7e4};

/* ---------------------------------------------------------------------- fitting ---- */

void test_fit_recovers_moduli(void)
{
    plume_curve t[2];
    make_targets(t, 2, &truth);
    synth s = {.targets = t};
    plume_ortho start = {1e8, 1e4, 0.3, 5e4}, res = {0, 0, 0, 0};
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    CHECK(o.free_mask == (PLUME_FIT_EYY | PLUME_FIT_GXY) && o.max_eval == 300 && o.xtol_rel == 1e-6 &&
          o.min_strain == 1e-12);
    plume_fit_report rep;
    plume_err err = {{0}};
    plume_status st = plume_fit_moduli(synth_model, &s, t, 2, &start, &o, &res, &rep, &err);
    CHECK(st == PLUME_OK);
    fprintf(stderr, "    E_yy %.9g G_xy %.9g: %d evaluations, residual %.3g, %s (%d), %.3f s\n",
            res.E_yy, res.G_xy, rep.evaluations, rep.residual, rep.stop, rep.nlopt_result, rep.seconds);
    CHECK_REL(res.E_yy, truth.E_yy, 1e-4, 0.0);
    CHECK_REL(res.G_xy, truth.G_xy, 1e-4, 0.0);
    CHECK(res.E_xx == start.E_xx && res.nu_xy == start.nu_xy); /* fixed moduli untouched */
    CHECK(rep.evaluations >= 1 && rep.evaluations <= o.max_eval);
    CHECK(s.calls == 2 * rep.evaluations);
    CHECK(rep.residual >= 0.0 && rep.residual < 1e-6);
    CHECK(rep.nlopt_result > 0);
    CHECK(strcmp(rep.stop, "xtol reached") == 0);
    CHECK(rep.seconds >= 0.0);

    /* NULL options mean the defaults, NULL report is allowed */
    s.calls = 0;
    plume_ortho res2;
    CHECK(plume_fit_moduli(synth_model, &s, t, 2, &start, NULL, &res2, NULL, NULL) == PLUME_OK);
    CHECK(res2.E_yy == res.E_yy && res2.G_xy == res.G_xy); /* deterministic */

    /* a tight evaluation budget stops on maxeval with the best point so far */
    o.max_eval = 7;
    CHECK(plume_fit_moduli(synth_model, &s, t, 2, &start, &o, &res2, &rep, &err) == PLUME_OK);
    CHECK(rep.evaluations == 7 && strcmp(rep.stop, "maxeval reached") == 0);
    CHECK(rep.residual > 1e-6);
    free_targets(t, 2);
}

void test_fit_one_free_modulus(void)
{
    plume_curve t[2];
    make_targets(t, 2, &truth);
    synth s = {.targets = t};
    plume_ortho start = {1e8, 1e4, 0.3, truth.G_xy}, res;
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    o.free_mask = PLUME_FIT_EYY;
    plume_fit_report rep;
    plume_err err = {{0}};
    CHECK(plume_fit_moduli(synth_model, &s, t, 2, &start, &o, &res, &rep, &err) == PLUME_OK);
    fprintf(stderr, "    n = 1: E_yy %.9g, %d evaluations, residual %.3g, %s\n", res.E_yy,
            rep.evaluations, rep.residual, rep.stop);
    CHECK_REL(res.E_yy, truth.E_yy, 1e-4, 0.0);
    CHECK(res.G_xy == truth.G_xy && res.E_xx == start.E_xx);
    CHECK(rep.residual < 1e-6 && rep.nlopt_result > 0 && rep.evaluations <= o.max_eval);
    free_targets(t, 2);
}

/* nu_xy is searched linearly; the model never sees a non-PD plane-stress tensor even where the
 * nu_xy box [-0.49, 0.49] reaches past the PD limit |nu_xy| < sqrt(E_xx/E_yy). */
void test_fit_poisson(void)
{
    plume_ortho tr = truth;
    tr.E_xx = 4.0 * tr.E_yy; /* PD limit |nu_xy| < 2: the whole box */
    plume_curve t[3];
    make_targets(t, 3, &tr);
    synth s = {.targets = t};
    plume_ortho start = {tr.E_xx, 1e4, 0.0, tr.G_xy}, res;
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    o.free_mask = PLUME_FIT_EYY | PLUME_FIT_NU;
    plume_fit_report rep;
    plume_err err = {{0}};
    CHECK(plume_fit_moduli(synth_model, &s, t, 3, &start, &o, &res, &rep, &err) == PLUME_OK);
    fprintf(stderr, "    E_yy %.9g nu %.9g: %d evaluations, residual %.3g\n", res.E_yy, res.nu_xy,
            rep.evaluations, rep.residual);
    CHECK_REL(res.E_yy, tr.E_yy, 1e-4, 0.0);
    CHECK_REL(res.nu_xy, tr.nu_xy, 1e-4, 0.0);
    CHECK(rep.residual < 1e-6);
    CHECK(s.not_pd_seen == 0 && s.at_pd_limit == 0);

    /* E_xx fixed low: PD needs nu_xy^2 < E_xx/E_yy, |nu_xy| < 0.57 at the start E_yy but < 0.32
     * at the truth (nu_xy = 0.3 there, close to the limit). From nu_xy = 0.45 the first step up
     * in E_yy (x2) is past the limit: the model runs at nu_xy pulled back onto it, and the truth
     * is still found. */
    synth s2 = {.targets = t};
    start.E_xx = 0.1 * tr.E_yy;
    start.nu_xy = 0.45;
    CHECK(plume_fit_moduli(synth_model, &s2, t, 3, &start, &o, &res, &rep, &err) == PLUME_OK);
    fprintf(stderr, "    E_xx = 0.1 E_yy: %d of %d evaluations pulled back onto the PD limit, "
            "nu %.9g, E_yy %.9g\n", s2.at_pd_limit / 3, rep.evaluations, res.nu_xy, res.E_yy);
    CHECK(s2.not_pd_seen == 0);
    CHECK(s2.at_pd_limit > 0);
    CHECK_REL(res.nu_xy, tr.nu_xy, 1e-4, 0.0);
    CHECK_REL(res.E_yy, tr.E_yy, 1e-4, 0.0);
    CHECK(res.E_xx == start.E_xx && res.G_xy == start.G_xy);

    /* nu_xy fixed at 0.45 with the same E_xx: E_yy cannot pass 0.999 E_xx/0.45^2 = 15.8e3 (the
     * truth 32e3 is out of reach); such points are refused without a model run */
    synth s3 = {.targets = t};
    o.free_mask = PLUME_FIT_EYY;
    CHECK(plume_fit_moduli(synth_model, &s3, t, 3, &start, &o, &res, &rep, &err) == PLUME_OK);
    int refused = rep.evaluations - s3.calls / 3;
    fprintf(stderr, "    nu fixed: %d of %d evaluations refused, E_yy %.9g\n", refused,
            rep.evaluations, res.E_yy);
    CHECK(s3.not_pd_seen == 0);
    CHECK(refused > 0);
    CHECK(res.nu_xy == 0.45);
    CHECK(res.E_yy < start.E_xx / (0.45 * 0.45) && res.E_yy > 0.99 * start.E_xx / (0.45 * 0.45));

    /* a start on the edge of the nu_xy box */
    synth s4 = {.targets = t};
    o.free_mask = PLUME_FIT_EYY | PLUME_FIT_NU;
    start.E_xx = tr.E_xx;
    start.nu_xy = 0.49;
    CHECK(plume_fit_moduli(synth_model, &s4, t, 3, &start, &o, &res, &rep, &err) == PLUME_OK);
    CHECK_REL(res.nu_xy, tr.nu_xy, 1e-4, 0.0);
    CHECK_REL(res.E_yy, tr.E_yy, 1e-4, 0.0);
    free_targets(t, 3);
}

/* A linear model on its own coarser grid: interpolation is exact for a linear response, targets
 * half a model step past its end are extrapolated, and a model curve that stops early (a run that
 * broke down: NaN after the third point) costs exactly 1 per missing point. */
typedef struct {
    int truncate;
    int unsorted;
} lin_model;

static plume_status linear_model(void *ctx, const plume_ortho *m, int ic, plume_curve *out, plume_err *err)
{
    lin_model *lm = ctx;
    if (!alloc_curve(out, 6))
        return plume_err_set(err, PLUME_ENOMEM, "linear model: out of memory");
    for (int i = 0; i < 6; i++) {
        out->strain[i] = 0.01 * i; /* 0 ... 0.05 */
        out->stress[i] = (ic == 0 ? m->E_yy : m->G_xy) * out->strain[i];
    }
    if (lm->truncate && ic == 1)
        out->strain[3] = out->stress[3] = NAN; /* the run failed after 0.02 */
    if (lm->unsorted)
        out->strain[4] = 0.001;
    return PLUME_OK;
}

void test_fit_interpolation(void)
{
    plume_curve t[2];
    for (int ic = 0; ic < 2; ic++) {
        memset(&t[ic], 0, sizeof t[ic]);
        alloc_curve(&t[ic], 23);
        for (int i = 0; i < 23; i++) { /* 0 ... 0.055: 0.055 is half a model step past 0.05 */
            t[ic].strain[i] = 0.0025 * i;
            t[ic].stress[i] = (ic == 0 ? truth.E_yy : truth.G_xy) * t[ic].strain[i];
        }
    }
    lin_model lm = {0, 0};
    plume_ortho start = {1e8, 1e4, 0.0, 5e4}, res;
    plume_fit_report rep;
    plume_err err = {{0}};
    CHECK(plume_fit_moduli(linear_model, &lm, t, 2, &start, NULL, &res, &rep, &err) == PLUME_OK);
    CHECK_REL(res.E_yy, truth.E_yy, 1e-4, 0.0);
    CHECK_REL(res.G_xy, truth.G_xy, 1e-4, 0.0);
    CHECK(rep.residual < 1e-6);

    /* curve 1 stops at 0.02: targets up to 0.025 (half a step) are reached, the 12 from 0.0275
     * on are not; 44 points in all (strain 0 skipped) */
    lm.truncate = 1;
    CHECK(plume_fit_moduli(linear_model, &lm, t, 2, &start, NULL, &res, &rep, &err) == PLUME_OK);
    CHECK_REL(res.E_yy, truth.E_yy, 1e-4, 0.0);
    CHECK_REL(res.G_xy, truth.G_xy, 1e-4, 0.0);
    CHECK_REL(rep.residual, sqrt(12.0 / 44.0), 1e-6, 0.0);

    /* an unsorted model curve is a model bug: an error, not a misfit */
    lm.truncate = 0;
    lm.unsorted = 1;
    res = start;
    CHECK(plume_fit_moduli(linear_model, &lm, t, 2, &start, NULL, &res, &rep, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "not sorted") != NULL);
    CHECK(res.E_yy == start.E_yy); /* result untouched on error */
    free_targets(t, 2);
}

void test_fit_model_error(void)
{
    plume_curve t[2];
    make_targets(t, 2, &truth);
    plume_ortho start = {1e8, 1e4, 0.3, 5e4}, res = start;
    plume_fit_report rep;
    plume_err err = {{0}};

    /* an I/O error of the model stops the fit with its status and message */
    synth s = {.targets = t, .fail_at = 5, .fail_status = PLUME_EIO};
    CHECK(plume_fit_moduli(synth_model, &s, t, 2, &start, NULL, &res, &rep, &err) == PLUME_EIO);
    CHECK(strcmp(err.msg, "synthetic model: disk failure at call 5") == 0);
    CHECK(s.calls == 5); /* no model call after the failure */
    CHECK(strcmp(rep.stop, "forced stop") == 0 && rep.nlopt_result == -5); /* NLOPT_FORCED_STOP */
    CHECK(rep.evaluations == 3);
    CHECK(res.E_yy == start.E_yy && res.G_xy == start.G_xy);

    /* an error without a message still gets one */
    synth s2 = {.targets = t, .fail_at = 1, .fail_status = PLUME_EDEP};
    err.msg[0] = '\0';
    CHECK(plume_fit_moduli(synth_model, &s2, t, 2, &start, NULL, &res, &rep, &err) == PLUME_EDEP);
    CHECK(strstr(err.msg, "disk failure") != NULL);

    /* infeasible points (G_xy above 6e4: the first step from 5e4 doubles it) do not stop it */
    synth s3 = {.targets = t, .infeasible_G = 6e4};
    CHECK(plume_fit_moduli(synth_model, &s3, t, 2, &start, NULL, &res, &rep, &err) == PLUME_OK);
    fprintf(stderr, "    %d infeasible of %d evaluations, residual %.3g\n", s3.infeasible_hits,
            rep.evaluations, rep.residual);
    CHECK(s3.infeasible_hits > 0);
    CHECK_REL(res.E_yy, truth.E_yy, 1e-4, 0.0);
    CHECK_REL(res.G_xy, truth.G_xy, 1e-4, 0.0);
    CHECK(rep.residual < 1e-6);

    /* a model infeasible everywhere leaves nothing to report */
    synth s4 = {.targets = t, .always_infeasible = 1};
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    o.max_eval = 20;
    res = start;
    CHECK(plume_fit_moduli(synth_model, &s4, t, 2, &start, &o, &res, &rep, &err) == PLUME_EINFEASIBLE);
    CHECK(strstr(err.msg, "infeasible") != NULL);
    CHECK(rep.evaluations > 0 && rep.evaluations <= 20);
    CHECK(res.E_yy == start.E_yy);
    free_targets(t, 2);
}

static int fit_fails(const plume_curve *t, int nc, const plume_ortho *start, const plume_fit_opts *o,
                     const char *part)
{
    synth s = {.targets = t};
    plume_ortho res;
    plume_err err = {{0}};
    plume_status st = plume_fit_moduli(synth_model, &s, t, nc, start, o, &res, NULL, &err);
    int ok = st == PLUME_EINVAL && strstr(err.msg, part) != NULL && s.calls == 0;
    if (!ok)
        fprintf(stderr, "    expected EINVAL with '%s': status %d, '%s'\n", part, (int)st, err.msg);
    return ok;
}

void test_fit_bad_inputs(void)
{
    plume_curve t[2];
    make_targets(t, 2, &truth);
    plume_ortho start = {1e8, 1e4, 0.3, 5e4}, res;
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    plume_err err = {{0}};

    CHECK(plume_fit_moduli(NULL, NULL, t, 2, &start, &o, &res, NULL, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "callback") != NULL);
    synth s = {.targets = t};
    CHECK(plume_fit_moduli(synth_model, &s, t, 2, NULL, &o, &res, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_fit_moduli(synth_model, &s, t, 2, &start, &o, NULL, NULL, &err) == PLUME_EINVAL);
    CHECK(fit_fails(t, 0, &start, &o, "0 target curves"));
    CHECK(fit_fails(t, -1, &start, &o, "-1 target curves"));
    CHECK(fit_fails(NULL, 2, &start, &o, "NULL"));

    t[1].stress[4] = NAN;
    CHECK(fit_fails(t, 2, &start, &o, "target curve 1, point 4: non-finite"));
    t[1].stress[4] = 1.0;
    t[0].strain[2] = INFINITY;
    CHECK(fit_fails(t, 2, &start, &o, "target curve 0, point 2: non-finite"));
    t[0].strain[2] = 0.01;
    plume_index n1 = t[1].n;
    t[1].n = 1;
    CHECK(fit_fails(t, 2, &start, &o, "target curve 1 has 1 point"));
    t[1].n = n1;
    double *keep = t[0].stress;
    t[0].stress = NULL;
    CHECK(fit_fails(t, 2, &start, &o, "no strain or stress array"));
    t[0].stress = keep;

    plume_ortho b = start;
    b.E_yy = -1.0;
    CHECK(fit_fails(t, 2, &b, &o, "start E_yy = -1"));
    b = start;
    b.G_xy = NAN;
    CHECK(fit_fails(t, 2, &b, &o, "start G_xy"));
    b = start;
    b.E_xx = b.E_yy;
    b.nu_xy = 1.5;
    CHECK(fit_fails(t, 2, &b, &o, "start nu_xy = 1.5 is not admissible"));
    b = start;
    b.nu_xy = 0.6; /* PD with E_xx >> E_yy, but outside the box of a free nu_xy */
    plume_fit_opts on = o;
    on.free_mask |= PLUME_FIT_NU;
    CHECK(fit_fails(t, 2, &b, &on, "outside the search range"));

    plume_fit_opts bo = o;
    bo.free_mask = 0;
    CHECK(fit_fails(t, 2, &start, &bo, "free_mask"));
    bo.free_mask = 16;
    CHECK(fit_fails(t, 2, &start, &bo, "free_mask"));
    bo = o;
    bo.max_eval = 0;
    CHECK(fit_fails(t, 2, &start, &bo, "max_eval 0"));
    bo = o;
    bo.xtol_rel = 0.0;
    CHECK(fit_fails(t, 2, &start, &bo, "xtol_rel"));
    bo = o;
    bo.min_strain = -1.0;
    CHECK(fit_fails(t, 2, &start, &bo, "min_strain"));
    bo = o;
    bo.min_strain = 1.0; /* skips every point */
    CHECK(fit_fails(t, 2, &start, &bo, "no target point"));

    plume_curve z[1];
    make_targets(z, 1, &truth);
    for (int i = 0; i < 11; i++)
        z[0].stress[i] = 0.0;
    CHECK(fit_fails(z, 1, &start, &o, "only zero stresses"));
    free_targets(z, 1);
    free_targets(t, 2);
}

/* ------------------------------------------------------------------ text curves ---- */

typedef struct {
    char dir[64];
    char path[8][128];
    int n;
} scratch;

static const char *scratch_file(scratch *s, const char *name, const char *text)
{
    char buf[sizeof s->path[0]];
    snprintf(buf, sizeof buf, "%s/%s", s->dir, name);
    char *p = s->path[s->n++];
    memcpy(p, buf, sizeof buf);
    FILE *f = fopen(p, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    return p;
}

static void scratch_close(scratch *s)
{
    for (int i = 0; i < s->n; i++)
        remove(s->path[i]);
    rmdir(s->dir);
}

static int read_expect(const char *path, plume_status want, const char *part)
{
    plume_curve c;
    plume_err err = {{0}};
    plume_status st = plume_curve_read_text(path, &c, &err);
    int ok = st == want && strstr(err.msg, part) != NULL && c.n == 0 && c.strain == NULL;
    if (!ok) {
        fprintf(stderr, "    %s: expected status %d with '%s': status %d, '%s'\n", path, (int)want, part,
                (int)st, err.msg);
        plume_curve_free(&c);
    }
    return ok;
}

void test_fit_read_text(void)
{
    scratch s = {.n = 0};
    snprintf(s.dir, sizeof s.dir, "/tmp/plume-test-fit-XXXXXX");
    CHECK(mkdtemp(s.dir) != NULL);

    const char *good = scratch_file(&s, "good.txt",
                                    "# traction test of sample T01, transverse\n"
                                    "\n"
                                    "strain, stress (Pa)\n"
                                    "0 0\n"
                                    "0.01, 100.5   # comma\n"
                                    "\t0.02\t201e0\n"
                                    "  0.03 ,  305.25  \r\n"
                                    "# a comment between points\n"
                                    "0.03,310\n"
                                    "0.05 -2.5E2");
    plume_curve c;
    plume_err err = {{0}};
    CHECK(plume_curve_read_text(good, &c, &err) == PLUME_OK);
    static const double es[6] = {0, 0.01, 0.02, 0.03, 0.03, 0.05};
    static const double ss[6] = {0, 100.5, 201, 305.25, 310, -250};
    CHECK(c.n == 6);
    if (c.n == 6) {
        for (int i = 0; i < 6; i++) {
            CHECK(c.strain[i] == es[i] && c.stress[i] == ss[i]);
            CHECK(c.wbar[i] == 0.0 && c.iterations[i] == 0.0 && c.seconds[i] == 0.0);
        }
    }
    plume_curve_free(&c);
    CHECK(c.n == 0 && c.strain == NULL);

    /* a measured curve read from text is a fit target */
    const char *lin = scratch_file(&s, "linear.txt", "0 0\n0.01 320\n0.02 640\n0.03 960\n0.04 1280\n");
    CHECK(plume_curve_read_text(lin, &c, &err) == PLUME_OK);
    lin_model lm = {0, 0};
    plume_ortho start = {1e8, 1e3, 0.0, 1e4}, res;
    plume_fit_opts o;
    plume_fit_opts_default(&o);
    o.free_mask = PLUME_FIT_EYY;
    CHECK(plume_fit_moduli(linear_model, &lm, &c, 1, &start, &o, &res, NULL, &err) == PLUME_OK);
    CHECK_REL(res.E_yy, 3.2e4, 1e-4, 0.0);
    plume_curve_free(&c);

    CHECK(read_expect(scratch_file(&s, "word.txt", "strain stress\n0 0\n0.01 1\n0.02 abc\n"),
                      PLUME_EFORMAT, "word.txt:4: expected two numbers"));
    CHECK(read_expect(scratch_file(&s, "three.txt", "0 0\n0.01 1 2\n"), PLUME_EFORMAT,
                      "three.txt:2: expected two numbers"));
    CHECK(read_expect(scratch_file(&s, "late_header.txt", "0 0\nstrain stress\n0.1 1\n"), PLUME_EFORMAT,
                      "late_header.txt:2:"));
    CHECK(read_expect(scratch_file(&s, "down.txt", "0 0\n# x\n0.02 1\n0.01 2\n"), PLUME_EFORMAT,
                      "down.txt:4: strain 0.01 is below the previous 0.02"));
    CHECK(read_expect(scratch_file(&s, "nan.txt", "0 0\nnan 1\n"), PLUME_EFORMAT,
                      "nan.txt:2: non-finite"));
    CHECK(read_expect(scratch_file(&s, "one.txt", "strain stress\n0 0\n"), PLUME_EFORMAT,
                      "1 data point(s); at least 2"));

    char missing[128];
    snprintf(missing, sizeof missing, "%s/missing.txt", s.dir);
    CHECK(read_expect(missing, PLUME_EIO, "missing.txt: cannot open: No such file"));
    CHECK(plume_curve_read_text(NULL, &c, &err) == PLUME_EINVAL);
    CHECK(plume_curve_read_text(good, NULL, &err) == PLUME_EINVAL);
    scratch_close(&s);
    CHECK(access(s.dir, F_OK) != 0);
}
