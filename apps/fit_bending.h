/* apps/fit --bending: the plate's bending moduli (D_long, D_trans, D_coupling, D_twist) fitted to
 * the bending curves of apps/traction --bending with the plate test as the model
 * (plume_plate_model_curve, macro/shell/plate_bending.h), by the fitter of the membrane moduli
 * (plume_fit_bending_moduli, include/plume/fit.h). Included by
 * apps/fit.c only (file-local functions; it uses fit.c's options and --starts machinery). */
#ifndef PLUME_APPS_FIT_BENDING_H
#define PLUME_APPS_FIT_BENDING_H

#define MAX_BEND_CURVES 16

/* The curves of the --bending files and what the model needs of them. */
typedef struct {
    int n;
    plume_curve curves[MAX_BEND_CURVES]; /* strain = curvature (1/m), stress = moment (N m / m) */
    char names[MAX_BEND_CURVES][1400];    /* FILE:SCALE/SCENARIO, for messages */
    double angles[MAX_BEND_CURVES], moments[MAX_BEND_CURVES];
    plume_bend_load loads[MAX_BEND_CURVES];
    double lx, ly;
    double D_recorded[4]; /* the homogenised D the first curve records (NaN when it does not) */
} bend_targets;

static void bend_targets_free(bend_targets *t)
{
    for (int k = 0; k < t->n; k++)
        plume_curve_free(&t->curves[k]);
}

/* Reads one curve into t (slot t->n): 0, or the exit code after a message. */
static int bend_read_curve(const char *path, const char *scale, const char *scenario, bend_targets *t)
{
    plume_err err = {{0}};
    const int k = t->n;
    snprintf(t->names[k], sizeof t->names[k], "%s:%s/%s", path, scale, scenario);
    /* the load is the scenario's prefix (<LOAD>_<angle>), the rest the curve's attributes */
    char load[32];
    const char *us = strchr(scenario, '_');
    snprintf(load, sizeof load, "%.*s", us ? (int)(us - scenario) : (int)strlen(scenario), scenario);
    if (plume_bend_load_parse(load, &t->loads[k]) != PLUME_OK)
        return cli_fail(APP, "--bending %s: '%s' is not a bending curve of apps/traction (<cylinder|twist>_<angle>)",
                        t->names[k], scenario);
    double lx, ly;
    if (plume_bend_curve_param(path, scale, scenario, "lx", &lx, &err) != PLUME_OK ||
        plume_bend_curve_param(path, scale, scenario, "ly", &ly, &err) != PLUME_OK ||
        plume_bend_curve_param(path, scale, scenario, "angle_deg", &t->angles[k], &err) != PLUME_OK)
        return cli_fail(APP, "--bending %s: %s", t->names[k], err.msg);
    if (!(lx > 0.0 && ly > 0.0 && isfinite(lx) && isfinite(ly) && t->angles[k] >= 0.0 && t->angles[k] <= 180.0))
        return cli_fail(APP, "--bending %s: lx %g, ly %g m, angle %g deg out of range", t->names[k], lx, ly,
                        t->angles[k]);
    if (k == 0) {
        t->lx = lx, t->ly = ly;
        for (int j = 0; j < 4; j++)
            if (plume_bend_curve_param(path, scale, scenario, bend_moduli[j], &t->D_recorded[j], &err) != PLUME_OK)
                t->D_recorded[j] = NAN;
    } else if (fabs(lx - t->lx) > 1e-12 * t->lx || fabs(ly - t->ly) > 1e-12 * t->ly) {
        /* one plate model: one specimen */
        return cli_fail(APP, "--bending %s: its specimen is %g x %g m but %s's is %g x %g m (one fit, one specimen)",
                        t->names[k], lx, ly, t->names[0], t->lx, t->ly);
    }
    plume_bend_curve bc;
    if (plume_bend_curve_read(path, scale, scenario, &bc, &err) != PLUME_OK)
        return cli_fail(APP, "--bending %s: %s", t->names[k], err.msg);
    int rc = 0;
    double mmax = 0.0;
    for (plume_index i = 0; i < bc.n; i++)
        mmax = fmax(mmax, fabs(bc.moment[i]));
    if (bc.n < 2 || !(mmax > 0.0) || !isfinite(mmax)) {
        rc = cli_fail(APP, "--bending %s: %ld point(s), largest moment %g: not a loaded curve", t->names[k], (long)bc.n,
                      mmax);
    } else {
        plume_curve *c = &t->curves[k];
        c->n = bc.n;
        c->strain = bc.curvature, bc.curvature = NULL;
        c->stress = bc.moment, bc.moment = NULL;
        c->iterations = bc.iterations, bc.iterations = NULL;
        c->seconds = bc.seconds, bc.seconds = NULL;
        c->wbar = calloc((size_t)bc.n, sizeof *c->wbar);
        if (!c->wbar)
            rc = cli_fail(APP, "out of memory");
        t->moments[k] = mmax;
        t->n++;
        if (rc)
            plume_curve_free(c), t->n--;
    }
    plume_bend_curve_free(&bc);
    return rc;
}

