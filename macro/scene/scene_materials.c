/* The materials of a scene (macro/scene/scene.h): membrane (orthotropic or isotropic), bending, density
 * and barb constraint of each material id. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/membrane.h"
#include "../../lib/io/curves.h"
#include "../../lib/io/frames.h"
#include "internal/scene_internal.h"

/* "bending": {"from_moduli": "file.h5", "drop_couplings": false}: the bending moduli apps/homogenize
 * wrote as attributes of /moduli (micro/cell_plate.h's convention, the same as bending.h's). The
 * shell has no bending-twist coupling: D_16 and D_26 above 1 % of sqrt(D_ii D_twist) are refused
 * unless "drop_couplings" is true (a cell with tilted barbules has some). */
static plume_status bending_from_moduli(const plume_json_ctx *c, json_t *jb, const char *kp, plume_bending_material *b,
                                        char *path, size_t npath)
{
    static const char *const keys[] = {"from_moduli", "drop_couplings", NULL};
    static const char *const names[6] = {"D_long", "D_trans", "D_coupling", "D_twist", "D_16", "D_26"};
    char kf[PLUME_JSON_KEY_MAX];
    plume_json_subkey(kf, kp, "from_moduli");
    plume_status st = plume_json_check_keys(c, jb, kp, keys);
    if (st != PLUME_OK)
        return st;
    json_t *jf = json_object_get(jb, "from_moduli"), *jd = json_object_get(jb, "drop_couplings");
    if (!json_is_string(jf))
        return plume_json_bad(c, PLUME_EFORMAT, kf, "must be the name of an HDF5 file of moduli, as apps/homogenize writes");
    if (jd && !json_is_boolean(jd)) {
        char kd[PLUME_JSON_KEY_MAX];
        plume_json_subkey(kd, kp, "drop_couplings");
        return plume_json_bad(c, PLUME_EFORMAT, kd, "must be true or false");
    }
    plume_json_resolve(c, json_string_value(jf), path, npath);
    double v[6];
    for (int k = 0; k < 6; k++) {
        plume_err e2 = {{0}};
        if ((st = plume_moduli_read_param(path, names[k], &v[k], &e2)) != PLUME_OK)
            return plume_json_bad(c, st, kf, "(%s): %s (a moduli file of apps/homogenize, which writes the bending moduli)",
                                  json_string_value(jf), e2.msg);
        if (!isfinite(v[k]) || (k < 4 && k != 2 && !(v[k] > 0.0)))
            return plume_json_bad(c, PLUME_EINVAL, kf, "(%s): %s must be finite%s (got %g)", json_string_value(jf),
                                  names[k], k < 4 && k != 2 ? " and > 0" : "", v[k]);
    }
    if (!(v[2] * v[2] <= v[0] * v[1]))
        return plume_json_bad(c, PLUME_EINVAL, kf, "(%s): D_coupling = %g makes the plate indefinite (need "
                              "D_coupling^2 <= D_long D_trans = %g)", json_string_value(jf), v[2], v[0] * v[1]);
    double r16 = fabs(v[4]) / sqrt(v[0] * v[3]), r26 = fabs(v[5]) / sqrt(v[1] * v[3]);
    if (!(jd && json_is_true(jd)) && (r16 > 0.01 || r26 > 0.01))
        return plume_json_bad(c, PLUME_EINVAL, kf,
                              "(%s): the cell couples bending and twist (D_16 %g, D_26 %g N m: %.3g and %.3g of "
                              "sqrt(D_ii D_twist)), which the shell cannot represent; add \"drop_couplings\": true "
                              "to use it without them", json_string_value(jf), v[4], v[5], r16, r26);
    b->D_long = v[0], b->D_trans = v[1], b->D_coupling = v[2], b->D_twist = v[3];
    return PLUME_OK;
}

/* "membrane": {"from_moduli": "file.h5", "thickness": t, "kappa": k}: E_xx, E_yy, nu_xy, G_xy from
 * the file's /moduli (apps/homogenize -o, apps/fit), resolved against the scene's directory into
 * `path`. A modulus key beside "from_moduli" is refused: one number, one place. The file's moduli
 * in Pa are a membrane stiffness (N/m) over the cell's reference thickness (its "thickness"
 * attribute), and the shell's membrane energy is h times the moduli's: the scene's thickness must
 * therefore be the cell's. Left out it is taken from the file; given, it must equal it (relative
 * PLUME_SCENE_THICKNESS_RTOL), else the stiffness would silently scale by h / thickness. A file
 * without a thickness (apps/fit's) needs the scene's. */
