/* apps/study — measured studies of the macroscale traction model: cost against error
 * (supplementary Figure 2 as a Pareto chart), the three solvers on the same problems, the
 * sensitivity to +-10 % on E_yy and G_xy (supplementary section 10, Table 2, Figure 15), the
 * cheapest model each shipped scenario needs, where methods fail, and the micro model against its
 * element size (linear and quadratic elements) and barb spacing (supplementary Figure 10). Writes DIR/study.h5, charts (PNG + SVG) and
 * DIR/summary.md. Every run is sequential so that the wall times are not shared between runs. */
#define _DEFAULT_SOURCE
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"
#include "schedule.h"

static const char *const usage =
    "usage: study -o DIR [--quick] [--json]\n"
    "  -o DIR    output directory (created if missing): study.h5, *.png, *.svg, summary.md\n"
    "  --quick   E_xx/E_yy = 1e4 only, two mesh sizes, coarse references, two micro element sizes and\n"
    "            barb spacings (well under a minute)\n"
    "  --json    print a JSON record of every run on stdout\n";

#define TOL_SCENE 0.02 /* section 4: stress at 5 % within 2 % of the richest model */

typedef struct {
    char name[160];  /* section/case; the HDF5 scenario under /curves/study is this with '/' -> '_' */
    char label[128];
    plume_study_config cfg;
    plume_study_result res;
    plume_status st;
    char msg[768];   /* error message when st != OK */
} run;

/* The homogenised moduli of the Figure 10 layout, which the macro runs of section 6 take. */
typedef struct {
    int done;
    plume_status st;
    plume_ortho moduli;
    long elements;
    double seconds;
    char msg[768]; /* when st != OK */
} fig10_cell;

/* The study runs in three passes so that its runs can be spread over MPI ranks (apps/schedule.h):
 * the sections are walked once to plan the runs (nothing runs, nothing is written), the runs are
 * executed, serially or over the ranks, and the sections are walked again to report, each do_run
 * then taking the next executed run in the planned order. */
typedef struct {
    const char *dir;
    char h5[1024];
    int quick, json;
    run *runs;
    int nruns, cap;
    int write_failures;
    double t0;
    int planning; /* 1: the first walk, which only lists the runs */
    int next;     /* the report walk: the run do_run takes next */
    fig10_cell cell; /* section 6: the homogenised Figure 10 layout (the plan walk computes it) */
} study;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static const char *model_name(const plume_study_config *c)
{
    if (c->micro)
        return c->layout.order == 1 ? "micro, linear elements" : "micro, quadratic elements";
    if (c->constraint)
        return c->mesh == PLUME_PATCH_ALIGNED ? "aligned+constraint" : "unaligned+constraint";
    return c->mesh == PLUME_PATCH_ALIGNED ? "aligned+penalty" : "unaligned+penalty";
}

static int ok(const run *r) /* a usable measurement: ran, reached the last step, converged */
{
    return r->st == PLUME_OK && r->res.complete && (r->res.converged || r->cfg.solver == PLUME_SOLVER_LINEARIZED);
}

static const char *outcome(const run *r)
{
    if (r->st != PLUME_OK)
        return "error";
    if (r->res.converged)
        return "converged";
    return plume_reason_name(r->res.reason);
}

/* Runs `cfg`, records it, writes its curve. Returns the run's index (the array may move). */
static int report_run(study *s, int i);

static int do_run(study *s, const plume_study_config *cfg, const char *name, const char *label)
{
    if (!s->planning) { /* the report walk: the run executed for this call */
        if (s->next >= s->nruns || strcmp(s->runs[s->next].name, name) != 0) {
            fprintf(stderr, "study: the report walk asked for '%s', not the planned run\n", name);
            exit(1);
        }
        return report_run(s, s->next++);
    }
    if (s->nruns == s->cap) {
        int cap = s->cap ? 2 * s->cap : 64;
        run *r = realloc(s->runs, (size_t)cap * sizeof *r);
        if (!r) {
            fprintf(stderr, "study: out of memory\n");
            exit(1);
        }
        s->runs = r, s->cap = cap;
    }
    run *r = &s->runs[s->nruns];
    memset(r, 0, sizeof *r);
    snprintf(r->name, sizeof r->name, "%s", name);
    snprintf(r->label, sizeof r->label, "%s", label);
    r->cfg = *cfg;
    s->nruns++;
    return s->nruns - 1;
}

/* A run's HDF5 attributes (params holds 32): the traction's, then the vane's or the micro layout's. */
static int run_params(const run *r, plume_param *params)
{
    const plume_study_config *c = &r->cfg;
    const plume_layout *l = &c->layout;
    const plume_param common[] = {
        {"angle_deg", c->angle}, {"lx", c->lx}, {"ly", c->ly}, {"h", c->h}, {"strain_max", c->strain_max},
        {"steps", c->steps}, {"max_iter", c->max_iter}, {"elements", (double)r->res.elements},
        {"converged", r->res.converged}, {"seconds_total", r->res.seconds}, {"iterations_total", r->res.iterations},
        {"micro", c->micro}};
    const plume_param vane[] = {
        {"E_xx", c->moduli.E_xx}, {"E_yy", c->moduli.E_yy}, {"G_xy", c->moduli.G_xy}, {"nu_xy", c->moduli.nu_xy},
        {"kappa", c->kappa}, {"constraint", c->constraint}, {"edge", c->edge}};
    const plume_param layout[] = {
        {"order", l->order}, {"e_rel", plume_layout_element_edge(l, PLUME_MESH_SPECIMEN) / plume_layout_barb_width(l)},
        {"d_B", l->d_B}, {"dB_rel", l->d_B / c->ly}, {"phi", l->phi}, {"ratio", l->ratio}, {"E_b", l->E_b},
        {"nu_b", l->nu_b}, {"nu_B", l->nu_B}, {"kappa", l->kappa}};
    int n = (int)(sizeof common / sizeof *common);
    memcpy(params, common, sizeof common);
    if (c->micro)
        memcpy(params + n, layout, sizeof layout), n += (int)(sizeof layout / sizeof *layout);
    else
        memcpy(params + n, vane, sizeof vane), n += (int)(sizeof vane / sizeof *vane);
    return n;
}

/* the report walk's side of a run: its log line and its curve in study.h5 */
static int report_run(study *s, int i)
{
    run *r = &s->runs[i];
    const plume_study_config *cfg = &r->cfg;
    const char *name = r->name;
    plume_err err = {{0}};
    fprintf(stderr, "study [%6.1f s] %-44s %-10s %8.3f s %4d it  stress %.6g\n", now() - s->t0, name,
            outcome(r), r->res.seconds, r->res.iterations, r->res.stress);
    if (r->st == PLUME_OK && r->res.curve.n > 0) {
        plume_param params[32];
        int np = run_params(r, params);
        const plume_sparam sp[] = {{"model", model_name(cfg)},
                                   {"mesh", cfg->micro ? "specimen" : cfg->mesh == PLUME_PATCH_ALIGNED ? "aligned" : "unaligned"},
                                   {"solver", plume_solver_kind_name(cfg->solver)},
                                   {"outcome", outcome(r)}};
        char h5name[160]; /* HDF5 scenario names are one level: '/' becomes '_' */
        snprintf(h5name, sizeof h5name, "%s", name);
        for (char *q = h5name; *q; q++)
            if (*q == '/')
                *q = '_';
        if (plume_curve_write(s->h5, "study", h5name, &r->res.curve, params, np, sp, 4, &err) != PLUME_OK) {
            fprintf(stderr, "study: %s\n", err.msg);
            s->write_failures++;
        }
    }
    return i;
}

