/* apps/traction — the traction test of a feather-vane sample at the macroscale (orthotropic
 * membrane, barb constraint), at the microscale (resolved barbs and barbules) or both:
 * stress–strain and deflection curves, solved to convergence, stored in HDF5, drawn as a chart. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"
#include "traction_size.h"
#include "traction_bending.h"
#include "traction_record.h"

static const char usage[] =
    "usage: traction [options]\n"
    "Quasi-static traction test of a vane sample, macroscale and/or microscale.\n"
    "  --model M           macro (orthotropic membrane, default) | micro (resolved layout) | both\n"
    "  --scenario S        longitudinal (barbs along the pull, 0 deg) | transverse (90) | tilted (45); default tilted\n"
    "  --angle DEG         barb angle from the pulling axis in [0, 180]; overrides the scenario's\n"
    "  --lx M --ly M --thickness M   sample width, length, thickness (default 1, 1.3, 1: Table 4 of the supplement)\n"
    "  --sample ID         a sample of supplementary Table 1 (L01..L13, T01..T14) from data/samples.json\n"
    "  --samples FILE      sample file for --sample (default: $PLUME_DATA/samples.json or data/ next to apps/)\n"
    "  --Exx --Eyy --Gxy PA, --nu V   orthotropic moduli in the barb frame (default 1e4, 1, 1, 0)\n"
    "  --moduli FILE.h5    read E_xx, E_yy, nu_xy, G_xy from /moduli of an HDF5 file\n"
    "  --kappa PA          compression-term coefficient (default 0)\n"
    "  --constraint on|off barb inextensibility constraint (default on); off = penalty with finite Exx\n"
    "  --mesh aligned|unaligned   (default aligned)\n"
    "  --edge M            target edge length (default min(lx, ly)/20)\n"
    "  --strain-max E      final nominal strain (default 0.05)\n"
    "  --path E1,E2,...    the strains the grip goes to in turn instead (load, unload, reload: 0.03,0,0.03),\n"
    "                      each leg in --steps steps\n"
    "  --peel V            the top grip turns as it pulls: a point at x moves by (1 - V + V x / lx) times the\n"
    "                      grip's displacement (0 straight, the default; 1 about its x = 0 end)\n"
    "  --top-grip-free V   the top grip holds x >= V lx only, the rest of its edge free (default 0)\n"
    "  --split-lines N     macro: N barb lines spread across the sample split when their hooks let go and\n"
    "                      zip again (aligned mesh; the separation law from --moduli FILE.h5 as apps/homogenize\n"
    "                      writes it for a layout with hooks, or with --model both the layout's own; docs/unzipping.md)\n"
    "  --steps N           quasi-static steps (default 10)\n"
    "  --checkpoint F.h5   the run's whole state after every step (positions, hooks, history, curve), replaced\n"
    "                      atomically; --restart F.h5 continues a run from it, bit for bit, with the same flags;\n"
    "                      --stop-after N ends the run after step N (one model: macro or micro)\n"
    "  --solver S          newton | ipopt | linearized (default newton)\n"
    "  --max-iter N        solver iteration cap per step (default 100)\n";
/* the help's second half (one literal each: C99 compilers need support only 4095 characters) */
static const char usage_micro[] =
    "Microscale layout (--model micro|both; see apps/homogenize --help):\n"
    "  --layout-config FILE.json, --layout strips|barbules, --phi V, --ratio R, --Eb PA,\n"
    "  --nu-barb V, --nu-barbule V, --dB-rel V (barb spacing over ly, default 0.086), --e-rel V\n"
    "  (element edge over barb width; default 0: chosen from the thinnest strip so that the curve is\n"
    "  within 2 % of its refined limit), --order 1|2 (element order: 2 quadratic triangles, the\n"
    "  default; 1 linear, the paper's); the layout thickness is --thickness.\n"
    "  --hook-strength N, --hook-opening M, --hook-slide M, --hook-capture M   barbule hooks that let go\n"
    "                      and catch again (layout --layout barbules; docs/unzipping.md; data/layout_hooks.json);\n"
    "                      the summary then counts hooks let go and caught again and the energy dissipated\n"
    "  --no-convergence    skip the micro run's convergence estimate (the same test on a mesh twice as coarse)\n"
    "  --size-effect V[,V...]  the micro specimen again at finer barb spacings (over ly, each finer than\n"
    "                      the last): -o adds /curves/micro_dB<V>/<scenario>, --plot draws the family with the\n"
    "                      macro curve as its limit, and the summary gives each one's difference from macro\n"
    "  With --model both the macro model uses --moduli FILE.h5 if given, else the layout's moduli\n"
    "  homogenised on the spot.\n"
    "  -o FILE.h5          write /curves/<macro|micro>/<scenario>/{strain,stress,wbar,iterations,seconds}\n"
    "                      and, with hooks or --split-lines, hooks: each pair's state at every point (1 engaged)\n"
    "  --plot FILE.png     chart (an SVG is written beside it)\n"
    "  --vtk DIR           the deformed sample of every step as a ParaView series: DIR/<macro|micro>/steps.pvd\n"
    "                      (the nominal strain as its time) with step_NNNNN.vtu (strain, stress, energy density,\n"
    "                      J per triangle; step_barbs_NNNNN.vtu the constrained barb edges' strain;\n"
    "                      step_hooks_NNNNN.vtu each hook's pairs with state 1 engaged, 0 let go)\n"
    "Bending (both scales; docs/bending-homogenisation.md):\n"
    "  --bending LOAD      cylinder (end moments about x: curvature along y, the barbs at --angle from it) | twist;\n"
    "                      the resolved layout (order 1 triangles, each phase a shell of its thickness) and/or the\n"
    "                      plate with the cell's bending tensor; default sample 0.01 x 0.02 m\n"
    "  --curvature K       the plate's predicted curvature at the last step (1/m, > 0; default 0.01)\n"
    "                      -o writes /curves/bending/<macro|micro>/<LOAD>_<angle>/{curvature,moment,...};\n"
    "                      --size-effect V[,V...] adds /curves/bending/micro_dB<V>/..., and --plot draws micro\n"
    "                      m/kappa against d_B / lx with the macro value as the limit\n"
    "  --json              print a summary object on stdout\n"
    "  --quiet / --verbose no progress line / solver iterations on stderr\n"
    "  --help\n";