#define PLUME_SCENE_THICKNESS_RTOL 1e-9
/* Without "tensor" a cell whose stretch-shear coupling max(|C13| / sqrt(C11 C33), |C23| /
 * sqrt(C22 C33)) passes this takes its full tensor: the four moduli would drop the coupling
 * (0.96 for layout_barbules_table3a.json, an 8 times too soft vane at 45 deg; 2e-5 for
 * layout_kovalev.json and 1e-11 for the strips, which keep the moduli). docs/monoclinic-vane.md */
#define PLUME_SCENE_COUPLING_MIN 1e-3

static double tensor_coupling(const double C[9])
{
    const double a = C[0] * C[8] > 0.0 ? fabs(C[2]) / sqrt(C[0] * C[8]) : 0.0;
    const double b = C[4] * C[8] > 0.0 ? fabs(C[5]) / sqrt(C[4] * C[8]) : 0.0;
    return fmax(a, b);
}
static plume_status membrane_from_moduli(const plume_json_ctx *c, json_t *mem, const char *kp, plume_membrane_material *mm,
                                         char *path, size_t npath, int *tensor, double C[9])
{
    static const char *const keys[] = {"from_moduli", "thickness", "kappa", "tensor", NULL};
    static const char *const moduli[] = {"E_xx", "E_yy", "nu_xy", "G_xy", "E", "nu", NULL};
    char kf[PLUME_JSON_KEY_MAX], kk[PLUME_JSON_KEY_MAX];
    plume_json_subkey(kf, kp, "from_moduli");
    json_t *jf = json_object_get(mem, "from_moduli");
    if (!json_is_string(jf))
        return plume_json_bad(c, PLUME_EFORMAT, kf, "must be the name of an HDF5 file with /moduli, as apps/homogenize writes");
    for (int k = 0; moduli[k]; k++)
        if (json_object_get(mem, moduli[k])) {
            plume_json_subkey(kk, kp, moduli[k]);
            return plume_json_bad(c, PLUME_EINVAL, kk, "is given twice: here and by \"from_moduli\": \"%s\" (its /moduli); "
                                  "remove one", json_string_value(jf));
        }
    plume_status st = plume_json_check_keys(c, mem, kp, keys);
    if (st != PLUME_OK)
        return st;
    plume_json_resolve(c, json_string_value(jf), path, npath);
    plume_ortho m;
    plume_err e2 = {{0}};
    if ((st = plume_moduli_read(path, &m, &e2)) != PLUME_OK)
        return plume_json_bad(c, st, kf, "(%s): %s", json_string_value(jf), e2.msg);
    mm->moduli = m;
    /* "tensor": "moduli" (the four moduli, orthotropic: the paper's vane), "full" (the cell's
     * plane-stress tensor, its stretch-shear coupling kept) or "hooked" (the hooked cell's, for a
     * vane whose lines hold by stiff links); docs/monoclinic-vane.md */
    json_t *jt = json_object_get(mem, "tensor");
    *tensor = 0;
    if (!jt && plume_moduli_read_tensor(path, "", C, &e2) == PLUME_OK && tensor_coupling(C) > PLUME_SCENE_COUPLING_MIN &&
        plume_membrane_tensor_check(C, &e2) == PLUME_OK)
        *tensor = 1; /* a coupled cell: the moduli would drop its coupling (the default, "full") */
    if (jt) {
        const char *v = json_is_string(jt) ? json_string_value(jt) : "";
        char kt[PLUME_JSON_KEY_MAX];
        plume_json_subkey(kt, kp, "tensor");
        if (strcmp(v, "moduli") == 0)
            *tensor = 0;
        else if (strcmp(v, "full") == 0)
            *tensor = 1;
        else if (strcmp(v, "hooked") == 0)
            *tensor = 2;
        else
            return plume_json_bad(c, PLUME_EINVAL, kt, "must be \"moduli\" (the four orthotropic moduli), \"full\" (the "
                                  "cell's tensor) or \"hooked\" (the hooked cell's)");
        if (*tensor) {
            e2.msg[0] = '\0';
            if ((st = plume_moduli_read_tensor(path, *tensor == 2 ? "separation_" : "", C, &e2)) != PLUME_OK)
                return plume_json_bad(c, st, kt, "(%s): %s%s", json_string_value(jf), e2.msg,
                                      *tensor == 2 ? " (apps/homogenize writes it for a layout with hooks)"
                                                   : " (apps/homogenize writes it)");
            if ((st = plume_membrane_tensor_check(C, &e2)) != PLUME_OK)
                return plume_json_bad(c, st, kt, "(%s): %s", json_string_value(jf), e2.msg);
        }
    }
    double h_file = NAN;
    e2.msg[0] = '\0';
    int has_h = plume_moduli_read_param(path, "thickness", &h_file, &e2) == PLUME_OK;
    if (has_h && !(h_file > 0.0 && isfinite(h_file)))
        return plume_json_bad(c, PLUME_EINVAL, kf, "(%s): /moduli attribute thickness must be finite and > 0 (got %g m)",
                              json_string_value(jf), h_file);
    int present = 0;
    if ((st = plume_json_positive(c, mem, kp, "thickness", !has_h, 0, &mm->h, &present)) != PLUME_OK)
        return st;
    if (has_h && !present)
        mm->h = h_file;
    else if (has_h && !(fabs(mm->h - h_file) <= PLUME_SCENE_THICKNESS_RTOL * h_file)) {
        plume_json_subkey(kk, kp, "thickness");
        return plume_json_bad(c, PLUME_EINVAL, kk, "= %g m is not the thickness %g m the moduli of \"from_moduli\": \"%s\" "
                              "are over (/moduli attribute thickness): the membrane stiffness would be %g times the "
                              "cell's; leave thickness out to take the file's", mm->h, h_file, json_string_value(jf),
                              mm->h / h_file);
    }
    return PLUME_OK;
}

