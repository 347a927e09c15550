/* apps/fit — macroscale moduli fitted to traction curves (microscale ones from apps/traction
 * --model micro, or measured ones as text files) with NLopt: the paper's protocol. With --bending,
 * the plate's bending moduli fitted the same way to the bending curves of apps/traction --bending
 * (docs/bending-homogenisation.md, "Fitting bending moduli"). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"
#include "schedule.h"

#define APP "fit"
#define MAX_TARGETS 16

static const char usage[] =
    "usage: fit --target CURVE --angle DEG [--target CURVE --angle DEG ...] [options]\n"
    "Fits the macroscale vane's moduli to traction curves (NLopt BOBYQA, log-space).\n"
    "  --target FILE.h5:SCALE/SCENARIO   a curve written by apps/traction (e.g. out.h5:micro/tilted)\n"
    "  --target FILE.txt                 a measured curve: two columns, strain and stress (Pa)\n"
    "  --angle DEG          barb angle of the last --target (default 45)\n"
    "  --lx M --ly M --thickness M   sample of the targets (default 1, 1.3, 1)\n"
    "  --Exx --Eyy --Gxy PA, --nu V  start values (and the fixed ones; default 1e4, 1, 1, 0)\n"
    "  --free LIST          moduli to fit, comma-separated from Exx,Eyy,nu,Gxy (default Eyy,Gxy)\n"
    "  --constraint on|off  barbs inextensible in the model (default on)\n"
    "  --edge M --steps N   model mesh and steps (default min(lx, ly)/20 as apps/traction, 5)\n"
    "  --max-eval N         (default 300)\n"
    "  --starts K           K fits from K starting points (the given one, then the free moduli scaled by\n"
    "                       10^[-1, 1] on a Halton sequence), the best kept; spread over MPI ranks under\n"
    "                       mpirun (default 1)\n"
    "  -o FILE.h5           write /moduli (fitted) and /curves/fit/<i>/... model curves\n"
    "  --plot FILE.png      targets and fitted model curves\n"
    "  --json               print the fitted moduli, residual, evaluations, seconds\n"
    "Bending (docs/bending-homogenisation.md):\n"
    "  --bending FILE.h5[:SCALE]  fit the plate's bending moduli to every bending curve of the file, the\n"
    "                       groups /curves/bending/SCALE/<LOAD>_<angle> of apps/traction --bending -o\n"
    "                       (SCALE micro by default); repeat for more files. The sample (lx, ly), the\n"
    "                       barb angle and the load are the curves' own; the model is the homogeneous plate\n"
    "                       test (linearized) on a mesh of --edge (default min(lx, ly)/20, as traction's)\n"
    "  --D-long --D-trans --D-coupling --D-twist NM   start values and the fixed ones (N m; default the\n"
    "                       homogenised D the curves record)\n"
    "  --free LIST          from D_long,D_trans,D_coupling,D_twist (default all four); a fit needs at least\n"
    "                       as many distinct curves (load and angle) as free moduli\n"
    "  --max-eval, --starts, --edge, -o, --json as above; -o writes /moduli with the fitted D as attributes\n"
    "                       D_long, D_trans, D_coupling, D_twist (D_16 = D_26 = 0) for a scene's\n"
    "                       \"from_moduli\"; its E_xx..G_xy are the model plate's membrane, not fitted.\n"
    "                       The membrane-only flags (--target, --angle, --lx, --ly, --thickness, --Exx,\n"
    "                       --Eyy, --Gxy, --nu, --constraint, --steps, --plot) are refused with --bending\n"
    "  --help\n";

#define MAX_BEND_FILES 8

/* the flags */
typedef struct {
    const char *targets[MAX_TARGETS];
    double angles[MAX_TARGETS];
    int nt, json, constraint, steps, max_eval, starts, free_set;
    double lx, ly, h, edge, angle;
    plume_ortho start;
    const char *out, *plot, *free_list;
    plume_fit_opts fo;
    /* --bending: the files; start D (D_long, D_trans, D_coupling, D_twist) and which were given;
     * the last membrane-only and bending-only flags seen (to refuse a mix) */
    const char *bend_files[MAX_BEND_FILES];
    int nb;
    double D_start[4];
    int D_set[4];
    const char *membrane_flag, *bend_flag;
} options;

