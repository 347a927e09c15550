/** \file
 * plume: barbule hooks, the joins between a barbule's distal end and the next barb that
 * can let go and catch again (docs/unzipping.md).
 *
 * A hook holds a set of vertex pairs (a on the barbule's tip, b on the barb), each a zero-length
 * spring with its own rest offset o_p: E = sum_p k_p / 2 |x_a - x_b - o_p|^2, the hook's stiffness
 * k = strength / opening shared equally by its pairs. Its force is F = sum_p k_p (x_a - x_b - o_p).
 *
 * The law is not smooth (a hook lets go at |F| = strength) and depends on the path, so the hooks
 * change state only between solves, at an equilibrium (plume_hooks_commit), never inside a Newton
 * iteration: there the term is a plain quadratic, exact and positive semidefinite.
 *  - Engaged, |F| > strength: the hook slides (its pairs' offsets move together by the return
 *    map that brings |F| back to the strength) while its slide so far stays within `slide`;
 *    otherwise it is released.
 *  - Released: no energy. Once the mean distance of its pairs has exceeded `capture` (the hooklet
 *    has cleared the barb), it catches again when that distance is back within `capture`, with its
 *    offsets set to the current gaps: it starts at zero force and the commit creates no energy.
 * A commit reports the energy the hooks lose at the same positions (released springs, slides):
 * the dissipated part of an energy balance. */
#ifndef PLUME_MICRO_HOOKS_H
#define PLUME_MICRO_HOOKS_H

#include "../../include/plume/homogenize.h"

#include "export.h"
#include "status.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** PLUME_EINVAL naming the first bad field and its value. */
plume_status plume_hook_law_check(const plume_hook_law *l, plume_err *err);

/** Which overloaded hooks a commit changes. */
typedef enum {
    PLUME_HOOKS_ALL = 0,  /**< every hook at or beyond its strength */
    PLUME_HOOKS_ONE = 1   /**< only the most loaded (a cascade then needs a solve per hook) */
} plume_hooks_mode;

typedef struct plume_hooks plume_hooks;

/** nhooks hooks, hook h holding pairs first[h] .. first[h+1] - 1 of pairs (2 vertex ids each: a
 * then b), all with the law `law`, engaged with offsets zero. Arrays are copied. Errors: a bad law,
 * a hook without pairs, a pair whose vertices are equal or outside [0, nv) (PLUME_EINVAL, naming
 * the hook and pair); PLUME_ENOMEM. */
plume_status plume_hooks_create(plume_index nv, int nhooks, const plume_index *first, const plume_index *pairs,
                                const plume_hook_law *law, plume_hooks **out, plume_err *err);
void plume_hooks_destroy(plume_hooks **h);

/** The energy term of the hooks (name "hooks", arity 2, a stencil per pair; released pairs add
 * nothing), with a commit (plume_term.commit: plume_hooks_commit of every hook, or an overshoot
 * when allowed to cut and a hook is loaded beyond the overshoot, PLUME_HOOKS_OVERSHOOT strengths unless set), a keep and
 * the pairs' states (1 engaged, 0 let go).
 * own: the term frees h with the problem; 0: it borrows h, which must outlive it. */
void plume_hooks_term(plume_hooks *h, int own, plume_term *t);

/** A commit allowed to cut refuses loads beyond this many strengths: the stepper halves its
 * increment, so hooks let go near their strength (docs/unzipping.md). The default. */
#define PLUME_HOOKS_OVERSHOOT 1.25

/** Sets the overshoot a commit allowed to cut refuses (> 1, finite): closer to 1, the hooks let go
 * closer to their strength, at the price of more cut increments. PLUME_EINVAL otherwise. */
plume_status plume_hooks_set_overshoot(plume_hooks *h, double factor);

/** Scales hook k's strength and stiffness by `scale` (> 0, finite; 1 at creation), its opening,
 * slide and capture unchanged: one law over hooks of different sizes, such as the pairs of a
 * macroscale barb line, each holding its own length of line (macro/shell/split_lines.h).
 * PLUME_EINVAL for a bad hook or scale. */
plume_status plume_hooks_set_scale(plume_hooks *h, int k, double scale);

