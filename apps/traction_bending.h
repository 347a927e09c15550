/* apps/traction --bending: the plate bending test of both scales (macro/shell/plate_bending.h) — the
 * resolved layout as a shell of its phases and the plate with the cell's bending tensor
 * (micro/cell_plate.h), the same loads, curves in /curves/bending/<scale>/<LOAD>_<angle>; with
 * --size-effect the micro specimen again at finer barb spacings (/curves/bending/micro_dB<V>/...)
 * and --plot the chart of m/kappa against d_B / lx with the macro value as the limit.
 * Included by apps/traction.c after traction_size.h only (file-local functions). */
#ifndef PLUME_APPS_TRACTION_BENDING_H
#define PLUME_APPS_TRACTION_BENDING_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../include/plume/plume.h"

typedef struct {
    const char *load, *out, *model;
    double lx, ly, angle, curvature;
    int curvature_set;
    double edge; /* macro plate's mesh edge (0: min(lx, ly) / 20) */
    int steps;
    const char *solver;
    int json, quiet;
    const size_family *fam; /* --size-effect: the spacings (d_rel over ly; results unused), or NULL */
    const char *plot;       /* --plot FILE.png, or NULL */
} bending_cli;

/* The loads of the test. The twist of an aligned laminate is uniform (docs/bending-homogenisation.md,
 * the strip laminate): its micro state is the uniform curvature, whose boundary loads grip every
 * barb, and with barbs at 0 or 90 deg the plate's uniform twist carries no other moment, so the
 * uniform-curvature loads are the edge moments for the plate. Elsewhere the edge moments. */
static plume_bend_loading bending_loading(plume_bend_load load, double angle)
{
    return load == PLUME_BEND_TWIST && fmod(angle, 90.0) == 0.0 ? PLUME_BEND_UNIFORM_CURVATURE
                                                                 : PLUME_BEND_EDGE_MOMENTS;
}

/* One scale's run: the test on the specimen (mesh, p), written to the curves file. */
static int bending_scale(const bending_cli *c, const char *scale, plume_mesh *mesh, plume_problem *p,
                         plume_bend_opts *bo, const char *scenario, const plume_param *params, int nparams,
                         double *stiffness)
{
    plume_err err = {{0}};
    plume_bend_result r;
    plume_status st = plume_bend_run(mesh, p, bo, &r, &err);
    if (st != PLUME_OK) {
        fprintf(stderr, "traction: --bending %s (%s): %s\n", c->load, scale, err.msg);
        return 1;
    }
    if (!r.converged) {
        fprintf(stderr, "traction: --bending %s (%s): the solver did not converge\n", c->load, scale);
        plume_bend_result_free(&r);
        return 1;
    }
    *stiffness = r.stiffness;
    if (!c->quiet)
        fprintf(stderr, "traction: bending %s %s: %ld triangles, m/kappa %.6g N m, %.2f s\n", scale, scenario,
                (long)mesh->nt, r.stiffness, r.seconds);
    int rc = 0;
    const plume_sparam sp[1] = {{"loads", bo->loading == PLUME_BEND_UNIFORM_CURVATURE ? "uniform curvature"
                                                                                     : "edge moments"}};
    if (c->out && plume_bend_curve_write(c->out, scale, scenario, &r.curve, params, nparams, sp, 1, &err) != PLUME_OK)
        rc = (fprintf(stderr, "traction: %s\n", err.msg), 1);
    plume_bend_result_free(&r);
    return rc;
}

