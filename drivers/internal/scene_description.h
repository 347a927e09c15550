/* plume (private, not installed): a loaded scene's description (include/plume/scene.h's
 * plume_scene_describe) as a jansson object, for the drivers that report on a scene without its
 * struct (the flat interface, the scene sweep). */
#ifndef PLUME_DRIVERS_SCENE_DESCRIPTION_H
#define PLUME_DRIVERS_SCENE_DESCRIPTION_H

#include <jansson.h>

#include "../../include/plume/scene.h"

/* The description, parsed (the caller json_decref's it); NULL with the error set. */
static inline json_t *plume_scene_description(const plume_scene *s, plume_err *err)
{
    char *text = NULL;
    if (plume_scene_describe(s, &text, err) != PLUME_OK)
        return NULL;
    json_t *j = json_loads(text, 0, NULL);
    plume_free(text);
    if (!j)
        plume_err_set(err, PLUME_ENOMEM, "scene: its description could not be read back (out of memory?)");
    return j;
}

/* A number of the description (NaN when absent). */
static inline double plume_scene_description_number(json_t *d, const char *key)
{
    json_t *v = json_object_get(d, key);
    return json_is_number(v) ? json_number_value(v) : (double)NAN;
}

#endif