typedef struct {
    const char *scenario, *sample, *samples_file, *moduli_file, *out, *plot, *mesh, *solver, *vtk;
    const char *model, *layout_file, *layout_kind;
    const char *bending, *traction_only; /* --bending LOAD; the last traction-only flag given */
    const char *size_effect;             /* --size-effect V[,V...] */
    const char *checkpoint, *restart;    /* --checkpoint FILE.h5, --restart FILE.h5 */
    int stop_after;                      /* --stop-after N */
    double curvature;
    int curvature_set, solver_set, steps_set;
    double phi, ratio, Eb, nu_barb, nu_barbule, dB_rel, e_rel;
    int phi_set, ratio_set, Eb_set, nu_barb_set, nu_barbule_set, dB_rel_set, e_rel_set, order, order_set;
    int no_convergence;
    double hook_strength, hook_opening, hook_slide, hook_capture;
    int hook_strength_set, hook_opening_set, hook_slide_set, hook_capture_set;
    const char *path_arg; /* --path E1,E2,... */
    double peel, top_grip_free;
    int split_lines;      /* --split-lines N */
    double path[1000];
    int npath;
    double angle, lx, ly, h, Exx, Eyy, Gxy, nu, kappa, edge, strain_max;
    int angle_set, lx_set, ly_set, h_set, constraint, steps, max_iter, json, quiet, verbose;
    int Exx_set, Eyy_set, Gxy_set, nu_set;
} options;

static int fail(const char *fmt, const char *a, const char *b)
{
    return cli_fail("traction", fmt, a, b);
}

static int parse_double(const char *flag, const char *s, double *out)
{
    return cli_double("traction", flag, s, out);
}

static int parse_int(const char *flag, const char *s, int *out)
{
    return cli_int("traction", flag, s, out);
}

/* --path E1,E2,...: comma-separated strains into o->path (plume_traction_run checks the legs).
 * Returns an exit code. */
static int parse_path(options *o)
{
    const char *q = o->path_arg;
    for (o->npath = 0; *q; o->npath++) {
        char *end = NULL;
        if (o->npath == (int)(sizeof o->path / sizeof o->path[0]))
            return fail("--path: more than %s strains%s", "1000", "");
        o->path[o->npath] = strtod(q, &end);
        if (end == q || (*end != ',' && *end != '\0') || !isfinite(o->path[o->npath])) {
            fprintf(stderr, "traction: --path: strain %d of '%s' is not a number\n", o->npath + 1, o->path_arg);
            return 2;
        }
        q = *end == ',' ? end + 1 : end;
    }
    return o->npath > 0 ? 0 : fail("--path needs at least one strain%s%s", "", "");
}

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->scenario = "tilted";
    o->model = "macro";
    o->dB_rel = plume_traction_default_barb_spacing(1.0), o->e_rel = 0.0;
    o->mesh = "aligned";
    o->solver = "newton";
    o->lx = 1.0, o->ly = 1.3, o->h = 1.0;
    o->Exx = 1e4, o->Eyy = 1.0, o->Gxy = 1.0, o->nu = 0.0;
    o->constraint = 1;
    o->strain_max = 0.05;
    o->steps = 10;
    o->max_iter = 100;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int r = 0, used = 1;
#define DBL(flag, field) else if (strcmp(a, flag) == 0) r = parse_double(flag, v, &o->field)
#define DBLSET(flag, field) else if (strcmp(a, flag) == 0) r = parse_double(flag, v, &o->field), o->field##_set = 1
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            fputs(usage_micro, stdout);
            return CLI_HELP;
        }
        DBLSET("--angle", angle);
        DBLSET("--lx", lx);
        DBLSET("--ly", ly);
        else if (strcmp(a, "--thickness") == 0) r = parse_double(a, v, &o->h), o->h_set = 1;
        DBLSET("--Exx", Exx);
        DBLSET("--Eyy", Eyy);
        DBLSET("--Gxy", Gxy);
        DBLSET("--nu", nu);
        DBL("--kappa", kappa);
        DBL("--edge", edge);
        else if (strcmp(a, "--strain-max") == 0) r = parse_double(a, v, &o->strain_max), o->traction_only = a;
        else if (strcmp(a, "--curvature") == 0) r = parse_double(a, v, &o->curvature), o->curvature_set = 1;
        else if (strcmp(a, "--bending") == 0) o->bending = v;
        else if (strcmp(a, "--steps") == 0) r = parse_int(a, v, &o->steps), o->steps_set = 1;
        else if (strcmp(a, "--max-iter") == 0) r = parse_int(a, v, &o->max_iter);
        else if (strcmp(a, "--order") == 0) r = parse_int(a, v, &o->order), o->order_set = 1;
        DBLSET("--phi", phi);
        DBLSET("--ratio", ratio);
        DBLSET("--Eb", Eb);
        DBLSET("--nu-barb", nu_barb);
        DBLSET("--nu-barbule", nu_barbule);
        DBLSET("--dB-rel", dB_rel);
        DBLSET("--e-rel", e_rel);
        DBLSET("--hook-strength", hook_strength);
        DBLSET("--hook-opening", hook_opening);
        DBLSET("--hook-slide", hook_slide);
        DBLSET("--hook-capture", hook_capture);
        else if (strcmp(a, "--path") == 0) o->path_arg = v, o->traction_only = a;
        else if (strcmp(a, "--peel") == 0) r = parse_double(a, v, &o->peel), o->traction_only = a;
        else if (strcmp(a, "--top-grip-free") == 0) r = parse_double(a, v, &o->top_grip_free), o->traction_only = a;
        else if (strcmp(a, "--split-lines") == 0) r = parse_int(a, v, &o->split_lines), o->traction_only = a;
        else if (strcmp(a, "--model") == 0) o->model = v;
        else if (strcmp(a, "--layout-config") == 0) o->layout_file = v;
        else if (strcmp(a, "--layout") == 0) o->layout_kind = v;
        else if (strcmp(a, "--scenario") == 0) o->scenario = v, o->traction_only = a;
        else if (strcmp(a, "--sample") == 0) o->sample = v, o->traction_only = a;
        else if (strcmp(a, "--samples") == 0) o->samples_file = v, o->traction_only = a;
        else if (strcmp(a, "--moduli") == 0) o->moduli_file = v;
        else if (strcmp(a, "--mesh") == 0) o->mesh = v, o->traction_only = a;
        else if (strcmp(a, "--solver") == 0) o->solver = v, o->solver_set = 1;
        else if (strcmp(a, "-o") == 0) o->out = v;
        else if (strcmp(a, "--plot") == 0) o->plot = v;
        else if (strcmp(a, "--vtk") == 0) o->vtk = v, o->traction_only = a;
        else if (strcmp(a, "--size-effect") == 0) o->size_effect = v;
        else if (strcmp(a, "--checkpoint") == 0) o->checkpoint = v, o->traction_only = a;
        else if (strcmp(a, "--restart") == 0) o->restart = v, o->traction_only = a;
        else if (strcmp(a, "--stop-after") == 0) r = parse_int(a, v, &o->stop_after), o->traction_only = a;
        else if (strcmp(a, "--constraint") == 0) {
            o->traction_only = a;
            if (v && strcmp(v, "on") == 0)
                o->constraint = 1;
            else if (v && strcmp(v, "off") == 0)
                o->constraint = 0;
            else
                return fail("--constraint expects on|off (got '%s')%s", v ? v : "", "");
        } else {
            used = 0;
            if (strcmp(a, "--json") == 0) o->json = 1;
            else if (strcmp(a, "--quiet") == 0) o->quiet = 1;
            else if (strcmp(a, "--verbose") == 0) o->verbose = 1;
            else if (strcmp(a, "--no-convergence") == 0) o->no_convergence = 1, o->traction_only = a;
            else return fail("unknown option '%s' (see --help)%s", a, "");
        }