/* The resolved specimen of `layout` as the shell of its phases, run and written as /curves/bending/<scale>/. */
static int bending_micro(const bending_cli *c, const plume_layout *layout, const plume_membrane_material *mats,
                         const plume_bending_material *phases, const plume_bend_opts *bo, const char *scale,
                         const char *scenario, const plume_param *params, int np, double *stiffness)
{
    plume_err err = {{0}};
    plume_mesh *planar = NULL, *mesh = NULL;
    plume_problem *p = NULL;
    plume_bend_opts o = *bo;
    o.phases = phases, o.nphases = 2;
    int rc;
    if (plume_specimen_mesh(layout, c->lx, c->ly, c->angle, &planar, &err) != PLUME_OK ||
        plume_shell_specimen(planar, mats, phases, 2, &mesh, &p, &err) != PLUME_OK)
        rc = (fprintf(stderr, "traction: --bending %s specimen (d_B %g m): %s\n", scale, layout->d_B, err.msg), 1);
    else
        rc = bending_scale(c, scale, mesh, p, &o, scenario, params, np, stiffness);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    plume_mesh_destroy(&planar);
    return rc;
}

/* --plot: micro m/kappa against d_B / lx (left) and its difference from macro in % (right), the
 * macro value drawn as a horizontal line from d_B = 0, the limit of the resolved specimens. */
static int bending_plot(const bending_cli *c, const char *scenario, double d_rel0, double sm, const double *sfam,
                        int nfam, double sM)
{
    double x[SIZE_EFFECT_MAX + 1], y[SIZE_EFFECT_MAX + 1], d[SIZE_EFFECT_MAX + 1], it[SIZE_EFFECT_MAX + 1] = {0};
    int n = 0;
    if (isfinite(sm))
        x[n] = d_rel0 * c->ly / c->lx, y[n] = sm, d[n] = 100.0 * (sm / sM - 1.0), n++;
    for (int k = 0; k < nfam; k++)
        x[n] = c->fam->d_rel[k] * c->ly / c->lx, y[n] = sfam[k], d[n] = 100.0 * (sfam[k] / sM - 1.0), n++;
    double mx[2] = {0.0, n ? x[0] : d_rel0 * c->ly / c->lx}, my[2] = {sM, sM}, md[2] = {0.0, 0.0}, mi[2] = {0};
    if (!isfinite(sM))
        for (int k = 0; k < n; k++)
            d[k] = 0.0;
    plume_curve curves[2] = {{n, x, y, d, it, it}, {2, mx, my, md, mi, mi}};
    const char *labels[2] = {"micro (resolved barbs)", "macro (homogenised D), the limit d_B -> 0"};
    const int nc = (isfinite(sM) ? 1 : 0) + (n ? 1 : 0);
    const plume_curve *cv = n ? curves : curves + 1;
    const char *const *lb = n ? labels : labels + 1;
    char title[256];
    snprintf(title, sizeof title, "bending %s, barbs at %g deg: resolved specimens approach the homogenised plate as "
             "their barb spacing d_B shrinks", scenario, c->angle);
    const plume_plot_axes ax = {.stress_label = "m / kappa (N m)",
                                .wbar_label = "micro - macro (%)",
                                .x_label = "barb spacing d_B / l_x",
                                .x_scale = 1.0};
    plume_err err = {{0}};
    if (plume_plot_curves_axes(c->plot, title, &ax, cv, lb, nc, &err) != PLUME_OK)
        return fprintf(stderr, "traction: %s\n", err.msg), 1;
    return 0;
}

