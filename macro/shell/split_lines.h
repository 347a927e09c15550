/** \file
 * plume (macro): barb lines of a vane mesh that can split and zip again (docs/unzipping.md, "The
 * macro split"). A barb line is a chain of mesh edges along the barbs (an aligned mesh has one
 * through every row of its vertices). Its vertices are duplicated once, when the model is built:
 * the triangles ahead of the line (along n = (d_y, -d_x), d the barb direction) take the copies,
 * and each (copy, original) pair is held by a link of the separation law homogenised from the
 * cell (plume_separation_law_of): a zero-length spring of the line's stiffness times the pair's
 * share of the line's length, which lets go when its force reaches the strength times that length
 * and catches again within the capture distance (lib/core/hooks.h, one hook per pair). The split is
 * intrinsic: while it holds, a line adds the hooks' own compliance, the part of the cell's
 * opening that the bonded moduli do not have. */
#ifndef PLUME_MACRO_SPLIT_LINES_H
#define PLUME_MACRO_SPLIT_LINES_H

#include "../../include/plume/homogenize.h"

#include "../../lib/core/export.h"
#include "../../lib/core/mesh.h"
#include "../../lib/core/problem.h"
#include "../../lib/core/hooks.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A line's links let go within this many strengths: a load step that would load one further is
 * cut (lib/core/hooks.h), so that the macro response resolves the strength to 2 % (the micro hooks
 * allow PLUME_HOOKS_OVERSHOOT). */
#define PLUME_SPLIT_OVERSHOOT 1.02

/** A link that caught again closes freely and seats (plume_hooks_set_seating) once its lips are
 * this many capture distances closer than where it caught: a line pressed shut holds from within
 * 5 % of the capture of where its lips met (docs/unzipping.md, "Seating"). */
#define PLUME_SPLIT_SEATING 0.05

/** A mesh opened along barb lines, and the pairs that hold it; everything owned
 * (plume_split_lines_free). */
typedef struct {
    plume_mesh *mesh;     /**< the opened mesh: the input's vertices first (same ids), then the copies;
                             the same triangles, those ahead of a line renumbered to its copies;
                             topology built */
    int nlines;           /**< lines opened */
    double *offset;       /**< [nlines] each line's offset n . X (m); NaN for a chain (plume_split_lines_open_chains) */
    plume_index *first;   /**< [nlines + 1] line l's pairs are first[l] .. first[l+1] - 1, in order along d */
    plume_index *pairs;   /**< [2 npairs] (copy, original) */
    double *length;       /**< [npairs] each pair's share of its line's length (m) */
    plume_index npairs;
} plume_split_lines;

/** Opens the barb lines of the planar mesh `m` (topology built) nearest to the offsets
 * c[0 .. nc-1] (n . X, m), d the barb direction (unit). A line runs from boundary to boundary,
 * and every pair of consecutive vertices on it must be a mesh edge. Errors (PLUME_EINVAL, naming
 * the offset): no vertices on a line, a line that is not a chain of mesh edges (an unaligned
 * mesh), two offsets on one line; PLUME_ENOMEM. */
plume_status plume_split_lines_open(const plume_mesh *m, const double d[2], const double *c, int nc,
                                    plume_split_lines *out, plume_err *err);

/** The same over a planar mesh or a flat shell (dim 2 or 3; the copies take their originals'
 * positions x too), where the vertices with held[v] non-zero (may be NULL) never split: a line
 * stops there, its last pair's triangles sharing the held vertex (a crack tip), such as a vane's
 * line where it meets the rachis. A line none of whose vertices may split is refused, naming its
 * offset. */
plume_status plume_split_lines_open_held(const plume_mesh *m, const double d[2], const double *c, int nc,
                                         const unsigned char *held, plume_split_lines *out, plume_err *err);

/** Opens lines along chains of mesh edges, such as a feather's curved barbs: chain l is the
 * vertices cverts[cfirst[l] .. cfirst[l+1] - 1], each two in a row a mesh edge. Each vertex of a
 * chain that may split gets a copy, taken by the triangles of its fan left of the chain (the side
 * of (b - a) x (c - a) > 0 for a chain edge a -> b), in the reference X; the copies keep their
 * originals' positions. A vertex stays whole where held[v] is set (may be NULL: the rachis), at a
 * chain's end inside the mesh (a crack tip), and where its fan has triangles on one side only. The
 * lines' offsets are NaN. Errors (PLUME_EINVAL, named): a chain of fewer than 2 vertices, a vertex
 * outside the mesh, two vertices in a row that are not an edge, a vertex on two chains, no vertex
 * that may split; PLUME_ENOMEM. */
plume_status plume_split_lines_open_chains(const plume_mesh *m, int nchains, const plume_index *cfirst,
                                           const plume_index *cverts, const unsigned char *held,
                                           plume_split_lines *out, plume_err *err);

/** The softening of a line's links (plume_hooks_set_softening) under `law`: brittle (1) unless the
 * law opens further after its peak (opening > peak_opening: the cell's hooks slid before they let
 * go); then the bilinear law of the same strength, stiffness and energy, the plateau's
 * strength x slide spread under a line down to zero: 1 + 2 slide / (strength / stiffness)
 * (docs/unzipping.md, "Softening"). */
double plume_split_softening(const plume_separation_law *law);

/** A law of stiff lines (the hooks' compliance carried by the membrane, the hooked cell's tensor):
 * `law` (the cell's, with its energy per crack area) given the stiffness `stiffness` (N/m^2) and
 * an opening past its peak such that its links, softening (plume_split_softening), hold the cell's
 * energy per length of line, energy x h (h the cell's thickness, m), or at least the cell's slide.
 * The energy is the cell's whole work of separation, the hooks' compliance included, which the
 * hooked membrane also gives up where a line opens (docs/monoclinic-vane.md). */
void plume_split_stiff_law(plume_separation_law *law, double stiffness, double h);

/** Adds the links of the opened lines to `p` (over out->mesh's vertices, not finalised) as the
 * hooks' term named "splits" (owned by the problem; *hooks, may be NULL, is a view valid while it lives), with
 * the law `law`: a pair of length L holds strength * L and stiffness * L, and softens past its
 * strength as plume_split_softening says. PLUME_EINVAL for a law out of range (naming the field). */
plume_status plume_split_lines_add(plume_problem *p, const plume_split_lines *s, const plume_separation_law *law,
                                   plume_hooks **hooks, plume_err *err);

void plume_split_lines_free(plume_split_lines *s);

#ifdef __cplusplus
}
#endif
#endif
