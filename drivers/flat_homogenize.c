/* plume: the flat interface's homogenize request (flat.h): a layout's moduli, its bending moduli,
 * the cell curves and, for a layout with hooks, the barb line's separation law. */
#include "flat.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "internal/flat_common.h"

/* homogenize request.output, checked before the solve so that a bad path costs no cell solves (as
 * apps/homogenize -o): not empty, not a directory, its directory created with its parents (as
 * write_frames does) and writable. */
static plume_status output_check(const char *path, plume_err *err)
{
    if (!*path)
        return plume_err_set(err, PLUME_EINVAL, "homogenize request: \"output\" must name a file (got \"\")");
    char dir[4096];
    if (strlen(path) >= sizeof dir)
        return plume_err_set(err, PLUME_EINVAL, "homogenize request: \"output\": the path '%.64s...' is longer than %d "
                                                "bytes", path, (int)sizeof dir - 1);
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return plume_err_set(err, PLUME_EINVAL, "homogenize request: \"output\": '%s' is a directory, not a file", path);
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == dir)
        dir[1] = '\0';
    else
        *slash = '\0';
    if (plume_make_dirs(dir) != 0)
        return plume_err_set(err, PLUME_EIO, "homogenize request: \"output\": cannot create the directory '%s' of '%s': %s",
                             dir, path, strerror(errno));
    if (access(dir, W_OK) != 0)
        return plume_err_set(err, PLUME_EIO, "homogenize request: \"output\": cannot write '%s' in the directory '%s': %s",
                             path, dir, strerror(errno));
    return PLUME_OK;
}

plume_status plume_flat_homogenize(const char *request, char **result, char *msg, long nmsg)
{
    plume_err err = {{0}};
    if (!result)
        return plume_flat_finish(plume_err_set(&err, PLUME_EINVAL, "homogenize: no result pointer"), &err, msg, nmsg);
    *result = NULL;
    static const char *const keys[] = {"layout", "strain_max", "steps", "output", NULL};
    json_t *req;
    const char *output = NULL;
    plume_status st = plume_flat_parse_request(request, "homogenize", keys, &req, &err);
    if (st != PLUME_OK)
        return plume_flat_finish(st, &err, msg, nmsg);
    plume_layout l;
    plume_layout_default(&l);
    plume_homog_opts ho;
    plume_homog_opts_default(&ho);
    plume_homog_result r;
    memset(&r, 0, sizeof r);
    if ((st = plume_flat_get_layout(req, "homogenize", &l, &err)) != PLUME_OK ||
        (st = plume_flat_get_number(req, "homogenize", "strain_max", &ho.strain_max, &err)) != PLUME_OK ||
        (st = plume_flat_get_int(req, "homogenize", "steps", &ho.steps, &err)) != PLUME_OK ||
        (st = plume_flat_get_string(req, "homogenize", "output", &output, &err)) != PLUME_OK ||
        (st = plume_layout_check(&l, &err)) != PLUME_OK || (output && (st = output_check(output, &err)) != PLUME_OK) ||
                                    (st = plume_homogenize(&l, &ho, &r, &err)) != PLUME_OK)
        goto done;
    plume_separation_law sep, *with = NULL; /* a layout with hooks: its barb line's separation law */
    double sep_tensor[9];                   /* and the hooked cell's tensor */
    if (l.kind == PLUME_LAYOUT_BARBULES && l.hooks.strength > 0.0) {
        if ((st = plume_separation_law_of(&l, &sep, &err)) != PLUME_OK ||
            (st = plume_separation_tensor(&l, sep_tensor, &err)) != PLUME_OK)
            goto done;
        with = &sep;
    }
    if (output && (st = plume_homog_write_separation(output, &l, &r, with, &err)) != PLUME_OK) {
        char why[sizeof err.msg];
        snprintf(why, sizeof why, "%s", err.msg);
        plume_err_set(&err, st, "homogenize request: \"output\": %s", why);
        goto done;
    }
    json_t *C = json_array();
    for (int k = 0; k < 9; k++)
        json_array_append_new(C, json_real(r.C[k]));
    json_t *o = json_pack("{s:f, s:f, s:f, s:f, s:o, s:f, s:I, s:I, s:i, s:f}", "E_xx", r.moduli.E_xx, "E_yy",
                          r.moduli.E_yy, "nu_xy", r.moduli.nu_xy, "G_xy", r.moduli.G_xy, "C", C, "shear_coupling",
                          r.coupling, "elements", (json_int_t)r.elements, "vertices", (json_int_t)r.vertices,
                          "newton_iterations", r.newton_iterations, "seconds", r.seconds);
    if (o) {
        json_t *D = json_array();
        for (int k = 0; k < 9; k++)
            json_array_append_new(D, json_real(r.D[k]));
        json_object_set_new(o, "D", D);
        json_object_set_new(o, "D_long", json_real(r.bending.D_long));
        json_object_set_new(o, "D_trans", json_real(r.bending.D_trans));
        json_object_set_new(o, "D_coupling", json_real(r.bending.D_coupling));
        json_object_set_new(o, "D_twist", json_real(r.bending.D_twist));
        json_object_set_new(o, "D_16", json_real(r.bending.D_16));
        json_object_set_new(o, "D_26", json_real(r.bending.D_26));
        json_object_set_new(o, "bending_change", json_real(r.bending_change));
        json_object_set_new(o, "order", json_integer(r.order));
        json_object_set_new(o, "element_edge", json_real(r.element_edge));
        json_object_set_new(o, "refinement_change", json_real(r.refinement_change));
        if (r.refinement_change >= 0.0) {
            json_object_set_new(o, "moduli_change",
                                json_pack("{s:f, s:f, s:f, s:f}", "E_xx", r.moduli_change[0], "E_yy", r.moduli_change[1],
                                          "nu_xy", r.moduli_change[2], "G_xy", r.moduli_change[3]));
            json_object_set_new(o, "refinement_edge", json_real(r.refinement_edge));
        }
    }
    if (o && with) {
        json_t *js = json_pack("{s:f, s:f, s:f, s:f, s:f, s:f, s:f, s:i, s:i}", "strength", sep.strength, "energy",
                               sep.energy, "opening", sep.opening, "capture", sep.capture, "stiffness", sep.stiffness,
                               "peak_opening", sep.peak_opening, "cell_length", sep.cell_length, "solves", sep.solves,
                               "newton_iterations", sep.newton_iterations);
        json_t *jt = json_array();
        for (int k = 0; k < 9; k++)
            json_array_append_new(jt, json_real(sep_tensor[k]));
        if (js)
            json_object_set_new(js, "tensor", jt);
        else
            json_decref(jt);
        json_object_set_new(o, "separation", js);
    }
    if (o && output)
        json_object_set_new(o, "output", json_string(output));
    if (o && ho.strain_max > 0.0)
        json_object_set_new(o, "curves", json_pack("{s:o, s:o, s:o}", "uniaxial_x", plume_flat_curve_json(&r.uniaxial_x),
                                                   "uniaxial_y", plume_flat_curve_json(&r.uniaxial_y), "shear",
                                                   plume_flat_curve_json(&r.shear)));
    st = plume_flat_emit(o, result, &err);
done:
    plume_homog_result_free(&r);
    json_decref(req);
    return plume_flat_finish(st, &err, msg, nmsg);
}