#undef DBL
#undef DBLSET
        if (r)
            return r;
        if (used) {
            if (!v)
                return fail("%s needs a value%s", a, "");
            i++;
        }
    }
    return o->path_arg ? parse_path(o) : 0;
}

/* data/samples.json: $PLUME_DATA, then ../data beside the executable, then ./data */
static void default_samples_path(const char *argv0, char *buf, size_t n)
{
    const char *env = getenv("PLUME_DATA");
    if (env) {
        snprintf(buf, n, "%s/samples.json", env);
        return;
    }
    const char *slash = strrchr(argv0, '/');
    if (slash) {
        snprintf(buf, n, "%.*s/../data/samples.json", (int)(slash - argv0), argv0);
        if (access(buf, R_OK) == 0)
            return;
    }
    snprintf(buf, n, "data/samples.json");
}

/* One model's run: its curve and figures. */
typedef struct {
    const char *scale; /* "macro" | "micro" */
    int wanted;
    plume_traction_result res;
    plume_index elements, vertices, barb_edges;
    long split_pairs;             /* macro --split-lines: vertex pairs holding the lines */
    int order;                    /* micro: element order */
    double edge;                  /* target element edge (m) */
    int has_conv;                 /* micro: conv holds the convergence estimate */
    plume_micro_convergence conv;
    int *links;                   /* hooks or split lines: their pairs' states at each point of the curve */
    int stop_after, nsteps;       /* --stop-after, and the schedule's steps */
    long links_rows;
    plume_index links_cols;
} model_run;

/* A traction run that failed: its message; the exit code, 2 (bad input) for a checkpoint that
 * cannot be continued, else 1. */
static int run_failed(const plume_err *err, plume_status st)
{
    fprintf(stderr, "%s\n", err->msg[0] ? err->msg : plume_strerror(st));
    return strncmp(err->msg, "restart: ", 9) == 0 ? 2 : 1;
}

/* The macroscale vane on an aligned or unaligned patch mesh. Returns an exit code. */
static int run_macro(const options *o, const plume_vane *vane, const plume_separation_law *law, plume_patch_kind kind,
                     double angle, double edge, const plume_traction_opts *to, model_run *run)
{
    plume_err err = {{0}};
    plume_mesh *patch = NULL;
    const plume_mesh *mesh = NULL;
    plume_splits *splits = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nbarbs = 0;
    plume_fields *fields = NULL;
    links_record rec = {0};
    plume_status st;
    int rc = 1;
    if ((st = plume_patch_mesh(o->lx, o->ly, angle, edge, kind, 2, &patch, &err)) != PLUME_OK) {
        fprintf(stderr, "traction: mesh: %s\n", err.msg);
        goto done;
    }
    if (o->split_lines > 0 && (st = plume_splits_open(patch, angle, o->split_lines, &splits, &err)) != PLUME_OK) {
        fprintf(stderr, "traction: --split-lines %d: %s\n", o->split_lines, err.msg);
        goto done;
    }
    /* with split lines the problem lives on the opened mesh (the patch's vertices, then the copies) */
    mesh = splits ? plume_splits_mesh(splits) : patch;
    if ((st = plume_problem_create(mesh->nv, 2, fmax(o->lx, o->ly), &p, &err)) != PLUME_OK ||
        (st = plume_vane_add(p, mesh, vane, &barbs, &nbarbs, &err)) != PLUME_OK ||
        (splits && (st = plume_splits_add(p, splits, law, &err)) != PLUME_OK)) {
        fprintf(stderr, "traction: %s\n", err.msg[0] ? err.msg : plume_strerror(st));
        goto done;
    }
    run->elements = mesh->nt, run->vertices = mesh->nv, run->barb_edges = nbarbs;
    run->split_pairs = plume_splits_pairs(splits);
    plume_traction_opts tv = *to;
    plume_membrane_material mat = plume_vane_material(vane);
    if (o->vtk && vtk_start(o->vtk, "macro", mesh, &mat, 1, barbs, nbarbs, &tv, &fields) != 0)
        goto done;
    if (fields && splits && (st = plume_fields_add_links(fields, p, "splits", &err)) != PLUME_OK) {
        fprintf(stderr, "traction: --vtk: %s\n", err.msg);
        goto done;
    }
    if (splits && o->out && (links_start(p, "splits", &tv, &rec) != 0 || (o->restart && links_seed(&rec, o->restart))))
        goto done;
    if ((st = plume_traction_run(mesh, p, barbs, nbarbs, &tv, &run->res, &err)) != PLUME_OK) {
        rc = run_failed(&err, st); /* the library's message already names the module */
        goto done;
    }
    links_keep(&rec, &run->links, &run->links_rows, &run->links_cols);
    rc = 0;
done:
    free(rec.v);
    plume_fields_destroy(&fields);
    free(barbs);
    plume_problem_destroy(&p);
    plume_splits_destroy(&splits);
    plume_mesh_destroy(&patch);
    return rc;
}

/* --stop-after ended the run before its schedule's end */
static int stopped_early(const model_run *run)
{
    return run->res.converged && run->stop_after > 0 && run->res.curve.n == run->stop_after + 1 &&
           run->stop_after < run->nsteps;
}

