/** \file
 * plume: contact between shells as one energy term (docs/design.md "Contact (many feathers)"):
 * point–triangle and edge–edge pairs of a triangle surface closer than dhat, with the barrier
 * kappa b(d) (incremental potential contact) or the paper's penalty stiffness (dhat - d)^2 / 2.
 * The term's stencils follow the state (plume_term.update: candidates from the CGAL broad phase,
 * lib/contact/contact_broad.h) and, for the barrier, it limits every solver step by continuous collision
 * detection (plume_term.max_step: Additive CCD, lib/contact/ccd.h), so that nothing crosses between two
 * iterates: zero interpenetration by construction. The pair maths is lib/contact/contact_narrow.h. */
#ifndef PLUME_CONTACT_H
#define PLUME_CONTACT_H

#include "../core/export.h"
#include "ccd.h"
#include "contact_broad.h"
#include "contact_narrow.h"
#include "../core/term.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Options of the contact term (plume_contact_term_opts_default). */
typedef struct {
    plume_contact_opts pair; /**< model, dhat, stiffness (kappa or the penalty's), PSD projection */
    int self_contact;        /**< 1: non-adjacent primitives of one body touch too (pairs already
                                within dhat at rest with dhat = half their rest distance);
                                0: only pairs of different bodies (body ids required). Default 0. */
    double margin;           /**< candidates are the pairs within dhat + margin when the stencils are
                                updated (before each step, and after it: a step whose solution
                                brings in new pairs is solved again, lib/sim/dynamics.c); default 0.
                                Pairs in the margin cost an evaluation and a place in the
                                pattern, and their barrier acts as soon as a solve brings them
                                within dhat: worth it where bodies close in fast (the contact
                                stack: 406 Newton iterations without, 185 with margin = dhat),
                                not where many lie just beyond dhat (the wing: 65x the pairs,
                                1.5x the time). docs/solver-nonconvexity.md */
    plume_ccd_opts ccd;      /**< the barrier's step limit; defaults of ccd.h */
    const plume_index *weld; /**< NULL (default), or [nv]: adjacency by welded vertices
                                (plume_contact_broad_opts.weld; copied): a split line's lips */
} plume_contact_term_opts;

/** Fills o with the defaults: plume_contact_opts_default for the pair, no self contact, no margin,
 * plume_ccd_opts_default. */
void plume_contact_term_opts_default(plume_contact_term_opts *o);

/** "barrier" or "penalty" (a static string; "unknown" for anything else). */
const char *plume_contact_model_name(plume_contact_model m);

/** What the term did (plume_contact_term_stats). */
typedef struct {
    plume_index candidates; /**< stencils of the last update */
    long updates;           /**< stencil updates */
    long step_limits;       /**< steps that CCD cut short */
    plume_index excluded;   /**< self contact: pairs of one body within dhat at rest; they
                               would be pushed apart from the first step, so their barrier acts
                               only within half their rest distance (CCD still applies) */
    double broad_seconds;   /**< wall time in the broad phase (stencil updates) */
    double narrow_seconds;  /**< wall time evaluating the pair energies */
    double ccd_seconds;     /**< wall time in continuous collision detection (step limits) */
    long broad_updates;     /**< broad-phase queries (stencil updates and CCD) */
    long broad_searches;    /**< of those, the ones that searched anew (plume_contact_broad_opts.reuse) */
} plume_contact_stats;

/** Opaque handle on a contact term's data, owned by the term (and so by the problem that holds
 * it): a way to ask the term what it did, never freed by the caller. */
typedef struct plume_contact plume_contact;

/** A contact term over a triangle surface in shell mode (dim 3): nv vertices (the problem's),
 * ntri triangles tri [3 ntri] (copied), body [nv] a body id per vertex or NULL (one body), xrest
 * [3 nv] rest positions (the edge–edge mollifier's threshold). *out is ready for
 * plume_problem_add_term, which takes ownership; *handle (may be NULL) stays valid as long as the
 * problem and serves plume_contact_term_stats. Errors name what is wrong. */
plume_status plume_contact_term_create(plume_index nv, plume_index ntri, const plume_index *tri, const int *body,
                                                 const double *xrest, const plume_contact_term_opts *o, plume_term *out,
                                                 plume_contact **handle, plume_err *err);

/** The pair that limited the term's last step check (plume_term.max_step, continuous collision
 * detection), when it cut the step (returns 1): its 4 vertices (point, then the triangle's; or
 * the two edges'), whether it is an edge-edge pair, and the fraction of the step it allowed. 0
 * when the last check allowed the whole step, or none ran. Any pointer may be NULL. */
int plume_contact_last_limit(const plume_contact *c, plume_index v[4], int *edge_edge, double *toi);

/** Copies the term's counters and timings into s (zeros for c NULL; s NULL: nothing). */
void plume_contact_term_stats(const plume_contact *c, plume_contact_stats *s);

/** The pairs of the term's last update (lagged friction reads them): *npt point–triangle then *nee
 * edge–edge stencils of 4 vertices in *stencil, their activation distances in *dhat (dhat, or the
 * reduced one of a self pair within reach at rest), and the pair options in *opts. Valid until the
 * next update; any output may be NULL. */
void plume_contact_term_pairs(const plume_contact *c, plume_index *npt, plume_index *nee, const plume_index **stencil,
                                        const double **dhat, plume_contact_opts *opts);

/** A measure that does not trust the model: the smallest distance between non-adjacent primitives
 * (point–triangle and edge–edge pairs of the broad phase b, lib/contact/contact_broad.h) at positions x,
 * or cap when no pair is closer than cap. The search looks within cap / 5 first and widens to cap only
 * when nothing is that close (the candidates grow with the cap squared). */
plume_status plume_contact_min_distance(plume_contact_broad *b, const double *x, double cap, double *dmin,
                                                  plume_err *err);

#ifdef __cplusplus
}
#endif
#endif