/* A chart series built point by point (x, y1, y2). */
typedef struct {
    double x[64], y1[64], y2[64];
    int n;
    char label[96];
} series;

static void series_sort(series *a)
{
    for (int i = 1; i < a->n; i++)
        for (int j = i; j > 0 && a->x[j] < a->x[j - 1]; j--) {
            double t;
            t = a->x[j], a->x[j] = a->x[j - 1], a->x[j - 1] = t;
            t = a->y1[j], a->y1[j] = a->y1[j - 1], a->y1[j - 1] = t;
            t = a->y2[j], a->y2[j] = a->y2[j - 1], a->y2[j - 1] = t;
        }
}

/* Series as curves: x goes in curve.strain, drawn unscaled with its own axis label. */
/* color/point: per series (NULL: the defaults); key_below: the legend under the panels. */
static int plot_series_styled(study *s, const char *file, const char *title, const char *x, const char *y1,
                              const char *y2, series *sr, int ns, const int *color, const int *point, FILE *md)
{
    if (s->planning)
        return 0;
    plume_curve cv[32];
    const char *labels[32];
    int nc = 0, colors[32], points[32];
    double xs[32][64];
    for (int k = 0; k < ns && nc < 32; k++) {
        if (sr[k].n == 0)
            continue;
        series_sort(&sr[k]);
        for (int i = 0; i < sr[k].n; i++)
            xs[nc][i] = sr[k].x[i];
        memset(&cv[nc], 0, sizeof cv[nc]);
        cv[nc].n = sr[k].n;
        cv[nc].strain = xs[nc];
        cv[nc].stress = sr[k].y1;
        cv[nc].wbar = sr[k].y2;
        labels[nc] = sr[k].label;
        colors[nc] = color ? color[k] : nc + 1;
        points[nc] = point ? point[k] : 7;
        nc++;
    }
    if (nc == 0) {
        fprintf(md, "\n(no chart %s: no usable point)\n", file);
        return 0;
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", s->dir, file);
    plume_plot_axes ax = {y1, y2, x, 1.0, 1, color ? colors : NULL, point ? points : NULL, color != NULL};
    plume_err err = {{0}};
    if (plume_plot_curves_axes(path, title, &ax, cv, labels, nc, &err) != PLUME_OK) {
        fprintf(stderr, "study: chart %s: %s\n", file, err.msg);
        fprintf(md, "\n(chart %s not drawn: %s)\n", file, err.msg);
        return -1;
    }
    fprintf(md, "\n![%s](%s) (SVG beside it)\n", title, file);
    return 0;
}

static int plot_series(study *s, const char *file, const char *title, const char *x, const char *y1, const char *y2,
                       series *sr, int ns, FILE *md)
{
    return plot_series_styled(s, file, title, x, y1, y2, sr, ns, NULL, NULL, md);
}

static void base_tilted(plume_study_config *c, double ratio)
{
    plume_study_config_default(c);
    c->moduli.E_xx = ratio; /* E_yy = G_xy = 1 */
}

static void set_model(plume_study_config *c, int model)
{
    c->constraint = model == 0;
    c->mesh = model == 2 ? PLUME_PATCH_UNALIGNED : PLUME_PATCH_ALIGNED;
}

static const char *const model_short[3] = {"aligned-constraint", "aligned-penalty", "unaligned-penalty"};

/* ---- 1. cost against error ---- */

/* One line on the reference run iref of a model whose two next-coarser runs (edges 2h, 4h) are
 * i2 (4h) and i1 (2h): successive differences, their ratio and the reference's own error by
 * Richardson extrapolation when the ratio says the model converges geometrically. */
static void reference_note(const study *s, double ratio, int i2, int i1, int iref, char *out, size_t n)
{
    const run *a = &s->runs[i2], *b = &s->runs[i1], *r = &s->runs[iref];
    if (!ok(a) || !ok(b) || !ok(r)) {
        snprintf(out, n, "E_xx/E_yy %g, reference %s: a run is missing, no estimate", ratio, model_name(&r->cfg));
        return;
    }
    double d1 = a->res.stress - b->res.stress, d2 = b->res.stress - r->res.stress, q = d1 != 0.0 ? d2 / d1 : NAN;
    if (q > 0.0 && q < 1.0)
        snprintf(out, n, "E_xx/E_yy %g, reference %s: d1 %.3g, d2 %.3g, r %.2f: own error ≈ %.1e, so the errors "
                 "above are low by about that much", ratio, model_name(&r->cfg), d1, d2, q,
                 fabs(d2) * q / (1.0 - q) / fabs(r->res.stress));
    else
        snprintf(out, n, "E_xx/E_yy %g, reference %s: d1 %.3g, d2 %.3g, r %.2f: the differences do not shrink "
                 "geometrically yet, so the reference's own error is not estimated (it may exceed the errors above)",
                 ratio, model_name(&r->cfg), d1, d2, q);
}
static void section_cost(study *s, FILE *md)
{
    const double ratios_full[] = {1.0, 1e2, 1e4}, ratios_quick[] = {1e4};
    const double edges_full[] = {0.1, 0.05, 0.025, 0.0125}, edges_quick[] = {0.1, 0.05};
    const double *ratios = s->quick ? ratios_quick : ratios_full, *edges = s->quick ? edges_quick : edges_full;
    int nr = s->quick ? 1 : 3, ne = s->quick ? 2 : 4;
    double ref_edge = s->quick ? 0.0125 : 0.00625;
    fprintf(md, "\n## 1. Cost against error (supplementary Figure 2 as a Pareto chart)\n\n"
                "Tilted 45° traction, l_x = 1, l_y = 1.3, h = 1, E_yy = G_xy = 1, ν = 0, 2 load steps to 5 %% strain, "
                "newton. Error: relative error of the nominal stress (and of w̄) at 5 %% strain. Reference: the "
                "aligned+constraint model at edge %g for the constraint model; the aligned+penalty model at edge %g "
                "of the same E_xx/E_yy for both penalty models. Time: wall time of the traction run (meshing "
                "excluded). A run that does not converge is listed as a failure with its reason and left out of "
                "the chart.\n\n", ref_edge, ref_edge);
    fprintf(md, "| E_xx/E_yy | model | edge | elements | seconds | iterations | outcome | stress | stress error | w̄ error |\n"
                "|---|---|---|---|---|---|---|---|---|---|\n");
    series sr[3 * 3];
    memset(sr, 0, sizeof sr);
    char refnotes[3][2][512]; /* how good each reference is, printed after the table */
    memset(refnotes, 0, sizeof refnotes);
    for (int ir = 0; ir < nr; ir++) {
        plume_study_config c;
        char name[160], label[128];
        int iref[2], irun[3][4];
        for (int k = 0; k < 2; k++) {
            base_tilted(&c, ratios[ir]);
            set_model(&c, k);
            c.edge = ref_edge;
            snprintf(name, sizeof name, "cost/r%g/reference_%s", ratios[ir], model_short[k]);
            snprintf(label, sizeof label, "reference %s", model_name(&c));
            iref[k] = do_run(s, &c, name, label);
        }
        for (int m = 0; m < 3; m++) {
            series *a = &sr[ir * 3 + m];
            snprintf(a->label, sizeof a->label, "%s, Exx/Eyy %g", model_short[m], ratios[ir]);
            for (int ie = 0; ie < ne; ie++) {
                base_tilted(&c, ratios[ir]);
                set_model(&c, m);
                c.edge = edges[ie];
                snprintf(name, sizeof name, "cost/r%g/%s/e%g", ratios[ir], model_short[m], edges[ie]);
                int i = irun[m][ie] = do_run(s, &c, name, name);
                const run *r = &s->runs[i], *ref = &s->runs[iref[m == 0 ? 0 : 1]];
                double es = NAN, ew = NAN;
                if (ok(r) && ok(ref)) {
                    es = plume_study_rel_error(r->res.stress, ref->res.stress);
                    ew = plume_study_rel_error(r->res.wbar, ref->res.wbar);
                    if (a->n < 64) {
                        a->x[a->n] = log10(fmax(r->res.seconds, 1e-6));
                        a->y1[a->n] = log10(fmax(es, 1e-16));
                        a->y2[a->n] = log10(fmax(ew, 1e-16));
                        a->n++;
                    }
                }
                fprintf(md, "| %g | %s | %g | %ld | %.3f | %d | %s%s%s | %.6g | %.2e | %.2e |\n", ratios[ir],
                        model_name(&c), edges[ie], r->res.elements, r->res.seconds, r->res.iterations, outcome(r),
                        r->st != PLUME_OK ? ": " : "", r->msg, r->res.stress, es, ew);
            }
        }
        for (int k = 0; k < 2; k++) {
            const run *r = &s->runs[iref[k]];
            fprintf(md, "| %g | reference %s | %g | %ld | %.3f | %d | %s%s%s | %.6g | — | — |\n", ratios[ir],
                    model_name(&r->cfg), ref_edge, r->res.elements, r->res.seconds, r->res.iterations, outcome(r),
                    r->st != PLUME_OK ? ": " : "", r->msg, r->res.stress);
            reference_note(s, ratios[ir], irun[k][ne - 2], irun[k][ne - 1], iref[k], refnotes[ir][k],
                           sizeof refnotes[ir][k]);
        }
    }
    if (!s->quick) {
        fprintf(md, "\nHow good the references are: with d1, d2 the stress differences between successive halvings "
                    "of the edge down to the reference's (%g → %g → %g) and r = d2 / d1, a model converging "
                    "geometrically is |d2| r / (1 − r) from its limit (Richardson); the errors above leave that out.\n\n",
                edges[ne - 2], edges[ne - 1], ref_edge);
        for (int ir = 0; ir < nr; ir++)
            for (int k = 0; k < 2; k++)
                fprintf(md, "- %s\n", refnotes[ir][k]);
    }
    /* colour by model, point type by E_xx/E_yy (circle, square, triangle), the legend under the panels */
    static const int ratio_point[3] = {7, 5, 9};
    int color[9], point[9];
    for (int ir = 0; ir < nr; ir++)
        for (int m = 0; m < 3; m++)
            color[ir * 3 + m] = m + 1, point[ir * 3 + m] = ratio_point[ir];
    plot_series_styled(s, "cost_error.png", "Cost against error, tilted 45 deg traction, 5% strain",
                       "log10 wall time (s)", "log10 relative stress error at 5% strain",
                       "log10 relative w-bar error at 5% strain", sr, nr * 3, color, point, md);
}

/* ---- 2. solvers ---- */
static void section_solvers(study *s, FILE *md)
{
    const double edges_full[] = {0.05, 0.025}, edges_quick[] = {0.1, 0.05};
    const double *edges = s->quick ? edges_quick : edges_full;
    const plume_solver_kind kinds[3] = {PLUME_SOLVER_NEWTON, PLUME_SOLVER_IPOPT, PLUME_SOLVER_LINEARIZED};
    fprintf(md, "\n## 2. Solvers on the same problems\n\n"
                "Aligned+constraint, tilted 45°, E_xx/E_yy = 1e4, 2 load steps to 5 %% strain. `linearized` takes one "
                "linear step per load step and never claims convergence: its stress error against newton is the "
                "paper's Figure 1 point.\n\n"
                "| edge | elements | solver | seconds | iterations | outcome | stress | stress error vs newton |\n"
                "|---|---|---|---|---|---|---|---|\n");
    for (int ie = 0; ie < 2; ie++) {
        int idx[3];
        for (int k = 0; k < 3; k++) {
            plume_study_config c;
            base_tilted(&c, 1e4);
            c.edge = edges[ie];
            c.solver = kinds[k];
            char name[160];
            snprintf(name, sizeof name, "solvers/e%g/%s", edges[ie], plume_solver_kind_name(kinds[k]));
            idx[k] = do_run(s, &c, name, name);
        }
        for (int k = 0; k < 3; k++) {
            const run *r = &s->runs[idx[k]], *nt = &s->runs[idx[0]];
            double e = ok(r) && ok(nt) ? plume_study_rel_error(r->res.stress, nt->res.stress) : NAN;
            fprintf(md, "| %g | %ld | %s | %.3f | %d | %s%s%s | %.6g | %.2e |\n", edges[ie], r->res.elements,
                    plume_solver_kind_name(kinds[k]), r->res.seconds, r->res.iterations, outcome(r),
                    r->st != PLUME_OK ? ": " : "", r->msg, r->res.stress, e);
        }
    }
}

/* ---- 3. sensitivity ---- */
static void section_sensitivity(study *s, FILE *md)
{
    double edge = s->quick ? 0.1 : 0.05;
    int steps = s->quick ? 5 : 10;
    fprintf(md, "\n## 3. Sensitivity to ±10 %% on E_yy and G_xy (supplementary §10, Table 2, Figure 15)\n\n"
                "Aligned+constraint, tilted 45°, l_x = 1, l_y = 1.38 (aspect 1.38 as Table 2), E_xx/E_yy = 1e4, "
                "edge %g, %d load steps to 5 %% strain, newton. Relative change against the reference moduli "
                "(E_yy = G_xy = 1) at 5 %% strain.\n\n"
                "| parameter | change | outcome | stress | Δstress/stress | w̄ | Δw̄/w̄ |\n|---|---|---|---|---|---|---|\n",
            edge, steps);
    plume_study_config c;
    base_tilted(&c, 1e4);
    c.ly = 1.38, c.edge = edge, c.steps = steps;
    int iref = do_run(s, &c, "sensitivity/reference", "reference");
    const char *pname[2] = {"E_yy", "G_xy"};
    char charts[2][256] = {"", ""}; /* after the table, which a chart line would cut in two */
    for (int p = 0; p < 2; p++) {
        int idx[2];
        for (int sgn = 0; sgn < 2; sgn++) {
            plume_study_config d = c;
            double f = sgn == 0 ? 1.1 : 0.9;
            if (p == 0)
                d.moduli.E_yy *= f;
            else
                d.moduli.G_xy *= f;
            char name[160], label[128];
            snprintf(name, sizeof name, "sensitivity/%s_%s10", pname[p], sgn == 0 ? "plus" : "minus");
            snprintf(label, sizeof label, "%s %s10%%", pname[p], sgn == 0 ? "+" : "-");
            idx[sgn] = do_run(s, &d, name, label);
        }
        const run *ref = &s->runs[iref];
        for (int sgn = 0; sgn < 2; sgn++) {
            const run *r = &s->runs[idx[sgn]];
            double ds = NAN, dw = NAN;
            if (ok(r) && ok(ref)) {
                ds = (r->res.stress - ref->res.stress) / ref->res.stress;
                dw = (r->res.wbar - ref->res.wbar) / ref->res.wbar;
            }
            fprintf(md, "| %s | %s10 %% | %s | %.6g | %+.4f | %.6g | %+.4f |\n", pname[p], sgn == 0 ? "+" : "−",
                    outcome(r), r->res.stress, ds, r->res.wbar, dw);
        }
        /* chart: reference, +10 %, -10 % */
        plume_curve cv[3];
        const char *labels[3];
        int n = 0;
        const int which[3] = {iref, idx[0], idx[1]};
        for (int k = 0; k < 3; k++) {
            const run *r = &s->runs[which[k]];
            if (r->st == PLUME_OK && r->res.curve.n > 0)
                cv[n] = r->res.curve, labels[n] = r->label, n++;
        }
        char file[64], path[1200], title[96];
        snprintf(file, sizeof file, "sensitivity_%s.png", pname[p]);
        snprintf(path, sizeof path, "%s/%s", s->dir, file);
        snprintf(title, sizeof title, "Sensitivity to %s, tilted 45 deg, aspect 1.38", pname[p]);
        plume_err err = {{0}};
        if (n > 0 && plume_plot_curves(path, title, cv, labels, n, &err) == PLUME_OK)
            snprintf(charts[p], sizeof charts[p], "\n![%s](%s) (stress and w̄ against strain; SVG beside it)\n",
                     title, file);
        else if (n > 0)
            fprintf(stderr, "study: chart %s: %s\n", file, err.msg);
    }    fprintf(md, "%s%s", charts[0], charts[1]);
}

/* ---- 4. model no more than a scene needs ---- */

/* Run i is within the tolerance of the richest run. */
static int within(const study *s, int i, const run *rich)
{
    return i >= 0 && ok(&s->runs[i]) && rich && ok(rich) &&
           plume_study_rel_error(s->runs[i].res.stress, rich->res.stress) <= TOL_SCENE;
}

#define SCENE_MAX_EDGES 4

/* Section 4's candidates: models × edges × solvers per scenario, their runs' indices (-1: none). */
typedef struct {
    const double *edges;
    int ne;
    int idx[3][SCENE_MAX_EDGES][3];
    int richest;
} scene_grid;

/* The section's heading, what it measures and the table's head. */
static void scenes_intro(FILE *md, const scene_grid *g)
{
    fprintf(md, "\n## 4. Model no more than a scene needs\n\n"
                "Each shipped traction scenario (l_x = 1, l_y = 1.3, E_xx/E_yy = 1e4, E_yy = G_xy = 1), 2 load "
                "steps to 5 %% strain. Candidates: {aligned+constraint, aligned+penalty, unaligned+penalty} × "
                "edges {");
    for (int ie = 0; ie < g->ne; ie++)
        fprintf(md, "%s%g", ie ? ", " : "", g->edges[ie]);
    fprintf(md, "} × {newton, ipopt, linearized}. Richest: aligned+constraint at edge %g with newton (the "
                "longitudinal scenario: aligned+penalty, because constrained barbs run from one grip to the "
                "other and the sample cannot stretch). Cheapest: the least wall time whose stress at 5 %% is "
                "within %.0f %% of the richest, and stays within it on every finer mesh of the same model and "
                "solver: a coarse mesh whose discretisation error happens to cancel the model's own difference "
                "does not count. The last column names the cheapest candidate that is within %.0f %% on its own "
                "mesh only, with the error of the same model and solver on the finest mesh.\n\n",
            g->edges[g->ne - 1], 100 * TOL_SCENE, 100 * TOL_SCENE);
    fprintf(md, "| scenario | richest stress | cheapest within %.0f %% | its seconds | its error | richest seconds | "
                "candidates within / also on finer meshes / measured | failures | within on its mesh only |\n"
                "|---|---|---|---|---|---|---|---|---|\n", 100 * TOL_SCENE);
}

/* Runs scenario sc's candidates (the longitudinal one's constrained model once: it is infeasible)
 * and names the richest. */
static void run_scene_candidates(study *s, int sc, scene_grid *g)
{
    const plume_solver_kind kinds[3] = {PLUME_SOLVER_NEWTON, PLUME_SOLVER_IPOPT, PLUME_SOLVER_LINEARIZED};
    const char *scen[3] = {"tilted", "transverse", "longitudinal"};
    const double angles[3] = {45.0, 90.0, 0.0};
    const int ne = g->ne;
    g->richest = -1;
    for (int m = 0; m < 3; m++)
        for (int ie = 0; ie < ne; ie++)
            for (int k = 0; k < 3; k++) {
                g->idx[m][ie][k] = -1;
                plume_study_config c;
                base_tilted(&c, 1e4);
                c.angle = angles[sc];
                set_model(&c, m);
                c.edge = g->edges[ie];
                c.solver = kinds[k];
                if (sc == 2 && m == 0 && !(ie == 0 && k == 0))
                    continue; /* infeasible: shown once, at the coarsest mesh with newton */
                char name[160];
                snprintf(name, sizeof name, "scenes/%s/%s/e%g/%s", scen[sc], model_short[m], g->edges[ie],
                         plume_solver_kind_name(kinds[k]));
                g->idx[m][ie][k] = do_run(s, &c, name, name);
                if (ie == ne - 1 && k == 0 && m == (sc == 2 ? 1 : 0))
                    g->richest = g->idx[m][ie][k];
            }
}

/* What a scenario's candidates gave against its richest run: the cheapest within the tolerance on
 * its mesh and every finer one (best), the cheapest within it on its own mesh only (lone, with the
 * same model and solver on the finest mesh), the counts and the failures. */
typedef struct {
    int best, lone, lone_finest, nwithin, nstable, measured;
    char failures[2048];
} scene_choice;

static void choose_scene_candidate(const study *s, const scene_grid *g, scene_choice *ch)
{
    const run *rich = g->richest >= 0 ? &s->runs[g->richest] : NULL;
    const int ne = g->ne;
    *ch = (scene_choice){.best = -1, .lone = -1, .lone_finest = -1};
    for (int m = 0; m < 3; m++)
        for (int ie = 0; ie < ne; ie++)
            for (int k = 0; k < 3; k++) {
                int i = g->idx[m][ie][k];
                if (i < 0)
                    continue;
                const run *r = &s->runs[i];
                ch->measured++;
                if (!ok(r)) {
                    size_t len = strlen(ch->failures);
                    snprintf(ch->failures + len, sizeof ch->failures - len, "%s`%s`: %s", len ? "; " : "", r->name,
                             r->st != PLUME_OK ? r->msg : outcome(r));
                    continue;
                }
                if (!within(s, i, rich))
                    continue;
                ch->nwithin++;
                int stable = 1;
                for (int f = ie + 1; f < ne; f++)
                    stable &= within(s, g->idx[m][f][k], rich);
                double t = r->res.seconds;
                if (stable) {
                    ch->nstable++;
                    if (ch->best < 0 || t < s->runs[ch->best].res.seconds)
                        ch->best = i;
                } else if (ch->lone < 0 || t < s->runs[ch->lone].res.seconds) {
                    ch->lone = i, ch->lone_finest = g->idx[m][ne - 1][k];
                }
            }
}

/* The scenario's row of the table. */
static void write_scene_row(FILE *md, const study *s, const char *scenario, const scene_grid *g,
                            const scene_choice *ch)
{
    const run *rich = g->richest >= 0 ? &s->runs[g->richest] : NULL;
    const int best = ch->best, lone = ch->lone, lone_finest = ch->lone_finest;
    char lonetxt[512] = "none";
    if (lone >= 0 && lone_finest >= 0 && s->runs[lone].res.seconds < (best >= 0 ? s->runs[best].res.seconds : INFINITY)) {
        const run *l = &s->runs[lone], *lf = &s->runs[lone_finest];
        char ferr[64];
        if (ok(lf) && rich && ok(rich))
            snprintf(ferr, sizeof ferr, "%.2e", plume_study_rel_error(lf->res.stress, rich->res.stress));
        else
            snprintf(ferr, sizeof ferr, "%s", outcome(lf));
        snprintf(lonetxt, sizeof lonetxt, "%s, edge %g, %s: %.3f s, error %.2e; at edge %g: %s", model_name(&l->cfg),
                 l->cfg.edge, plume_solver_kind_name(l->cfg.solver), l->res.seconds,
                 plume_study_rel_error(l->res.stress, rich->res.stress), g->edges[g->ne - 1], ferr);
    }
    const char *failures = ch->failures[0] ? ch->failures : "none";
    if (best >= 0) {
        const run *b = &s->runs[best];
        fprintf(md, "| %s | %.6g | %s, edge %g, %s | %.3f | %.2e | %.3f | %d / %d / %d | %s | %s |\n", scenario,
                rich->res.stress, model_name(&b->cfg), b->cfg.edge, plume_solver_kind_name(b->cfg.solver),
                b->res.seconds, plume_study_rel_error(b->res.stress, rich->res.stress), rich->res.seconds, ch->nwithin,
                ch->nstable, ch->measured, failures, lonetxt);
    } else {
        fprintf(md, "| %s | %s | none | — | — | — | %d / %d / %d | %s | %s |\n", scenario,
                rich && ok(rich) ? "measured" : "richest run failed", ch->nwithin, ch->nstable, ch->measured, failures,
                lonetxt);
    }
}

static void section_scenes(study *s, FILE *md)
{
    static const double edges_full[SCENE_MAX_EDGES] = {0.1, 0.05, 0.025, 0.0125}, edges_quick[2] = {0.1, 0.05};
    const char *scen[3] = {"tilted", "transverse", "longitudinal"};
    scene_grid g = {.edges = s->quick ? edges_quick : edges_full, .ne = s->quick ? 2 : 4};
    scenes_intro(md, &g);
    for (int sc = 0; sc < 3; sc++) {
        scene_choice ch;
        run_scene_candidates(s, sc, &g);
        choose_scene_candidate(s, &g, &ch);
        write_scene_row(md, s, scen[sc], &g, &ch);
    }
    fprintf(md, "\nA `linearized` candidate never converges by design; it counts when its stress is within the "
                "tolerance. All stresses of every candidate are in study.h5 under /curves/study/scenes_*.\n");
}

/* 5. the stability matrix: each cell measured (or said not to be) */
static void section_stability(study *s, FILE *md)
{
    if (s->planning) /* no traction runs: measured in the report walk */
        return;
    plume_err err = {{0}};
    fprintf(md, "\n## 5. Stability: where each method fails\n\n"
                "| cell | measured | outcome |\n|---|---|---|\n");
    /* penalty conditioning per ratio (paper Figure 6) */
    const double ratios[4] = {1.0, 1e2, 1e4, 1e6};
    for (int k = 0; k < (s->quick ? 3 : 4); k++) {
        double pen = NAN, con = NAN;
        plume_status a = plume_stability_condition(ratios[k], 0.1, 0, &pen, &err);
        plume_status b = plume_stability_condition(ratios[k], 0.1, 1, &con, &err);
        fprintf(md, "| conditioning, E_xx/E_yy = %g (tilted 45°, edge 0.1) | condition estimate 1/rcond: penalty %.3g, "
                    "constrained %.3g | %s |\n",
                ratios[k], pen, con, a || b ? err.msg : "the penalty model's grows with the ratio, the constraint's does not");
    }
    /* St Venant-Kirchhoff collapse under compression, with and without the cubic term */
    const double kappa[2] = {0.0, 1000.0};
    for (int k = 0; k < 2; k++) {
        double jmin = NAN, jmax = NAN;
        int conv = 0, it = 0;
        double t0 = now();
        plume_status st = plume_stability_compression(kappa[k], 0, 0.3, 30, &jmin, &jmax, &conv, &it, &err);
        fprintf(md, "| compression to 30 %% length, kappa = %g (supplementary Figure 7) | element area ratio J in "
                    "[%.3f, %.3f], %d iterations, %.2f s, %s | %s |\n",
                kappa[k], jmin, jmax, it, now() - t0, conv ? "converged" : "not converged",
                st ? err.msg : jmin < 0.0 ? "collapse: elements invert so that others stretch" : "every element stays open");
    }
    fprintf(md, "| single linearised step (supplementary Figure 1) | see section 2: stress error of `linearized` | "
                "diverges from the converged curve |\n"
                "| unaligned mesh, penalty, E_xx/E_yy = 1e4 | see section 1: error against edge, load steps cut "
                "where an increment fails | locking: converges, but its error falls slowly with the mesh (paper "
                "Figure 2) |\n"
                );
    double jmin = NAN, jmax = NAN;
    int conv = 0, it = 0;
    double t0 = now();
    plume_status st = plume_stability_compression(1000.0, 1, 0.3, 30, &jmin, &jmax, &conv, &it, &err);
    fprintf(md, "| log barrier kappa/12 (J - 1 - ln J) in place of the cubic term (§8), kappa = 1000 | J in [%.3f, %.3f], "
                "%d iterations, %.2f s | %s |\n",
            jmin, jmax, it, now() - t0,
            st ? err.msg : conv ? "converged: every element stays open" : "the solver did not converge (as the paper found)");
}

/* ---- 6. Figure 10: the micro model against element size and barb spacing ---- */

#define FIG10_DB_REL 0.086 /* d_B / l_y of the element-size part (supplementary Figure 10, left) */

/* The micro specimen of supplementary Figure 10 (data/layout_fig10.json): strips, phi 0.16,
 * E_B/E_b 1e-6, E_b 2.5 GPa, nu 0.3, thickness 1, d_B = dB_rel l_y, on the study's tilted 1 x 1.3
 * sample; e_rel 0 is the automatic element edge. */
static void fig10_config(plume_study_config *c, int order, double e_rel, double dB_rel)
{
    plume_study_config_default(c);
    c->micro = 1;
    plume_layout *l = &c->layout;
    l->kind = PLUME_LAYOUT_STRIPS;
    l->phi = 0.16, l->ratio = 1e-6, l->E_b = 2.5e9, l->nu_b = 0.3, l->nu_B = 0.3;
    l->h = c->h;
    l->d_B = dB_rel * c->ly;
    l->order = order;
    l->e_rel = e_rel;
}

static double fig10_e_rel(const plume_study_config *c) /* the element edge used, over the barb width */
{
    return plume_layout_element_edge(&c->layout, PLUME_MESH_SPECIMEN) / plume_layout_barb_width(&c->layout);
}

/* The layout's periodic cell homogenised (apps/homogenize's defaults, the tensor only): the same on
 * every rank, so that every rank plans the same macro run. */
static void fig10_homogenize(fig10_cell *cell)
{
    plume_study_config c;
    fig10_config(&c, 2, 0.0, FIG10_DB_REL); /* the cell's moduli do not depend on its size */
    plume_homog_opts o;
    plume_homog_opts_default(&o);
    o.strain_max = 0.0;
    o.convergence = 0; /* a strips cell is a laminate, exact on any mesh (micro/layout.c) */
    plume_homog_result r;
    plume_err err = {{0}};
    cell->st = plume_homogenize(&c.layout, &o, &r, &err);
    cell->done = 1;
    if (cell->st != PLUME_OK) {
        snprintf(cell->msg, sizeof cell->msg, "%s", err.msg);
        return;
    }
    cell->moduli = r.moduli, cell->elements = (long)r.elements, cell->seconds = r.seconds;
    plume_homog_result_free(&r);
}

static double rel_or_nan(const run *a, const run *ref, int wbar)
{
    if (!ok(a) || !ok(ref))
        return NAN;
    return wbar ? plume_study_rel_error(a->res.wbar, ref->res.wbar) : plume_study_rel_error(a->res.stress, ref->res.stress);
}

static void series_add(series *a, double x, double y1, double y2)
{
    if (a->n < 64 && isfinite(x) && isfinite(y1))
        a->x[a->n] = x, a->y1[a->n] = y1, a->y2[a->n] = y2, a->n++;
}

/* The measured ratios of part 6a: successive changes per order, and the time the quadratic
 * elements need to be as accurate as the finest linear run. */
static void fig10_elements_findings(const study *s, int idx[2][4], const double *e_rel, int ne, FILE *md)
{
    const run *ref = &s->runs[idx[1][ne - 1]];
    double first[2];
    for (int o = 0; o < 2; o++) {
        fprintf(md, "%s- Order %d, relative stress change between successive element sizes:", o ? "" : "\n", o + 1);
        for (int k = 0; k + 1 < ne; k++) {
            double d = rel_or_nan(&s->runs[idx[o][k + 1]], &s->runs[idx[o][k]], 0);
            if (k == 0)
                first[o] = d;
            fprintf(md, " %g → %g: %.2e%s", e_rel[k], e_rel[k + 1], d, k + 2 < ne ? ";" : ".\n");
        }
    }
    fprintf(md, "- From e_rel %g to %g the linear elements' stress changes %.1f times as much as the quadratic "
                "ones'.\n", e_rel[0], e_rel[1], first[0] / first[1]);
    const run *lin = &s->runs[idx[0][ne - 1]];
    double elin = rel_or_nan(lin, ref, 0);
    int best = -1;
    for (int k = 0; k < ne - 1; k++) { /* the reference itself excluded */
        const run *q = &s->runs[idx[1][k]];
        if (rel_or_nan(q, ref, 0) <= elin && (best < 0 || q->res.seconds < s->runs[best].res.seconds))
            best = idx[1][k];
    }
    if (best >= 0)
        fprintf(md, "- The finest linear run (e_rel %g, %.2e from the reference) took %.3f s; the cheapest quadratic "
                    "run at most as far (e_rel %g, %.2e) took %.3f s: a time ratio of %.2f.\n", e_rel[ne - 1], elin,
                lin->res.seconds, s->runs[best].cfg.layout.e_rel, rel_or_nan(&s->runs[best], ref, 0),
                s->runs[best].res.seconds, lin->res.seconds / s->runs[best].res.seconds);
    else
        fprintf(md, "- No quadratic run coarser than the reference is as close to it as the finest linear run "
                    "(%.2e).\n", elin);
}

/* Part 6a: order 1 and 2 over element sizes at d_B / l_y = 0.086, against the finest order-2 run. */
static void fig10_elements(study *s, FILE *md)
{
    const double e_full[] = {2.9, 1.45, 0.725, 0.3625}, e_quick[] = {2.9, 1.45};
    const double *e_rel = s->quick ? e_quick : e_full;
    int ne = s->quick ? 2 : 4, idx[2][4];
    for (int o = 0; o < 2; o++)
        for (int k = 0; k < ne; k++) {
            plume_study_config c;
            fig10_config(&c, o + 1, e_rel[k], FIG10_DB_REL);
            char name[160];
            snprintf(name, sizeof name, "fig10/elements/p%d/e%g", o + 1, e_rel[k]);
            idx[o][k] = do_run(s, &c, name, name);
        }
    if (s->planning)
        return;
    const run *ref = &s->runs[idx[1][ne - 1]];
    fprintf(md, "\n### 6a. Element size (d_B / l_y = %g)\n\nReference: order 2 at e_rel %g, %.6g Pa.\n\n"
                "| e_rel | order | elements | seconds | iterations | outcome | stress (Pa) | error vs reference |\n"
                "|---|---|---|---|---|---|---|---|\n", FIG10_DB_REL, e_rel[ne - 1], ref->res.stress);
    series size[2], cost[2];
    memset(size, 0, sizeof size), memset(cost, 0, sizeof cost);
    for (int o = 0; o < 2; o++) {
        snprintf(size[o].label, sizeof size[o].label, "order %d", o + 1);
        snprintf(cost[o].label, sizeof cost[o].label, "order %d", o + 1);
        for (int k = 0; k < ne; k++) {
            const run *r = &s->runs[idx[o][k]];
            double es = rel_or_nan(r, ref, 0), ew = rel_or_nan(r, ref, 1);
            fprintf(md, "| %g | %d | %ld | %.3f | %d | %s%s%s | %.6g | %.2e |\n", e_rel[k], o + 1, r->res.elements,
                    r->res.seconds, r->res.iterations, outcome(r), r->st != PLUME_OK ? ": " : "", r->msg,
                    r->res.stress, es);
            if (ok(r))
                series_add(&size[o], log10(e_rel[k]), r->res.stress, log10(fmax(r->res.seconds, 1e-6)));
            if (r != ref && es > 0.0)
                series_add(&cost[o], log10(fmax(r->res.seconds, 1e-6)), log10(es), log10(fmax(ew, 1e-16)));
        }
    }
    fig10_elements_findings(s, idx, e_rel, ne, md);
    char title[160];
    snprintf(title, sizeof title, "Micro model, dB/ly %g: stress at 5%% against element size (reference %.1f Pa)",
             FIG10_DB_REL, ref->res.stress);
    plot_series(s, "fig10_element_size.png", title, "log10 e_rel (element edge / barb width)",
                "nominal stress at 5% strain (Pa)", "log10 wall time (s)", size, 2, md);
    plot_series(s, "fig10_cost_error.png", "Micro model: cost against error, linear and quadratic elements",
                "log10 wall time (s)", "log10 relative stress error at 5% strain",
                "log10 relative w-bar error at 5% strain", cost, 2, md);
}

/* The observed order of the micro-macro difference between successive barb spacings. */
static void fig10_spacing_findings(const study *s, const int *idx, const double *db, int nd, int imacro, FILE *md)
{
    const run *macro = &s->runs[imacro];
    int shrinks = 1;
    fprintf(md, "\n");
    for (int k = 0; k + 1 < nd; k++) {
        double a = rel_or_nan(&s->runs[idx[k]], macro, 0), b = rel_or_nan(&s->runs[idx[k + 1]], macro, 0);
        shrinks &= b < a;
        fprintf(md, "- d_B / l_y %g → %g: the difference goes from %.2e to %.2e, a ratio of %.2f: observed order "
                    "%.2f.\n", db[k], db[k + 1], a, b, a / b, log(a / b) / log(db[k] / db[k + 1]));
    }
    fprintf(md, "- %s\n", shrinks ? "The difference shrinks at every refinement of the spacing."
                                   : "The difference does not shrink at every refinement of the spacing: these "
                                     "spacings show no asymptotic order.");
}

/* Part 6b: order 2 at its automatic element edge over barb spacings, against the homogenised macro model. */
static void fig10_spacing(study *s, FILE *md)
{
    const double db_full[] = {0.172, 0.086, 0.043}, db_quick[] = {0.172, 0.086};
    const double *db = s->quick ? db_quick : db_full;
    int nd = s->quick ? 2 : 3, idx[3], imacro = -1;
    if (s->planning && !s->cell.done)
        fig10_homogenize(&s->cell);
    for (int k = 0; k < nd; k++) {
        plume_study_config c;
        fig10_config(&c, 2, 0.0, db[k]);
        char name[160];
        snprintf(name, sizeof name, "fig10/spacing/dB%g", db[k]);
        idx[k] = do_run(s, &c, name, name);
    }
    plume_study_config m;
    plume_study_config_default(&m);
    m.moduli = s->cell.moduli; /* constraint on: inextensible barbs; aligned mesh */
    m.edge = s->quick ? 0.05 : 0.02;
    if (s->cell.st == PLUME_OK)
        imacro = do_run(s, &m, "fig10/spacing/macro", "macro");
    if (s->planning)
        return;
    if (imacro < 0) {
        fprintf(md, "\n### 6b. Barb spacing\n\nThe cell could not be homogenised: %s\n", s->cell.msg);
        return;
    }
    const run *macro = &s->runs[imacro];
    fprintf(md, "\n### 6b. Barb spacing (supplementary Figure 10, right)\n\nOrder 2 at its automatic element edge. "
                "Macro model: the cell homogenised (%ld elements, %.2f s: E_xx %.4g Pa, E_yy %.4g Pa, G_xy %.4g Pa, "
                "ν_xy %.3g), inextensible barbs, aligned mesh, edge %g: %.6g Pa at 5 %% (%s, %.3f s).\n\n"
                "| d_B / l_y | e_rel | order | elements | seconds | iterations | outcome | stress (Pa) | "
                "difference vs macro |\n|---|---|---|---|---|---|---|---|---|\n",
            s->cell.elements, s->cell.seconds, m.moduli.E_xx, m.moduli.E_yy, m.moduli.G_xy, m.moduli.nu_xy, m.edge,
            macro->res.stress, outcome(macro), macro->res.seconds);
    series diff = {.label = "micro (order 2) against macro"};
    for (int k = 0; k < nd; k++) {
        const run *r = &s->runs[idx[k]];
        double es = rel_or_nan(r, macro, 0), ew = rel_or_nan(r, macro, 1);
        fprintf(md, "| %g | %.3g | 2 | %ld | %.3f | %d | %s%s%s | %.6g | %.2e |\n", db[k], fig10_e_rel(&r->cfg),
                r->res.elements, r->res.seconds, r->res.iterations, outcome(r), r->st != PLUME_OK ? ": " : "", r->msg,
                r->res.stress, es);
        if (es > 0.0)
            series_add(&diff, log10(db[k]), log10(es), log10(fmax(ew, 1e-16)));
    }
    fig10_spacing_findings(s, idx, db, nd, imacro, md);
    plot_series(s, "fig10_barb_spacing.png", "Micro against homogenised macro model at 5% strain",
                "log10 dB/ly (barb spacing / sample length)", "log10 relative stress difference",
                "log10 relative w-bar difference", &diff, 1, md);
}

static void section_figure10(study *s, FILE *md)
{
    fprintf(md, "\n## 6. Figure 10: the micro model's element size and barb spacing\n\n"
                "The resolved micro specimen of supplementary Figure 10: strips, φ = 0.16, E_B/E_b = 10⁻⁶, "
                "E_b = 2.5 GPa, ν = 0.3, l_x = 1, l_y = 1.3, h = 1, tilted 45°, 2 load steps to 5 %% strain, newton. "
                "e_rel is the element edge over the barb width; order 1 is the paper's linear triangles, order 2 "
                "quadratic ones (elements counts those).\n");
    fig10_elements(s, md);
    fig10_spacing(s, md);
}

/* the schedule's callbacks (apps/schedule.h): run k executes on any rank and comes back to rank 0
 * as JSON (every double with 17 digits: the same bits as a run in place) */
static json_t *doubles(const double *v, plume_index n)
{
    json_t *a = json_array();
    for (plume_index i = 0; i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static char *execute(void *vctx, int k)
{
    const study *s = vctx;
    plume_study_result res;
    plume_err err = {{0}};
    plume_status st = plume_study_traction(&s->runs[k].cfg, &res, &err);
    const plume_curve *c = &res.curve;
    json_t *j = json_pack("{s:i, s:s, s:f, s:f, s:f, s:f, s:i, s:b, s:b, s:i, s:I, s:I}", "status", (int)st, "message",
                          err.msg, "strain", res.strain, "stress", res.stress, "wbar", res.wbar, "seconds", res.seconds,
                          "iterations", res.iterations, "converged", res.converged, "complete", res.complete, "reason",
                          (int)res.reason, "elements", (json_int_t)res.elements, "vertices", (json_int_t)res.vertices);
    json_object_set_new(j, "c_strain", doubles(c->strain, c->n));
    json_object_set_new(j, "c_stress", doubles(c->stress, c->n));
    json_object_set_new(j, "c_wbar", doubles(c->wbar, c->n));
    json_object_set_new(j, "c_iterations", doubles(c->iterations, c->n));
    json_object_set_new(j, "c_seconds", doubles(c->seconds, c->n));
    char *text = json_dumps(j, JSON_COMPACT | JSON_REAL_PRECISION(17));
    json_decref(j);
    if (st == PLUME_OK)
        plume_study_result_free(&res);
    return text;
}

/* a JSON number that may be a NaN written as null (json_real refuses NaN: it is dropped) */
static double number(json_t *o, const char *key)
{
    json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static int keep(void *vctx, int k, const char *record)
{
    study *s = vctx;
    run *r = &s->runs[k];
    json_t *j = json_loads(record, 0, NULL);
    if (!j)
        return 1;
    memset(&r->res, 0, sizeof r->res);
    r->st = (plume_status)json_integer_value(json_object_get(j, "status"));
    snprintf(r->msg, sizeof r->msg, "%s", json_string_value(json_object_get(j, "message")));
    r->res.strain = number(j, "strain"), r->res.stress = number(j, "stress"), r->res.wbar = number(j, "wbar");
    r->res.seconds = number(j, "seconds");
    r->res.iterations = (int)json_integer_value(json_object_get(j, "iterations"));
    r->res.converged = json_is_true(json_object_get(j, "converged"));
    r->res.complete = json_is_true(json_object_get(j, "complete"));
    r->res.reason = (plume_reason)json_integer_value(json_object_get(j, "reason"));
    r->res.elements = (long)json_integer_value(json_object_get(j, "elements"));
    r->res.vertices = (long)json_integer_value(json_object_get(j, "vertices"));
    plume_curve *c = &r->res.curve;
    static const char *const names[5] = {"c_strain", "c_stress", "c_wbar", "c_iterations", "c_seconds"};
    double **dst[5] = {&c->strain, &c->stress, &c->wbar, &c->iterations, &c->seconds};
    c->n = (plume_index)json_array_size(json_object_get(j, names[0]));
    for (int q = 0; q < 5; q++) {
        json_t *a = json_object_get(j, names[q]);
        *dst[q] = calloc((size_t)c->n + 1, sizeof(double));
        for (plume_index i = 0; *dst[q] && i < c->n; i++) {
            json_t *v = json_array_get(a, (size_t)i);
            (*dst[q])[i] = json_is_number(v) ? json_number_value(v) : NAN;
        }
    }
    json_decref(j);
    return 0;
}

/* A run's relative cost, for the order the runs are handed out in (nothing else depends on it):
 * elements x steps, 20x for the unaligned penalty model (hundreds of iterations: locking), 2.5x
 * for Ipopt, a tenth for the single linearised step; a micro run by its element edge. */
static double cost_estimate(const plume_study_config *c)
{
    if (c->micro) { /* a quadratic element has about 4x the unknowns of a linear one of its edge */
        double h = plume_layout_element_edge(&c->layout, PLUME_MESH_SPECIMEN);
        return c->lx * c->ly / (h * h) * c->steps * (c->layout.order == 2 ? 4.0 : 1.0);
    }
    double e = c->lx * c->ly / (c->edge * c->edge) * c->steps;
    if (c->mesh != PLUME_PATCH_ALIGNED && !c->constraint)
        e *= 20.0;
    if (c->solver == PLUME_SOLVER_IPOPT)
        e *= 2.5;
    else if (c->solver == PLUME_SOLVER_LINEARIZED)
        e *= 0.1;
    return e;
}

static const study *cost_order; /* the study qsort's comparison reads (main sets it once) */

static int by_cost(const void *a, const void *b)
{
    int i = *(const int *)a, j = *(const int *)b;
    double ci = cost_estimate(&cost_order->runs[i].cfg), cj = cost_estimate(&cost_order->runs[j].cfg);
    return ci > cj ? -1 : ci < cj ? 1 : i - j;
}

/* Parses argv into s's flags (dir, quick, json). 0, CLI_HELP after --help, or the exit code of
 * bad input. */
static int parse_args(int argc, char **argv, study *s)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-o") == 0) {
            if (i + 1 >= argc)
                return cli_fail("study", "-o expects a directory");
            s->dir = argv[++i];
        } else if (strcmp(a, "--quick") == 0) {
            s->quick = 1;
        } else if (strcmp(a, "--json") == 0) {
            s->json = 1;
        } else if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            return CLI_HELP;
        } else {
            fputs(usage, stderr);
            return cli_fail("study", "unknown flag '%s'", a);
        }
    }
    if (!s->dir || !*s->dir) {
        fputs(usage, stderr);
        return cli_fail("study", "-o DIR is required");
    }
    return 0;
}