/* One material entry. */
static plume_status parse_material(const plume_json_ctx *c, json_t *jm, const char *where, int need_density,
                                   plume_scene_material *out)
{
    static const char *const keys[] = {"name", "membrane", "bending", "density", "constraint", NULL};
    static const char *const ortho[] = {"E_xx", "E_yy", "nu_xy", "G_xy", "thickness", "kappa", NULL};
    static const char *const iso[] = {"E", "nu", "thickness", "kappa", NULL};
    static const char *const bend2[] = {"D_long", "D_trans", "D_twist", "D_coupling", NULL};
    static const char *const bend1[] = {"D", NULL};
    char kp[PLUME_JSON_KEY_MAX];
    plume_status st;
    if (!json_is_object(jm))
        return plume_json_bad(c, PLUME_EFORMAT, where, "must be an object with membrane, bending, density, constraint");
    if ((st = plume_json_check_keys(c, jm, where, keys)) != PLUME_OK)
        return st;
    memset(out, 0, sizeof *out);
    json_t *jn = json_object_get(jm, "name");
    if (jn) {
        plume_json_subkey(kp, where, "name");
        if (!json_is_string(jn) || !json_string_length(jn) || json_string_length(jn) >= sizeof out->name)
            return plume_json_bad(c, PLUME_EFORMAT, kp, "must be a non-empty string of at most %d bytes",
                                  (int)sizeof out->name - 1);
        snprintf(out->name, sizeof out->name, "%s", json_string_value(jn));
    }
    plume_membrane_material *mm = &out->membrane;
    plume_json_subkey(kp, where, "membrane");
    json_t *mem = json_object_get(jm, "membrane");
    if (!json_is_object(mem))
        return plume_json_bad(c, PLUME_EFORMAT, kp,
                   mem ? "must be an object {E_xx, E_yy, nu_xy, G_xy, thickness, kappa}, {E, nu, thickness, kappa} "
                         "or {from_moduli, thickness, kappa, tensor}"
                       : "is missing (an object {E_xx, E_yy, nu_xy, G_xy, thickness, kappa}, {E, nu, thickness, kappa} "
                         "or {from_moduli, thickness, kappa, tensor})");
    if (json_object_get(mem, "from_moduli")) {
        if ((st = membrane_from_moduli(c, mem, kp, mm, out->membrane_from, sizeof out->membrane_from, &out->tensor,
                                        out->C)) != PLUME_OK)
            return st;
    } else if (json_object_get(mem, "E")) {
        double E = 0.0, nu = 0.0;
        if ((st = plume_json_check_keys(c, mem, kp, iso)) != PLUME_OK || (st = plume_json_positive(c, mem, kp, "E", 1, 0, &E, NULL)) ||
            (st = plume_json_number(c, mem, kp, "nu", 0, &nu, NULL)))
            return st;
        if (!(nu > -1.0 && nu < 0.5)) {
            char kn[PLUME_JSON_KEY_MAX];
            plume_json_subkey(kn, kp, "nu");
            return plume_json_bad(c, PLUME_EINVAL, kn, "must be in (-1, 0.5) (got %g)", nu);
        }
        mm->moduli.E_xx = mm->moduli.E_yy = E;
        mm->moduli.nu_xy = nu;
        mm->moduli.G_xy = E / (2.0 * (1.0 + nu));
    } else {
        if ((st = plume_json_check_keys(c, mem, kp, ortho)) != PLUME_OK ||
            (st = plume_json_positive(c, mem, kp, "E_xx", 1, 0, &mm->moduli.E_xx, NULL)) ||
            (st = plume_json_positive(c, mem, kp, "E_yy", 1, 0, &mm->moduli.E_yy, NULL)) ||
            (st = plume_json_number(c, mem, kp, "nu_xy", 0, &mm->moduli.nu_xy, NULL)) ||
            (st = plume_json_positive(c, mem, kp, "G_xy", 1, 0, &mm->moduli.G_xy, NULL)))
            return st;
    }
    if ((!out->membrane_from[0] && (st = plume_json_positive(c, mem, kp, "thickness", 1, 0, &mm->h, NULL))) ||
        (st = plume_json_positive(c, mem, kp, "kappa", 0, 1, &mm->kappa, NULL)))
        return st;
    plume_err e2 = {{0}};
    if ((st = plume_membrane_material_check(mm, &e2)) != PLUME_OK)
        return plume_json_bad(c, st, kp, "is not a valid material: %s", e2.msg);

    /* bending: explicit, or that of a plate of the membrane's moduli and thickness */
    plume_json_subkey(kp, where, "bending");
    json_t *jb = json_object_get(jm, "bending");
    if (!jb || (json_is_string(jb) && strcmp(json_string_value(jb), "from_membrane") == 0)) {
        double nu_yx = mm->moduli.nu_xy * mm->moduli.E_yy / mm->moduli.E_xx, h3 = mm->h * mm->h * mm->h;
        double den = 12.0 * (1.0 - mm->moduli.nu_xy * nu_yx);
        out->bending.D_long = mm->moduli.E_xx * h3 / den;
        out->bending.D_trans = mm->moduli.E_yy * h3 / den;
        out->bending.D_coupling = mm->moduli.nu_xy * out->bending.D_trans; /* D_12 = nu_xy D_22 */
        out->bending.D_twist = mm->moduli.G_xy * h3 / 12.0;                /* D_66 = G t^3 / 12 */
    } else if (json_is_object(jb) && json_object_get(jb, "from_moduli")) {
        if ((st = bending_from_moduli(c, jb, kp, &out->bending, out->bending_from, sizeof out->bending_from)) != PLUME_OK)
            return st;
    } else if (json_is_object(jb) && json_object_get(jb, "D")) {
        double D = 0.0;
        if ((st = plume_json_check_keys(c, jb, kp, bend1)) != PLUME_OK || (st = plume_json_positive(c, jb, kp, "D", 1, 1, &D, NULL)))
            return st;
        out->bending.D_long = out->bending.D_trans = D;
    } else if (json_is_object(jb)) {
        if ((st = plume_json_check_keys(c, jb, kp, bend2)) != PLUME_OK ||
            (st = plume_json_positive(c, jb, kp, "D_long", 1, 1, &out->bending.D_long, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_trans", 1, 1, &out->bending.D_trans, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_twist", 0, 1, &out->bending.D_twist, NULL)) ||
            (st = plume_json_positive(c, jb, kp, "D_coupling", 0, 1, &out->bending.D_coupling, NULL)))
            return st;
    } else {
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be {\"D_long\", \"D_trans\"}, {\"D\"}, {\"from_moduli\": \"file.h5\"} "
                              "or \"from_membrane\"");
    }
    if ((st = plume_json_positive(c, jm, where, "density", need_density, 0, &out->density, NULL)) != PLUME_OK)
        return st;
    json_t *jc = json_object_get(jm, "constraint");
    plume_json_subkey(kp, where, "constraint");
    if (jc && !json_is_boolean(jc))
        return plume_json_bad(c, PLUME_EFORMAT, kp, "must be true or false");
    out->constraint = jc ? json_is_true(jc) : 0;
    return PLUME_OK;
}

