/* plume: what a loaded scene holds, as a JSON text (include/plume/scene.h's plume_scene_describe) and its mesh,
 * and its probes' displacements: what a caller reports about a scene without its struct. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "scene.h"

/* Each material's moduli and, when read from a file, the file. */
static json_t *materials_json(const plume_scene *s)
{
    json_t *ja = json_array();
    for (int k = 0; k < s->nmat; k++) {
        const plume_scene_material *m = s->mats + k;
        json_t *jm = json_object(), *jb = json_object();
        json_t *jmem = json_pack("{s:f, s:f, s:f, s:f, s:f, s:f}", "E_xx", m->membrane.moduli.E_xx, "E_yy", m->membrane.moduli.E_yy,
                                 "nu_xy", m->membrane.moduli.nu_xy, "G_xy", m->membrane.moduli.G_xy, "thickness", m->membrane.h,
                                 "kappa", m->membrane.kappa);
        json_object_set_new(jb, "D_long", json_real(m->bending.D_long));
        json_object_set_new(jb, "D_trans", json_real(m->bending.D_trans));
        json_object_set_new(jb, "D_coupling", json_real(m->bending.D_coupling));
        json_object_set_new(jb, "D_twist", json_real(m->bending.D_twist));
        if (m->membrane_from[0])
            json_object_set_new(jmem, "from_moduli", json_string(m->membrane_from));
        if (m->tensor) {
            json_t *jc = json_array();
            for (int k = 0; k < 9; k++)
                json_array_append_new(jc, json_real(m->C[k]));
            json_object_set_new(jmem, "tensor", json_string(m->tensor == 2 ? "hooked" : "full"));
            json_object_set_new(jmem, "C", jc);
        }
        if (m->bending_from[0])
            json_object_set_new(jb, "from_moduli", json_string(m->bending_from));
        json_object_set_new(jm, "membrane", jmem);
        json_object_set_new(jm, "bending", jb);
        json_object_set_new(jm, "density", json_real(m->density));
        json_object_set_new(jm, "constraint", json_boolean(m->constraint));
        json_array_append_new(ja, jm);
    }
    return ja;
}

/* Each probe: its name, vertices, reference (null where a component has none) and its source. */
static json_t *probes_json(const plume_scene *s)
{
    json_t *ja = json_array();
    for (int q = 0; q < s->nprobes; q++) {
        const plume_scene_probe *pr = s->probes + q;
        json_t *j = json_object(), *jr = json_array();
        json_object_set_new(j, "name", json_string(pr->name));
        json_object_set_new(j, "vertices", json_integer(pr->n));
        for (int a = 0; a < 3; a++)
            json_array_append_new(jr, pr->has_reference & (1 << a) ? json_real(pr->reference[a]) : json_null());
        json_object_set_new(j, "reference", pr->has_reference ? jr : json_null());
        if (!pr->has_reference)
            json_decref(jr);
        if (pr->source)
            json_object_set_new(j, "source", json_string(pr->source));
        json_array_append_new(ja, j);
    }
    return ja;
}

plume_status plume_scene_describe(const plume_scene *s, char **json, plume_err *err)
{
    if (!json)
        return plume_err_set(err, PLUME_EINVAL, "plume_scene_describe: json is NULL");
    *json = NULL;
    if (!s)
        return plume_err_set(err, PLUME_EINVAL, "plume_scene_describe: the scene is NULL");
    json_t *j = json_object();
    json_object_set_new(j, "file", json_string(s->path ? s->path : ""));
    json_object_set_new(j, "solve", json_string(s->is_static ? "static" : "dynamic"));
    json_object_set_new(j, "elements", json_integer(s->mesh->nt));
    json_object_set_new(j, "vertices", json_integer(s->mesh->nv));
    json_object_set_new(j, "constrained_edges", json_integer(s->nbarb));
    json_object_set_new(j, "objects", json_integer(s->nobjects));
    json_object_set_new(j, "bending_model", json_string(plume_scene_bending_name(s->bending_model)));
    json_object_set_new(j, "solver", json_string(plume_solver_kind_name(s->solver)));
    json_object_set_new(j, "predictor", json_string(plume_predictor_name(s->predictor)));
    json_object_set_new(j, "globalization", json_string(plume_globalization_name(s->globalization)));
    json_object_set_new(j, "max_halvings", json_integer(s->max_halvings));
    json_object_set_new(j, "max_iter", json_integer(s->max_iter));
    json_object_set_new(j, "verbose", json_boolean(s->verbose));
    if (s->is_static) {
        json_object_set_new(j, "steps", json_integer(s->steps));
        json_object_set_new(j, "probes", probes_json(s));
    } else {
        json_object_set_new(j, "dt", json_real(s->dt));
        json_object_set_new(j, "duration", json_real(s->duration));
        json_object_set_new(j, "adaptive_dt", json_boolean(s->adaptive_dt));
        json_object_set_new(j, "output_every", json_integer(s->output_every));
        json_object_set_new(j, "render_field", json_string(s->render_field));
        json_object_set_new(j, "gltf", !s->gltf ? json_null()
                                                : json_pack("{s:s, s:s, s:s?}", "file", s->gltf_file, "animation",
                                                            s->gltf_animation == PLUME_GLTF_FRAMES ? "frames" : "morph",
                                                            "field", s->gltf_field[0] ? s->gltf_field : NULL));
    }
    if (s->has_contact)
        json_object_set_new(j, "contact", json_pack("{s:s, s:f, s:f}", "model",
                                                    plume_contact_model_name(s->contact.pair.model), "dhat",
                                                    s->contact.pair.dhat, "friction_mu", s->friction_mu));
    json_object_set_new(j, "materials", materials_json(s));
    *json = json_dumps(j, JSON_INDENT(2) | JSON_REAL_PRECISION(17));
    json_decref(j);
    return *json ? PLUME_OK : plume_err_set(err, PLUME_ENOMEM, "plume_scene_describe: out of memory");
}

const plume_mesh *plume_scene_mesh(const plume_scene *s)
{
    return s ? s->mesh : NULL;
}
