/* plume (private, not installed): the feather mesher's tolerances, its state and the functions its
 * files call across. The design (steps and the decisions behind them) is the comment at the top of
 * macro/feather/feather_mesh.c, which also holds the driver; the other jobs live beside it:
 *   feather_segments.c  vertices and segments of the state, and the proximity queries on them;
 *   feather_centre.c    the rachis centre line: construction, width, offsets, projection;
 *   feather_barbs.c     barb shapes and their blending, the barb walk, the strip side ends;
 *   feather_stations.c  corner-exact stations;
 *   feather_check.c     input validation.
 * Functions called across files are named plume_fm_* (libplume.a is linked statically into other
 * programs, so no short global names); the others are static in their file. */
#ifndef PLUME_MACRO_INTERNAL_FEATHER_MESHER_H
#define PLUME_MACRO_INTERNAL_FEATHER_MESHER_H

#include "../../../lib/core/pslg.h"
#include "../../../lib/core/status.h"
#include "../feather_mesh.h"
#include "bins.h"
#include "feather_geom.h"
#include "sampled_curve.h"

/* Tolerances, as fractions of the target edge e (the header has no options struct; these are the
 * knobs to expose if callers need them). */
#define GAP_POINT 0.3      /* a barb point nearer the outline or another vertex is dropped */
#define GAP_SEGMENT 0.2    /* ... nearer another constrained edge (and a new edge nearer a vertex) */
#define SNAP_OUTLINE 0.1   /* a barb end this close to an outline vertex ends on the vertex */
#define SNAP_SIDE 1e-3     /* a rachis side end this close to an outline vertex ends on it */
#define SUBSTEPS 16        /* integration steps per e along barbs and strip sides */
#define LAST_ARC 1.6       /* longest arc (in e) one barb edge may bridge */
#define SAMPLES 8          /* curve samples per e (at least 16 per curve) */
#define MAX_TRIANGLES 5e6  /* refuse edges that would give more (estimate area / (0.43 e^2)) */
#define MAX_OUTLINE_SPREAD 40 /* bounding-box diagonal over sqrt(area) of an outline (plume_fm_validate) */
#define IDW_RADIUS 1.5     /* radius (in e) of the barb edges averaged for a triangle without one */
#define PROJECT_COARSE 512 /* coarse samples of the centre line scanned by a projection */
#define FILL_CLEAR 0.7     /* a fill barb starts where it is this far from every vertex and barb */
#define FILL_LEVELS 3      /* fill barbs from half, quarter and eighth stations */
#define CORNER_GAP 0.5     /* a corner station closer than this (in station spacings) to a kept one is dropped */
#define CORNER_TOL 1e-6    /* a corner barb must meet its outline vertex within this (in e) */
#define CORNER_BISECT 64   /* bisection steps of a corner station (stops earlier once exact) */
#define OUTLINE_GAP 2.0    /* an outline gap up to this (in e) between barb ends is left whole */

/* ------------------------------------------------------------------ mesher state */

enum { SEG_OUTLINE, SEG_SIDE, SEG_BARB };

typedef struct {
    double a[2], b[2];
    plume_index v0, v1; /* vertex ids (constrained segments), -1 otherwise */
    int kind, side;     /* side +1 left, -1 right */
    plume_index tag;    /* outline: edge index; barb: barb number; side: 0 left, 1 right */
    double t0, t1;      /* outline: parameter range of the piece on its edge */
} fseg;

/* An input barb as relative angle theta(tau), tau the arc length from its root. */
typedef struct {
    double s_root;
    double *tau, *theta;
    plume_index n;
} shape;

typedef struct {
    plume_index edge; /* outline edge (from vertex edge to edge+1) */
    double t;
    plume_index id;
} anchor;

typedef struct {
    const plume_feather_input *in;
    plume_err *err;
    double e;
    /* outline, counter-clockwise */
    double *o;
    plume_index no;
    double *ocum, per; /* [no + 1] arc length of the outline at each vertex; its perimeter */
    double bb[4], diag; /* bounding box (x0, y0, x1, y1) and its diagonal */
    /* output vertices and constrained segments (ids in g.p order) */
    plume_pslg g;
    unsigned char *outline_used; /* [no] outline vertex already ends a barb or side */
    /* geometric segments */
    fseg *s;
    plume_index ns, scap;
    unsigned *stamp;
    unsigned qid;
    plume_bins pg, sg;
    anchor *anc;
    plume_index nanc, anccap;
    /* centre line: samples with s = 0 at the base exit, L at the tip exit, margins beyond */
    plume_sampled_curve c;
    double L, s_in0, s_in1;
    /* input barb shapes per side (0 left, 1 right), sorted by root station */
    shape *sh[2];
    int nsh[2];
    double max_barb_len;
    /* barb constrained segments: pslg segment indices */
    plume_index *barb_seg;
    plume_index nbarb_seg, barb_cap;
} fm;

/* The blend of a station: shapes j and j+1 with weight w on j+1. */
typedef struct {
    const shape *a, *b;
    double w, phi;
} blend;

/* Loops over the items of the cells of grid gr that the box (xa, ya)-(xb, yb) overlaps, `node`
 * the item's node (gr->item[node] its id); an item spanning several cells comes once per cell
 * (the callers stamp or tolerate repeats). Declares r_ in the enclosing block. */
