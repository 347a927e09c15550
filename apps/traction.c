/* apps/traction — the macroscale traction test of a feather-vane sample: stress–strain and
 * deflection curves, solved to convergence, stored in HDF5 and drawn as a chart. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <jansson.h>

#include "../lib/plume.h"
#include "cli.h"

static const char usage[] =
    "usage: traction [options]\n"
    "Quasi-static traction test of a vane sample (macroscale orthotropic membrane).\n"
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
    "  --steps N           quasi-static steps (default 10)\n"
    "  --solver S          newton | ipopt | linearized (default newton)\n"
    "  --max-iter N        solver iteration cap per step (default 100)\n"
    "  -o FILE.h5          write /curves/macro/<scenario>/{strain,stress,wbar,iterations,seconds}\n"
    "  --plot FILE.png     chart (an SVG is written beside it)\n"
    "  --json              print a summary object on stdout\n"
    "  --quiet / --verbose no progress line / solver iterations on stderr\n"
    "  --help\n";

typedef struct {
    const char *scenario, *sample, *samples_file, *moduli_file, *out, *plot, *mesh, *solver;
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

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->scenario = "tilted";
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
            exit(0);
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
        DBL("--strain-max", strain_max);
        else if (strcmp(a, "--steps") == 0) r = parse_int(a, v, &o->steps);
        else if (strcmp(a, "--max-iter") == 0) r = parse_int(a, v, &o->max_iter);
        else if (strcmp(a, "--scenario") == 0) o->scenario = v;
        else if (strcmp(a, "--sample") == 0) o->sample = v;
        else if (strcmp(a, "--samples") == 0) o->samples_file = v;
        else if (strcmp(a, "--moduli") == 0) o->moduli_file = v;
        else if (strcmp(a, "--mesh") == 0) o->mesh = v;
        else if (strcmp(a, "--solver") == 0) o->solver = v;
        else if (strcmp(a, "-o") == 0) o->out = v;
        else if (strcmp(a, "--plot") == 0) o->plot = v;
        else if (strcmp(a, "--constraint") == 0) {
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
    return 0;
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

int main(int argc, char **argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc;
    plume_err err = {{0}};
    plume_status st;
    double angle;
    if (strcmp(o.scenario, "longitudinal") == 0)
        angle = 0.0;
    else if (strcmp(o.scenario, "transverse") == 0)
        angle = 90.0;
    else if (strcmp(o.scenario, "tilted") == 0)
        angle = 45.0;
    else
        return fail("--scenario expects longitudinal|transverse|tilted (got '%s')%s", o.scenario, "");

    if (o.sample) {
        char path[4096];
        if (o.samples_file)
            snprintf(path, sizeof path, "%s", o.samples_file);
        else
            default_samples_path(argv[0], path, sizeof path);
        plume_sample s;
        if ((st = plume_sample_load(path, o.sample, &s, &err)) != PLUME_OK)
            return fail("%s%s", err.msg, "");
        if (!o.lx_set)
            o.lx = s.lx;
        if (!o.ly_set)
            o.ly = s.ly;
        if (!o.h_set)
            o.h = s.h;
        if (strcmp(o.scenario, "tilted") == 0) /* the sample decides unless --scenario changed it */
            o.scenario = strcmp(s.scenario, "transverse") == 0 ? "transverse" : strcmp(s.scenario, "longitudinal") == 0 ? "longitudinal" : "tilted";
        angle = strcmp(o.scenario, "longitudinal") == 0 ? 0.0 : strcmp(o.scenario, "transverse") == 0 ? 90.0 : 45.0;
    }
    if (o.angle_set)
        angle = o.angle;
    if (!(angle >= 0.0 && angle <= 180.0))
        return fprintf(stderr, "traction: --angle must be in [0, 180] degrees (got %g)\n", angle), 2;
    if (!(o.lx > 0) || !(o.ly > 0) || !(o.h > 0))
        return fprintf(stderr, "traction: --lx, --ly and --thickness must be > 0 (got %g, %g, %g m): a zero-area or zero-thickness sample cannot be tested\n",
                       o.lx, o.ly, o.h), 2;

    plume_vane vane;
    plume_vane_default(&vane);
    vane.moduli.E_xx = o.Exx, vane.moduli.E_yy = o.Eyy, vane.moduli.G_xy = o.Gxy, vane.moduli.nu_xy = o.nu;
    if (o.moduli_file) {
        if ((st = plume_moduli_read(o.moduli_file, &vane.moduli, &err)) != PLUME_OK)
            return fail("%s%s", err.msg, "");
        /* explicit flags override the file */
        if (o.Exx_set) vane.moduli.E_xx = o.Exx;
        if (o.Eyy_set) vane.moduli.E_yy = o.Eyy;
        if (o.Gxy_set) vane.moduli.G_xy = o.Gxy;
        if (o.nu_set) vane.moduli.nu_xy = o.nu;
    }
    vane.h = o.h;
    vane.kappa = o.kappa;
    vane.constraint = o.constraint;
    if (!(o.kappa >= 0))
        return fprintf(stderr, "traction: --kappa must be >= 0 (got %g)\n", o.kappa), 2;
    if ((st = plume_vane_check(&vane, &err)) != PLUME_OK)
        return fail("moduli: %s%s", err.msg, "");

    plume_patch_kind kind;
    if (plume_patch_kind_parse(o.mesh, &kind) != PLUME_OK)
        return fail("--mesh expects aligned|unaligned (got '%s')%s", o.mesh, "");
    plume_traction_opts to;
    plume_traction_opts_default(&to);
    if (plume_solver_kind_parse(o.solver, &to.solver) != PLUME_OK)
        return fail("--solver expects newton|ipopt|linearized (got '%s')%s", o.solver, "");
    if (!(o.strain_max > 0 && o.strain_max < 10))
        return fprintf(stderr, "traction: --strain-max must be in (0, 10) (got %g)\n", o.strain_max), 2;
    double edge = o.edge > 0 ? o.edge : fmin(o.lx, o.ly) / 20.0;
    if (o.edge < 0)
        return fprintf(stderr, "traction: --edge must be > 0 (got %g)\n", o.edge), 2;
    to.lx = o.lx, to.ly = o.ly, to.h = o.h;
    to.strain_max = o.strain_max;
    to.steps = o.steps;
    to.solver_opts.max_iter = o.max_iter;
    to.solver_opts.verbose = o.verbose;
    to.progress = o.quiet ? 0 : 1;

    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_index *barbs = NULL, nbarbs = 0;
    plume_traction_result res;
    memset(&res, 0, sizeof res);
    rc = 1;
    if ((st = plume_patch_mesh(o.lx, o.ly, angle, edge, kind, 2, &mesh, &err)) != PLUME_OK) {
        fprintf(stderr, "traction: mesh: %s\n", err.msg);
        goto done;
    }
    if ((st = plume_problem_create(mesh->nv, 2, fmax(o.lx, o.ly), &p)) != PLUME_OK ||
        (st = plume_vane_add(p, mesh, &vane, &barbs, &nbarbs, &err)) != PLUME_OK) {
        fprintf(stderr, "traction: %s\n", err.msg[0] ? err.msg : plume_strerror(st));
        goto done;
    }
    st = plume_traction_run(mesh, p, barbs, nbarbs, &to, &res, &err);
    if (st != PLUME_OK) { /* the library's message already names the module */
        fprintf(stderr, "%s\n", err.msg[0] ? err.msg : plume_strerror(st));
        goto done;
    }
    int usable = res.converged || to.solver == PLUME_SOLVER_LINEARIZED;
    if (!res.converged)
        fprintf(stderr, "traction: %s at step %d of %d (%s)%s\n",
                to.solver == PLUME_SOLVER_LINEARIZED ? "single linearised steps, not converged" : "did not converge",
                res.failed_step, to.steps, plume_reason_name(res.failed_reason),
                usable ? "" : "; no output written");
    if (usable && o.out) {
        plume_param params[] = {
            {"lx", o.lx}, {"ly", o.ly}, {"thickness", o.h}, {"angle_deg", angle},
            {"E_xx", vane.moduli.E_xx}, {"E_yy", vane.moduli.E_yy}, {"nu_xy", vane.moduli.nu_xy},
            {"G_xy", vane.moduli.G_xy}, {"kappa", o.kappa}, {"edge", edge}, {"strain_max", o.strain_max},
            {"steps", o.steps}, {"elements", (double)mesh->nt}, {"vertices", (double)mesh->nv},
            {"constraint", o.constraint}, {"initial_slope", res.initial_slope},
            {"converged", res.converged}, {"max_constraint_violation", res.max_violation}};
        plume_sparam sparams[] = {{"solver", o.solver}, {"mesh", o.mesh}, {"scenario", o.scenario},
                                  {"sample", o.sample ? o.sample : ""}};
        if ((st = plume_curve_write(o.out, "macro", o.scenario, &res.curve, params,
                                    (int)(sizeof params / sizeof params[0]), sparams, 4, &err)) != PLUME_OK) {
            fprintf(stderr, "traction: %s\n", err.msg);
            goto done;
        }
    }
    if (usable && o.plot) {
        char title[256];
        snprintf(title, sizeof title, "%s traction, barbs at %g deg, %s mesh, constraint %s, %s",
                 o.scenario, angle, o.mesh, o.constraint ? "on" : "off", o.solver);
        const char *label = o.solver;
        if ((st = plume_plot_curves(o.plot, title, &res.curve, &label, 1, &err)) != PLUME_OK) {
            fprintf(stderr, "traction: %s\n", err.msg);
            goto done;
        }
    }
    if (!o.json) {
        plume_index last = res.curve.n - 1;
        printf("%s %g deg, %s, %s mesh (%ld elements), constraint %s: stress at %g%% strain %.6g Pa, "
               "wbar %.4g, initial slope %.6g Pa, %d iterations, %.2f s, %s\n",
               o.scenario, angle, o.solver, o.mesh, (long)mesh->nt, o.constraint ? "on" : "off",
               100.0 * res.curve.strain[last], res.curve.stress[last], res.curve.wbar[last], res.initial_slope,
               res.newton_iterations, res.seconds,
               res.converged ? "converged" : plume_reason_name(res.failed_reason));
    } else {
        plume_index last = res.curve.n - 1;
        json_t *j = json_object();
        json_object_set_new(j, "scenario", json_string(o.scenario));
        json_object_set_new(j, "angle_deg", json_real(angle));
        json_object_set_new(j, "solver", json_string(o.solver));
        json_object_set_new(j, "mesh", json_string(o.mesh));
        json_object_set_new(j, "constraint", json_boolean(o.constraint));
        json_object_set_new(j, "initial_slope", json_real(res.initial_slope));
        json_object_set_new(j, "strain_at_end", json_real(res.curve.strain[last]));
        json_object_set_new(j, "stress_at_max_strain", res.converged || usable ? json_real(res.curve.stress[last]) : json_null());
        json_object_set_new(j, "wbar_at_max_strain", res.converged || usable ? json_real(res.curve.wbar[last]) : json_null());
        json_object_set_new(j, "elements", json_integer(mesh->nt));
        json_object_set_new(j, "vertices", json_integer(mesh->nv));
        json_object_set_new(j, "barb_edges", json_integer(nbarbs));
        json_object_set_new(j, "steps", json_integer(o.steps));
        json_object_set_new(j, "newton_iterations", json_integer(res.newton_iterations));
        json_object_set_new(j, "max_constraint_violation", json_real(res.max_violation));
        json_object_set_new(j, "converged", json_boolean(res.converged));
        json_object_set_new(j, "stop_reason", json_string(res.converged ? "converged" : plume_reason_name(res.failed_reason)));
        json_object_set_new(j, "failed_step", json_integer(res.failed_step));
        json_object_set_new(j, "factorizations", json_integer(res.factorizations));
        json_object_set_new(j, "factor_seconds", json_real(res.factor_seconds));
        json_object_set_new(j, "seconds", json_real(res.seconds));
        if (o.out)
            json_object_set_new(j, "output", json_string(o.out));
        char *txt = json_dumps(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        if (txt)
            puts(txt);
        free(txt);
        json_decref(j);
    }
    rc = usable ? 0 : 3;
done:
    plume_traction_result_free(&res);
    free(barbs);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return rc;
}