static const char *const bend_moduli[4] = {"D_long", "D_trans", "D_coupling", "D_twist"};
static const char *const bend_flags[4] = {"--D-long", "--D-trans", "--D-coupling", "--D-twist"};
/* the free-modulus bit of each (plume_fit_bending_moduli) */
static const unsigned bend_bits[4] = {PLUME_FIT_D_LONG, PLUME_FIT_D_TRANS, PLUME_FIT_D_COUPLING, PLUME_FIT_D_TWIST};

/* whether a is a flag of the membrane fit only */
static int membrane_only(const char *a)
{
    static const char *const f[] = {"--target", "--angle", "--lx", "--ly", "--thickness", "--Exx", "--Eyy", "--Gxy",
                                    "--nu", "--constraint", "--steps", "--plot", NULL};
    for (int k = 0; f[k]; k++)
        if (strcmp(a, f[k]) == 0)
            return 1;
    return 0;
}

/* Parses argv into o (defaults first). 0, CLI_HELP after --help, or the exit code of bad input. */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->constraint = 1, o->steps = 5, o->max_eval = 300, o->starts = 1;
    o->lx = 1.0, o->ly = 1.3, o->h = 1.0, o->edge = -1.0, o->angle = 45.0;
    o->start = (plume_ortho){1e4, 1.0, 0.0, 1.0};
    o->free_list = "Eyy,Gxy";
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int r = 0;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            return CLI_HELP;
        }
        if (strcmp(a, "--json") == 0) {
            o->json = 1;
            continue;
        }
        if (!v)
            return cli_fail(APP, "%s needs a value (see --help)", a);
        i++;
        if (membrane_only(a))
            o->membrane_flag = a;
        int bk = -1;
        for (int k = 0; k < 4; k++)
            if (strcmp(a, bend_flags[k]) == 0)
                bk = k;
        if (bk >= 0) {
            o->bend_flag = a;
            r = cli_double(APP, a, v, &o->D_start[bk]);
            o->D_set[bk] = 1;
        } else if (strcmp(a, "--bending") == 0) {
            if (o->nb == MAX_BEND_FILES)
                return cli_fail(APP, "at most %d --bending files", MAX_BEND_FILES);
            o->bend_files[o->nb++] = v;
        } else if (strcmp(a, "--target") == 0) {
            if (o->nt == MAX_TARGETS)
                return cli_fail(APP, "at most %d targets", MAX_TARGETS);
            o->targets[o->nt] = v;
            o->angles[o->nt++] = o->angle;
        } else if (strcmp(a, "--angle") == 0) {
            r = cli_double(APP, a, v, &o->angle);
            if (!r && o->nt > 0)
                o->angles[o->nt - 1] = o->angle;
        } else if (strcmp(a, "--lx") == 0) r = cli_double(APP, a, v, &o->lx);
        else if (strcmp(a, "--ly") == 0) r = cli_double(APP, a, v, &o->ly);
        else if (strcmp(a, "--thickness") == 0) r = cli_double(APP, a, v, &o->h);
        else if (strcmp(a, "--Exx") == 0) r = cli_double(APP, a, v, &o->start.E_xx);
        else if (strcmp(a, "--Eyy") == 0) r = cli_double(APP, a, v, &o->start.E_yy);
        else if (strcmp(a, "--Gxy") == 0) r = cli_double(APP, a, v, &o->start.G_xy);
        else if (strcmp(a, "--nu") == 0) r = cli_double(APP, a, v, &o->start.nu_xy);
        else if (strcmp(a, "--edge") == 0) r = cli_double(APP, a, v, &o->edge);
        else if (strcmp(a, "--steps") == 0) r = cli_int(APP, a, v, &o->steps);
        else if (strcmp(a, "--max-eval") == 0) r = cli_int(APP, a, v, &o->max_eval);
        else if (strcmp(a, "--starts") == 0) {
            r = cli_int(APP, a, v, &o->starts);
            if (!r && (o->starts < 1 || o->starts > 10000))
                return cli_fail(APP, "--starts must be in [1, 10000] (got %d)", o->starts);
        }
        else if (strcmp(a, "--free") == 0) o->free_list = v, o->free_set = 1;
        else if (strcmp(a, "--constraint") == 0) {
            if (strcmp(v, "on") && strcmp(v, "off"))
                return cli_fail(APP, "--constraint expects on|off (got '%s')", v);
            o->constraint = strcmp(v, "on") == 0;
        } else if (strcmp(a, "-o") == 0) o->out = v;
        else if (strcmp(a, "--plot") == 0) o->plot = v;
        else
            return cli_fail(APP, "unknown option '%s' (see --help)", a);
        if (r)
            return r;
    }
    if (o->nb > 0 && o->membrane_flag)
        return cli_fail(APP, "--bending cannot be combined with %s (a flag of the membrane fit; the bending "
                        "curves give the sample, angles and loads)", o->membrane_flag);
    if (o->nb == 0 && o->bend_flag)
        return cli_fail(APP, "%s is a start value of a bending fit: it needs --bending FILE.h5", o->bend_flag);
    if (o->nb > 0) {
        plume_fit_opts_default(&o->fo);
        o->fo.max_eval = o->max_eval;
        o->fo.free_mask = 0;
        for (int k = 0; k < 4; k++)
            if (o->D_set[k] && !(isfinite(o->D_start[k]) && (k == 2 || o->D_start[k] > 0.0)))
                return cli_fail(APP, "%s must be finite%s (got %g N m)", bend_flags[k], k == 2 ? "" : " and > 0",
                                o->D_start[k]);
        char list[128];
        snprintf(list, sizeof list, "%s", o->free_set ? o->free_list : "D_long,D_trans,D_coupling,D_twist");
        char *save = NULL;
        for (char *tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
            int k = 0;
            while (k < 4 && strcmp(tok, bend_moduli[k]))
                k++;
            if (k == 4)
                return cli_fail(APP, "--free: '%s' is not a bending modulus (D_long, D_trans, D_coupling, D_twist)",
                                tok);
            o->fo.free_mask |= bend_bits[k];
        }
        if (!o->fo.free_mask)
            return cli_fail(APP, "--free names no modulus");
        return 0;
    }
    if (o->nt == 0)
        return cli_fail(APP, "no --target given (see --help; --bending FILE.h5 fits bending moduli)");
    if (!(o->lx > 0 && o->ly > 0 && o->h > 0))
        return cli_fail(APP, "--lx, --ly and --thickness must be > 0 (got %g, %g, %g)", o->lx, o->ly, o->h);
    plume_fit_opts_default(&o->fo);
    o->fo.max_eval = o->max_eval;
    o->fo.free_mask = 0;
    char list[128];
    snprintf(list, sizeof list, "%s", o->free_list);
    char *save = NULL;
    for (char *tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (strcmp(tok, "Exx") == 0) o->fo.free_mask |= PLUME_FIT_EXX;
        else if (strcmp(tok, "Eyy") == 0) o->fo.free_mask |= PLUME_FIT_EYY;
        else if (strcmp(tok, "nu") == 0) o->fo.free_mask |= PLUME_FIT_NU;
        else if (strcmp(tok, "Gxy") == 0) o->fo.free_mask |= PLUME_FIT_GXY;
        else
            return cli_fail(APP, "--free: unknown modulus '%s' (Exx, Eyy, nu, Gxy)", tok);
    }
    if (!o->fo.free_mask)
        return cli_fail(APP, "--free names no modulus");
    return 0;
}