plume_status plume_scene_parse_materials(const plume_json_ctx *c, json_t *doc, plume_scene *s)
{
    plume_status st;
    json_t *jm = json_object_get(doc, "materials");
    if (!json_is_array(jm) || json_array_size(jm) < 1)
        return plume_json_bad(c, PLUME_EFORMAT, "materials", jm ? "must be a non-empty array of materials (indexed by material id)"
                                                     : "is missing (an array of materials indexed by material id)");
    s->nmat = (int)json_array_size(jm);
    s->mats = calloc((size_t)s->nmat, sizeof *s->mats);
    if (!s->mats)
        return plume_err_set(c->err, PLUME_ENOMEM, "%s: out of memory", c->file);
    for (int k = 0; k < s->nmat; k++) {
        char kp[PLUME_JSON_KEY_MAX];
        plume_json_subindex(kp, "materials", (size_t)k);
        if ((st = parse_material(c, json_array_get(jm, (size_t)k), kp, !s->is_static, s->mats + k)) != PLUME_OK)
            return st;
    }

    return PLUME_OK;
}

plume_status plume_scene_materials_record(const plume_scene *s, const char *frames_path, plume_err *err)
{
    if (!s || !s->mats || !frames_path)
        return plume_err_set(err, PLUME_EINVAL, "scene materials record: invalid arguments");
    for (int k = 0; k < s->nmat; k++) {
        const plume_scene_material *m = s->mats + k;
        const plume_param p[] = {{"E_xx", m->membrane.moduli.E_xx},         {"E_yy", m->membrane.moduli.E_yy},
                                 {"nu_xy", m->membrane.moduli.nu_xy},       {"G_xy", m->membrane.moduli.G_xy},
                                 {"thickness", m->membrane.h},       {"kappa", m->membrane.kappa},
                                 {"D_long", m->bending.D_long},      {"D_trans", m->bending.D_trans},
                                 {"D_coupling", m->bending.D_coupling}, {"D_twist", m->bending.D_twist},
                                 {"density", m->density},            {"constraint", (double)m->constraint},
                                 /* with a tensor law: the tensor the membrane used */
                                 {"C11", m->C[0]}, {"C12", m->C[1]}, {"C13", m->C[2]},
                                 {"C22", m->C[4]}, {"C23", m->C[5]}, {"C33", m->C[8]}};
        const int np = (int)(sizeof p / sizeof p[0]) - (m->tensor ? 0 : 6);
        plume_sparam sp[3];
        int ns = 0;
        if (m->membrane_from[0])
            sp[ns++] = (plume_sparam){"membrane_from_moduli", m->membrane_from};
        if (m->bending_from[0])
            sp[ns++] = (plume_sparam){"bending_from_moduli", m->bending_from};
        if (m->tensor)
            sp[ns++] = (plume_sparam){"membrane_tensor", m->tensor == 2 ? "hooked" : "full"};
        plume_status st = plume_frames_material_write(frames_path, k, p, np, sp, ns,
                                                      m->tensor ? "E_xx, E_yy, G_xy, kappa, C11, C12, C13, C22, C23, C33: "
                                                                  "Pa; nu_xy: 1; thickness: m; D_long, D_trans, "
                                                                  "D_coupling, D_twist: N m; density: kg/m^2; "
                                                                  "constraint: 1"
                                                                : "E_xx, E_yy, G_xy, kappa: Pa; nu_xy: 1; thickness: m; "
                                                                  "D_long, D_trans, D_coupling, D_twist: N m; density: "
                                                                  "kg/m^2; constraint: 1",
                                                      err);
        if (st != PLUME_OK)
            return st;
    }
    return PLUME_OK;
}