/* Every bending curve of the --bending files (FILE.h5[:SCALE]) into t: 0 or the exit code. */
static int bend_read_targets(const options *o, bend_targets *t)
{
    memset(t, 0, sizeof *t);
    for (int f = 0; f < o->nb; f++) {
        char path[1024], scale[64] = "micro";
        const char *spec = o->bend_files[f], *colon = strrchr(spec, ':');
        if (colon && colon != spec && !strchr(colon, '/')) {
            snprintf(path, sizeof path, "%.*s", (int)(colon - spec), spec);
            snprintf(scale, sizeof scale, "%s", colon + 1);
        } else {
            snprintf(path, sizeof path, "%s", spec);
        }
        plume_err err = {{0}};
        char **names = NULL;
        int nn = 0;
        if (plume_bend_curve_names(path, scale, &names, &nn, &err) != PLUME_OK)
            return cli_fail(APP, "--bending %s: %s", spec, err.msg);
        int rc = 0;
        for (int k = 0; k < nn && !rc; k++) {
            if (t->n == MAX_BEND_CURVES)
                rc = cli_fail(APP, "--bending: at most %d curves", MAX_BEND_CURVES);
            else
                rc = bend_read_curve(path, scale, names[k], t);
        }
        plume_bend_curve_names_free(names, nn);
        if (rc)
            return rc;
    }
    return 0;
}

/* How many of the curves are distinct tests (load and barb angle modulo 180 deg): a linear test
 * gives one number, so the fit needs as many as free moduli. */
static int bend_distinct(const bend_targets *t)
{
    int d = 0;
    for (int k = 0; k < t->n; k++) {
        int seen = 0;
        for (int j = 0; j < k && !seen; j++)
            seen = t->loads[j] == t->loads[k] && fabs(remainder(t->angles[j] - t->angles[k], 180.0)) < 1e-9;
        d += !seen;
    }
    return d;
}

