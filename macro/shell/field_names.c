/* plume: the names of the per-triangle fields a render is coloured by, their labels, and the
 * values of one by name (fields.h). */
#include "fields.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

/* The per-triangle fields a render can be coloured by: name, label with unit, where the values are
 * (array and stride within plume_field_values) */
typedef struct {
    const char *name, *label;
    size_t offset; /* of the array pointer in plume_field_values */
    int stride, component;
} field_entry;

static const field_entry field_table[] = {
    {"mean_curvature", "mean curvature (1/m)", offsetof(plume_field_values, mean_curvature), 1, 0},
    {"J", "J, deformed over reference area", offsetof(plume_field_values, J), 1, 0},
    {"membrane_energy", "membrane energy (J/m^2)", offsetof(plume_field_values, membrane_energy), 1, 0},
    {"bending_energy", "bending energy (J/m^2)", offsetof(plume_field_values, bending_energy), 1, 0},
    {"strain_bb", "Green strain along the barbs", offsetof(plume_field_values, green_strain), 3, 0},
    {"strain_tt", "Green strain across the barbs", offsetof(plume_field_values, green_strain), 3, 1},
    {"strain_bt", "Green shear strain (barb frame)", offsetof(plume_field_values, green_strain), 3, 2},
    {"stress_bb", "stress along the barbs (Pa)", offsetof(plume_field_values, stress), 3, 0},
    {"stress_tt", "stress across the barbs (Pa)", offsetof(plume_field_values, stress), 3, 1},
    {"stress_bt", "shear stress, barb frame (Pa)", offsetof(plume_field_values, stress), 3, 2},
    {"crease_angle", "crease angle (rad)", offsetof(plume_field_values, crease_angle), 1, 0},
    {"curvature_bb", "curvature along the barbs (1/m)", offsetof(plume_field_values, curvature), 3, 0},
    {"curvature_tt", "curvature across the barbs (1/m)", offsetof(plume_field_values, curvature), 3, 1},
    {"curvature_bt", "twist, barb frame (1/m)", offsetof(plume_field_values, curvature), 3, 2},
};

static const field_entry *field_find(const char *name)
{
    for (size_t k = 0; name && k < sizeof field_table / sizeof field_table[0]; k++)
        if (strcmp(field_table[k].name, name) == 0)
            return &field_table[k];
    return NULL;
}

const char *plume_field_names(void)
{
    return "mean_curvature, J, membrane_energy, bending_energy, strain_bb, strain_tt, strain_bt, stress_bb, "
           "stress_tt, stress_bt, crease_angle, curvature_bb, curvature_tt, curvature_bt";
}

int plume_render_field_valid(const char *name)
{
    return name && (strcmp(name, "material") == 0 || strcmp(name, "object") == 0 || field_find(name));
}

const char *plume_field_label(const char *name)
{
    const field_entry *e = field_find(name);
    return e ? e->label : NULL;
}

plume_status plume_field_values_select(const plume_field_values *v, const char *name, double *out, plume_err *err)
{
    const field_entry *e = field_find(name);
    if (!v || !out)
        return plume_err_set(err, PLUME_EINVAL, "fields: invalid arguments");
    if (!e)
        return plume_err_set(err, PLUME_EINVAL, "fields: unknown field '%s' (expected one of %s)", name ? name : "(null)",
                             plume_field_names());
    const double *a = *(const double *const *)((const char *)v + e->offset);
    for (plume_index t = 0; t < v->nt; t++)
        out[t] = a ? a[(size_t)e->stride * (size_t)t + (size_t)e->component] : NAN;
    return PLUME_OK;
}