/* The microscale specimen: the layout resolved on the sample. Returns an exit code. */
static int run_micro(const options *o, const plume_layout *layout, double angle, const plume_traction_opts *to,
                     model_run *run)
{
    plume_err err = {{0}};
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_fields *fields = NULL;
    links_record rec = {0};
    plume_status st;
    int rc = 1;
    if ((st = plume_micro_specimen(layout, o->lx, o->ly, angle, &mesh, &p, &err)) != PLUME_OK) {
        fprintf(stderr, "traction: micro specimen: %s\n", err.msg[0] ? err.msg : plume_strerror(st));
        goto done;
    }
    run->order = layout->order;
    run->elements = plume_micro_specimen_elements(layout, mesh), run->vertices = mesh->nv;
    run->edge = plume_layout_element_edge(layout, PLUME_MESH_SPECIMEN);
    plume_traction_opts tv = *to;
    plume_membrane_material mats[2];
    plume_layout_materials(layout, mats);
    if (o->vtk && vtk_start(o->vtk, "micro", mesh, mats, 2, NULL, 0, &tv, &fields) != 0)
        goto done;
    const int hooked = layout->kind == PLUME_LAYOUT_BARBULES && layout->hooks.strength > 0.0;
    if (fields && hooked && (st = plume_fields_add_links(fields, p, "hooks", &err)) != PLUME_OK) { /* each step */
        fprintf(stderr, "traction: --vtk: %s\n", err.msg);
        goto done;
    }
    if (hooked && o->out && (links_start(p, "hooks", &tv, &rec) != 0 || (o->restart && links_seed(&rec, o->restart))))
        goto done;
    if ((st = plume_traction_run(mesh, p, NULL, 0, &tv, &run->res, &err)) != PLUME_OK) {
        rc = run_failed(&err, st);
        goto done;
    }
    links_keep(&rec, &run->links, &run->links_rows, &run->links_cols);
    if (!o->no_convergence && run->res.converged && to->solver != PLUME_SOLVER_LINEARIZED && !stopped_early(run)) {
        /* how converged the curve is: the same test on a mesh twice as coarse (this run's mesh,
         * its problem and the fields that borrow the mesh freed first), from rest, unrecorded */
        plume_fields_destroy(&fields);
        plume_problem_destroy(&p);
        plume_mesh_destroy(&mesh);
        plume_traction_opts tc = *to;
        tc.checkpoint = tc.restart = NULL, tc.stop_after = 0;
        if ((st = plume_micro_traction_convergence(layout, o->lx, o->ly, angle, &tc, &run->res, &run->conv, &err)) !=
            PLUME_OK) {
            fprintf(stderr, "traction: micro convergence estimate: %s\n", err.msg[0] ? err.msg : plume_strerror(st));
            goto done;
        }
        run->has_conv = 1;
    }
    rc = 0;
done:
    free(rec.v);
    plume_fields_destroy(&fields);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return rc;
}

/* Micro (reference) against macro at the micro curve's strains: the largest stress difference
 * over the curve and the differences at the last point, relative to the micro values. */
static void compare_curves(const plume_curve *micro, const plume_curve *macro, double *dmax, double *dend, double *dwend)
{
    double smax = 0.0;
    plume_index n = micro->n < macro->n ? micro->n : macro->n;
    for (plume_index k = 0; k < n; k++)
        smax = fmax(smax, fabs(micro->stress[k]));
    *dmax = 0.0;
    for (plume_index k = 0; k < n; k++)
        *dmax = fmax(*dmax, fabs(macro->stress[k] - micro->stress[k]) / (smax > 0 ? smax : 1.0));
    plume_index e = n - 1;
    *dend = fabs(macro->stress[e] - micro->stress[e]) / fmax(fabs(micro->stress[e]), 1e-300);
    *dwend = fabs(macro->wbar[e] - micro->wbar[e]) / fmax(fabs(micro->wbar[e]), 1e-300);
}

static json_t *run_json(const model_run *r, const options *o, double angle)
{
    plume_index last = r->res.curve.n - 1;
    int usable = r->res.converged || strcmp(o->solver, "linearized") == 0;
    json_t *j = json_object();
    json_object_set_new(j, "model", json_string(r->scale));
    json_object_set_new(j, "scenario", json_string(o->scenario));
    json_object_set_new(j, "angle_deg", json_real(angle));
    json_object_set_new(j, "solver", json_string(o->solver));
    json_object_set_new(j, "mesh", json_string(strcmp(r->scale, "macro") == 0 ? o->mesh : "specimen"));
    json_object_set_new(j, "constraint", json_boolean(strcmp(r->scale, "macro") == 0 && o->constraint));
    json_object_set_new(j, "initial_slope", json_real(r->res.initial_slope));
    json_object_set_new(j, "strain_at_end", json_real(r->res.curve.strain[last]));
    json_object_set_new(j, "stress_at_max_strain", usable ? json_real(r->res.curve.stress[last]) : json_null());
    json_object_set_new(j, "wbar_at_max_strain", usable ? json_real(r->res.curve.wbar[last]) : json_null());
    json_object_set_new(j, "elements", json_integer(r->elements));
    json_object_set_new(j, "vertices", json_integer(r->vertices));
    json_object_set_new(j, "barb_edges", json_integer(r->barb_edges));
    json_object_set_new(j, "steps", json_integer(o->steps));
    json_object_set_new(j, "newton_iterations", json_integer(r->res.newton_iterations));
    json_object_set_new(j, "max_constraint_violation", json_real(r->res.max_violation));
    json_object_set_new(j, "converged", json_boolean(r->res.converged));
    json_object_set_new(j, "stop_reason",
                        json_string(r->res.converged ? "converged" : plume_reason_name(r->res.failed_reason)));
    json_object_set_new(j, "failed_step", json_integer(r->res.failed_step));
    json_object_set_new(j, "factorizations", json_integer(r->res.factorizations));
    json_object_set_new(j, "chord_steps", json_integer(r->res.chord_steps));
    json_object_set_new(j, "step_cuts", json_integer(r->res.cuts));
    json_object_set_new(j, "substeps", json_integer(r->res.substeps));
    json_object_set_new(j, "factor_seconds", json_real(r->res.factor_seconds));
    json_object_set_new(j, "seconds", json_real(r->res.seconds));
    if (r->split_pairs > 0)
        json_object_set_new(j, "split_pairs", json_integer(r->split_pairs));
    if (o->restart)
        json_object_set_new(j, "restarted_from", json_string(o->restart));
    if (stopped_early(r))
        json_object_set_new(j, "stopped_after", json_integer(r->stop_after));
    json_object_set_new(j, "hooks_released", json_integer(r->res.released));
    json_object_set_new(j, "hooks_reengaged", json_integer(r->res.reengaged));
    json_object_set_new(j, "largest_cascade", json_integer(r->res.largest_cascade));
    json_object_set_new(j, "release_events", json_integer(r->res.release_events));
    json_object_set_new(j, "peak_stress", json_real(r->res.peak_stress));
    json_object_set_new(j, "work", json_real(r->res.work));
    json_object_set_new(j, "stored_energy", json_real(r->res.stored_energy));
    json_object_set_new(j, "dissipated_energy", json_real(r->res.dissipated_energy));
    json_object_set_new(j, "energy_balance_error", json_real(r->res.energy_balance_error));
    if (strcmp(r->scale, "micro") == 0) {
        json_object_set_new(j, "order", json_integer(r->order));
        json_object_set_new(j, "element_edge", json_real(r->edge));
    }
    if (r->has_conv) {
        json_t *c = json_object();
        json_object_set_new(c, "stress_change", json_real(r->conv.stress_change));
        json_object_set_new(c, "slope_change", json_real(r->conv.slope_change));
        json_object_set_new(c, "refinement_edge", json_real(r->conv.refinement_edge));
        json_object_set_new(c, "refinement_elements", json_integer(r->conv.refinement_elements));
        json_object_set_new(c, "converged", json_boolean(r->conv.converged));
        json_object_set_new(c, "seconds", json_real(r->conv.seconds));
        json_object_set_new(j, "refinement", c);
        json_object_set_new(j, "refinement_change", json_real(r->conv.stress_change));
    }
    return j;
}

