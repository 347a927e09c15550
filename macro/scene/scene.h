/** \file
 * plume: a shell scene from JSON: mesh (an OBJ triangle mesh, the feather mesher or a rectangle),
 * per-material membrane, bending, density and barb constraint, handles, gravity, contact, many
 * objects, time stepping (dynamic scenes) or clamps, supports, loads and probes (static scenes),
 * validated as a whole, then built into a problem and an implicit Euler stepper (lib/sim/dynamics.h)
 * or a load-stepping driver (lib/sim/statics.h).
 *
 * The format (every key, its units, default and error messages) is documented in one place:
 * docs/scene-format.md. */
#ifndef PLUME_SCENE_H
#define PLUME_SCENE_H

#include "../../include/plume/scene.h"

#include "../../lib/core/export.h"
#include "../../lib/contact/contact.h"
#include "../../lib/sim/dynamics.h"
#include "../../lib/core/membrane.h"
#include "../../lib/core/mesh.h"
#include "../../lib/core/problem.h"
#include "../../lib/sim/statics.h"
#include "../shell/bending.h"
#include "../shell/fields.h"
#include "../shell/split_lines.h"

/** plume_scene.clamped bits: a clamped vertex; the second row of a clamp that holds boundary
 * edges (rest height fixed only with the hinge bending); the second row of a clamp with no
 * boundary edge (rest height always fixed). */
enum {
    PLUME_CLAMP_HELD = 1,     /**< a clamped vertex */
    PLUME_CLAMP_ROW_EDGE = 2, /**< second row of a clamp holding boundary edges (rest height fixed
                                   only with the hinge bending) */
    PLUME_CLAMP_ROW = 4       /**< second row of a clamp with no boundary edge (rest height always fixed) */
};

/** The scene's bending term ("bending_model"). */
enum {
    PLUME_BENDING_SHAPE_OPERATOR = 0, /**< "shape_operator": shared edge slopes (default) */
    PLUME_BENDING_HINGE = 1,          /**< "hinge": a dihedral angle per interior edge */
    PLUME_BENDING_MIDEDGE = 2         /**< "midedge": an angle unknown per edge (midedge_term.h) */
};