/** Seating, off at creation. With it on, a hook caught again at a gap (its offsets that gap) holds
 * its lips apart only as far as they were: closing them further along the gap's direction, down to
 * where they meet, is free (its energy sees the stretch less its closing part), and only opening
 * and sliding load it; pressed through each other, it resists about their meeting point as a hook
 * at creation does. A hook pressed closer than its catch by more than `distance` (m, >= 0) seats
 * at a commit: each pair's offset shortens along its direction by the closing (to zero where the
 * lips met), so that it holds from there. A seat moves no force and no energy, so
 * the stepper does not solve again for it. The hooks at creation (offsets zero) are two-sided and
 * never seat (the macro lines: closing a line by pressing its lips together, docs/unzipping.md).
 * With seating on, a released hook whose mean gap comes back within `distance` also catches
 * again, whether or not it opened beyond the capture since it let go (a link by a held line end
 * that let go with its lips together).
 * PLUME_EINVAL for a negative or non-finite distance. */
plume_status plume_hooks_set_seating(plume_hooks *h, double distance);

/** Softening, off at creation (ratio 1: a hook lets go at its strength, between solves). With ratio
 * > 1 (every hook one pair; PLUME_EINVAL otherwise, and for a ratio below 1 or not finite) a hook
 * follows a bilinear cohesive law inside the solves: its force rises to the strength at its
 * opening d0, then falls linearly to zero at ratio x d0. Its history, the largest opening a commit
 * saw, makes it a damage law: below that opening it is the secant spring back to zero. A commit
 * moves the history (the energy above the new secant is dissipated) and lets the hook go at
 * ratio x d0, where its force is zero already; neither moves the equilibrium. The energy under the
 * law is ratio / 2 x strength x d0. The falling branch is not convex: the term's Hessian is exact,
 * and projected by dropping that branch's negative curvature along the pair
 * (plume_term.partial_projection, set by plume_hooks_term when softening is on: set it first). A
 * hook caught again starts whole. Replaces the slide. */
plume_status plume_hooks_set_softening(plume_hooks *h, double ratio);

/** Hooks, and pairs. */
int plume_hooks_count(const plume_hooks *h);
/** 1 engaged, 0 released. */
int plume_hooks_engaged(const plume_hooks *h, int k);
/** The force of hook k at positions x (dim per vertex) into f[dim]; 0 when released. */
void plume_hooks_force(const plume_hooks *h, int dim, const double *x, int k, double *f);
/** The largest |F| / strength over the engaged hooks at x, and which hook (-1 when none is
 * engaged): a caller cuts its load step when this is well above 1 before committing. */
double plume_hooks_max_load(const plume_hooks *h, int dim, const double *x, int *which);

/** What a commit did. */
typedef struct {
    int released;        /**< hooks let go */
    int reengaged;       /**< hooks caught again */
    int slid;            /**< hooks that slid */
    int seated;          /**< caught hooks pressed closer that seated (plume_hooks_set_seating) */
    int softened;        /**< softening hooks opened beyond their history (plume_hooks_set_softening) */
    int soft_released;   /**< of `released`, softening hooks let go at the end of their law, at zero force */
    double energy_drop;  /**< J: the hooks' energy at x before the commit minus after (>= 0) */
} plume_hooks_events;

/** Updates the hooks' states at the equilibrium x (above) and adds the counts to the totals.
 * `ev` (may be NULL) gets this commit's events. */
plume_status plume_hooks_commit(plume_hooks *h, int dim, const double *x, plume_hooks_mode mode,
                                plume_hooks_events *ev, plume_err *err);

/** Totals since creation: releases, re-engagements, and the energy dropped by commits (J). */
void plume_hooks_totals(const plume_hooks *h, long *released, long *reengaged, double *dropped);

/** The hooks' state as doubles, everything a commit changes (engaged, armed, slide, the pairs' offsets,
 * the softening history, the totals): plume_hooks_state_size values. A restart that sets it back repeats the run bit
 * for bit. */
plume_index plume_hooks_state_size(const plume_hooks *h);
void plume_hooks_state_get(const plume_hooks *h, double *s);
/** Sets the state from s (as plume_hooks_state_get wrote it) and keeps it (plume_term.keep).
 * PLUME_EINVAL (named) for a non-finite value, a flag not 0 or 1, a negative slide, history or total;
 * nothing changes then. */
plume_status plume_hooks_state_set(plume_hooks *h, const double *s, plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
