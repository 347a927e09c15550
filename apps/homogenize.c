/* apps/homogenize — macroscale orthotropic moduli of a vane microstructure by numerical
 * homogenisation of its periodic cell, and the cell's response curves at finite strain. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"

static const char usage[] =
    "usage: homogenize [options]\n"
    "Effective orthotropic moduli (E_xx along the barbs, E_yy, nu_xy, G_xy) of a vane microstructure,\n"
    "and its bending moduli (D_long along the barbs, D_trans, D_coupling, D_twist, in N m).\n"
    "  --config FILE.json   layout keys (docs/apps/homogenize.md); flags given after it override it\n"
    "  --layout strips|barbules   barb strips in a soft barbule matrix (default), or explicit barbules\n"
    "  --phi V              barb surface fraction w_B/d_B in (0, 1) (default 0.16)\n"
    "  --dB M | --wB M      barb spacing, or barb width (default d_B = 1e-3 m)\n"
    "  --Eb PA --nu-barb V  barb material (default 2.5e9, 0.3)\n"
    "  --ratio R            barbule modulus over barb modulus, > 0 (default 1e-6)\n"
    "  --nu-barbule V       barbule material Poisson ratio (default 0.3)\n"
    "  --thickness M        reference thickness (default 1e-4): the moduli in Pa are the membrane\n"
    "                       stiffness (N/m) over it\n"
    "  --thickness-barb M --thickness-barbule M   each phase's own thickness (default: --thickness)\n"
    "  --kappa PA           compression-term coefficient (default 0)\n"
    "  --barbule-width M --barbule-spacing M --barbule-angle DEG   explicit barbules\n"
    "  --hook-strength N --hook-opening M --hook-slide M --hook-capture M   barbule hooks (explicit barbules):\n"
    "                       the moduli stay the bonded cell's; the separation law of a barb line (strength\n"
    "                       N/m, energy J/m^2, opening and capture m) is added (docs/unzipping.md)\n"
    "  --order 1|2          element order: 2 quadratic triangles (default), 1 linear (the paper's)\n"
    "  --e-rel V            element edge over barb width, e-bar (default 0: chosen from the thinnest\n"
    "                       strip so that the moduli are within 1 % of the refined limit)\n"
    "  --no-convergence     skip the convergence estimate (the tensor again on a mesh twice as coarse)\n"
    "  --strain-max E --steps N   cell response curves (default 0.05, 10; --strain-max 0: none)\n"
    "  -o FILE.h5           write /moduli (with the bending moduli as attributes D_long, D_trans,\n"
    "                       D_coupling, D_twist, D_16, D_26, and with hooks separation_strength,\n"
    "                       separation_energy, separation_opening, separation_capture,\n"
    "                       separation_stiffness, separation_peak_opening) and\n"
    "                       /curves/cell/{uniaxial_x,uniaxial_y,shear}\n"
    "  --plot FILE.png      chart of the cell curves (SVG beside it)\n"
    "  --vtk DIR            the deformed cell at every step of each curve as ParaView series:\n"
    "                       DIR/{uniaxial_x,uniaxial_y,shear}/steps.pvd (the strain as the time) with\n"
    "                       step_NNNNN.vtu (strain, stress, energy density, J per triangle)\n"
    "  --json               print E_xx, E_yy, nu_xy, G_xy (Pa), D_long, D_trans, D_coupling, D_twist (N m),\n"
    "                       seconds and more on stdout\n"
    "  --help\n";

#define APP "homogenize"

/* --vtk: one series per load case, started at its rest state */
typedef struct {
    const char *dir;
    plume_membrane_material mats[2];
    plume_fields *series[3];
} vtk_out;

