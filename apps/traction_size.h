/* apps/traction --size-effect: the micro specimen again at finer barb spacings d_B (over l_y), the
 * same sample, load and mesh rule, so that a chart shows the micro curves approaching the macro
 * curve as d_B shrinks: the macro model is the limit d_B -> 0 of the resolved one
 * (docs/micro-convergence.md, "Barb spacing"). Curves in /curves/micro_dB<V>/<scenario>.
 * Included by apps/traction.c only (file-local functions). */
#ifndef PLUME_APPS_TRACTION_SIZE_H
#define PLUME_APPS_TRACTION_SIZE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../include/plume/plume.h"

#define SIZE_EFFECT_MAX 6

typedef struct {
    int n;
    double d_rel[SIZE_EFFECT_MAX];        /* barb spacing over l_y, coarse to fine */
    plume_traction_result res[SIZE_EFFECT_MAX];
    plume_index elements[SIZE_EFFECT_MAX];
} size_family;

/* Parses "V[,V...]": up to SIZE_EFFECT_MAX spacings, each in (0, 1) and smaller than the one before
 * (the first smaller than the main run's d_rel0). Returns an exit code (2 with a message naming
 * the flag). */
static int size_effect_parse(const char *list, double d_rel0, size_family *fam)
{
    memset(fam, 0, sizeof *fam);
    const char *s = list;
    double prev = d_rel0;
    while (s && *s) {
        char *end;
        double v = strtod(s, &end);
        if (end == s || (*end && *end != ',') || !(v > 0.0 && v < 1.0) || !(v < prev))
            return fprintf(stderr,
                           "traction: --size-effect expects spacings over l_y in (0, 1), comma-separated, each finer "
                           "than the one before and than --dB-rel %g (got '%s')\n",
                           d_rel0, list), 2;
        if (fam->n == SIZE_EFFECT_MAX)
            return fprintf(stderr, "traction: --size-effect takes at most %d spacings (got '%s')\n", SIZE_EFFECT_MAX,
                           list), 2;
        fam->d_rel[fam->n++] = prev = v;
        s = *end ? end + 1 : end;
    }
    if (fam->n == 0)
        return fprintf(stderr, "traction: --size-effect needs at least one spacing\n"), 2;
    return 0;
}

/* Runs the micro specimen of `layout` (its d_B rescaled, barbules in proportion) at each spacing. */
static int size_effect_run(const plume_layout *layout, double lx, double ly, double angle,
                           const plume_traction_opts *to, size_family *fam)
{
    for (int k = 0; k < fam->n; k++) {
        plume_layout l = *layout;
        plume_layout_set_spacing(&l, fam->d_rel[k] * ly);
        plume_err err = {{0}};
        plume_mesh *mesh = NULL;
        plume_problem *p = NULL;
        plume_status st = plume_micro_specimen(&l, lx, ly, angle, &mesh, &p, &err);
        if (st == PLUME_OK) {
            fam->elements[k] = plume_micro_specimen_elements(&l, mesh);
            st = plume_traction_run(mesh, p, NULL, 0, to, &fam->res[k], &err);
        }
        plume_problem_destroy(&p);
        plume_mesh_destroy(&mesh);
        if (st != PLUME_OK)
            return fprintf(stderr, "traction: --size-effect at d_B = %g l_y: %s\n", fam->d_rel[k],
                           err.msg[0] ? err.msg : plume_strerror(st)), 1;
        if (!fam->res[k].converged)
            return fprintf(stderr, "traction: --size-effect at d_B = %g l_y did not converge at step %d (%s); no "
                           "family written\n", fam->d_rel[k], fam->res[k].failed_step,
                           plume_reason_name(fam->res[k].failed_reason)), 3;
    }
    return 0;
}

static void size_effect_scale(const size_family *fam, int k, char *buf, size_t n)
{
    snprintf(buf, n, "micro_dB%g", fam->d_rel[k]);
}