static void print_summary(const model_run *r, const options *o, double angle)
{
    plume_index last = r->res.curve.n - 1;
    printf("%s %s %g deg, %s, %s (%ld elements)%s: stress at %g%% strain %.6g Pa, wbar %.4g, initial slope %.6g Pa, "
           "%d iterations (%d factorisations%s), %.2f s, %s\n",
           r->scale, o->scenario, angle, o->solver, strcmp(r->scale, "macro") == 0 ? o->mesh : "specimen",
           (long)r->elements,
           strcmp(r->scale, "macro") == 0 ? (o->constraint ? ", constraint on" : ", constraint off") : "",
           100.0 * r->res.curve.strain[last], r->res.curve.stress[last], r->res.curve.wbar[last], r->res.initial_slope,
           r->res.newton_iterations, r->res.factorizations, r->res.cuts ? ", steps cut" : "", r->res.seconds,
           r->res.converged ? "converged" : plume_reason_name(r->res.failed_reason));
    if (o->restart)
        printf("%s run restarted from '%s' (the counts and energies are the whole run's)\n", r->scale, o->restart);
    if (stopped_early(r))
        printf("%s run stopped after step %d of %d (--stop-after); continue it with --restart %s\n", r->scale,
               r->stop_after, r->nsteps, o->checkpoint);
    if (r->split_pairs > 0)
        printf("%s split lines: %ld vertex pairs hold them\n", r->scale, r->split_pairs);
    if (r->res.released > 0 || r->res.reengaged > 0)
        printf("%s %s: %ld let go (at most %d at one equilibrium), %ld caught again, peak stress %.6g Pa; %.4g J "
               "dissipated of %.4g J work, %.4g J stored (energy balance error %.2g)\n",
               r->scale, r->split_pairs > 0 ? "split pairs" : "hooks", r->res.released, r->res.largest_cascade,
               r->res.reengaged, r->res.peak_stress, r->res.dissipated_energy,
               r->res.work, r->res.stored_energy, r->res.energy_balance_error);
    if (r->has_conv && r->conv.converged)
        printf("%s curve converged to %.2g %% (its largest stress change from a mesh of %.3g m elements, %ld of them; "
               "initial slope %.2g %%)\n",
               r->scale, 100.0 * r->conv.stress_change, r->conv.refinement_edge, (long)r->conv.refinement_elements,
               100.0 * r->conv.slope_change);
    else if (r->has_conv)
        printf("%s curve: no convergence estimate (the run on a mesh of %.3g m elements did not converge)\n", r->scale,
               r->conv.refinement_edge);
}

/* What main builds from the options and runs: the models' inputs, their runs and the size-effect
 * family. */
typedef struct {
    double angle, edge;
    int want_macro, want_micro;
    plume_layout layout;
    plume_vane vane;
    const char *moduli_source; /* "flags", "homogenised" or the --moduli file */
    plume_separation_law law;  /* --split-lines: the barb lines' separation law */
    plume_patch_kind kind;
    plume_traction_opts to;
    plume_solver_opts so;        /* to's solver options */
    size_family fam;
    model_run runs[2]; /* 0 macro, 1 micro */
} traction_job;

/* The barb angle: the scenario's, or the --sample's (whose size and thickness fill the ones not
 * given), or --angle; the sample's size checked. Returns an exit code. */
static int resolve_angle(options *o, const char *argv0, double *angle_out)
{
    plume_err err = {{0}};
    double angle;
    if (strcmp(o->scenario, "longitudinal") == 0)
        angle = 0.0;
    else if (strcmp(o->scenario, "transverse") == 0)
        angle = 90.0;
    else if (strcmp(o->scenario, "tilted") == 0)
        angle = 45.0;
    else
        return fail("--scenario expects longitudinal|transverse|tilted (got '%s')%s", o->scenario, "");

    if (o->sample) {
        char path[4096];
        if (o->samples_file)
            snprintf(path, sizeof path, "%s", o->samples_file);
        else
            default_samples_path(argv0, path, sizeof path);
        plume_sample s;
        if (plume_sample_load(path, o->sample, &s, &err) != PLUME_OK)
            return fail("%s%s", err.msg, "");
        if (!o->lx_set)
            o->lx = s.lx;
        if (!o->ly_set)
            o->ly = s.ly;
        if (!o->h_set)
            o->h = s.h;
        if (strcmp(o->scenario, "tilted") == 0) /* the sample decides unless --scenario changed it */
            o->scenario = strcmp(s.scenario, "transverse") == 0 ? "transverse" : strcmp(s.scenario, "longitudinal") == 0 ? "longitudinal" : "tilted";
        angle = strcmp(o->scenario, "longitudinal") == 0 ? 0.0 : strcmp(o->scenario, "transverse") == 0 ? 90.0 : 45.0;
    }
    if (o->angle_set)
        angle = o->angle;
    if (!(angle >= 0.0 && angle <= 180.0))
        return fprintf(stderr, "traction: --angle must be in [0, 180] degrees (got %g)\n", angle), 2;
    if (!(o->lx > 0) || !(o->ly > 0) || !(o->h > 0))
        return fprintf(stderr, "traction: --lx, --ly and --thickness must be > 0 (got %g, %g, %g m): a zero-area or zero-thickness sample cannot be tested\n",
                       o->lx, o->ly, o->h), 2;
    *angle_out = angle;
    return 0;
}

/* The microscale layout: defaults, then the file, then the flags; sized on the sample (checked when
 * the micro model runs). Returns an exit code. */
static int build_layout(const options *o, int want_micro, plume_layout *layout)
{
    plume_err err = {{0}};
    plume_layout_default(layout);
    if (o->layout_file && plume_layout_load_json(o->layout_file, layout, &err) != PLUME_OK)
        return fail("%s%s", err.msg, "");
    if (o->layout_kind) {
        if (strcmp(o->layout_kind, "strips") == 0)
            layout->kind = PLUME_LAYOUT_STRIPS;
        else if (strcmp(o->layout_kind, "barbules") == 0)
            layout->kind = PLUME_LAYOUT_BARBULES;
        else
            return fail("--layout expects strips|barbules (got '%s')%s", o->layout_kind, "");
    }
    if (o->phi_set) layout->phi = o->phi;
    if (o->ratio_set) layout->ratio = o->ratio;
    if (o->Eb_set) layout->E_b = o->Eb;
    if (o->nu_barb_set) layout->nu_b = o->nu_barb;
    if (o->nu_barbule_set) layout->nu_B = o->nu_barbule;
    if (o->e_rel_set || !o->layout_file) layout->e_rel = o->e_rel;
    if (o->order_set) layout->order = o->order;
    if (o->hook_strength_set) layout->hooks.strength = o->hook_strength;
    if (o->hook_opening_set) layout->hooks.opening = o->hook_opening;
    if (o->hook_slide_set) layout->hooks.slide = o->hook_slide;
    if (o->hook_capture_set) layout->hooks.capture = o->hook_capture;
    if (o->dB_rel_set || !o->layout_file)
        plume_layout_set_spacing(layout, o->dB_rel * o->ly); /* barbule geometry kept proportional */
    if (!o->bending || o->h_set)
        layout->h = o->h;
    layout->kappa = o->kappa;
    if (o->bending)
        layout->order = 1; /* the shell's triangles are linear */
    if (want_micro && plume_layout_check(layout, &err) != PLUME_OK)
        return fail("layout: %s%s", err.msg, "");
    return 0;
}

