/* The "contact" block of a scene and the bodies it acts between (macro/scene/scene.h). */
#include <stdlib.h>
#include <string.h>

#include "internal/scene_internal.h"

plume_status plume_scene_parse_contact(const plume_json_ctx *c, json_t *v, plume_scene *s)
{
    static const char *const keys[] = {"model", "dhat", "stiffness", "self", "margin", "friction", "eps_v", NULL};
    if (!json_is_object(v))
        return plume_json_bad(c, PLUME_EFORMAT, "contact",
                              "must be an object {\"model\": \"barrier\"|\"penalty\", \"dhat\": m, \"stiffness\": ...}");
    if (s->is_static)
        return plume_json_bad(c, PLUME_EINVAL, "contact", "is for dynamic scenes only (this one is \"solve\": \"static\")");
    plume_status st = plume_json_check_keys(c, v, "contact", keys);
    if (st != PLUME_OK)
        return st;
    plume_contact_term_opts *o = &s->contact;
    plume_contact_term_opts_default(o);
    o->pair.dhat = 1e-3;
    json_t *m = json_object_get(v, "model");
    if (m) {
        const char *mv = json_is_string(m) ? json_string_value(m) : "";
        if (strcmp(mv, "barrier") != 0 && strcmp(mv, "penalty") != 0)
            return plume_json_bad(c, PLUME_EINVAL, "contact.model", "must be \"barrier\" or \"penalty\"");
        o->pair.model = mv[0] == 'b' ? PLUME_CONTACT_BARRIER : PLUME_CONTACT_PENALTY;
    }
    if ((st = plume_json_positive(c, v, "contact", "dhat", 0, 0, &o->pair.dhat, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, v, "contact", "stiffness", 1, 0, &o->pair.stiffness, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, v, "contact", "margin", 0, 1, &o->margin, NULL)) != PLUME_OK)
        return st;
    json_t *self = json_object_get(v, "self");
    if (self && !json_is_boolean(self))
        return plume_json_bad(c, PLUME_EFORMAT, "contact.self", "must be true or false");
    o->self_contact = self && json_is_true(self);
    s->friction_mu = 0.0;
    s->friction_eps_v = 1e-3;
    if ((st = plume_json_positive(c, v, "contact", "friction", 0, 1, &s->friction_mu, NULL)) != PLUME_OK ||
        (st = plume_json_positive(c, v, "contact", "eps_v", 0, 0, &s->friction_eps_v, NULL)) != PLUME_OK)
        return st;
    s->has_contact = 1;
    return PLUME_OK;
}

static plume_index find_root(plume_index *parent, plume_index i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

int plume_scene_bodies(const plume_scene *s, int *body)
{
    const plume_mesh *m = s->mesh;
    plume_index *parent = malloc((size_t)(m->nv + 1) * sizeof *parent);
    if (!parent)
        return -1;
    for (plume_index v = 0; v < m->nv; v++)
        parent[v] = v;
    for (plume_index t = 0; t < m->nt; t++)
        for (int k = 1; k < 3; k++)
            parent[find_root(parent, m->tri[3 * t + k])] = find_root(parent, m->tri[3 * t]);
    for (plume_index k = 0; s->splits && k < s->splits->npairs; k++) /* a split line's lips: one body */
        parent[find_root(parent, s->splits->pairs[2 * k])] = find_root(parent, s->splits->pairs[2 * k + 1]);
    int n = 0;
    for (plume_index v = 0; v < m->nv; v++)
        body[v] = -1;
    for (plume_index v = 0; v < m->nv; v++) {
        plume_index r = find_root(parent, v);
        if (body[r] < 0)
            body[r] = n++;
        body[v] = body[r];
    }
    free(parent);
    return n;
}

int *plume_scene_body_labels(const plume_scene *s, plume_err *err)
{
    int *body = malloc((size_t)(s->mesh->nv + 1) * sizeof *body);
    if (!body || plume_scene_bodies(s, body) < 0) {
        free(body);
        plume_err_set(err, PLUME_ENOMEM, "scene: out of memory");
        return NULL;
    }
    return body;
}

plume_status plume_scene_contact_broad(const plume_scene *s, plume_contact_broad **out, plume_err *err)
{
    const plume_mesh *m = s->mesh;
    int *body = plume_scene_body_labels(s, err);
    if (!body)
        return PLUME_ENOMEM;
    plume_contact_broad_opts bo;
    plume_contact_broad_opts_default(&bo);
    bo.self_contact = s->contact.self_contact;
    bo.weld = s->split_weld;
    plume_status st = plume_contact_broad_create(m->nv, m->nt, m->tri, body, &bo, out, err);
    free(body);
    return st;
}
