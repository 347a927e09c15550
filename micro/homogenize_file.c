/* plume: a homogenisation's results in an HDF5 file (docs/hdf5-layout.md): /moduli with the bending
 * moduli, the thickness they are over, how converged they are and the layout's provenance, and the
 * cell curves under /curves/cell. The file a scene material reads with "from_moduli"; apps/homogenize
 * -o and the library's users write it the same way. */
#include "homogenize.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../lib/io/curves.h"
#include "layout.h"

plume_status plume_homog_write_separation(const char *path, const plume_layout *l, const plume_homog_result *r,
                                          const plume_separation_law *sep, plume_err *err)
{
    if (!path || !l || !r)
        return plume_err_set(err, PLUME_EINVAL, "homogenisation file: a path, the layout and its result are needed");
    const char *kind = l->kind == PLUME_LAYOUT_STRIPS ? "strips" : "barbules";
    const double h_barb = plume_layout_thickness(l, PLUME_MAT_BARB), h_barbule = plume_layout_thickness(l, PLUME_MAT_BARBULE);
    char prov[512];
    snprintf(prov, sizeof prov,
             "plume homogenize: %s layout, phi %g, d_B %g m, E_b %g Pa, nu_b %g, ratio %g, nu_B %g, "
             "thickness %g m (barbs %g m, barbules %g m), order %d, element edge %g m, %ld elements",
             kind, l->phi, l->d_B, l->E_b, l->nu_b, l->ratio, l->nu_B, l->h, h_barb, h_barbule, r->order,
             r->element_edge, (long)r->elements);
    const plume_param params[] = {{"phi", l->phi}, {"d_B", l->d_B}, {"E_b", l->E_b}, {"nu_b", l->nu_b},
                                  {"ratio", l->ratio}, {"nu_B", l->nu_B}, {"thickness", l->h},
                                  {"thickness_barb", h_barb}, {"thickness_barbule", h_barbule},
                                  {"e_rel", r->element_edge / plume_layout_barb_width(l)},
                                  {"elements", (double)r->elements}, {"order", (double)r->order},
                                  {"refinement_change", r->refinement_change}};
    double Ch[9] = {0}; /* with a law: the hooked cell's tensor */
    if (sep) {
        plume_status st = plume_separation_tensor(l, Ch, err);
        if (st != PLUME_OK)
            return st;
    }
    const plume_param mparams[] = {{"C11", r->C[0]}, {"C12", r->C[1]}, {"C13", r->C[2]},
                                   {"C22", r->C[4]}, {"C23", r->C[5]}, {"C33", r->C[8]},
                                   {"order", (double)r->order},
                                   {"element_edge", r->element_edge},
                                   {"elements", (double)r->elements},
                                   {"refinement_change", r->refinement_change},
                                   {"refinement_edge", r->refinement_change >= 0.0 ? r->refinement_edge : -1.0},
                                   {"E_xx_change", r->moduli_change[0]},
                                   {"E_yy_change", r->moduli_change[1]},
                                   {"nu_xy_change", r->moduli_change[2]},
                                   {"G_xy_change", r->moduli_change[3]},
                                   {"D_long", r->bending.D_long},
                                   {"D_trans", r->bending.D_trans},
                                   {"D_coupling", r->bending.D_coupling},
                                   {"D_twist", r->bending.D_twist},
                                   {"D_16", r->bending.D_16},
                                   {"D_26", r->bending.D_26},
                                   {"bending_change", r->bending_change},
                                   {"thickness", l->h},
                                   {"thickness_barb", h_barb},
                                   {"thickness_barbule", h_barbule},
                                   {"separation_strength", sep ? sep->strength : 0.0},
                                   {"separation_energy", sep ? sep->energy : 0.0},
                                   {"separation_opening", sep ? sep->opening : 0.0},
                                   {"separation_capture", sep ? sep->capture : 0.0},
                                   {"separation_stiffness", sep ? sep->stiffness : 0.0},
                                   {"separation_peak_opening", sep ? sep->peak_opening : 0.0},
                                   {"separation_C11", Ch[0]}, {"separation_C12", Ch[1]}, {"separation_C13", Ch[2]},
                                   {"separation_C22", Ch[4]}, {"separation_C23", Ch[5]}, {"separation_C33", Ch[8]}};
    const int nsep = 12; /* the last attributes: written only with a law */
    const plume_sparam sp[] = {{"layout", kind}};
    plume_status st = plume_moduli_write_params(path, &r->moduli, prov, mparams,
                                                (int)(sizeof mparams / sizeof mparams[0]) - (sep ? 0 : nsep), err);
    static const char *const names[3] = {"uniaxial_x", "uniaxial_y", "shear"};
    const plume_curve *cv[3] = {&r->uniaxial_x, &r->uniaxial_y, &r->shear};
    for (int k = 0; k < 3 && st == PLUME_OK; k++)
        if (cv[k]->n > 0)
            st = plume_curve_write(path, "cell", names[k], cv[k], params, (int)(sizeof params / sizeof params[0]), sp,
                                   1, err);
    return st;
}

plume_status plume_homog_write(const char *path, const plume_layout *l, const plume_homog_result *r, plume_err *err)
{
    return plume_homog_write_separation(path, l, r, NULL, err);
}

plume_status plume_separation_read(const char *path, plume_separation_law *s, plume_err *err)
{
    if (!path || !s)
        return plume_err_set(err, PLUME_EINVAL, "separation law: a path and an output are required");
    memset(s, 0, sizeof *s);
    static const char *const names[5] = {"separation_strength", "separation_energy", "separation_opening",
                                         "separation_capture", "separation_stiffness"};
    double *v[5] = {&s->strength, &s->energy, &s->opening, &s->capture, &s->stiffness};
    for (int k = 0; k < 5; k++) {
        plume_status st = plume_moduli_read_param(path, names[k], v[k], err);
        if (st != PLUME_OK)
            return st;
        const int ok = isfinite(*v[k]) && (k == 3 ? *v[k] >= 0.0 : *v[k] > 0.0);
        if (!ok) {
            const double bad = *v[k];
            memset(s, 0, sizeof *s);
            return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': /moduli attribute %s = %g must be %s", path,
                                 names[k], bad, k == 3 ? ">= 0" : "> 0");
        }
    }
    /* the opening at the strength: written since 3.5; without it the law is taken brittle
     * (peak_opening = opening, no slide) */
    s->peak_opening = s->opening;
    if (plume_moduli_has_param(path, "separation_peak_opening")) {
        double peak = 0.0;
        plume_status st = plume_moduli_read_param(path, "separation_peak_opening", &peak, err);
        if (st != PLUME_OK)
            return st;
        if (!(isfinite(peak) && peak > 0.0 && peak <= s->opening)) {
            const double open = s->opening;
            memset(s, 0, sizeof *s);
            return plume_err_set(err, PLUME_EINVAL, "moduli file '%s': /moduli attribute separation_peak_opening = %g "
                                 "must be > 0 and at most separation_opening (%g)", path, peak, open);
        }
        s->peak_opening = peak;
    }
    return PLUME_OK;
}