static int run_bending(const bending_cli *c, const plume_layout *layout, int want_macro, int want_micro)
{
    plume_bend_load load;
    if (plume_bend_load_parse(c->load, &load) != PLUME_OK)
        return fprintf(stderr, "traction: --bending expects cylinder|twist (got '%s')\n", c->load), 2;
    if (!(c->curvature > 0.0) || !isfinite(c->curvature))
        return fprintf(stderr, "traction: --curvature must be finite and > 0 (got %g 1/m; the sign of a linear "
                               "test carries no information)\n", c->curvature), 2;
    if (!(c->angle >= 0.0 && c->angle <= 180.0))
        return fprintf(stderr, "traction: --angle must be in [0, 180] degrees (got %g)\n", c->angle), 2;
    if (c->edge < 0.0 || !isfinite(c->edge))
        return fprintf(stderr, "traction: --edge must be >= 0 (got %g m)\n", c->edge), 2;
    plume_bend_opts bo;
    plume_bend_opts_default(&bo);
    bo.load = load, bo.lx = c->lx, bo.ly = c->ly, bo.steps = c->steps;
    if (plume_solver_kind_parse(c->solver, &bo.solver) != PLUME_OK)
        return fprintf(stderr, "traction: --solver expects newton|ipopt|linearized (got '%s')\n", c->solver), 2;

    /* the cell's bending tensor: the plate's moduli and the moment that gives the curvature asked for */
    plume_err err = {{0}};
    plume_membrane_material mats[2];
    plume_layout_materials(layout, mats);
    double D[9];
    plume_plate_moduli pm;
    plume_status st = plume_homogenize_bending(layout, D, &pm, &err);
    if (st != PLUME_OK)
        return fprintf(stderr, "traction: --bending: the cell's plate tensor: %s\n", err.msg), 1;
    if (fabs(pm.D_16) > 0.01 * sqrt(pm.D_long * pm.D_twist) || fabs(pm.D_26) > 0.01 * sqrt(pm.D_trans * pm.D_twist))
        return fprintf(stderr, "traction: --bending: the layout's cell couples bending and twist (D_16 %g, D_26 %g N m), "
                               "which the plate cannot represent; use a layout symmetric about the barbs (e.g. "
                               "barbule_angle 90)\n", pm.D_16, pm.D_26), 2;
    double stiff_pred = 0.0;
    if ((st = plume_bend_expected(D, c->angle, load, c->curvature, &bo.moment, &stiff_pred, &err)) != PLUME_OK)
        return fprintf(stderr, "traction: --bending: %s\n", err.msg), 1;
    const plume_bending_material hom = {.D_long = pm.D_long, .D_trans = pm.D_trans, .D_twist = pm.D_twist,
                                        .D_coupling = pm.D_coupling};
    char scenario[64];
    snprintf(scenario, sizeof scenario, "%s_%g", plume_bend_load_name(load), c->angle);
    const plume_param params[] = {
        {"lx", c->lx}, {"ly", c->ly}, {"angle_deg", c->angle}, {"d_B", layout->d_B}, {"phi", layout->phi},
        {"thickness_barb", plume_layout_thickness(layout, PLUME_MAT_BARB)},
        {"thickness_barbule", plume_layout_thickness(layout, PLUME_MAT_BARBULE)},
        {"D_long", pm.D_long}, {"D_trans", pm.D_trans}, {"D_coupling", pm.D_coupling}, {"D_twist", pm.D_twist},
        {"predicted_stiffness", stiff_pred}, {"steps", c->steps}};
    const int np = (int)(sizeof params / sizeof params[0]);

    double sm = NAN, sM = NAN;
    int rc = 0;
    plume_bending_material phases[2];
    plume_plate_of_membrane(&mats[0], &phases[0]);
    plume_plate_of_membrane(&mats[1], &phases[1]);
    bo.loading = bending_loading(load, c->angle);
    if (want_micro)
        rc = bending_micro(c, layout, mats, phases, &bo, "micro", scenario, params, np, &sm);
    /* --size-effect: the same specimen at finer spacings, barbules in proportion (as traction's) */
    const int nfam = c->fam ? c->fam->n : 0;
    double sfam[SIZE_EFFECT_MAX];
    for (int k = 0; k < nfam && !rc; k++) {
        plume_layout l = *layout;
        plume_layout_set_spacing(&l, c->fam->d_rel[k] * c->ly);
        char name[64];
        size_effect_scale(c->fam, k, name, sizeof name);
        plume_param pk[sizeof params / sizeof params[0]];
        memcpy(pk, params, sizeof pk);
        pk[3].value = l.d_B;
        rc = bending_micro(c, &l, mats, phases, &bo, name, scenario, pk, np, &sfam[k]);
    }
    if (!rc && want_macro) {
        plume_mesh *mesh = NULL;
        plume_problem *p = NULL;
        /* the in-plane moduli do not enter a linear bending test of a flat plate: the barb phase's */
        const double edge = c->edge > 0.0 ? c->edge : plume_traction_default_edge(c->lx, c->ly);
        plume_bend_opts bm = bo;
        bm.phases = &hom, bm.nphases = 1;
        if ((st = plume_plate_specimen(c->lx, c->ly, c->angle, edge, &mats[0], &hom, &mesh, &p, &err)) != PLUME_OK)
            rc = (fprintf(stderr, "traction: --bending macro plate: %s\n", err.msg), 1);
        else
            rc = bending_scale(c, "macro", mesh, p, &bm, scenario, params, np, &sM);
        plume_problem_destroy(&p);
        plume_mesh_destroy(&mesh);
    }
    if (rc)
        return rc;
    /* The homogeneous plate reproduces plate theory: the edge moments make the uniform state its
     * discrete solution, and every solver finds it at the default contrast (within 4e-6,
     * tests/test_plate_bending.c). A departure means the test went wrong (a solver stopping early,
     * a mesh too coarse for the end loads): it is reported, not passed off as a result. */
    const double departure = want_macro ? sM / stiff_pred - 1.0 : 0.0;
    if (want_macro && !(fabs(departure) <= 0.05))
        fprintf(stderr,
                "traction: warning: the macro plate's m/kappa is %+.1f %% from plate theory's (--ratio %g, --solver "
                "%s): do not trust this run's figures\n",
                100.0 * departure, layout->ratio, c->solver);
    const double d_rel0 = layout->d_B / c->ly;
    if (c->plot && (rc = bending_plot(c, scenario, d_rel0, want_micro ? sm : NAN, sfam, nfam, want_macro ? sM : NAN)))
        return rc;
    if (c->json) {
        printf("{\"load\": \"%s\", \"angle_deg\": %g, \"loads\": \"%s\", \"moment\": %.10g, "
               "\"predicted_stiffness\": %.10g, \"micro_stiffness\": %.10g, \"macro_stiffness\": %.10g", c->load,
               c->angle, bo.loading == PLUME_BEND_UNIFORM_CURVATURE ? "uniform curvature" : "edge moments", bo.moment,
               stiff_pred, want_micro ? sm : -1.0, want_macro ? sM : -1.0);
        if (nfam) {
            printf(", \"size_effect\": [");
            for (int k = -1; k < nfam; k++) {
                const double s = k < 0 ? sm : sfam[k];
                printf("%s{\"dB_rel\": %.10g, \"micro_stiffness\": %.10g", k < 0 ? "" : ", ",
                       k < 0 ? d_rel0 : c->fam->d_rel[k], want_micro || k >= 0 ? s : -1.0);
                if (want_macro && (want_micro || k >= 0))
                    printf(", \"relative_to_macro\": %.10g", s / sM - 1.0);
                printf("}");
            }
            printf("]");
        }
        printf("}\n");
    } else {
        printf("bending %s: m = %.6g N m/m; m/kappa (N m):", scenario, bo.moment);
        if (want_micro)
            printf(" micro %.6g,", sm);
        if (want_macro)
            printf(" macro %.6g,", sM);
        printf(" plate theory %.6g", stiff_pred);
        if (want_micro && want_macro)
            printf("; micro - macro %.2f %%", 100.0 * (sm / sM - 1.0));
        printf("\n");
        if (nfam) {
            printf("bending size effect: micro m/kappa");
            for (int k = want_micro ? -1 : 0; k < nfam; k++) {
                const double s = k < 0 ? sm : sfam[k];
                printf("%s %.6g N m (d_B %g lx", k < (want_micro ? 0 : 1) ? "" : ",", s,
                       (k < 0 ? d_rel0 : c->fam->d_rel[k]) * c->ly / c->lx);
                if (want_macro)
                    printf(", %+.2f %% from macro", 100.0 * (s / sM - 1.0));
                printf(")");
            }
            if (want_macro)
                printf("; macro %.6g N m, the limit as d_B -> 0", sM);
            printf("\n");
        }
    }
    return 0;
}

#endif