static plume_status vtk_state(void *user, int load_case, int step, double strain, const plume_cell *cell,
                              const double *x)
{
    static const char *names[3] = {"uniaxial_x", "uniaxial_y", "shear"};
    vtk_out *v = user;
    plume_err err = {{0}};
    plume_status st = PLUME_OK;
    if (load_case < 0 || load_case > 2)
        return PLUME_EINVAL;
    if (!v->series[load_case]) {
        char dir[4200];
        snprintf(dir, sizeof dir, "%s/%s", v->dir, names[load_case]);
        if (plume_make_dirs(dir) != 0) {
            fprintf(stderr, "%s: --vtk: cannot create the directory '%s': %s\n", APP, dir, strerror(errno));
            return PLUME_EIO;
        }
        if ((st = plume_fields_create(plume_cell_mesh_of(cell), 2, plume_cell_mesh_of(cell)->nt, v->mats, 2, NULL, NULL, 0, &v->series[load_case],
                                      &err)) != PLUME_OK ||
            (st = plume_fields_series_start(v->series[load_case], dir, "steps.pvd", "step", -1.0, &err)) != PLUME_OK) {
            fprintf(stderr, "%s: --vtk: %s\n", APP, err.msg);
            return st;
        }
    }
    if ((st = plume_fields_series_frame(v->series[load_case], step, strain, x, &err)) != PLUME_OK)
        fprintf(stderr, "%s: --vtk: %s\n", APP, err.msg);
    return st;
}

/* the flags: a layout, the curves' options and the outputs */
typedef struct {
    plume_layout l;
    plume_homog_opts ho;
    const char *out, *plot, *vtk_dir;
    int json;
    double wB;
} options;

/* Parses argv into o (defaults first). 0, CLI_HELP after --help, or the exit code of bad input. */
static int parse_args(int argc, char **argv, options *o)
{
    plume_layout_default(&o->l);
    plume_homog_opts_default(&o->ho);
    o->out = o->plot = o->vtk_dir = NULL;
    o->json = 0;
    o->wB = -1.0;
    plume_err err = {{0}};
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
        if (strcmp(a, "--no-convergence") == 0) {
            o->ho.convergence = 0;
            continue;
        }
        if (!v)
            return cli_fail(APP, "%s needs a value (see --help)", a);
        i++;
        plume_layout *l = &o->l;
        if (strcmp(a, "--config") == 0) {
            if (plume_layout_load_json(v, l, &err) != PLUME_OK)
                return cli_fail(APP, "%s", err.msg);
        } else if (strcmp(a, "--layout") == 0) {
            if (strcmp(v, "strips") == 0)
                l->kind = PLUME_LAYOUT_STRIPS;
            else if (strcmp(v, "barbules") == 0)
                l->kind = PLUME_LAYOUT_BARBULES;
            else
                return cli_fail(APP, "--layout expects strips|barbules (got '%s')", v);
        } else if (strcmp(a, "--phi") == 0) r = cli_double(APP, a, v, &l->phi);
        else if (strcmp(a, "--dB") == 0) r = cli_double(APP, a, v, &l->d_B);
        else if (strcmp(a, "--wB") == 0) r = cli_double(APP, a, v, &o->wB);
        else if (strcmp(a, "--Eb") == 0) r = cli_double(APP, a, v, &l->E_b);
        else if (strcmp(a, "--nu-barb") == 0) r = cli_double(APP, a, v, &l->nu_b);
        else if (strcmp(a, "--ratio") == 0) r = cli_double(APP, a, v, &l->ratio);
        else if (strcmp(a, "--nu-barbule") == 0) r = cli_double(APP, a, v, &l->nu_B);
        else if (strcmp(a, "--thickness") == 0) r = cli_double(APP, a, v, &l->h);
        else if (strcmp(a, "--thickness-barb") == 0 || strcmp(a, "--thickness-barbule") == 0) {
            double t = 0.0;
            if ((r = cli_double(APP, a, v, &t)) != 0)
                return r;
            /* 0 means "the thickness" inside the layout only: given here it is a mistake */
            if (!(t > 0.0) || !isfinite(t))
                return cli_fail(APP, "%s must be a finite thickness > 0 (got %g m)", a, t);
            *(strcmp(a, "--thickness-barb") == 0 ? &l->h_barb : &l->h_barbule) = t;
        }
        else if (strcmp(a, "--kappa") == 0) r = cli_double(APP, a, v, &l->kappa);
        else if (strcmp(a, "--barbule-width") == 0) r = cli_double(APP, a, v, &l->barbule_width);
        else if (strcmp(a, "--barbule-spacing") == 0) r = cli_double(APP, a, v, &l->barbule_spacing);
        else if (strcmp(a, "--barbule-angle") == 0) r = cli_double(APP, a, v, &l->barbule_angle);
        else if (strcmp(a, "--hook-strength") == 0) r = cli_double(APP, a, v, &l->hooks.strength);
        else if (strcmp(a, "--hook-opening") == 0) r = cli_double(APP, a, v, &l->hooks.opening);
        else if (strcmp(a, "--hook-slide") == 0) r = cli_double(APP, a, v, &l->hooks.slide);
        else if (strcmp(a, "--hook-capture") == 0) r = cli_double(APP, a, v, &l->hooks.capture);
        else if (strcmp(a, "--e-rel") == 0) r = cli_double(APP, a, v, &l->e_rel);
        else if (strcmp(a, "--order") == 0) r = cli_int(APP, a, v, &l->order);
        else if (strcmp(a, "--strain-max") == 0) r = cli_double(APP, a, v, &o->ho.strain_max);
        else if (strcmp(a, "--steps") == 0) r = cli_int(APP, a, v, &o->ho.steps);
        else if (strcmp(a, "-o") == 0) o->out = v;
        else if (strcmp(a, "--plot") == 0) o->plot = v;
        else if (strcmp(a, "--vtk") == 0) o->vtk_dir = v;
        else
            return cli_fail(APP, "unknown option '%s' (see --help)", a);
        if (r)
            return r;
    }
    if (o->wB >= 0.0) {
        if (!(o->wB > 0.0))
            return cli_fail(APP, "--wB must be > 0 (got %g)", o->wB);
        o->l.d_B = o->wB / o->l.phi;
    }
    if (plume_layout_check(&o->l, &err) != PLUME_OK)
        return cli_fail(APP, "%s", err.msg);
    if (o->vtk_dir && !(o->ho.strain_max > 0.0))
        return cli_fail(APP, "--vtk writes the cell curves' states: it needs --strain-max > 0");
    return 0;
}

