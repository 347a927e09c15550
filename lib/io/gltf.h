/** \file
 * plume: glTF 2.0 binary files (.glb) of animated triangle meshes, for graphics tools (Blender, web
 * viewers, game engines). The caller gives the meshes in glTF's axes (y up, metres) with their
 * positions at every frame. The writer adds vertex normals, materials, and the animation:
 *
 *  - PLUME_GLTF_MORPH: one node and mesh per object, its first frame as the base and one morph
 *    target per later frame (displacements of positions and normals, and of the field), the
 *    weights animated over the frames' times with linear interpolation (so positions interpolate
 *    linearly between frames);
 *  - PLUME_GLTF_FRAMES: one node per object with a child node per frame, each with its own mesh
 *    (the triangles' indices shared), shown in turn by a scale animated with step interpolation
 *    (1 over its frame, 0 before and after).
 *
 * docs/graphics.md says which clients handle which better, with the measurements. */
#ifndef PLUME_GLTF_H
#define PLUME_GLTF_H

#include <stdint.h>

#include "../../include/plume/scene.h"

#include "../core/export.h"
#include "../core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A set of triangles of one mesh drawn with one material. */
typedef struct {
    int material;        /**< index into plume_gltf_doc.mats */
    uint32_t ntri;       /**< number of triangles */
    const uint32_t *tri; /**< [3 ntri] vertex ids of the mesh (0 .. nv - 1), counter-clockwise */
} plume_gltf_primitive;

/** A glTF material: metallic-roughness PBR with a base colour. */
typedef struct {
    const char *name;  /**< the material's name */
    float rgba[4];     /**< base colour, linear, alpha 1 for opaque */
    float roughness;   /**< 0 .. 1 */
    int double_sided;  /**< 1: both sides are lit and drawn (thin shells) */
} plume_gltf_material;

/** One object: a node (and its meshes) named `name`. */
typedef struct {
    const char *name;                   /**< node and mesh name */
    uint32_t nv;                        /**< vertices */
    int nprim;                          /**< entries of prims (>= 1) */
    const plume_gltf_primitive *prims;  /**< [nprim] */
    const float *x;                     /**< [nframes][3 nv] positions (m, glTF axes: y up) */
    const float *field;                 /**< [nframes][nv] a value per vertex, or NULL */
    const char *extras;                 /**< JSON object text for the node's "extras", or NULL */
} plume_gltf_mesh;

/** A whole file. */
typedef struct {
    int nmesh;                          /**< entries of meshes (>= 1) */
    const plume_gltf_mesh *meshes;      /**< [nmesh] */
    int nmat;                           /**< entries of mats (>= 1) */
    const plume_gltf_material *mats;    /**< [nmat] */
    int nframes;                        /**< frames (>= 1; one frame: no animation) */
    const double *times;                /**< [nframes] increasing times (s) */
    int animation;                      /**< PLUME_GLTF_MORPH or PLUME_GLTF_FRAMES (include/plume/scene.h) */
    const char *field_name;             /**< the field's attribute is "_" + this in upper case
                                             (application-specific, glTF 3.7.2.1); NULL without */
    const char *scene_name;             /**< the glTF scene's name */
    const char *extras;                 /**< JSON object text for the scene's "extras", or NULL */
} plume_gltf_doc;

/** Writes `d` to `path` as a binary glTF (.glb), through a temporary file renamed over it (a
 * reader never sees half a file). Errors: a bad document, naming the mesh and what (PLUME_EINVAL);
 * the file (PLUME_EIO, naming it); PLUME_ENOMEM. */
plume_status plume_gltf_write(const char *path, const plume_gltf_doc *d, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
