/* plume (private, not installed): the pieces of scene loading shared by -> (the
 * document) and macro/scene/scene_mesh.c (its mesh). */
#ifndef PLUME_INTERNAL_SCENE_INTERNAL_H
#define PLUME_INTERNAL_SCENE_INTERNAL_H

#include "../../../lib/io/json_read.h"
#include "../scene.h"

/* Mesh from an OBJ ("mesh": {"obj", "materials_by_group", "barb_direction"}): reference x, y,
 * material by group, constant barb direction. *vertex_map gets, for every OBJ vertex (0-based),
 * its mesh id or -1 if no face uses it (*nobj of them); the caller frees it. */
plume_status plume_scene_mesh_from_obj(const plume_json_ctx *c, json_t *m, plume_scene *s, plume_index **vertex_map,
                                       plume_index *nobj);

/* Mesh from the feather mesher ("mesh": {"feather", "outline", "edge"}); s->barb_edges gets the
 * mesher's barb edges (filtered by plume_scene_constrained_edges); o (may be NULL)
 * overrides the edge. */
plume_status plume_scene_mesh_from_feather(const plume_json_ctx *c, json_t *m, plume_scene *s,
                                           const plume_scene_load_opts *o);

/* s->barb_edges <- the constrained barb edges: edges along the barb direction of an adjacent
 * triangle whose material is constrained (for the feather, among the mesher's barb edges). */
plume_status plume_scene_constrained_edges(plume_scene *s, plume_err *err);

/* Mesh of a rectangle ("mesh": {"rectangle": [lx, ly], "edge", "pattern", "barb_direction"});
 * o (may be NULL) overrides the edge and the pattern. */
plume_status plume_scene_mesh_from_rectangle(const plume_json_ctx *c, json_t *m, plume_scene *s,
                                             const plume_scene_load_opts *o);

/* The vertices (mesh ids) that the selector of `obj` ("near" + "radius", "vertices" or "box",
 * on the reference positions) picks: ids[0..*count) (ids has room for nv); map/nobj translate
 * OBJ vertex numbers (NULL: mesh ids). Selecting nothing is an error naming the key. */
plume_status plume_scene_select(const plume_json_ctx *c, json_t *obj, const char *where, const plume_scene *s,
                                const plume_index *map, plume_index nobj, plume_index *ids, plume_index *count);

/* The run settings (scene_settings.c), the materials (scene_materials.c) and the handles of a
 * "mesh" scene (scene_handles.c; map/nobj as for plume_scene_select); errors name the key. */
plume_status plume_scene_parse_settings(const plume_json_ctx *c, json_t *doc, plume_scene *s);
plume_status plume_scene_parse_materials(const plume_json_ctx *c, json_t *doc, plume_scene *s);
plume_status plume_scene_parse_handles(const plume_json_ctx *c, json_t *doc, plume_scene *s, const plume_index *map,
                                       plume_index nobj);

/* One handle {selector, "keyframes": [[t, dx, dy, dz], ...]} into *h (its arrays malloc'ed even on
 * failure: the caller frees them); map/nobj as for plume_scene_select. */
plume_status plume_scene_parse_handle(const plume_json_ctx *c, json_t *jh, const char *where, const plume_scene *s,
                                      const plume_index *map, plume_index nobj, plume_handle *h);

/* A scene's "objects" list (instead of "mesh" and "handles"): builds s->mesh, s->elastic,
 * s->objects, s->handles (objects' handles, attachments and kinematic bodies), s->barb_edges and
 * s->length; o (may be NULL) overrides the feathers' edge. Errors name the key. */
plume_status plume_scene_parse_objects(const plume_json_ctx *c, json_t *v, plume_scene *s, const plume_scene_load_opts *o);

/* The static part of a scene (clamps, loads, moments) and its probes, after the mesh and the
 * handles; keys of a static scene in a dynamic one are refused. */
plume_status plume_scene_parse_static(const plume_json_ctx *c, json_t *doc, plume_scene *s, const plume_index *map,
                                      plume_index nobj);

/* The "contact" block of a dynamic scene into s->contact (s->has_contact = 1); errors name the
 * key. */
plume_status plume_scene_parse_contact(const plume_json_ctx *c, json_t *v, plume_scene *s);

/* The "splits" block of a "mesh" scene (after its mesh and materials, before anything selects
 * vertices): opens the lines and makes the opened mesh the scene's; errors name the key. */
plume_status plume_scene_parse_splits(const plume_json_ctx *c, json_t *doc, plume_scene *s);
/* Lines along a feather's barbs (scene_split_chains.c): the chains of the mesher's barb edges in
 * the materials `split` ("lines": that many spread along the rachis, or "every": every k-th),
 * opened with `held` vertices whole; errors name the key. */
plume_status plume_scene_split_chains(const plume_json_ctx *c, json_t *js, const plume_scene *s,
                                      const unsigned char *split, const unsigned char *held, plume_split_lines *out);
/* After the lines opened: the mesher's barb edges (s->barb_edges, when the mesh has them) gain
 * each lip's own copy of the edges along a line. */
plume_status plume_scene_split_barb_edges(plume_scene *s, const plume_split_lines *sl, plume_err *err);
/* Frees the scene's split lines (not its mesh). */
void plume_scene_splits_free(plume_scene *s);
/* s->split_weld (each vertex's original with the lines welded shut: contact's adjacency,
 * plume_contact_term_opts.weld) from the scene's mesh and lines, once both are final */
plume_status plume_scene_splits_weld(plume_scene *s, plume_err *err);
/* 1 when triangles t1 and t2 share a vertex with the split lines welded shut: a line's lips touch
 * there as neighbours do, and an audit of intersections does not count them (0 without splits) */
int plume_scene_welded_neighbours(const plume_scene *s, plume_index t1, plume_index t2);

/* plume_scene_bodies into a new array (nv + 1 ints; the caller frees it), or NULL with the error
 * set when memory runs out. */
int *plume_scene_body_labels(const plume_scene *s, plume_err *err);

#endif
