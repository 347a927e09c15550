/* plume: contact between shells as one energy term (DESIGN.md "Contact (many feathers)"):
 * point–triangle and edge–edge pairs of a triangle surface closer than dhat, with the barrier
 * kappa b(d) (incremental potential contact) or the paper's penalty stiffness (dhat - d)^2 / 2.
 * The term's stencils follow the state (plume_term.update: candidates from the CGAL broad phase,
 * lib/contact_broad.h) and, for the barrier, it limits every solver step by continuous collision
 * detection (plume_term.max_step: Additive CCD, lib/ccd.h), so that nothing crosses between two
 * iterates: zero interpenetration by construction. The pair maths is lib/contact_narrow.h. */
#ifndef PLUME_CONTACT_H
#define PLUME_CONTACT_H

#include "ccd.h"
#include "contact_narrow.h"
#include "term.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    plume_contact_opts pair; /* model, dhat, stiffness (kappa or the penalty's), PSD projection */
    int self_contact;        /* 1: non-adjacent primitives of one body touch too; 0: only pairs of
                                different bodies (body ids required). Default 0. */
    double margin;           /* candidates are the pairs within dhat + margin when the stencils are
                                updated (once per step): pairs that come closer during the step's
                                solve are found when it is checked (plume_contact_missed);
                                default 0 = dhat */
    plume_ccd_opts ccd;      /* the barrier's step limit; defaults of ccd.h */
} plume_contact_term_opts;

void plume_contact_term_opts_default(plume_contact_term_opts *o);

/* What the term did (plume_contact_term_stats). */
typedef struct {
    plume_index candidates; /* stencils of the last update */
    plume_index active;     /* pairs closer than dhat at the last evaluation */
    double min_distance;    /* smallest pair distance at the last evaluation (INFINITY: none) */
    long updates, step_limits;
    double broad_seconds, narrow_seconds, ccd_seconds;
} plume_contact_stats;

typedef struct plume_contact plume_contact;

/* A contact term over a triangle surface in shell mode (dim 3): nv vertices (the problem's),
 * ntri triangles tri [3 ntri] (copied), body [nv] a body id per vertex or NULL (one body), xrest
 * [3 nv] rest positions (the edge–edge mollifier's threshold). *out is ready for
 * plume_problem_add_term, which takes ownership; *handle (may be NULL) stays valid as long as the
 * problem and serves plume_contact_term_stats. Errors name what is wrong. */
plume_status plume_contact_term_create(plume_index nv, plume_index ntri, const plume_index *tri, const int *body,
                                       const double *xrest, const plume_contact_term_opts *o, plume_term *out,
                                       plume_contact **handle, plume_err *err);

void plume_contact_term_stats(const plume_contact *c, plume_contact_stats *s);

/* 1 when a pair that is not a stencil of the term is closer than dhat at positions x (3 nv): the
 * solution of a step missed it, update the stencils and solve again. */
int plume_contact_missed(plume_contact *c, const double *x);

#ifdef __cplusplus
}
#endif
#endif