/* Writes each member as /curves/micro_dB<V>/<scenario>. */
static int size_effect_write(const char *path, const char *scenario, const plume_layout *layout, double ly,
                             const size_family *fam)
{
    for (int k = 0; k < fam->n; k++) {
        char scale[64];
        size_effect_scale(fam, k, scale, sizeof scale);
        plume_param params[] = {{"d_B_rel", fam->d_rel[k]}, {"d_B", fam->d_rel[k] * ly},
                                {"phi", layout->phi}, {"ratio", layout->ratio}, {"E_b", layout->E_b},
                                {"order", layout->order}, {"elements", (double)fam->elements[k]},
                                {"initial_slope", fam->res[k].initial_slope}, {"converged", fam->res[k].converged}};
        plume_sparam sparams[] = {{"scenario", scenario}, {"mesh", "specimen"}};
        plume_err err = {{0}};
        if (plume_curve_write(path, scale, scenario, &fam->res[k].curve, params,
                              (int)(sizeof params / sizeof params[0]), sparams, 2, &err) != PLUME_OK)
            return fprintf(stderr, "traction: %s\n", err.msg), 1;
    }
    return 0;
}

/* The last stress of a curve. */
static double size_effect_end_stress(const plume_curve *c)
{
    return c->n ? c->stress[c->n - 1] : NAN;
}

/* One line: micro - macro at the last strain for each spacing, and the ratio of successive
 * differences (about 1/2 per halving of d_B when the difference is first order in d_B). */
static void size_effect_print(double d_rel0, const plume_curve *micro0, const plume_curve *macro,
                              const size_family *fam, double strain_max)
{
    double sM = macro ? size_effect_end_stress(macro) : NAN;
    printf("size effect at %g %% strain: micro", 100.0 * strain_max);
    for (int k = -1; k < fam->n; k++) {
        double s = size_effect_end_stress(k < 0 ? micro0 : &fam->res[k].curve);
        printf("%s %.4g Pa (d_B %g l_y", k < 0 ? "" : ",", s, k < 0 ? d_rel0 : fam->d_rel[k]);
        if (macro)
            printf(", %+.1f %% from macro", 100.0 * (s / sM - 1.0));
        printf(")");
    }
    if (macro)
        printf("; macro %.4g Pa, the limit as d_B -> 0", sM);
    printf("\n");
}

/* The family chart: micro at every spacing, the macro curve (if run) drawn as their limit. */
static int size_effect_plot(const char *png, const char *scenario, double angle, double d_rel0,
                            const plume_curve *micro0, const plume_curve *macro, const char *macro_label,
                            const size_family *fam)
{
    plume_curve curves[SIZE_EFFECT_MAX + 2];
    char names[SIZE_EFFECT_MAX + 2][96];
    const char *labels[SIZE_EFFECT_MAX + 2];
    int nc = 0;
    for (int k = -1; k < fam->n; k++, nc++) {
        curves[nc] = k < 0 ? *micro0 : fam->res[k].curve;
        snprintf(names[nc], sizeof names[nc], "micro, d_B = %g l_y", k < 0 ? d_rel0 : fam->d_rel[k]);
        labels[nc] = names[nc];
    }
    if (macro) {
        curves[nc] = *macro;
        snprintf(names[nc], sizeof names[nc], "%s, the limit d_B -> 0", macro_label);
        labels[nc] = names[nc];
        nc++;
    }
    char title[256];
    snprintf(title, sizeof title, "%s traction, barbs at %g deg: resolved barbs (micro) approach the homogenised "
             "macro model as their spacing d_B shrinks", scenario, angle);
    plume_err err = {{0}};
    if (plume_plot_curves(png, title, curves, labels, nc, &err) != PLUME_OK)
        return fprintf(stderr, "traction: %s\n", err.msg), 1;
    return 0;
}

static void size_effect_free(size_family *fam)
{
    for (int k = 0; k < fam->n; k++)
        plume_traction_result_free(&fam->res[k]);
}

#endif
