/* plume: microstructure layouts — defaults, validation and the two isotropic materials. */
#include "layout.h"

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void plume_layout_default(plume_layout *l)
{
    l->kind = PLUME_LAYOUT_STRIPS;
    l->phi = 0.16; /* supplementary Figure 10 */
    l->d_B = 1e-3;
    l->E_b = 2.5e9;
    l->nu_b = 0.3;
    l->ratio = 1e-6;
    l->nu_B = 0.3;
    l->h = 1e-4;
    l->h_barb = 0.0;
    l->h_barbule = 0.0;
    l->kappa = 0.0;
    /* At 60 deg a barbule 0.2 d_B wide spans (1 - phi) d_B cot 60 + 0.2 d_B / sin 60 < 0.82 d_B along
     * the barbs whatever phi is, so a spacing of one d_B always fits (layout.h). */
    l->barbule_width = 0.2 * l->d_B;
    l->barbule_spacing = 1.0 * l->d_B;
    l->barbule_angle = 60.0;
    l->order = 2;
    l->e_rel = 0.0;
    plume_hook_law_default(&l->hooks); /* the literature's opening and capture, ready when ... */
    l->hooks.strength = 0.0;           /* ... a strength turns the hooks on: bonded by default */
}

void plume_layout_set_spacing(plume_layout *l, double d_B)
{
    const double scale = d_B / l->d_B;
    l->d_B = d_B;
    l->barbule_width *= scale;
    l->barbule_spacing *= scale;
}

double plume_layout_barb_width(const plume_layout *l)
{
    return l->phi * l->d_B;
}

double plume_layout_thinnest(const plume_layout *l)
{
    double w = plume_layout_barb_width(l), t = fmin(w, l->d_B - w);
    return l->kind == PLUME_LAYOUT_BARBULES ? fmin(t, l->barbule_width) : t;
}

/* The automatic element edge over the thinnest strip, [use][layout kind][order - 1], measured
 * (docs/micro-convergence.md): the largest fraction whose default run is within 1 % (cell) or 2 %
 * (specimen) of its refined limit. Barbules meet the barbs at re-entrant corners, where the strain is
 * singular and every element order converges at about h^1.1; strips have no such corner inside. A
 * strips cell needs no refinement at all: its fields are uniform in each strip (the laminate), which
 * any conforming mesh represents exactly. */
static const double auto_edge[2][2][2] = {
    /* cell:     strips {P1, P2},  barbules {P1, P2} */
    {{1.0, 1.0}, {0.03, 0.125}},
    /* specimen: strips {P1, P2},  barbules {P1, P2} */
    {{0.35, 2.0}, {0.25, 1.0}},
};

double plume_layout_element_edge(const plume_layout *l, plume_mesh_use use)
{
    if (l->e_rel > 0.0)
        return l->e_rel * plume_layout_barb_width(l);
    int u = use == PLUME_MESH_CELL ? 0 : 1, k = l->kind == PLUME_LAYOUT_STRIPS ? 0 : 1, o = l->order == 1 ? 0 : 1;
    return auto_edge[u][k][o] * plume_layout_thinnest(l);
}

void plume_layout_refinement(const plume_layout *l, plume_mesh_use use, plume_layout *out)
{
    double w = plume_layout_barb_width(l), e = plume_layout_element_edge(l, use);
    *out = *l;
    out->e_rel = 2.0 * e / w;
    plume_err ignored;
    if (plume_layout_check(out, &ignored) != PLUME_OK)
        out->e_rel = 0.5 * e / w;
}