/* --starts: the K fits, as runs of apps/schedule.h, of the membrane moduli (model, start,
 * best_fit) or, with bending, of the plate's bending moduli (bmodel, bstart, best_bfit) */
typedef struct {
    plume_fit_model model;
    plume_fit_bending_model bmodel;
    void *mm;
    int bending;
    const plume_curve *curves;
    int nt;
    plume_ortho start;
    plume_bending_material bstart;
    plume_fit_opts fo;
    /* rank 0: the best fit so far */
    int best, done;
    plume_ortho best_fit;
    plume_bending_material best_bfit;
    plume_fit_report best_rep;
    double best_residual;
} starts_ctx;

/* the radical inverse of k in base b: the Halton sequence, in [0, 1) */
static double halton(int k, int b)
{
    double f = 1.0, r = 0.0;
    for (; k > 0; k /= b) {
        f /= b;
        r += f * (k % b);
    }
    return r;
}

/* start k: the given one for k = 0, else each free modulus scaled by 10^u, u in [-1, 1) (nu_xy
 * shifted by 0.4 u instead) */
static plume_ortho start_point(const starts_ctx *c, int k)
{
    plume_ortho s = c->start;
    static const int base[4] = {2, 3, 5, 7};
    double *m[4] = {&s.E_xx, &s.E_yy, &s.nu_xy, &s.G_xy};
    static const unsigned bit[4] = {PLUME_FIT_EXX, PLUME_FIT_EYY, PLUME_FIT_NU, PLUME_FIT_GXY};
    for (int j = 0; k > 0 && j < 4; j++) {
        if (!(c->fo.free_mask & bit[j]))
            continue;
        double u = 2.0 * halton(k, base[j]) - 1.0;
        *m[j] = j == 2 ? fmax(-0.9, fmin(0.9, *m[j] + 0.4 * u)) : *m[j] * pow(10.0, u);
    }
    return s;
}