/* -o: /moduli with the refinement and bending figures and provenance, and the cell curves
 * (plume_homog_write: the file a scene's "from_moduli" reads). Exit code. */
static int write_results(const char *out, const plume_layout *l, const plume_homog_result *r,
                         const plume_separation_law *sep)
{
    plume_err err = {{0}};
    if (plume_homog_write_separation(out, l, r, sep, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        return 1;
    }
    return 0;
}

/* --plot: the three responses differ by the contrast (1e6): each is drawn over its own
 * small-strain modulus, so the charts show the nonlinearity (a straight line is linear
 * elasticity). Exit code. */
static int plot_responses(const char *plot, const plume_homog_opts *ho, const plume_homog_result *r)
{
    plume_err err = {{0}};
    int rc = 0;
    plume_curve cv[3] = {r->uniaxial_x, r->uniaxial_y, r->shear};
    const double mod[3] = {r->moduli.E_xx, r->moduli.E_yy, r->moduli.G_xy};
    double *scaled = malloc((size_t)(3 * (ho->steps + 1)) * sizeof *scaled);
    for (int k = 0; k < 3 && scaled; k++) {
        for (plume_index i = 0; i < cv[k].n; i++)
            scaled[k * (ho->steps + 1) + i] = cv[k].stress[i] / mod[k];
        cv[k].stress = scaled + k * (ho->steps + 1);
    }
    const char *labels[3] = {"uniaxial along barbs (/E_xx)", "uniaxial across barbs (/E_yy)",
                             "shear, normal stresses free (/G_xy)"};
    const plume_plot_axes axes = {"stress / small-strain modulus", "lateral strain (uniaxial)", NULL, 0.0, 0, NULL, NULL, 0};
    if (!scaled || plume_plot_curves_axes(plot, "periodic cell response", &axes, cv, labels, 3, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, scaled ? err.msg : "out of memory");
        rc = 1;
    }
    free(scaled);
    return rc;
}

/* --json: the moduli, the bending tensor, the membrane tensor and the run's figures. */
static json_t *result_json(const plume_layout *l, const plume_homog_result *r, const plume_separation_law *sep,
                           const double *sep_tensor,
                           const char *out)
{
    json_t *j = json_object();
    json_object_set_new(j, "E_xx", json_real(r->moduli.E_xx));
    json_object_set_new(j, "E_yy", json_real(r->moduli.E_yy));
    json_object_set_new(j, "nu_xy", json_real(r->moduli.nu_xy));
    json_object_set_new(j, "G_xy", json_real(r->moduli.G_xy));
    json_object_set_new(j, "D_long", json_real(r->bending.D_long));
    json_object_set_new(j, "D_trans", json_real(r->bending.D_trans));
    json_object_set_new(j, "D_coupling", json_real(r->bending.D_coupling));
    json_object_set_new(j, "D_twist", json_real(r->bending.D_twist));
    json_object_set_new(j, "D_16", json_real(r->bending.D_16));
    json_object_set_new(j, "D_26", json_real(r->bending.D_26));
    json_t *D = json_array();
    for (int k = 0; k < 9; k++)
        json_array_append_new(D, json_real(r->D[k]));
    json_object_set_new(j, "D", D);
    json_object_set_new(j, "bending_change", json_real(r->bending_change));
    json_object_set_new(j, "plate_dofs", json_integer(r->plate_dofs));
    json_object_set_new(j, "layout", json_string(l->kind == PLUME_LAYOUT_STRIPS ? "strips" : "barbules"));
    json_t *C = json_array();
    for (int k = 0; k < 9; k++)
        json_array_append_new(C, json_real(r->C[k]));
    json_object_set_new(j, "C", C);
    json_object_set_new(j, "shear_coupling", json_real(r->coupling));
    json_object_set_new(j, "elements", json_integer(r->elements));
    json_object_set_new(j, "order", json_integer(r->order));
    json_object_set_new(j, "element_edge", json_real(r->element_edge));
    json_object_set_new(j, "refinement_change", json_real(r->refinement_change));
    if (r->refinement_change >= 0.0) {
        json_t *mc = json_object();
        const char *mn[4] = {"E_xx", "E_yy", "nu_xy", "G_xy"};
        for (int k = 0; k < 4; k++)
            json_object_set_new(mc, mn[k], json_real(r->moduli_change[k]));
        json_object_set_new(j, "moduli_change", mc);
        json_object_set_new(j, "refinement_edge", json_real(r->refinement_edge));
    }
    json_object_set_new(j, "vertices", json_integer(r->vertices));
    json_object_set_new(j, "newton_iterations", json_integer(r->newton_iterations));
    json_object_set_new(j, "seconds", json_real(r->seconds));
    if (sep) {
        json_t *js = json_object();
        json_object_set_new(js, "strength", json_real(sep->strength));
        json_object_set_new(js, "energy", json_real(sep->energy));
        json_object_set_new(js, "opening", json_real(sep->opening));
        json_object_set_new(js, "capture", json_real(sep->capture));
        json_object_set_new(js, "stiffness", json_real(sep->stiffness));
        json_object_set_new(js, "peak_opening", json_real(sep->peak_opening));
        json_object_set_new(js, "cell_length", json_real(sep->cell_length));
        json_object_set_new(js, "solves", json_integer(sep->solves));
        json_object_set_new(js, "newton_iterations", json_integer(sep->newton_iterations));
        if (sep_tensor) {
            json_t *jt = json_array();
            for (int k = 0; k < 9; k++)
                json_array_append_new(jt, json_real(sep_tensor[k]));
            json_object_set_new(js, "tensor", jt);
        }
        json_object_set_new(j, "separation", js);
    }
    if (out)
        json_object_set_new(j, "output", json_string(out));
    return j;
}

/* The summary on stdout: the JSON object (--json) or the moduli, the bending moduli and the
 * convergence estimate in words. */
static void report(const plume_layout *l, const plume_homog_result *r, const plume_separation_law *sep,
                   const double *sep_tensor, const char *out, int json)
{
    if (json) {
        json_t *j = result_json(l, r, sep, sep_tensor, out);
        cli_print_json(j, JSON_INDENT(2) | JSON_REAL_PRECISION(12));
        return;
    }
    printf("%s layout, phi %g, ratio %g: E_xx %.6g Pa, E_yy %.6g Pa, nu_xy %.4g, G_xy %.6g Pa "
           "(%ld %s elements, %d iterations, %.2f s)\n",
           l->kind == PLUME_LAYOUT_STRIPS ? "strips" : "barbules", l->phi, l->ratio, r->moduli.E_xx, r->moduli.E_yy,
           r->moduli.nu_xy, r->moduli.G_xy, (long)r->elements, r->order == 2 ? "quadratic" : "linear",
           r->newton_iterations, r->seconds);
    printf("bending: D_long %.6g N m, D_trans %.6g N m, D_coupling %.4g N m, D_twist %.6g N m\n", r->bending.D_long,
           r->bending.D_trans, r->bending.D_coupling, r->bending.D_twist);
    if (r->refinement_change >= 0.0)
        printf("converged to %.2g %% (the tensor's change from a mesh of %.3g m elements; E_xx %.2g %%, E_yy %.2g %%, "
               "nu_xy %.2g %%, G_xy %.2g %%)\n",
               100.0 * r->refinement_change, r->refinement_edge, 100.0 * r->moduli_change[0],
               100.0 * r->moduli_change[1], 100.0 * r->moduli_change[2], 100.0 * r->moduli_change[3]);
    if (sep)
        printf("separation of a barb line (hooks): strength %.6g N/m, energy %.6g J/m^2, traction gone at an opening "
               "of %.4g m, catches again within %.4g m (stiffness %.4g N/m^2 while it holds, peak at %.4g m; %d cell "
               "solves)\n", sep->strength, sep->energy, sep->opening, sep->capture, sep->stiffness, sep->peak_opening,
               sep->solves);
}

int main(int argc, char **argv)
{
    plume_openmp_serial(); /* CHOLMOD's 4-thread OpenMP loops cost more than they save here */
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc == CLI_HELP ? 0 : rc;
    if ((o.out && (rc = cli_output_file(APP, "-o", o.out))) ||
        (o.plot && (rc = cli_output_file(APP, "--plot", o.plot))) ||
        (o.vtk_dir && (rc = cli_output_dir(APP, "--vtk", o.vtk_dir))))
        return rc;
    plume_layout l = o.l;
    plume_homog_opts ho = o.ho;
    vtk_out vtk;
    memset(&vtk, 0, sizeof vtk);
    vtk.dir = o.vtk_dir;
    plume_err err = {{0}};
    if (vtk.dir) {
        plume_layout_materials(&l, vtk.mats);
        ho.on_state = vtk_state;
        ho.on_state_user = &vtk;
    }
    plume_homog_result r;
    plume_status hs = plume_homogenize(&l, &ho, &r, &err);
    for (int k = 0; k < 3; k++)
        plume_fields_destroy(&vtk.series[k]);
    if (hs != PLUME_OK)
        return fprintf(stderr, "%s: %s\n", APP, err.msg), 1;
    plume_separation_law sep, *with = NULL;
    double sep_tensor[9];
    if (l.kind == PLUME_LAYOUT_BARBULES && l.hooks.strength > 0.0) {
        if (plume_separation_law_of(&l, &sep, &err) != PLUME_OK ||
            (o.json && plume_separation_tensor(&l, sep_tensor, &err) != PLUME_OK)) {
            plume_homog_result_free(&r);
            return fprintf(stderr, "%s: %s\n", APP, err.msg), 1;
        }
        with = &sep;
    }
    if (o.out)
        rc = write_results(o.out, &l, &r, with);
    if (o.plot && ho.strain_max > 0.0 && rc == 0)
        rc = plot_responses(o.plot, &ho, &r);
    report(&l, &r, with, with ? sep_tensor : NULL, o.out, o.json);
    plume_homog_result_free(&r);
    return rc;
}