/* --bending: the plate test at both scales (apps/traction_bending.h). Returns an exit code. */
static int bending_main(const options *o, const plume_layout *layout, int want_macro, int want_micro)
{
    size_family bfam = {0};
    int rc;
    if (o->size_effect) {
        if (!want_micro)
            return fail("--size-effect needs --model micro or both (got '%s')%s", o->model, "");
        if ((rc = size_effect_parse(o->size_effect, layout->d_B / o->ly, &bfam)))
            return rc;
    }
    bending_cli bc = {o->bending, o->out, o->model, o->lx, o->ly, o->angle_set ? o->angle : 0.0,
                      o->curvature_set ? o->curvature : 0.01, o->curvature_set, o->edge, o->steps_set ? o->steps : 2,
                      o->solver_set ? o->solver : "linearized", o->json, o->quiet, o->size_effect ? &bfam : NULL,
                      o->plot};
    return run_bending(&bc, layout, want_macro, want_micro);
}

/* --split-lines: the separation law of the --moduli file, or with both models the layout's own.
 * Returns an exit code. */
static int split_law(const options *o, traction_job *j)
{
    plume_err err = {{0}};
    if (o->mesh && strcmp(o->mesh, "aligned") != 0)
        return fprintf(stderr, "traction: --split-lines needs --mesh aligned: a barb line that splits is a line of "
                       "mesh edges\n"), 2;
    if (o->moduli_file) {
        if (plume_separation_read(o->moduli_file, &j->law, &err) != PLUME_OK)
            return fprintf(stderr, "traction: --split-lines: %s (apps/homogenize writes it for a layout with "
                           "hooks)\n", err.msg), 2;
        return 0;
    }
    if (j->want_micro && j->layout.kind == PLUME_LAYOUT_BARBULES && j->layout.hooks.strength > 0.0) {
        if (plume_separation_law_of(&j->layout, &j->law, &err) != PLUME_OK)
            return fprintf(stderr, "traction: --split-lines: %s\n", err.msg), 1;
        return 0;
    }
    return fprintf(stderr, "traction: --split-lines needs a separation law: --moduli FILE.h5 from apps/homogenize "
                   "of a layout with hooks, or --model both with such a layout\n"), 2;
}

/* The macroscale vane: the moduli from the flags, the --moduli file, or (both models, no file) the
 * layout's cell homogenised on the spot, explicit flags overriding; checked when the macro model
 * runs. Returns an exit code. */
static int build_vane(const options *o, traction_job *j)
{
    plume_err err = {{0}};
    plume_vane *vane = &j->vane;
    plume_vane_default(vane);
    vane->moduli.E_xx = o->Exx, vane->moduli.E_yy = o->Eyy, vane->moduli.G_xy = o->Gxy, vane->moduli.nu_xy = o->nu;
    j->moduli_source = "flags";
    if (o->moduli_file) {
        if (plume_moduli_read(o->moduli_file, &vane->moduli, &err) != PLUME_OK)
            return fail("%s%s", err.msg, "");
        j->moduli_source = o->moduli_file;
    } else if (j->want_macro && j->want_micro) {
        /* the macro model of the same microstructure: homogenise the layout's cell */
        plume_homog_opts ho;
        plume_homog_opts_default(&ho);
        ho.strain_max = 0.0;
        plume_homog_result hr;
        if (plume_homogenize(&j->layout, &ho, &hr, &err) != PLUME_OK)
            return fprintf(stderr, "traction: %s\n", err.msg), 1;
        vane->moduli = hr.moduli;
        plume_homog_result_free(&hr);
        j->moduli_source = "homogenised";
    }
    /* explicit flags override the file */
    if (o->Exx_set) vane->moduli.E_xx = o->Exx;
    if (o->Eyy_set) vane->moduli.E_yy = o->Eyy;
    if (o->Gxy_set) vane->moduli.G_xy = o->Gxy;
    if (o->nu_set) vane->moduli.nu_xy = o->nu;
    vane->h = o->h;
    vane->kappa = o->kappa;
    vane->constraint = o->constraint;
    if (!(o->kappa >= 0))
        return fprintf(stderr, "traction: --kappa must be >= 0 (got %g)\n", o->kappa), 2;
    if (j->want_macro && plume_vane_check(vane, &err) != PLUME_OK)
        return fail("moduli: %s%s", err.msg, "");
    return o->split_lines && j->want_macro ? split_law(o, j) : 0;
}

/* --checkpoint, --restart, --stop-after: one traction run (macro or micro, no size-effect family;
 * a ParaView series is not continued). Returns an exit code. */
static int restart_opts(const options *o, traction_job *j)
{
    const char *flag = o->restart ? "--restart" : o->checkpoint ? "--checkpoint" : o->stop_after ? "--stop-after" : NULL;
    if (!flag)
        return 0;
    if (j->want_macro && j->want_micro)
        return fail("%s needs one model (--model macro or micro)%s", flag, "");
    if (o->size_effect)
        return fail("%s and --size-effect cannot be combined%s", flag, "");
    if (o->restart && o->vtk)
        return fail("--restart does not continue a --vtk series: write it from a run without a restart%s%s", "", "");
    if (o->stop_after < 0)
        return fprintf(stderr, "traction: --stop-after must be >= 0 (got %d)\n", o->stop_after), 2;
    if (o->stop_after > 0 && !o->checkpoint)
        return fail("--stop-after needs --checkpoint FILE.h5, where the run is continued from%s%s", "", "");
    j->to.checkpoint = o->checkpoint, j->to.restart = o->restart, j->to.stop_after = o->stop_after;
    return 0;
}