static int run_bending_fit(const options *o, int rank, int size)
{
    bend_targets t;
    int rc = bend_read_targets(o, &t);
    plume_fit_opts fo = o->fo;
    /* the start: the flags, else the homogenised D the curves record */
    plume_bending_material sb;
    double *sd[4] = {&sb.D_long, &sb.D_trans, &sb.D_coupling, &sb.D_twist};
    for (int k = 0; k < 4 && !rc; k++) {
        *sd[k] = o->D_set[k] ? o->D_start[k] : t.D_recorded[k];
        if (!isfinite(*sd[k]))
            rc = cli_fail(APP, "--bending: %s records no %s: give a start value with %s", t.names[0], bend_moduli[k],
                          bend_flags[k]);
    }
    if (!rc && !(sb.D_coupling * sb.D_coupling < sb.D_long * sb.D_trans))
        rc = cli_fail(APP, "the start D_coupling %g N m makes the plate indefinite (need D_coupling^2 < D_long "
                      "D_trans = %g)", sb.D_coupling, sb.D_long * sb.D_trans);
    int nfree = 0;
    for (int k = 0; k < 4; k++)
        nfree += (fo.free_mask & bend_bits[k]) != 0;
    const int nd = rc ? 0 : bend_distinct(&t);
    if (!rc && nd < nfree)
        rc = cli_fail(APP, "--bending: %d distinct curve(s) (load, angle) cannot determine %d moduli: fix some with "
                      "--free (e.g. --free D_long,D_twist) or add curves (traction --bending cylinder|twist --angle DEG)",
                      nd, nfree);
    if (rc) {
        bend_targets_free(&t);
        return rc;
    }
    /* the model: traction's macro plate, linearized (its membrane then does not enter: the barb
     * phase's isotropic stand-in), one step (the response is linear in the moment) */
    const plume_membrane_material membrane = {.moduli = {1e9, 1e9, 0.3, 1e9 / 2.6}, .h = 1e-4};
    plume_plate_model pm = {t.lx,     t.ly, o->edge > 0 ? o->edge : plume_traction_default_edge(t.lx, t.ly), membrane, t.n, t.angles,
                            t.loads, t.moments, 1, PLUME_SOLVER_LINEARIZED};
    plume_bending_material b = {0};
    plume_fit_report rep;
    plume_err err = {{0}};
    if (o->starts > 1 || size > 1) {
        starts_ctx c = {.bmodel = plume_plate_model_curve, .mm = &pm, .bending = 1, .curves = t.curves, .nt = t.n,
                        .bstart = sb, .fo = fo, .best = -1, .best_residual = INFINITY};
        int *todo = malloc((size_t)o->starts * sizeof *todo);
        for (int k = 0; k < o->starts; k++)
            todo[k] = k;
        rc = schedule_run(rank, size, todo, o->starts, fit_start, keep_start, &c);
        free(todo);
        if (rank > 0) {
            bend_targets_free(&t);
            return 0;
        }
        if (c.best < 0) {
            fprintf(stderr, "%s: none of the %d starts gave a fit\n", APP, o->starts);
            rc = 1;
        } else {
            b = c.best_bfit, rep = c.best_rep;
            fprintf(stderr, "%s: the best of %d starts is start %d (misfit %.3g)\n", APP, o->starts, c.best,
                    rep.residual);
        }
    } else if (plume_fit_bending_moduli(plume_plate_model_curve, &pm, t.curves, t.n, &sb, &fo, &b, &rep, &err) !=
               PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        rc = 1;
    }
    if (rc == 0 && o->out) {
        char prov[512];
        snprintf(prov, sizeof prov, "plume fit --bending: %d curve(s) from %s%s, %d evaluations, RMS relative misfit "
                 "%.3g, %s; E_xx, E_yy, nu_xy, G_xy are the model plate's membrane, not fitted", t.n, o->bend_files[0],
                 o->nb > 1 ? " and more" : "", rep.evaluations, rep.residual, rep.stop);
        const plume_ortho mem = membrane.moduli;
        const plume_param params[] = {{"D_long", b.D_long}, {"D_trans", b.D_trans}, {"D_coupling", b.D_coupling},
                                      {"D_twist", b.D_twist}, {"D_16", 0.0},          {"D_26", 0.0},
                                      {"residual", rep.residual}, {"lx", t.lx}, {"ly", t.ly}};
        if (plume_moduli_write_params(o->out, &mem, prov, params, (int)(sizeof params / sizeof params[0]), &err) !=
            PLUME_OK) {
            fprintf(stderr, "%s: %s\n", APP, err.msg);
            rc = 1;
        }
    }
    if (rc == 0) {
        if (o->json) {
            json_t *j = json_object();
            json_object_set_new(j, "D_long", json_real(b.D_long));
            json_object_set_new(j, "D_trans", json_real(b.D_trans));
            json_object_set_new(j, "D_coupling", json_real(b.D_coupling));
            json_object_set_new(j, "D_twist", json_real(b.D_twist));
            json_object_set_new(j, "residual", json_real(rep.residual));
            json_object_set_new(j, "evaluations", json_integer(rep.evaluations));
            json_object_set_new(j, "stop", json_string(rep.stop));
            json_object_set_new(j, "seconds", json_real(rep.seconds));
            json_t *jc = json_array();
            for (int k = 0; k < t.n; k++)
                json_array_append_new(jc, json_string(t.names[k]));
            json_object_set_new(j, "curves", jc);
            cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        } else {
            printf("fitted to %d bending curve(s): D_long %.6g, D_trans %.6g, D_coupling %.6g, D_twist %.6g N m; RMS "
                   "relative misfit %.3g after %d evaluations (%s, %.2f s)\n",
                   t.n, b.D_long, b.D_trans, b.D_coupling, b.D_twist, rep.residual, rep.evaluations, rep.stop,
                   rep.seconds);
        }
    }
    bend_targets_free(&t);
    return rc;
}

#endif
