/* plume (private, not installed): the pieces of scene loading shared by macro/scene.c (the
 * document) and macro/scene_mesh.c (its mesh). */
#ifndef PLUME_INTERNAL_SCENE_INTERNAL_H
#define PLUME_INTERNAL_SCENE_INTERNAL_H

#include "../../lib/internal/json_read.h"
#include "../scene.h"

/* Mesh from an OBJ ("mesh": {"obj", "materials_by_group", "barb_direction"}): reference x, y,
 * material by group, constant barb direction. *vertex_map gets, for every OBJ vertex (0-based),
 * its mesh id or -1 if no face uses it (*nobj of them); the caller frees it. */
plume_status plume_scene_mesh_from_obj(const plume_json_ctx *c, json_t *m, plume_scene *s, plume_index **vertex_map,
                                       plume_index *nobj);

/* Mesh from the feather mesher ("mesh": {"feather", "outline", "edge"}); s->barb_edges gets the
 * mesher's barb edges (filtered by plume_scene_constrained_edges). */
plume_status plume_scene_mesh_from_feather(const plume_json_ctx *c, json_t *m, plume_scene *s);

/* s->barb_edges <- the constrained barb edges: edges along the barb direction of an adjacent
 * triangle whose material is constrained (for the feather, among the mesher's barb edges). */
plume_status plume_scene_constrained_edges(plume_scene *s, plume_err *err);

#endif