/* bending start k: the given one for k = 0, else D_long, D_trans and D_twist (the free ones) scaled
 * by 10^u, u in [-1, 1), and the coupling's ratio D_coupling / sqrt(D_long D_trans) shifted by 0.4 u
 * within (-0.9, 0.9) */
static plume_bending_material bending_start_point(const starts_ctx *c, int k)
{
    plume_bending_material s = c->bstart;
    static const int base[4] = {2, 3, 5, 7};
    double ratio = s.D_coupling / sqrt(s.D_long * s.D_trans);
    double *m[4] = {&s.D_long, &s.D_trans, &ratio, &s.D_twist};
    for (int j = 0; k > 0 && j < 4; j++) {
        if (!(c->fo.free_mask & bend_bits[j]))
            continue;
        double u = 2.0 * halton(k, base[j]) - 1.0;
        *m[j] = j == 2 ? fmax(-0.9, fmin(0.9, *m[j] + 0.4 * u)) : *m[j] * pow(10.0, u);
    }
    s.D_coupling = ratio * sqrt(s.D_long * s.D_trans);
    return s;
}

/* the record of a bending start: its fit and its start's D_trans and D_twist */
static json_t *bending_start_json(const starts_ctx *c, int k)
{
    plume_bending_material s = bending_start_point(c, k), fit = {0};
    plume_fit_report rep;
    plume_err err = {{0}};
    if (plume_fit_bending_moduli(c->bmodel, c->mm, c->curves, c->nt, &s, &c->fo, &fit, &rep, &err) != PLUME_OK)
        return json_pack("{s:s}", "error", err.msg);
    return json_pack("{s:f, s:f, s:f, s:f, s:f, s:i, s:s, s:f, s:f, s:f}", "D_long", fit.D_long, "D_trans", fit.D_trans,
                     "D_coupling", fit.D_coupling, "D_twist", fit.D_twist, "residual", rep.residual, "evaluations",
                     rep.evaluations, "stop", rep.stop, "seconds", rep.seconds, "start_D_trans", s.D_trans,
                     "start_D_twist", s.D_twist);
}