plume_status plume_layout_check(const plume_layout *l, plume_err *err)
{
    if (!l)
        return plume_err_set(err, PLUME_EINVAL, "layout is NULL");
    if (l->kind != PLUME_LAYOUT_STRIPS && l->kind != PLUME_LAYOUT_BARBULES)
        return plume_err_set(err, PLUME_EINVAL, "kind must be PLUME_LAYOUT_STRIPS or PLUME_LAYOUT_BARBULES (got %d)",
                             (int)l->kind);
    /* !(x > lo && x < hi) also rejects NaN */
    if (!(l->phi > 0.0 && l->phi < 1.0))
        return plume_err_set(err, PLUME_EINVAL, "phi must be in (0, 1) (got %g)", l->phi);
    if (!(l->d_B > 0.0) || !isfinite(l->d_B))
        return plume_err_set(err, PLUME_EINVAL, "d_B must be finite and > 0 (got %g m)", l->d_B);
    if (!(l->E_b > 0.0) || !isfinite(l->E_b))
        return plume_err_set(err, PLUME_EINVAL, "E_b must be finite and > 0 (got %g Pa)", l->E_b);
    if (!(l->nu_b > -1.0 && l->nu_b < 0.5))
        return plume_err_set(err, PLUME_EINVAL, "nu_b must be in (-1, 0.5) (got %g)", l->nu_b);
    if (!(l->ratio > 0.0) || !isfinite(l->ratio) || !isfinite(l->ratio * l->E_b) || !(l->ratio * l->E_b > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "ratio must be finite and > 0, with ratio * E_b finite and > 0 "
                             "(got ratio %g, E_b %g Pa)", l->ratio, l->E_b);
    if (!(l->nu_B > -1.0 && l->nu_B < 0.5))
        return plume_err_set(err, PLUME_EINVAL, "nu_B must be in (-1, 0.5) (got %g)", l->nu_B);
    if (!(l->h > 0.0) || !isfinite(l->h))
        return plume_err_set(err, PLUME_EINVAL, "h must be finite and > 0 (got %g m)", l->h);
    /* A barbule phase thicker than the barbs is allowed: real barbules are thinner, but the cell
     * problems hold for any positive thicknesses on a common mid-surface, and parameter studies
     * (the soft phase standing for a filled matrix, or swapped contrasts) need no special case. */
    if (!(l->h_barb >= 0.0) || !isfinite(l->h_barb))
        return plume_err_set(err, PLUME_EINVAL, "thickness_barb must be finite and > 0, or 0 for the thickness h (got %g m)",
                             l->h_barb);
    if (!(l->h_barbule >= 0.0) || !isfinite(l->h_barbule))
        return plume_err_set(err, PLUME_EINVAL,
                             "thickness_barbule must be finite and > 0, or 0 for the thickness h (got %g m)", l->h_barbule);
    if (!(l->kappa >= 0.0) || !isfinite(l->kappa))
        return plume_err_set(err, PLUME_EINVAL, "kappa must be finite and >= 0 (got %g Pa)", l->kappa);
    double w = plume_layout_barb_width(l);
    if (l->order != 1 && l->order != 2)
        return plume_err_set(err, PLUME_EINVAL, "order must be 1 (linear) or 2 (quadratic triangles) (got %d)",
                             l->order);
    if (!(l->e_rel >= 0.0) || !isfinite(l->e_rel))
        return plume_err_set(err, PLUME_EINVAL, "e_rel must be finite and >= 0, 0 for automatic (got %g)", l->e_rel);
    if (l->e_rel > 0.0 && !(l->e_rel * w <= l->d_B))
        return plume_err_set(err, PLUME_EINVAL,
                             "e_rel = %g gives elements of %g m, larger than the cell d_B = %g m "
                             "(e_rel must be <= 1/phi = %g)",
                             l->e_rel, l->e_rel * w, l->d_B, 1.0 / l->phi);
    /* Elements may be longer than a strip is wide (the paper's e-bar = 2.9: the strip is still
     * resolved by its constrained boundaries, as thin elements), but a strip narrower than a
     * quarter of an element is a sliver the mesh cannot follow: refused. */
    if (l->e_rel > PLUME_LAYOUT_MAX_E_REL)
        return plume_err_set(err, PLUME_EINVAL,
                             "strips narrower than an element: the barb strip (%g m) is less than a quarter of the "
                             "element edge e_rel * w_B = %g m (e_rel = %g must be <= %g)",
                             w, l->e_rel * w, l->e_rel, PLUME_LAYOUT_MAX_E_REL);
    const plume_hook_law *hk = &l->hooks;
    if (!(hk->strength >= 0.0) || !isfinite(hk->strength))
        return plume_err_set(err, PLUME_EINVAL, "hook_strength must be finite and >= 0, 0 for bonded barbules (got %g N)",
                             hk->strength);
    if (l->kind == PLUME_LAYOUT_STRIPS) {
        if (hk->strength > 0.0)
            return plume_err_set(err, PLUME_EINVAL, "hook_strength = %g N needs the layout \"barbules\": a strips "
                                 "layout has no barbule ends to hook", hk->strength);
        return PLUME_OK; /* the barbule fields are not used */
    }
    if (l->e_rel > 0.0 && l->barbule_width * PLUME_LAYOUT_MAX_E_REL < l->e_rel * w)
        return plume_err_set(err, PLUME_EINVAL,
                             "strips narrower than an element: barbule_width = %g m is less than a quarter of the "
                             "element edge %g m (lower e_rel)",
                             l->barbule_width, l->e_rel * w);
    if (!(l->barbule_width > 0.0) || !isfinite(l->barbule_width))
        return plume_err_set(err, PLUME_EINVAL, "barbule_width must be finite and > 0 (got %g m)",
                             l->barbule_width);
    if (!(l->barbule_spacing > l->barbule_width) || !isfinite(l->barbule_spacing))
        return plume_err_set(err, PLUME_EINVAL,
                             "barbule_spacing must be finite and > barbule_width = %g m (got %g m)",
                             l->barbule_width, l->barbule_spacing);
    if (!(l->barbule_angle > 0.0 && l->barbule_angle < 180.0))
        return plume_err_set(err, PLUME_EINVAL, "barbule_angle must be in (0, 180) degrees (got %g)",
                             l->barbule_angle);
    double th = l->barbule_angle * M_PI / 180.0, gap = l->d_B - w;
    double extent = gap * fabs(cos(th) / sin(th)) + l->barbule_width / sin(th);
    if (!(extent < l->barbule_spacing))
        return plume_err_set(err, PLUME_EINVAL,
                             "cell too small for its layout: a barbule %g m wide at %g deg across the %g m gap "
                             "spans %g m along the barbs, not less than barbule_spacing = %g m",
                             l->barbule_width, l->barbule_angle, gap, extent, l->barbule_spacing);
    if (hk->strength == 0.0)
        return PLUME_OK;
    if (!(hk->opening > 0.0) || !isfinite(hk->opening))
        return plume_err_set(err, PLUME_EINVAL, "hook_opening must be finite and > 0 (got %g m)", hk->opening);
    if (!(hk->slide >= 0.0) || !isfinite(hk->slide))
        return plume_err_set(err, PLUME_EINVAL, "hook_slide must be finite and >= 0 (got %g m)", hk->slide);
    if (!(hk->capture >= 0.0) || !isfinite(hk->capture))
        return plume_err_set(err, PLUME_EINVAL, "hook_capture must be finite and >= 0 (got %g m)", hk->capture);
    /* a capture beyond the spacing would catch a hooklet on the next barbule's place */
    if (!(hk->capture < l->barbule_spacing))
        return plume_err_set(err, PLUME_EINVAL, "hook_capture = %g m must be less than barbule_spacing = %g m",
                             hk->capture, l->barbule_spacing);
    return PLUME_OK;
}

double plume_layout_thickness(const plume_layout *l, int phase)
{
    double t = phase == PLUME_MAT_BARB ? l->h_barb : l->h_barbule;
    return t > 0.0 ? t : l->h;
}

void plume_layout_materials(const plume_layout *l, plume_membrane_material mats[2])
{
    double E[2] = {l->E_b, l->ratio * l->E_b}, nu[2] = {l->nu_b, l->nu_B};
    for (int k = 0; k < 2; k++) { /* isotropic: E_xx = E_yy, G = E / (2 (1 + nu)) (docs/design.md) */
        mats[k].moduli.E_xx = E[k];
        mats[k].moduli.E_yy = E[k];
        mats[k].moduli.nu_xy = nu[k];
        mats[k].moduli.G_xy = E[k] / (2.0 * (1.0 + nu[k]));
        mats[k].h = plume_layout_thickness(l, k);
        mats[k].kappa = l->kappa;
    }
}