/* Every section of the study, in order, into md (/dev/null while the runs are planned). */
static void all_sections(study *s, FILE *md)
{
    section_cost(s, md);
    section_solvers(s, md);
    section_sensitivity(s, md);
    section_scenes(s, md);
    section_stability(s, md);
    section_figure10(s, md);
}

/* The runs, planned on every rank by the same walk of the sections. Exit code. */
static int plan_runs(study *s)
{
    FILE *null = fopen("/dev/null", "w");
    if (!null)
        return fprintf(stderr, "study: cannot open /dev/null\n"), 1;
    s->planning = 1;
    all_sections(s, null);
    fclose(null);
    s->planning = 0;
    return 0;
}

/* The runs executed over the ranks, handed out longest first by a cost estimate: a dynamic
 * schedule cannot make up for a long run that starts last (the full study's 142 s Ipopt run,
 * planned near the end, kept 2 ranks at 231 s against the 156 s the longest-first order allows).
 * Returns schedule_run's code. */
static int execute_runs(study *s, int rank, int size)
{
    int *todo = malloc(((size_t)s->nruns + 1) * sizeof *todo);
    for (int k = 0; k < s->nruns; k++)
        todo[k] = k;
    cost_order = s;
    qsort(todo, (size_t)s->nruns, sizeof *todo, by_cost);
    int rc = schedule_run(rank, size, todo, s->nruns, execute, keep, s);
    free(todo);
    return rc;
}