/* The mesh kind, the element edge and the traction options of the flags. Returns an exit code. */
static int build_traction_opts(const options *o, traction_job *j)
{
    if (plume_patch_kind_parse(o->mesh, &j->kind) != PLUME_OK)
        return fail("--mesh expects aligned|unaligned (got '%s')%s", o->mesh, "");
    plume_traction_opts *to = &j->to;
    plume_traction_opts_default(to);
    if (plume_solver_kind_parse(o->solver, &to->solver) != PLUME_OK)
        return fail("--solver expects newton|ipopt|linearized (got '%s')%s", o->solver, "");
    if (!(o->strain_max > 0 && o->strain_max < 10))
        return fprintf(stderr, "traction: --strain-max must be in (0, 10) (got %g)\n", o->strain_max), 2;
    j->edge = o->edge > 0 ? o->edge : plume_traction_default_edge(o->lx, o->ly);
    if (o->edge < 0)
        return fprintf(stderr, "traction: --edge must be > 0 (got %g)\n", o->edge), 2;
    to->lx = o->lx, to->ly = o->ly, to->h = o->h;
    to->strain_max = o->strain_max;
    to->steps = o->steps;
    if (o->npath > 0)
        to->path = o->path, to->npath = o->npath;
    to->peel = o->peel, to->top_grip_free = o->top_grip_free;
    if (!(o->peel >= 0.0 && o->peel <= 1.0))
        return fprintf(stderr, "traction: --peel must be in [0, 1] (got %g)\n", o->peel), 2;
    if (!(o->top_grip_free >= 0.0 && o->top_grip_free < 1.0))
        return fprintf(stderr, "traction: --top-grip-free must be in [0, 1) (got %g)\n", o->top_grip_free), 2;
    for (int k = 0; k < o->npath; k++)
        if (!(o->path[k] > -1.0) || o->path[k] == (k ? o->path[k - 1] : 0.0))
            return fprintf(stderr, "traction: --path: strain %d (%g) must be > -1 and differ from the one before "
                           "(the first from 0)\n", k + 1, o->path[k]), 2;
    plume_solver_opts_default(&j->so);
    j->so.max_iter = o->max_iter;
    j->so.verbose = o->verbose;
    to->solver_opts = &j->so;
    to->progress = o->quiet ? 0 : 1;
    return restart_opts(o, j);
}

/* Runs the requested models; a model that did not converge is reported, and ends the app (exit 3)
 * unless the linearised solver took its single steps by design. Returns an exit code. */
static int run_models(const options *o, traction_job *j)
{
    model_run *runs = j->runs;
    runs[0].scale = "macro";
    runs[1].scale = "micro";
    int rc = 0;
    for (int k = 0; k < 2 && rc == 0; k++) {
        if (!(k == 0 ? j->want_macro : j->want_micro))
            continue;
        runs[k].wanted = 1;
        runs[k].stop_after = o->stop_after, runs[k].nsteps = o->steps * (o->npath > 0 ? o->npath : 1);
        rc = k == 0 ? run_macro(o, &j->vane, &j->law, j->kind, j->angle, j->edge, &j->to, &runs[0])
                    : run_micro(o, &j->layout, j->angle, &j->to, &runs[1]);
    }
    if (rc)
        return rc;
    int usable = 1;
    for (int k = 0; k < 2; k++)
        if (runs[k].wanted && !runs[k].res.converged) {
            int lin = j->to.solver == PLUME_SOLVER_LINEARIZED;
            fprintf(stderr, "traction: %s model %s at step %d of %d (%s)%s\n", runs[k].scale,
                    lin ? "single linearised steps, not converged" : "did not converge", runs[k].res.failed_step,
                    j->to.steps, plume_reason_name(runs[k].res.failed_reason), lin ? "" : "; no output written");
            usable &= lin;
        }
    return usable ? 0 : 3;
}

/* -o: each model's curve with its parameters, and the size-effect family. Returns an exit code. */
static int write_curves(const options *o, const traction_job *j)
{
    plume_err err = {{0}};
    const model_run *runs = j->runs;
    const plume_vane *vane = &j->vane;
    const plume_layout *layout = &j->layout;
    for (int k = 0; k < 2; k++) {
        if (!runs[k].wanted)
            continue;
        plume_param params[] = {
            {"lx", o->lx}, {"ly", o->ly}, {"thickness", o->h}, {"angle_deg", j->angle},
            {"E_xx", vane->moduli.E_xx}, {"E_yy", vane->moduli.E_yy}, {"nu_xy", vane->moduli.nu_xy},
            {"G_xy", vane->moduli.G_xy}, {"kappa", o->kappa}, {"edge", k == 0 ? j->edge : runs[k].edge},
            {"strain_max", o->strain_max}, {"steps", o->steps}, {"elements", (double)runs[k].elements},
            {"vertices", (double)runs[k].vertices}, {"constraint", k == 0 ? o->constraint : 0},
            {"initial_slope", runs[k].res.initial_slope}, {"converged", runs[k].res.converged},
            {"max_constraint_violation", runs[k].res.max_violation}, {"phi", layout->phi},
            {"ratio", layout->ratio}, {"E_b", layout->E_b}, {"d_B", layout->d_B},
            {"e_rel", runs[k].edge / plume_layout_barb_width(layout)}, {"order", runs[k].order},
            {"refinement_change", runs[k].has_conv ? runs[k].conv.stress_change : -1.0},
            {"slope_refinement_change", runs[k].has_conv ? runs[k].conv.slope_change : -1.0},
            {"refinement_edge", runs[k].has_conv ? runs[k].conv.refinement_edge : -1.0}};
        int np = k == 0 ? 18 : (int)(sizeof params / sizeof params[0]);
        plume_sparam sparams[] = {{"solver", o->solver}, {"mesh", k == 0 ? o->mesh : "specimen"},
                                  {"scenario", o->scenario}, {"sample", o->sample ? o->sample : ""},
                                  {"moduli", j->moduli_source}};
        if (plume_curve_write(o->out, runs[k].scale, o->scenario, &runs[k].res.curve, params, np, sparams, 5, &err) !=
                PLUME_OK ||
            (runs[k].links && plume_curve_write_states(o->out, runs[k].scale, o->scenario, "hooks", runs[k].links_rows,
                                                       (long)runs[k].links_cols, runs[k].links, &err) != PLUME_OK)) {
            fprintf(stderr, "traction: %s\n", err.msg);
            return 1;
        }
    }
    if (j->fam.n)
        return size_effect_write(o->out, o->scenario, layout, o->ly, &j->fam);
    return 0;
}

/* --plot: the models' curves, or the size-effect family with the macro curve as its limit. Returns
 * an exit code. */
static int plot_curves(const options *o, const traction_job *j)
{
    const model_run *runs = j->runs;
    if (j->fam.n)
        return size_effect_plot(o->plot, o->scenario, j->angle, j->layout.d_B / o->ly, &runs[1].res.curve,
                                runs[0].wanted ? &runs[0].res.curve : NULL,
                                o->constraint ? "macro" : "macro (penalty)", &j->fam);
    plume_err err = {{0}};
    char title[256];
    snprintf(title, sizeof title, "%s traction, barbs at %g deg, %s", o->scenario, j->angle, o->model);
    plume_curve curves[2];
    const char *labels[2];
    int nc = 0;
    for (int k = 0; k < 2; k++)
        if (runs[k].wanted) {
            curves[nc] = runs[k].res.curve;
            labels[nc++] = k == 0 ? (o->constraint ? "macro (barbs inextensible)" : "macro (penalty)")
                                  : "micro (resolved barbs)";
        }
    if (plume_plot_curves(o->plot, title, curves, labels, nc, &err) != PLUME_OK) {
        fprintf(stderr, "traction: %s\n", err.msg);
        return 1;
    }
    return 0;
}

