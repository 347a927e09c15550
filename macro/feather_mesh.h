/** \file
 * plume: the feather mesher of supplementary §6 — a rachis strip walked at the target edge length
 * with linearly interpolated width, and from each rachis vertex a barb curve interpolated from the
 * closest input barb curves of that side only, walked to the outline; points and barb edges
 * triangulated by constrained Delaunay (lib/core/cdt.h). With corner_exact set, a barb ends on every
 * outline vertex it can reach, so nearly every vane triangle owns a barb edge; either way
 * plume_feather_uncovered says why each other one does not. */
#ifndef PLUME_FEATHER_MESH_H
#define PLUME_FEATHER_MESH_H

#include "../lib/core/export.h"
#include "../lib/core/mesh.h"
#include "obj_outline.h" /* plume_obj_outline, the usual source of the outline */

#ifdef __cplusplus
extern "C" {
#endif

/** A polyline in the 2D reference (material) plane. */
typedef struct {
    plume_index n;   /**< number of points */
    const double *p; /**< [2 n], owned by the caller */
} plume_polyline;

/** Mesher input; every array is owned by the caller. All in metres. */
typedef struct {
    plume_polyline outline;     /**< closed outline of the whole feather (last point != first) */
    plume_polyline rachis;      /**< rachis centre line from base to tip (extrapolated linearly to
                                   the outline if it stops short) */
    double rachis_width_base;   /**< rachis width at the base */
    double rachis_width_tip;    /**< rachis width at the tip (linear in between) */
    int nbarbs_left;            /**< entries of barbs_left */
    int nbarbs_right;           /**< entries of barbs_right */
    const plume_polyline *barbs_left;  /**< barb curves on the left side, from the rachis outward
                                          (extrapolated to the outline) */
    const plume_polyline *barbs_right; /**< barb curves on the right side, likewise */
    double edge;                /**< target edge length e */
    int corner_exact;           /**< 1: corner-exact stations, a barb ending on every outline vertex it
                                   can reach (macro/feather_mesh.c, step 3b); on the shipped feather
                                   98.4 / 98.8 / 99.5 % of vane triangles own a barb edge at 5 / 3.5 /
                                   2.5 mm instead of 89.0 / 93.1 / 95.2 %. 0 (what zero-initialised
                                   callers get): stations every ds, the layout of earlier versions.
                                   Not the default yet: the shipped dynamic feather scene needs about
                                   2x the Newton iterations on it, and far more at 4.6-4.8 mm. */
} plume_feather_input;

/** Material ids of the output. */
enum {
    PLUME_FEATHER_VANE = 0,  /**< a vane triangle */
    PLUME_FEATHER_RACHIS = 1 /**< a triangle of the rachis strip */
};

/** Meshes the feather. Output: a mesh with X (2D reference), x = X (z = 0 in shell mode), material
 * per triangle (vane or rachis), barb_dir per vane triangle (local barb direction; for the rachis
 * the rachis tangent), topology built; *barb_edges receives the 2*nbarb vertex ids of the barb
 * edges (malloc'ed). Errors (PLUME_EINVAL, message naming the curve and point): an outline or
 * curve with fewer than 2 points or non-finite coordinates, a self-intersecting outline or barb
 * curve, a rachis or barb curve whose start lies outside the outline, a side with no barb curve,
 * edge <= 0 or too small for the outline (more than 5e6 triangles). */
plume_status plume_feather_mesh(const plume_feather_input *in, int dim, plume_mesh **out, plume_index **barb_edges,
                                          plume_index *nbarb, plume_err *err);

/** Why a vane triangle owns no barb edge: the first of these that applies to one of its vertices.
 * Each such vertex forces one: in the strip between two barbs, a boundary vertex that ends no barb
 * or a barb that ends inside adds a triangle and no barb edge (the count behind docs/design.md, "Meshes
 * that respect the fibres"). */
enum {
    PLUME_FEATHER_UNCOVERED_RACHIS = 0,   /**< rachis junction: a vertex of the rachis strip from which no
                                             barb leaves (the strip's ends, where it meets the outline) */
    PLUME_FEATHER_UNCOVERED_OUTLINE = 1,  /**< a vertex on the outline where no barb ends: the outline runs
                                             along the barbs there, or wraps around the strip's end, or
                                             bends twice within one barb spacing */
    PLUME_FEATHER_UNCOVERED_BARB_END = 2, /**< a vertex inside the vane where a barb starts or stops (a fill
                                             barb where neighbours diverge, a barb cut where it converges
                                             on another) */
    PLUME_FEATHER_UNCOVERED_OTHER = 3,    /**< none of the above */
    PLUME_FEATHER_UNCOVERED_REASONS = 4   /**< the number of reasons (not a reason) */
};

/** Names of the reasons above ("rachis junction", "outline", "barb end", "other"); NULL out of range. */
const char *plume_feather_uncovered_name(int reason);

/** Barb coverage and quality of a feather mesh (docs/design.md, "Meshes that respect the fibres"). */
typedef struct {
    plume_index vane_triangles;   /**< triangles of material PLUME_FEATHER_VANE */
    plume_index vane_covered;     /**< of them, those owning one of the returned barb edges (so
                                     inextensible under the constraint) */
    plume_index rachis_triangles; /**< triangles of material PLUME_FEATHER_RACHIS */
    plume_index uncovered[PLUME_FEATHER_UNCOVERED_REASONS]; /**< the other vane triangles by reason
                                     (plume_feather_uncovered); they sum to vane_triangles - vane_covered */
    double vane_min_angle;        /**< smallest angle of a vane triangle, degrees */
    double rachis_min_angle;      /**< smallest angle of a rachis triangle, degrees */
} plume_feather_stats;

/** The vane triangles of a feather mesh `m` (materials and topology as plume_feather_mesh leaves
 * them) that own none of the nbarb barb edges (2*nbarb vertex ids), with their reasons: *n of
 * them, ids in *tri and reasons (PLUME_FEATHER_UNCOVERED_*) in *reason, both malloc'ed (NULL when
 * none; either output may be NULL if unwanted). Works on the mesh alone: a vertex is on the
 * outline when it is a boundary vertex, of the strip when a rachis triangle uses it, and ends a
 * barb when exactly one barb edge uses it. Errors: PLUME_EINVAL (NULL mesh or n, no topology,
 * vertex id out of range), PLUME_ENOMEM. */
plume_status plume_feather_uncovered(const plume_mesh *m, const plume_index *barb_edges, plume_index nbarb,
                                               plume_index **tri, unsigned char **reason, plume_index *n, plume_err *err);

/** plume_feather_mesh, and *stats (if non-NULL) filled as above; same outputs and errors. */
plume_status plume_feather_mesh_with_stats(const plume_feather_input *in, int dim, plume_mesh **out,
                                                     plume_index **barb_edges, plume_index *nbarb, plume_feather_stats *stats,
                                                     plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