/* DIR/summary.md (written under a temporary name, then renamed); *failed: the runs without a
 * converged curve. Exit code. */
static int write_summary(study *s, const char *mdpath, int *failed)
{
    char mdtmp[1300];
    snprintf(mdtmp, sizeof mdtmp, "%s.tmp", mdpath);
    FILE *md = fopen(mdtmp, "w");
    if (!md)
        return fprintf(stderr, "study: cannot write %s: %s\n", mdtmp, strerror(errno)), 1;
    s->t0 = now();
    fprintf(md, "# plume study (%s)\n\nWritten by `apps/study%s`. Curves of every run: study.h5, "
                "/curves/study/<section>_<case>, with the run's parameters as attributes (`outcome` says converged "
                "or why not). Times are wall times of the traction run on this machine, one run at a time.\n",
            s->quick ? "quick" : "full", s->quick ? " --quick" : "");
    all_sections(s, md);
    *failed = 0;
    for (int i = 0; i < s->nruns; i++)
        *failed += !ok(&s->runs[i]);
    fprintf(md, "\n## Totals\n\n%d runs, %d without a converged curve to 5 %% strain (listed above), %.1f s wall time "
                "for the whole study.\n", s->nruns, *failed, now() - s->t0);
    int bad = ferror(md);
    if (fclose(md) != 0 || bad || rename(mdtmp, mdpath) != 0) {
        fprintf(stderr, "study: cannot write %s\n", mdpath);
        return 1;
    }
    return 0;
}