/* --json: one model's object, or both models' with the moduli and their differences (diff: the
 * largest, the last stress and the last w-bar, relative), and the size-effect family. */
static json_t *summary_json(const options *o, const traction_job *j, const double diff[3])
{
    const model_run *runs = j->runs;
    const double angle = j->angle, d_rel0 = j->layout.d_B / o->ly;
    json_t *s;
    if (!(runs[0].wanted && runs[1].wanted)) {
        s = run_json(&runs[runs[0].wanted ? 0 : 1], o, angle);
    } else {
        s = json_object();
        json_object_set_new(s, "scenario", json_string(o->scenario));
        json_object_set_new(s, "angle_deg", json_real(angle));
        json_object_set_new(s, "model", json_string("both"));
        json_object_set_new(s, "macro", run_json(&runs[0], o, angle));
        json_object_set_new(s, "micro", run_json(&runs[1], o, angle));
        json_t *m = json_object();
        json_object_set_new(m, "E_xx", json_real(j->vane.moduli.E_xx));
        json_object_set_new(m, "E_yy", json_real(j->vane.moduli.E_yy));
        json_object_set_new(m, "nu_xy", json_real(j->vane.moduli.nu_xy));
        json_object_set_new(m, "G_xy", json_real(j->vane.moduli.G_xy));
        json_object_set_new(m, "source", json_string(j->moduli_source));
        json_object_set_new(s, "moduli", m);
        json_t *d = json_object();
        json_object_set_new(d, "stress_max_relative", json_real(diff[0]));
        json_object_set_new(d, "stress_at_max_strain_relative", json_real(diff[1]));
        json_object_set_new(d, "wbar_at_max_strain_relative", json_real(diff[2]));
        json_object_set_new(s, "relative_difference", d);
        json_object_set_new(s, "converged", json_boolean(runs[0].res.converged && runs[1].res.converged));
        json_object_set_new(s, "seconds", json_real(runs[0].res.seconds + runs[1].res.seconds));
    }
    if (j->fam.n) {
        const size_family *fam = &j->fam;
        json_t *a = json_array();
        for (int k = -1; k < fam->n; k++) {
            json_t *e = json_object();
            const plume_curve *c = k < 0 ? &runs[1].res.curve : &fam->res[k].curve;
            double s_end = size_effect_end_stress(c);
            json_object_set_new(e, "dB_rel", json_real(k < 0 ? d_rel0 : fam->d_rel[k]));
            json_object_set_new(e, "elements", json_integer(k < 0 ? runs[1].elements : fam->elements[k]));
            json_object_set_new(e, "stress_at_max_strain", json_real(s_end));
            if (runs[0].wanted)
                json_object_set_new(e, "relative_to_macro",
                                    json_real(s_end / size_effect_end_stress(&runs[0].res.curve) - 1.0));
            json_array_append_new(a, e);
        }
        json_object_set_new(s, "size_effect", a);
    }
    if (o->out)
        json_object_set_new(s, "output", json_string(o->out));
    return s;
}

/* The summary on stdout: the JSON object (--json) or a line per model, their difference and the
 * size-effect family. */
static void report(const options *o, const traction_job *j)
{
    const model_run *runs = j->runs;
    double diff[3] = {0.0, 0.0, 0.0}; /* largest, last stress and last w-bar difference, relative */
    int both = runs[0].wanted && runs[1].wanted;
    if (both)
        compare_curves(&runs[1].res.curve, &runs[0].res.curve, &diff[0], &diff[1], &diff[2]);
    if (o->json) {
        json_t *s = summary_json(o, j, diff);
        cli_print_json(s, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        return;
    }
    for (int k = 0; k < 2; k++)
        if (runs[k].wanted)
            print_summary(&runs[k], o, j->angle);
    if (both)
        printf("micro vs macro: max stress difference %.3g of the micro stress range, %.3g at %g%% strain; "
               "w-bar %.3g\n", diff[0], diff[1], 100.0 * o->strain_max, diff[2]);
    if (j->fam.n)
        size_effect_print(j->layout.d_B / o->ly, &runs[1].res.curve, runs[0].wanted ? &runs[0].res.curve : NULL,
                          &j->fam, o->strain_max);
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc == CLI_HELP ? 0 : rc;
    if ((o.out && (rc = cli_output_file("traction", "-o", o.out))) ||
        (o.plot && (rc = cli_output_file("traction", "--plot", o.plot))) ||
        (o.vtk && (rc = cli_output_dir("traction", "--vtk", o.vtk))) ||
        (o.checkpoint && (rc = cli_output_file("traction", "--checkpoint", o.checkpoint))) ||
        (o.restart && access(o.restart, R_OK) != 0 &&
         (rc = cli_fail("traction", "--restart %s: cannot read it: %s", o.restart, strerror(errno)))))
        return rc;
    if (o.bending) {
        if (o.traction_only)
            return fail("--bending cannot be combined with %s (a traction option)%s", o.traction_only, "");
        if (!o.lx_set)
            o.lx = 0.01;
        if (!o.ly_set)
            o.ly = 0.02;
    }
    traction_job j;
    memset(&j, 0, sizeof j);
    if ((rc = resolve_angle(&o, argv[0], &j.angle)))
        return rc;
    j.want_macro = strcmp(o.model, "macro") == 0 || strcmp(o.model, "both") == 0;
    j.want_micro = strcmp(o.model, "micro") == 0 || strcmp(o.model, "both") == 0;
    if (!j.want_macro && !j.want_micro)
        return fail("--model expects macro|micro|both (got '%s')%s", o.model, "");
    if ((rc = build_layout(&o, j.want_micro, &j.layout)))
        return rc;
    if (o.bending)
        return bending_main(&o, &j.layout, j.want_macro, j.want_micro);
    if ((rc = build_vane(&o, &j)) || (rc = build_traction_opts(&o, &j)))
        return rc;
    if (o.size_effect) {
        if (!j.want_micro)
            return fail("--size-effect needs --model micro or both (got '%s')%s", o.model, "");
        if ((rc = size_effect_parse(o.size_effect, o.dB_rel_set || !o.layout_file ? o.dB_rel : j.layout.d_B / o.ly,
                                    &j.fam)))
            return rc;
    }
    if ((rc = run_models(&o, &j)) == 0 &&
        (!j.fam.n || (rc = size_effect_run(&j.layout, o.lx, o.ly, j.angle, &j.to, &j.fam)) == 0) &&
        (!o.out || (rc = write_curves(&o, &j)) == 0) && (!o.plot || (rc = plot_curves(&o, &j)) == 0))
        report(&o, &j);
    size_effect_free(&j.fam);
    for (int k = 0; k < 2; k++) {
        plume_traction_result_free(&j.runs[k].res);
        free(j.runs[k].links);
    }
    return rc;
}