static char *fit_start(void *vctx, int k)
{
    starts_ctx *c = vctx;
    plume_ortho s = start_point(c, k), fit;
    plume_fit_report rep;
    plume_err err = {{0}};
    json_t *j;
    if (c->bending)
        j = bending_start_json(c, k);
    else if (plume_fit_moduli(c->model, c->mm, c->curves, c->nt, &s, &c->fo, &fit, &rep, &err) == PLUME_OK)
        j = json_pack("{s:f, s:f, s:f, s:f, s:f, s:i, s:s, s:f, s:f, s:f}", "E_xx", fit.E_xx, "E_yy", fit.E_yy, "nu_xy",
                      fit.nu_xy, "G_xy", fit.G_xy, "residual", rep.residual, "evaluations", rep.evaluations, "stop",
                      rep.stop, "seconds", rep.seconds, "start_E_yy", s.E_yy, "start_G_xy", s.G_xy);
    else
        j = json_pack("{s:s}", "error", err.msg);
    char *text = json_dumps(j, JSON_REAL_PRECISION(17) | JSON_COMPACT);
    json_decref(j);
    return text;
}

static int keep_start(void *vctx, int k, const char *record)
{
    starts_ctx *c = vctx;
    json_t *j = json_loads(record, 0, NULL);
    c->done++;
    if (!j)
        return 1;
    if (json_object_get(j, "error")) {
        fprintf(stderr, "%s: start %d: %s\n", APP, k, json_string_value(json_object_get(j, "error")));
    } else {
        double r = json_real_value(json_object_get(j, "residual"));
        /* the two moduli a start's line shows: the cross-barb stiffness and the shear or twist */
        const char *k1 = c->bending ? "D_trans" : "E_yy", *k2 = c->bending ? "D_twist" : "G_xy";
        char s1[32], s2[32];
        snprintf(s1, sizeof s1, "start_%s", k1);
        snprintf(s2, sizeof s2, "start_%s", k2);
        fprintf(stderr, "%s: start %d (%s %.4g, %s %.4g): %s %.6g, %s %.6g %s, misfit %.3g\n", APP, k, k1,
                json_real_value(json_object_get(j, s1)), k2, json_real_value(json_object_get(j, s2)), k1,
                json_real_value(json_object_get(j, k1)), k2, json_real_value(json_object_get(j, k2)),
                c->bending ? "N m" : "Pa", r);
        /* the smallest misfit; ties to the lowest start, so the answer does not depend on the ranks */
        if (c->best < 0 || r < c->best_residual || (r == c->best_residual && k < c->best)) {
            c->best = k, c->best_residual = r;
            if (c->bending)
                c->best_bfit = (plume_bending_material){.D_long = json_real_value(json_object_get(j, "D_long")),
                                                        .D_trans = json_real_value(json_object_get(j, "D_trans")),
                                                        .D_coupling = json_real_value(json_object_get(j, "D_coupling")),
                                                        .D_twist = json_real_value(json_object_get(j, "D_twist"))};
            else
                c->best_fit = (plume_ortho){json_real_value(json_object_get(j, "E_xx")),
                                            json_real_value(json_object_get(j, "E_yy")),
                                            json_real_value(json_object_get(j, "nu_xy")),
                                            json_real_value(json_object_get(j, "G_xy"))};
            memset(&c->best_rep, 0, sizeof c->best_rep);
            c->best_rep.residual = r;
            c->best_rep.evaluations = (int)json_integer_value(json_object_get(j, "evaluations"));
            c->best_rep.seconds = json_real_value(json_object_get(j, "seconds"));
            snprintf(c->best_rep.stop, sizeof c->best_rep.stop, "%s", json_string_value(json_object_get(j, "stop")));
        }
    }
    json_decref(j);
    return 0;
}

#include "fit_bending.h"

/* The --target curves (FILE.h5:SCALE/SCENARIO or a text file) into curves, and the largest last
 * strain among them; each --angle checked. Exit code. */