#ifdef __cplusplus
extern "C" {
#endif

/** The "bending_model" name of a PLUME_BENDING_* (static string). */
const char *plume_scene_bending_name(int model);

/** Why `field` cannot be a glTF file's per-vertex field, into why[n] ("\"x\" is not a field; one
 * of: ..."), or 0 when it can: a field of the renders (macro/shell/fields.h), not "material" or
 * "object", and not the midedge operator's curvature_*, which needs every frame's edge unknowns.
 * The scene key and plume_run_write_gltf both ask it (macro/scene/run_gltf.c). */
int plume_gltf_field_refused(const char *field, char *why, size_t n);

/** The longest moduli file name a scene material records (bytes, with the NUL). */
#define PLUME_SCENE_PATH_MAX 4096

/** The longest material name (bytes, with the NUL). */
#define PLUME_SCENE_NAME_MAX 64

/** One material of a scene. */
typedef struct {
    plume_membrane_material membrane; /**< moduli in the barb frame, thickness, kappa */
    plume_bending_material bending;   /**< N m */
    double density;                   /**< surface mass density, kg/m^2 */
    int constraint;                   /**< 1: the barb edges of this material's triangles are inextensible */
    char name[PLUME_SCENE_NAME_MAX];  /**< the material's "name" ("vane", "rachis": glTF materials and
                                           renderers go by it), "" when the scene gives none */
    char membrane_from[PLUME_SCENE_PATH_MAX]; /**< the moduli file ("membrane": {"from_moduli"}) the
                                                   membrane moduli were read from, resolved against
                                                   the scene's directory; "" when the scene sets them */
    char bending_from[PLUME_SCENE_PATH_MAX];  /**< the same for "bending": {"from_moduli"} */
    int tensor;                       /**< the membrane's law ("membrane": {"tensor"}): 0 the moduli
                                           (orthotropic), 1 "full" (the cell's tensor), 2 "hooked"
                                           (the hooked cell's); docs/monoclinic-vane.md */
    double C[9];                      /**< with tensor: the plane-stress tensor (Pa, row-major) */
} plume_scene_material;

/** A follower end moment of a static scene (lib/core/moment.h). */
typedef struct {
    plume_index nend;             /**< vertices of the loaded end */
    plume_index nrow;             /**< vertices of its second row */
    plume_index *end;             /**< [nend] the selected end's vertex ids */
    plume_index *row;             /**< [nrow] its second row's vertex ids */
    double axis[3];               /**< unit axis of the moment */
    double moment;                /**< the nominal moment (N m) */
} plume_scene_moment;

/** A named point of interest: the mean displacement of its vertices. */
typedef struct {
    char *name;                   /**< the probe's name in the scene */
    plume_index n;                /**< number of vertices */
    plume_index *vertices;        /**< [n] their ids */
    int has_reference;            /**< bit a: component a has a reference (0: none) */
    double reference[3];          /**< expected displacement at the full load (m); NaN where none */
    char *source;                 /**< where the reference comes from, or NULL */
} plume_scene_probe;

/** One entry of a scene's "objects": its vertices and triangles in the scene's mesh. */
typedef struct {
    char *name;                   /**< the object's "name" in the scene (every object has one) */
    int kinematic;                /**< 1: a rigid body moved by keyframes (no elastic energy) */
    plume_index v0;               /**< its first vertex: its vertices are v0 .. v0 + nv - 1 */
    plume_index nv;               /**< its number of vertices */
    plume_index t0;               /**< its first triangle: its triangles are t0 .. t0 + nt - 1 */
    plume_index nt;               /**< its number of triangles */
} plume_scene_object;

/** A loaded, validated scene. Everything is owned by the scene (plume_scene_destroy). The caller
 * may change the run settings (dt, solver, ...) before plume_scene_dynamics. */
struct plume_scene {
    char *path;                   /**< the scene file as given */
    plume_mesh *mesh;             /**< shell mode (dim 3), topology built, x = (X, 0), or for objects
                                     their placed positions */
    plume_mesh *elastic;          /**< NULL, or (objects with kinematic bodies) the elastic part: all
                                     vertices, the triangles before the kinematic ones; the elastic
                                     terms are built on it */
    int nobjects;                 /**< entries of objects (0 for a "mesh" scene) */
    plume_scene_object *objects;  /**< [nobjects], NULL for a "mesh" scene */
    int nmat;                     /**< number of materials */
    plume_scene_material *mats;   /**< [nmat], indexed by material id */
    int nhandles;                 /**< number of handles */
    plume_handle *handles;        /**< [nhandles]; their arrays are owned by the scene */
    plume_index nbarb;            /**< number of constrained barb edges */
    plume_index *barb_edges;      /**< [2 nbarb] constrained (inextensible) edges */
    double gravity[3];            /**< m/s^2; default (0, 0, -9.81) */
    double dt;                    /**< time step (s) */
    double duration;              /**< simulated time (s) */
    int adaptive_dt;              /**< "adaptive_dt": true: steps grow after easy solves and are cut
                                     when the solver stalls (plume_dynamics_opts.adaptive); default
                                     false */
    double dt_max;                /**< "dt_max": the largest adaptive step (s); 0 (default): dt */
    plume_solver_kind solver;     /**< default newton */
    int max_halvings;             /**< default 6 */
    int max_iter;                 /**< solver iterations per step; default 100 */
    int verbose;                  /**< solver iterations on stderr; default 0 (not read from the file) */
    int output_every;             /**< steps per output frame; default 1 */
    int nrender;                  /**< entries of render */
    long *render;                 /**< [nrender] frame indices to render as PNG */
    double camera[2];             /**< rot_x, rot_z (degrees); default 60, 30 */
    char render_field[32];        /**< what the renders are coloured by: "material" (default),
                                     "object" (one colour per scene object), or a field of
                                     plume_field_names (macro/shell/fields.h) with a colour bar */
    int gltf;                     /**< "gltf": 1 when a dynamic run with an output directory ends
                                     by writing its frames as glTF (plume_run_write_gltf) */
    char gltf_file[PLUME_SCENE_PATH_MAX]; /**< its file: absolute, or relative to the output directory;
                                     default "frames.glb" */
    int gltf_animation;           /**< PLUME_GLTF_MORPH (default) or PLUME_GLTF_FRAMES */
    char gltf_field[32];          /**< a render field written per vertex, "" for none */
    double length;                /**< diagonal of the reference bounding box (m) */
    int bending_model;            /**< "bending_model": a PLUME_BENDING_*; default "shape_operator" */
    int has_contact;              /**< a "contact" block */
    plume_contact_term_opts contact; /**< its settings */
    double friction_mu;           /**< lagged Coulomb friction between touching shells; 0: none */
    double friction_eps_v;        /**< its sticking speed threshold (m/s); default 1e-3 */
    /* static scenes */
    int is_static;                /**< "solve": "static" */
    int steps;                    /**< load steps; default 10 */
    plume_predictor predictor;    /**< "predictor": "tangent" (default) | "secant" | "none" |
                                     "secant_tangent" (lib/sim/statics.h); dynamic scenes: "tangent"
                                     or "secant_tangent" set plume_dynamics_opts.tangent_predictor,
                                     "secant" and "none" start every step at x + dt v */
    plume_globalization globalization; /**< "globalization": "curved_line_search" (default) |
                                     "line_search" | "trust_region" (lib/solve/solver.h) */
    unsigned char *clamped;       /**< [nv] or NULL: PLUME_CLAMP_* bits */
    unsigned char *supported;     /**< [nv] or NULL: bit a set = coordinate a held ("supports"); bit
                                     a + 3: on a symmetry plane normal to axis a ("symmetry": true) */
    double *force;                /**< [3 nv] or NULL: nominal point and line loads (N) */
    int nmoments;                 /**< number of end moments */
    plume_scene_moment *moments;  /**< [nmoments] */
    int nprobes;                  /**< number of probes */
    plume_scene_probe *probes;    /**< [nprobes] */
    /* barb lines that split and zip again ("splits", dynamic "mesh" scenes) */
    plume_split_lines *splits;    /**< NULL, or the opened lines: their mesh is `mesh` (the copies after
                                     the input's vertices), their pairs the links of the law below */
    plume_separation_law split_law; /**< the lines' law (per barb length) */
    char split_law_from[PLUME_SCENE_PATH_MAX]; /**< the moduli file it was read from, "" when the scene
                                                   sets it */
    plume_index *split_weld;      /**< [nv] with splits: the vertex each one stands for with the lines
                                     welded shut (a copy's original; itself otherwise), else NULL */
};

/** Builds the problem of a static scene (membrane, bending, constraints, the nominal loads and
 * moments; clamps and handles fixed) and its load-stepping driver (lib/sim/statics.h) with the
 * scene's steps, solver and max_iter. *p and *st belong to the caller (destroy st first); the
 * scene must outlive them. Errors: the scene is not static (PLUME_EINVAL). */
plume_status plume_scene_statics(const plume_scene *s, plume_problem **p, plume_statics **st, plume_err *err);

/** plume_scene_fields for a run over problem p (may be NULL): a midedge scene's bending energies
 * are read from p's term, whose edge angles and frames they need (without p they are refused). */
plume_status plume_scene_fields_of(const plume_scene *s, plume_problem *p, plume_fields **out, plume_err *err);

/** Builds the problem (membrane and bending terms per material, edge-length constraints on the
 * barb edges) with x at the rest state, and the implicit Euler stepper with the scene's
 * densities, handles, gravity, dt, solver, max_halvings and max_iter. *p and *d belong to the
 * caller (destroy d first); the scene must outlive them. */
plume_status plume_scene_dynamics(const plume_scene *s, plume_problem **p, plume_dynamics **d, plume_err *err);

/** The same, and *contact (may be NULL; NULL without a "contact" block) the contact term's handle
 * for plume_contact_term_stats, valid as long as *p. A contact scene is first checked by
 * plume_scene_check_start. */
plume_status plume_scene_dynamics_contact(const plume_scene *s, plume_problem **p, plume_dynamics **d,
                                                    plume_contact **contact, plume_err *err);

/** Checks the start of a contact scene (no-op without contact): its bodies at rest, and on the way
 * to where the handles' keyframes put them at t = 0 (the first step makes that jump; 16 placements
 * along it, the last at t = 0), must not intersect — barrier contact cannot start from crossed
 * bodies. PLUME_EINVAL naming the scene, the two bodies (objects' names, else "body N") and the
 * first crossing pair of triangles. */
plume_status plume_scene_check_start(const plume_scene *s, plume_err *err);

/** Records each material of `s` in the frames file `frames_path` (lib/io/frames.h,
 * plume_frames_material_write): /materials/<k> with its moduli E_xx, E_yy, nu_xy, G_xy, thickness,
 * kappa, D_long, D_trans, D_coupling, D_twist, density and constraint, and the string attributes
 * membrane_from_moduli, bending_from_moduli naming the moduli file each part was read from (absent
 * when the scene set it). Errors of plume_frames_material_write. */
plume_status plume_scene_materials_record(const plume_scene *s, const char *frames_path, plume_err *err);


/** The body of each vertex (body [nv], caller-allocated): the connected components of the scene's
 * mesh, a split line's copies joined to their originals (the lips are one body's), numbered from 0
 * in vertex order; returns their count. */
int plume_scene_bodies(const plume_scene *s, int *body);

/** Adds the links of the scene's split lines to p (the term "splits"); nothing without splits.
 * Errors of plume_split_lines_add. */
plume_status plume_scene_add_splits(const plume_scene *s, plume_problem *p, plume_err *err);

/** A broad phase over the scene's bodies (plume_scene_bodies) with the scene's self-contact
 * setting, for measuring distances and intersections after each step (apps/feather, sweeps);
 * the caller destroys *out. */
plume_status plume_scene_contact_broad(const plume_scene *s, plume_contact_broad **out, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