#define FOR_CELLS(gr, xa, ya, xb, yb, node)                                                                         \
    long r_[4];                                                                                                    \
    plume_bins_range(gr, xa, ya, xb, yb, r_);                                                                      \
    for (long j_ = r_[2]; j_ <= r_[3]; j_++)                                                                        \
        for (long i_ = r_[0]; i_ <= r_[1]; i_++)                                                                    \
            for (plume_index node = (gr)->head[j_ * (gr)->nx + i_]; node >= 0; node = (gr)->next[node])

/* ------------------------------------------------------------------ feather_segments.c */

/* A geometric segment in the segment grid (kind SEG_*); 0, or -1 (no memory). */
int plume_fm_add_seg(fm *f, const double *a, const double *b, plume_index v0, plume_index v1, int kind, int side,
                     plume_index tag, double t0, double t1);
/* A new output vertex, registered in the point grid; its id or -1 (no memory). */
plume_index plume_fm_add_vertex(fm *f, const double *p);
/* A constrained edge between vertices (SEG_SIDE or SEG_BARB); 0, or -1 (no memory). */
int plume_fm_add_constraint(fm *f, plume_index v0, plume_index v1, int kind, int side, plume_index tag);
/* A vertex on outline edge `edge` at parameter t (an edge end closer than `snap`); its id or -1. */
plume_index plume_fm_outline_vertex(fm *f, plume_index edge, double t, double snap);
/* The outline vertex plume_fm_outline_vertex would snap to, or -1. */
plume_index plume_fm_snap_target(const fm *f, plume_index edge, double t, double snap);
/* Earliest crossing of p->q with the outline: 1 and t along pq, the edge and its parameter u. */
int plume_fm_outline_cross(const fm *f, const double *p, const double *q, double *t, plume_index *edge, double *u);
/* Any segment of the kinds (bit mask of 1u << SEG_*) within r of p, but those incident to `skip`. */
int plume_fm_near_segment(const fm *f, const double *p, double r, unsigned kinds, plume_index skip);
/* Any side or barb segment crossing or within r of ab, but those incident to `skip`. */
int plume_fm_blocked(const fm *f, const double *a, const double *b, double r, plume_index skip);
/* Any vertex but `skip` within r of segment ab (a point when a == b). */
int plume_fm_near_vertex(const fm *f, const double *a, const double *b, double r, plume_index skip);

/* ------------------------------------------------------------------ feather_centre.c */

/* Rachis width at arc length s. */
double plume_fm_width(const fm *f, double s);
/* Centre point and tangent angle at arc length s. */
void plume_fm_centre(const fm *f, double s, double p[2], double *ang);
/* Point of side sigma (+1 left, -1 right) of the strip at arc length s. */
void plume_fm_offset(const fm *f, double s, int sigma, double p[2]);
/* Arc length of the nearest centre-line point and the signed distance (> 0 on the left). */
void plume_fm_project(const fm *f, const double *p, double *s_out, double *d_out);
/* Nearest exit through the outline of the ray from p at angle ang; 1 and the point, or 0. */
int plume_fm_ray_hit(const fm *f, const double *p, double ang, double hit[2]);
/* The centre line (f->c, f->L, f->s_in0, f->s_in1) from the input rachis (step 1). */
plume_status plume_fm_build_centre(fm *f);

/* ------------------------------------------------------------------ feather_barbs.c */

/* The input barbs as shapes (f->sh, f->nsh, f->max_barb_len), after the centre line (step 3). */
plume_status plume_fm_build_shapes(fm *f);
/* The blend of the station at arc length s on a side (0 left, 1 right). */
void plume_fm_blend(const fm *f, int side, double s, blend *bl);
/* Absolute tangent angle of a blended barb at arc length tau from its root. */
double plume_fm_blend_angle(const blend *bl, double tau);
/* Past every input barb's end: jump along the straight barb to a sub-step before the outline. */
int plume_fm_jump_to_outline(const fm *f, double a, double h, double p[2], double q[2], double *tau);
/* Walks and meshes one barb (steps 3 and 4). */
plume_status plume_fm_walk(fm *f, int side, const double *start, plume_index root, int root_on_outline, int fill,
                           const blend *bl, plume_index tag);
/* Closes a strip side on the outline (step 2): *end the vertex there. */
plume_status plume_fm_side_end(fm *f, int sigma, double s, double dir, plume_index from, plume_index *end);

/* ------------------------------------------------------------------ feather_stations.c */

/* How far past the strip run's end station s a corner station may root its barb (step 3b). */
double plume_fm_run_extent(const fm *f, int sigma, double s, double ds, int dir);
/* The stations of one side, corner-exact when the input asks (step 3b). */
plume_status plume_fm_stations(fm *f, int side, double ds, long kmin, long kmax, double s0, double s1,
                               const double ext[2], double **out, long *n, long *r0, long *r1);

/* ------------------------------------------------------------------ feather_check.c */

/* The input's curves, edge, widths and dim (2 or 3); PLUME_EINVAL with a message naming the
 * offending curve and point, or PLUME_ENOMEM. */
plume_status plume_fm_validate(const plume_feather_input *in, int dim, plume_err *err);

#endif