static int read_targets(const options *o, plume_curve *curves, double *strain_max)
{
    plume_err err = {{0}};
    int rc = 0;
    for (int k = 0; k < o->nt && rc == 0; k++) {
        const char *target = o->targets[k], *colon = strrchr(target, ':');
        plume_status st;
        if (colon && colon != target) { /* FILE.h5:SCALE/SCENARIO */
            char path[1024], group[256];
            snprintf(path, sizeof path, "%.*s", (int)(colon - target), target);
            snprintf(group, sizeof group, "%s", colon + 1);
            char *slash = strchr(group, '/');
            if (!slash) {
                rc = cli_fail(APP, "--target %s: expected FILE.h5:SCALE/SCENARIO", target);
                break;
            }
            *slash = '\0';
            st = plume_curve_read(path, group, slash + 1, &curves[k], &err);
        } else {
            st = plume_curve_read_text(target, &curves[k], &err);
        }
        if (st != PLUME_OK)
            rc = cli_fail(APP, "%s", err.msg);
        else if (!(o->angles[k] >= 0.0 && o->angles[k] <= 180.0))
            rc = cli_fail(APP, "--angle must be in [0, 180] (got %g)", o->angles[k]);
        else
            *strain_max = curves[k].n ? fmax(*strain_max, curves[k].strain[curves[k].n - 1]) : *strain_max;
    }
    return rc;
}

/* --starts K (or several ranks): K fits spread over the ranks, the best kept on rank 0 (*fit,
 * *rep); *worker is set on the other ranks, which are done. Exit code. */
static int fit_from_starts(const options *o, int rank, int size, plume_macro_model *mm, const plume_curve *curves,
                           plume_ortho *fit, plume_fit_report *rep, int *worker)
{
    starts_ctx c = {.model = plume_macro_model_curve, .mm = mm, .curves = curves, .nt = o->nt, .start = o->start,
                    .fo = o->fo, .best = -1, .best_residual = INFINITY};
    int *todo = malloc((size_t)o->starts * sizeof *todo);
    for (int k = 0; k < o->starts; k++)
        todo[k] = k;
    int rc = schedule_run(rank, size, todo, o->starts, fit_start, keep_start, &c);
    free(todo);
    if (rank > 0) {
        *worker = 1;
        return rc;
    }
    if (c.best < 0) {
        fprintf(stderr, "%s: none of the %d starts gave a fit\n", APP, o->starts);
        return 1;
    }
    *fit = c.best_fit, *rep = c.best_rep;
    fprintf(stderr, "%s: the best of %d starts is start %d (misfit %.3g)\n", APP, o->starts, c.best, rep->residual);
    return rc;
}