/* --json: every run's figures, the failures, and where the results are. */
static void print_json(const study *s, int failed, const char *mdpath)
{
    json_t *j = json_object(), *arr = json_array();
    for (int i = 0; i < s->nruns; i++) {
        const run *r = &s->runs[i];
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(r->name));
        json_object_set_new(o, "model", json_string(model_name(&r->cfg)));
        json_object_set_new(o, "solver", json_string(plume_solver_kind_name(r->cfg.solver)));
        if (r->cfg.micro) {
            json_object_set_new(o, "order", json_integer(r->cfg.layout.order));
            json_object_set_new(o, "e_rel", json_real(fig10_e_rel(&r->cfg)));
            json_object_set_new(o, "dB_rel", json_real(r->cfg.layout.d_B / r->cfg.ly));
        } else {
            json_object_set_new(o, "edge", json_real(r->cfg.edge));
        }
        json_object_set_new(o, "outcome", json_string(outcome(r)));
        if (r->st != PLUME_OK)
            json_object_set_new(o, "error", json_string(r->msg));
        json_object_set_new(o, "elements", json_integer(r->res.elements));
        json_object_set_new(o, "seconds", json_real(r->res.seconds));
        json_object_set_new(o, "iterations", json_integer(r->res.iterations));
        if (isfinite(r->res.stress))
            json_object_set_new(o, "stress", json_real(r->res.stress));
        if (isfinite(r->res.wbar))
            json_object_set_new(o, "wbar", json_real(r->res.wbar));
        json_array_append_new(arr, o);
    }
    json_object_set_new(j, "quick", json_boolean(s->quick));
    json_object_set_new(j, "runs", arr);
    json_object_set_new(j, "failures", json_integer(failed));
    json_object_set_new(j, "seconds", json_real(now() - s->t0));
    json_object_set_new(j, "h5", json_string(s->h5));
    json_object_set_new(j, "summary", json_string(mdpath));
    cli_print_json(j, JSON_INDENT(2));
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    int rank, size;
    schedule_init(&argc, &argv, &rank, &size);
    study s;
    memset(&s, 0, sizeof s);
    int rc = parse_args(argc, argv, &s);
    if (rc) {
        schedule_finalize();
        return rc == CLI_HELP ? 0 : rc;
    }
    /* the output directory first (rank 0), so that a bad one stops the study before its runs */
    int bad_dir = 0;
    if (rank == 0)
        bad_dir = cli_output_dir("study", "-o", s.dir) != 0;
    if (schedule_share(bad_dir)) {
        schedule_finalize();
        return 2;
    }
    snprintf(s.h5, sizeof s.h5, "%s/study.h5", s.dir);
    if ((rc = plan_runs(&s))) {
        schedule_finalize();
        return rc;
    }
    double t_runs = now();
    int rc_runs = execute_runs(&s, rank, size);
    if (rank > 0) {
        schedule_finalize();
        return 0;
    }
    if (rc_runs)
        fprintf(stderr, "study: a run's result was lost on its way to rank 0\n");
    fprintf(stderr, "study: %d runs in %.1f s on %d rank%s\n", s.nruns, now() - t_runs, size, size == 1 ? "" : "s");
    char mdpath[1200];
    snprintf(mdpath, sizeof mdpath, "%s/summary.md", s.dir);
    int failed = 0;
    if ((rc = write_summary(&s, mdpath, &failed))) {
        schedule_finalize();
        return rc;
    }
    if (s.json)
        print_json(&s, failed, mdpath);
    for (int i = 0; i < s.nruns; i++)
        plume_study_result_free(&s.runs[i].res);
    free(s.runs);
    schedule_finalize();
    return s.write_failures ? 1 : 0;
}