/* -o: /moduli with the fit's provenance, and the fitted model's curves. Exit code. */
static int write_fit(const options *o, const plume_ortho *fit, const plume_fit_report *rep, const plume_curve *model)
{
    plume_err err = {{0}};
    int rc = 0;
    char prov[256];
    snprintf(prov, sizeof prov, "plume fit: %d curve(s), %d evaluations, RMS relative misfit %.3g, %s", o->nt,
             rep->evaluations, rep->residual, rep->stop);
    if (plume_moduli_write(o->out, fit, prov, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        rc = 1;
    }
    for (int k = 0; k < o->nt && rc == 0; k++) {
        char name[32];
        snprintf(name, sizeof name, "curve%d", k);
        plume_param params[] = {{"angle_deg", o->angles[k]}, {"residual", rep->residual}};
        plume_sparam sp[] = {{"target", o->targets[k]}};
        if (plume_curve_write(o->out, "fit", name, &model[k], params, 2, sp, 1, &err) != PLUME_OK) {
            fprintf(stderr, "%s: %s\n", APP, err.msg);
            rc = 1;
        }
    }
    return rc;
}

/* --plot: each target with its fitted model curve. Exit code. */
static int plot_fit(const options *o, const plume_curve *curves, const plume_curve *model)
{
    plume_err err = {{0}};
    plume_curve all[2 * MAX_TARGETS];
    char names[2 * MAX_TARGETS][64];
    const char *labels[2 * MAX_TARGETS];
    for (int k = 0; k < o->nt; k++) {
        all[2 * k] = curves[k], all[2 * k + 1] = model[k];
        snprintf(names[2 * k], 64, "target %d (%g deg)", k + 1, o->angles[k]);
        snprintf(names[2 * k + 1], 64, "fitted macro %d", k + 1);
        labels[2 * k] = names[2 * k], labels[2 * k + 1] = names[2 * k + 1];
    }
    if (plume_plot_curves(o->plot, "moduli fitted to traction curves", all, labels, 2 * o->nt, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        return 1;
    }
    return 0;
}

/* The fitted moduli on stdout: a JSON object (--json) or a line. */
static void report(const options *o, const plume_ortho *fit, const plume_fit_report *rep)
{
    if (o->json) {
        json_t *j = json_object();
        json_object_set_new(j, "E_xx", json_real(fit->E_xx));
        json_object_set_new(j, "E_yy", json_real(fit->E_yy));
        json_object_set_new(j, "nu_xy", json_real(fit->nu_xy));
        json_object_set_new(j, "G_xy", json_real(fit->G_xy));
        json_object_set_new(j, "residual", json_real(rep->residual));
        json_object_set_new(j, "evaluations", json_integer(rep->evaluations));
        json_object_set_new(j, "stop", json_string(rep->stop));
        json_object_set_new(j, "seconds", json_real(rep->seconds));
        cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
    } else {
        printf("fitted to %d curve(s): E_xx %.6g Pa, E_yy %.6g Pa, nu_xy %.4g, G_xy %.6g Pa; RMS relative misfit "
               "%.3g after %d evaluations (%s, %.2f s)\n",
               o->nt, fit->E_xx, fit->E_yy, fit->nu_xy, fit->G_xy, rep->residual, rep->evaluations, rep->stop,
               rep->seconds);
    }
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    int rank, size;
    schedule_init(&argc, &argv, &rank, &size);
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc) {
        schedule_finalize();
        return rc == CLI_HELP ? 0 : rc;
    }
    /* rank 0 writes; every rank stops on a bad output before the fit */
    int bad_out = 0;
    if (rank == 0)
        bad_out = (o.out && cli_output_file(APP, "-o", o.out)) || (o.plot && cli_output_file(APP, "--plot", o.plot));
    if (schedule_share(bad_out)) {
        schedule_finalize();
        return 2;
    }
    if (o.nb > 0) {
        rc = run_bending_fit(&o, rank, size);
        schedule_finalize();
        return rc;
    }
    plume_err err = {{0}};
    plume_curve curves[MAX_TARGETS], model[MAX_TARGETS];
    memset(curves, 0, sizeof curves);
    memset(model, 0, sizeof model);
    double strain_max = 0.0;
    rc = read_targets(&o, curves, &strain_max);
    plume_macro_model mm = {o.lx, o.ly, o.h, o.edge > 0 ? o.edge : plume_traction_default_edge(o.lx, o.ly), PLUME_PATCH_ALIGNED,
                            o.constraint, 0.0, strain_max, o.steps, o.nt, o.angles, PLUME_SOLVER_NEWTON};
    plume_ortho fit;
    plume_fit_report rep;
    int worker = 0;
    rc = schedule_share(rc);
    if (rc == 0 && (o.starts > 1 || size > 1)) { /* K fits over the ranks, the best kept */
        rc = fit_from_starts(&o, rank, size, &mm, curves, &fit, &rep, &worker);
        if (worker)
            rc = 0; /* workers are done */
    } else if (rc == 0 &&
               plume_fit_moduli(plume_macro_model_curve, &mm, curves, o.nt, &o.start, &o.fo, &fit, &rep, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        rc = 1;
    }
    for (int k = 0; k < o.nt && rc == 0 && !worker; k++)
        if (plume_macro_model_curve(&mm, &fit, k, &model[k], &err) != PLUME_OK) {
            fprintf(stderr, "%s: %s\n", APP, err.msg);
            rc = 1;
        }
    if (rc == 0 && !worker && o.out)
        rc = write_fit(&o, &fit, &rep, model);
    if (rc == 0 && !worker && o.plot)
        rc = plot_fit(&o, curves, model);
    if (rc == 0 && !worker)
        report(&o, &fit, &rep);
    for (int k = 0; k < o.nt; k++) {
        plume_curve_free(&curves[k]);
        plume_curve_free(&model[k]);
    }
    schedule_finalize();
    return rc;
}
