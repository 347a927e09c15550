/* The midedge bending term over a mesh (midedge_bending.h): builds each triangle's kernel numbers
 * (midedge_face.c) and the edges' rest directors, and sums the kernel over the triangles on
 * (x, theta) arrays. docs/theory-bending-midedge.md has the formulation.
 *
 * Rest state. The rest director of an edge is the caller's (plume_midedge_bending_opts) or the
 * mean of its faces' rest normals, made perpendicular to the rest edge (a boundary edge: its one
 * face's normal); theta = 0 is that director, and the rest slopes s0 are measured with it, so the
 * rest shape stores no energy whatever the mesh. On a flat rest every s0 is 0. On a curved one
 * the mean normal is the surface's midpoint normal only up to O(h) on an irregular mesh, and the
 * rest curvatures inherit the error (tests/test_midedge_bending.c, the curved rest: 40 % of a
 * change of curvature at h = 1/8): a curved rest wants its true normals. */
#include "midedge_bending.h"
#include "../../lib/core/vec3.h"
#include "internal/midedge_anchor.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A reference triangle whose doubled area is below this fraction of its squared edge lengths is
 * degenerate up to rounding (the membrane's and the shape operator's test). */
#define MIDEDGE_DEGENERATE_REL (64.0 * DBL_EPSILON)

struct plume_midedge_bending {
    plume_index nv, nt, ne;
    plume_index *tri;         /* [3 nt] copy of mesh->tri */
    plume_index *edges;       /* [2 ne] copy of mesh->edges */
    plume_index *face_edge;   /* [3 nt] edge of slot k */
    plume_midedge_face *face; /* [nt] */
    double *r0;               /* [3 ne] reference vectors (an anchored edge's: its anchors' at the last re-basing) */
    plume_midedge_anchors anchors;
};


static plume_status check_inputs(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                 const double *rest_x, plume_err *err)
{
    if (!mesh || !mats)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: mesh or materials missing");
    if (mesh->dim != 3)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: the mesh must be in shell mode (dim 3), got dim %d",
                             mesh->dim);
    if (nmat < 1)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: nmat must be >= 1 (got %d)", nmat);
    if (mesh->nv < 0 || mesh->nt < 1 || !mesh->X || !mesh->tri || !mesh->barb_dir || !mesh->material)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: mesh arrays missing or no triangle");
    if (!mesh->edges || !mesh->edge_tri)
        return plume_err_set(err, PLUME_EINVAL,
                             "midedge bending: mesh topology not built (call plume_mesh_build_topology)");
    plume_status st = plume_plate_moduli_check(mats, nmat, "midedge bending", err);
    if (st != PLUME_OK)
        return st;
    for (plume_index t = 0; t < mesh->nt; t++) {
        if (mesh->material[t] < 0 || mesh->material[t] >= nmat)
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld: material id %d out of range [0, %d)",
                                 (long)t, mesh->material[t], nmat);
        for (int k = 0; k < 3; k++)
            if (mesh->tri[3 * t + k] < 0 || mesh->tri[3 * t + k] >= mesh->nv)
                return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld: vertex id %ld out of range [0, %ld)",
                                     (long)t, (long)mesh->tri[3 * t + k], (long)mesh->nv);
        if (!(hypot(mesh->barb_dir[2 * t], mesh->barb_dir[2 * t + 1]) > 0.0))
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld: barb direction of zero length", (long)t);
    }
    if (rest_x)
        for (plume_index i = 0; i < 3 * mesh->nv; i++)
            if (!isfinite(rest_x[i]))
                return plume_err_set(err, PLUME_EINVAL, "midedge bending: rest_x[%ld] is not finite", (long)i);
    return PLUME_OK;
}

/* Slots: face_edge[3 t + k] = the edge opposite vertex k of t, and the sign of its direction. */
static plume_status build_slots(const plume_mesh *m, plume_midedge_bending *b, plume_err *err)
{
    for (plume_index i = 0; i < 3 * m->nt; i++)
        b->face_edge[i] = -1;
    for (plume_index e = 0; e < m->ne; e++) {
        const plume_index va = m->edges[2 * e], vb = m->edges[2 * e + 1];
        for (int side = 0; side < 2; side++) {
            const plume_index t = m->edge_tri[2 * e + side];
            if (t < 0)
                continue;
            const plume_index *v = m->tri + 3 * t;
            for (int k = 0; k < 3; k++)
                if (v[k] != va && v[k] != vb) {
                    b->face_edge[3 * t + k] = e;
                    b->face[t].sigma[k] = v[(k + 1) % 3] == va ? 1.0 : -1.0;
                }
        }
    }
    for (plume_index i = 0; i < 3 * m->nt; i++)
        if (b->face_edge[i] < 0)
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld has an edge the topology does not list",
                                 (long)(i / 3));
    return PLUME_OK;
}

/* Rest directors: the caller's, or the mean of the faces' rest normals; made perpendicular to
 * the rest edge. */
static plume_status rest_directors(const plume_mesh *m, const double *rest_x, const double *rest_dir,
                                   plume_midedge_bending *b, plume_err *err)
{
    memset(b->r0, 0, sizeof(double) * 3 * (size_t)m->ne);
    if (rest_dir)
        for (plume_index i = 0; i < 3 * m->ne; i++) {
            if (!isfinite(rest_dir[i]))
                return plume_err_set(err, PLUME_EINVAL, "midedge bending: rest director of edge %ld is not finite",
                                     (long)(i / 3));
            b->r0[i] = rest_dir[i];
        }
    for (plume_index t = 0; t < m->nt; t++) {
        double p[3][3], e1[3], e2[3], N[3];
        for (int k = 0; k < 3; k++)
            plume_midedge_rest_point(m, rest_x, m->tri[3 * t + k], p[k]);
        sub3(p[1], p[0], e1);
        sub3(p[2], p[0], e2);
        cross3(e1, e2, N);
        const double L = sqrt(dot3(N, N));
        if (!(L > MIDEDGE_DEGENERATE_REL * (dot3(e1, e1) + dot3(e2, e2))))
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld is degenerate in the rest shape", (long)t);
        for (int k = 0; k < 3; k++) {
            double *r = b->r0 + 3 * b->face_edge[3 * t + k];
            if (!rest_dir)
                for (int i = 0; i < 3; i++)
                    r[i] += N[i] / L;
            else if (!(dot3(r, N) > 0.0))
                return plume_err_set(err, PLUME_EINVAL,
                                     "midedge bending: rest director of edge %ld points away from triangle %ld",
                                     (long)b->face_edge[3 * t + k], (long)t);
        }
    }
    for (plume_index e = 0; e < m->ne; e++) {
        double pa[3], pb[3], E[3], d[3];
        plume_midedge_rest_point(m, rest_x, m->edges[2 * e], pa);
        plume_midedge_rest_point(m, rest_x, m->edges[2 * e + 1], pb);
        sub3(pb, pa, E);
        const double ee = dot3(E, E), re = dot3(b->r0 + 3 * e, E);
        for (int i = 0; i < 3; i++)
            d[i] = b->r0[3 * e + i] - re * E[i] / ee;
        const double dl = sqrt(dot3(d, d));
        if (!(dl > 1e-6))
            return plume_err_set(err, PLUME_EINVAL,
                                 rest_dir ? "midedge bending: rest director of edge %ld lies along the edge"
                                          : "midedge bending: edge %ld: its two rest faces are folded onto each other",
                                 (long)e);
        for (int i = 0; i < 3; i++)
            b->r0[3 * e + i] = d[i] / dl;
    }
    return PLUME_OK;
}

/* Triangle t's kernel numbers: c, K and (with the rest directors) s0. */
static plume_status build_face(const plume_mesh *m, const plume_bending_material *mat, const double *rest_x,
                               plume_midedge_bending *b, plume_index t, plume_err *err)
{
    plume_midedge_face *f = &b->face[t];
    const plume_index *v = m->tri + 3 * t;
    const double *P[3] = {m->X + 2 * v[0], m->X + 2 * v[1], m->X + 2 * v[2]};
    const double det = (P[1][0] - P[0][0]) * (P[2][1] - P[0][1]) - (P[2][0] - P[0][0]) * (P[1][1] - P[0][1]);
    double lsq = 0.0;
    for (int k = 0; k < 3; k++) {
        const double ex = P[(k + 2) % 3][0] - P[(k + 1) % 3][0], ey = P[(k + 2) % 3][1] - P[(k + 1) % 3][1];
        lsq = fmax(lsq, ex * ex + ey * ey);
    }
    if (!(det > MIDEDGE_DEGENERATE_REL * lsq))
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld is degenerate or clockwise in X", (long)t);
    const double A = 0.5 * det;
    double gl[3][2], N[3][2], l[3];
    for (int k = 0; k < 3; k++) {
        const double ex = P[(k + 2) % 3][0] - P[(k + 1) % 3][0], ey = P[(k + 2) % 3][1] - P[(k + 1) % 3][1];
        l[k] = hypot(ex, ey);
        gl[k][0] = -ey / det, gl[k][1] = ex / det; /* grad lambda_k: the edge turned inward */
        N[k][0] = ey / l[k], N[k][1] = -ex / l[k]; /* outward normal of the edge opposite k */
    }
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++)
            f->c[k][j] = gl[j][0] * N[k][0] + gl[j][1] * N[k][1];
    const double bn = hypot(m->barb_dir[2 * t], m->barb_dir[2 * t + 1]);
    const double d[2] = {m->barb_dir[2 * t] / bn, m->barb_dir[2 * t + 1] / bn}, dp[2] = {-d[1], d[0]};
    /* kappa = B s: column k is (l_k / A) ((N.d)^2, (N.dp)^2, (N.d)(N.dp)) */
    double B[3][3];
    for (int k = 0; k < 3; k++) {
        const double nd = N[k][0] * d[0] + N[k][1] * d[1], np = N[k][0] * dp[0] + N[k][1] * dp[1];
        B[0][k] = l[k] / A * nd * nd, B[1][k] = l[k] / A * np * np, B[2][k] = l[k] / A * nd * np;
    }
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            f->B[3 * r + k] = B[r][k];
    const double D66 = mat->D_twist > 0.0 ? mat->D_twist : fmax(0.0, 0.5 * (sqrt(mat->D_long * mat->D_trans) - mat->D_coupling));
    const double Dv[3][3] = {{mat->D_long, mat->D_coupling, 0.0}, {mat->D_coupling, mat->D_trans, 0.0}, {0.0, 0.0, 4.0 * D66}};
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++) {
            double s = 0.0;
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++)
                    s += B[r][a] * Dv[r][q] * B[q][c];
            f->K[3 * a + c] = A * s;
        }
    double xv[9];
    for (int k = 0; k < 3; k++)
        plume_midedge_rest_point(m, rest_x, v[k], xv + 3 * k);
    for (int k = 0; k < 3; k++) {
        f->s0[k] = 0.0;
        if (plume_midedge_face_slope(f, xv, k, 0.0, b->r0 + 3 * b->face_edge[3 * t + k], &f->s0[k]) != 0)
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: triangle %ld: rest slope undefined (a rest fold)",
                                 (long)t);
    }
    return PLUME_OK;
}

/* The anchored edges' frames, from the rest positions and the rest directors. */
static plume_status init_anchors(const plume_mesh *m, const double *rest_x, const plume_index *anchor,
                                 plume_midedge_bending *b, plume_err *err)
{
    double *rest = malloc(3 * (size_t)(m->nv > 0 ? m->nv : 1) * sizeof *rest);
    if (!rest)
        return plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory for the edges' anchors");
    for (plume_index v = 0; v < m->nv; v++)
        plume_midedge_rest_point(m, rest_x, v, rest + 3 * v);
    plume_status st = plume_midedge_anchors_init(&b->anchors, b->ne, b->nv, anchor, rest, b->r0, err);
    free(rest);
    return st;
}

plume_status plume_midedge_bending_create(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                          const double *rest_x, plume_midedge_bending **out, plume_err *err)
{
    return plume_midedge_bending_create_opts(mesh, mats, nmat, rest_x, NULL, out, err);
}

plume_status plume_midedge_bending_create_opts(const plume_mesh *mesh, const plume_bending_material *mats, int nmat,
                                               const double *rest_x, const plume_midedge_bending_opts *o,
                                               plume_midedge_bending **out, plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "midedge bending: out is NULL");
    *out = NULL;
    plume_status st = check_inputs(mesh, mats, nmat, rest_x, err);
    if (st != PLUME_OK)
        return st;
    plume_midedge_bending *b = calloc(1, sizeof *b);
    if (!b)
        return plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory");
    b->nv = mesh->nv, b->nt = mesh->nt, b->ne = mesh->ne;
    b->tri = malloc(sizeof(plume_index) * 3 * (size_t)b->nt);
    b->edges = malloc(sizeof(plume_index) * 2 * (size_t)(b->ne > 0 ? b->ne : 1));
    b->face_edge = malloc(sizeof(plume_index) * 3 * (size_t)b->nt);
    b->face = calloc((size_t)b->nt, sizeof *b->face);
    b->r0 = malloc(sizeof(double) * 3 * (size_t)(b->ne > 0 ? b->ne : 1));
    if (!b->tri || !b->edges || !b->face_edge || !b->face || !b->r0) {
        st = plume_err_set(err, PLUME_ENOMEM, "midedge bending: out of memory for %ld triangles", (long)b->nt);
        goto cleanup;
    }
    memcpy(b->tri, mesh->tri, sizeof(plume_index) * 3 * (size_t)b->nt);
    memcpy(b->edges, mesh->edges, sizeof(plume_index) * 2 * (size_t)b->ne);
    if ((st = build_slots(mesh, b, err)) != PLUME_OK || (st = rest_directors(mesh, rest_x, o ? o->rest_dir : NULL, b, err)) != PLUME_OK)
        goto cleanup;
    for (plume_index t = 0; t < b->nt; t++)
        if ((st = build_face(mesh, &mats[mesh->material[t]], rest_x, b, t, err)) != PLUME_OK)
            goto cleanup;
    if (o && o->anchor && (st = init_anchors(mesh, rest_x, o->anchor, b, err)) != PLUME_OK)
        goto cleanup;
    *out = b;
    return PLUME_OK;
cleanup:
    plume_midedge_bending_destroy(&b);
    return st;
}

void plume_midedge_bending_destroy(plume_midedge_bending **pb)
{
    if (!pb || !*pb)
        return;
    plume_midedge_bending *b = *pb;
    free(b->tri);
    free(b->edges);
    free(b->face_edge);
    free(b->face);
    free(b->r0);
    plume_midedge_anchors_free(&b->anchors);
    free(b);
    *pb = NULL;
}

plume_index plume_midedge_bending_nedge(const plume_midedge_bending *b) { return b->ne; }
plume_index plume_midedge_bending_nface(const plume_midedge_bending *b) { return b->nt; }
const plume_index *plume_midedge_bending_face_edges(const plume_midedge_bending *b) { return b->face_edge; }
const plume_midedge_face *plume_midedge_bending_face(const plume_midedge_bending *b, plume_index t) { return &b->face[t]; }

/* Edge e's reference vector at x: its anchors' frame (written in buf) when it has anchors, else
 * the stored one. */
static const double *edge_frame(const plume_midedge_bending *b, const double *x, plume_index e, double buf[3])
{
    return plume_midedge_anchors_frame(&b->anchors, x, e, buf) ? buf : b->r0 + 3 * e;
}

/* Triangle t's kernel inputs at (x, theta); rbuf holds the anchored edges' reference vectors. */
static void face_inputs(const plume_midedge_bending *b, const double *x, const double *theta, plume_index t,
                        double xv[9], double th[3], const double *r0[3], double rbuf[9])
{
    const plume_index *v = b->tri + 3 * t, *fe = b->face_edge + 3 * t;
    for (int k = 0; k < 3; k++) {
        memcpy(xv + 3 * k, x + 3 * v[k], 3 * sizeof(double));
        th[k] = theta[fe[k]];
        r0[k] = edge_frame(b, x, fe[k], rbuf + 3 * k);
    }
}

/* The error of a triangle whose kernel failed: PLUME_ESINGULAR, the energy undefined there (a
 * solver's trial point, which its line search then shortens, as it does for a degenerate triangle
 * of the other terms). */
static plume_status face_failed(plume_err *err, plume_index t)
{
    return plume_err_set(err, PLUME_ESINGULAR,
                         "midedge bending: triangle %ld has collapsed or a director has left its side", (long)t);
}

plume_status plume_midedge_bending_eval(const plume_midedge_bending *b, const double *x, const double *theta,
                                        double *energy, double *gx, double *gtheta, double *hblocks, int project,
                                        plume_err *err)
{
    double Esum = 0.0;
    for (plume_index t = 0; t < b->nt; t++) {
        const plume_index *v = b->tri + 3 * t, *fe = b->face_edge + 3 * t;
        double xv[9], th[3], E = 0.0, g[12];
        const double *r0[3];
        double rbuf[9];
        face_inputs(b, x, theta, t, xv, th, r0, rbuf);
        const int want_g = gx || gtheta;
        if (plume_midedge_face_eval(&b->face[t], xv, th, r0, &E, want_g ? g : NULL,
                                    hblocks ? hblocks + 144 * (size_t)t : NULL, project) != 0)
            return face_failed(err, t);
        Esum += E;
        for (int k = 0; k < 3 && want_g; k++) {
            if (gx)
                for (int i = 0; i < 3; i++)
                    gx[3 * v[k] + i] += g[3 * k + i];
            if (gtheta)
                gtheta[fe[k]] += g[9 + k];
        }
    }
    if (energy)
        *energy += Esum;
    return PLUME_OK;
}

plume_status plume_midedge_bending_blocks(const plume_midedge_bending *b, const double *x, const double *theta,
                                          plume_index first, plume_index count, double *hblocks, int project,
                                          plume_err *err)
{
    for (plume_index t = first; t < first + count; t++) {
        double xv[9], th[3], E = 0.0;
        const double *r0[3];
        double rbuf[9];
        face_inputs(b, x, theta, t, xv, th, r0, rbuf);
        if (plume_midedge_face_eval(&b->face[t], xv, th, r0, &E, NULL, hblocks + 144 * (size_t)(t - first), project) != 0)
            return face_failed(err, t);
    }
    return PLUME_OK;
}

plume_status plume_midedge_bending_energies(const plume_midedge_bending *b, const double *x, const double *theta,
                                            double *e, plume_err *err)
{
    for (plume_index t = 0; t < b->nt; t++) {
        double xv[9], th[3];
        const double *r0[3];
        double rbuf[9];
        face_inputs(b, x, theta, t, xv, th, r0, rbuf);
        e[t] = 0.0;
        if (plume_midedge_face_eval(&b->face[t], xv, th, r0, &e[t], NULL, NULL, 0) != 0)
            return face_failed(err, t);
    }
    return PLUME_OK;
}

plume_status plume_midedge_bending_curvatures(const plume_midedge_bending *b, const double *x, const double *theta,
                                              double *kappa, plume_err *err)
{
    for (plume_index t = 0; t < b->nt; t++) {
        double xv[9], th[3], rbuf[9], sl[3];
        const double *r0[3];
        face_inputs(b, x, theta, t, xv, th, r0, rbuf);
        for (int k = 0; k < 3; k++)
            if (plume_midedge_face_slope(&b->face[t], xv, k, th[k], r0[k], &sl[k]) != 0)
                return face_failed(err, t);
        const double *B = b->face[t].B;
        for (int r = 0; r < 3; r++)
            kappa[3 * t + r] = B[3 * r] * sl[0] + B[3 * r + 1] * sl[1] + B[3 * r + 2] * sl[2];
    }
    return PLUME_OK;
}

static void edge_vector(const plume_midedge_bending *b, const double *x, plume_index e, double E[3])
{
    const plume_index va = b->edges[2 * e], vb = b->edges[2 * e + 1];
    sub3(x + 3 * vb, x + 3 * va, E);
}

void plume_midedge_bending_director(const plume_midedge_bending *b, const double *x, const double *theta,
                                    plume_index e, double d[3])
{
    double E[3], buf[3];
    edge_vector(b, x, e, E);
    if (plume_midedge_director(E, theta[e], edge_frame(b, x, e, buf), d) != 0)
        d[0] = d[1] = d[2] = 0.0;
}

double plume_midedge_bending_angle_of(const plume_midedge_bending *b, const double *x, plume_index e,
                                      const double d[3])
{
    double E[3], buf[3];
    edge_vector(b, x, e, E);
    return plume_midedge_angle(E, edge_frame(b, x, e, buf), d);
}

plume_status plume_midedge_bending_lag(plume_midedge_bending *b, const double *x, plume_err *err)
{
    for (plume_index e = 0; e < b->ne; e++) {
        double E[3], r[3];
        if (plume_midedge_anchors_frame(&b->anchors, x, e, b->r0 + 3 * e))
            continue; /* the anchors' frame, perpendicular to the edge */
        edge_vector(b, x, e, E);
        /* at angle 0 the director is the normalised part of r0 perpendicular to the edge */
        if (plume_midedge_director(E, 0.0, b->r0 + 3 * e, r) != 0)
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: edge %ld has turned onto its reference vector",
                                 (long)e);
        memcpy(b->r0 + 3 * e, r, sizeof r);
    }
    return PLUME_OK;
}

plume_status plume_midedge_bending_rebase(plume_midedge_bending *b, const double *x, double *theta, plume_err *err)
{
    for (plume_index e = 0; e < b->ne; e++) {
        double E[3], d[3];
        if (plume_midedge_anchors_frame(&b->anchors, x, e, b->r0 + 3 * e))
            continue; /* measured from its anchors' frame: the angle stays */
        edge_vector(b, x, e, E);
        if (plume_midedge_director(E, theta[e], b->r0 + 3 * e, d) != 0)
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: edge %ld has turned onto its reference vector",
                                 (long)e);
        memcpy(b->r0 + 3 * e, d, sizeof d);
        theta[e] = 0.0;
    }
    return PLUME_OK;
}

const double *plume_midedge_bending_frames(const plume_midedge_bending *b) { return b->r0; }

plume_status plume_midedge_bending_set_frames(plume_midedge_bending *b, const double *r0, plume_err *err)
{
    for (plume_index e = 0; e < b->ne; e++) {
        const double n = sqrt(dot3(r0 + 3 * e, r0 + 3 * e));
        if (!(n > 0.0) || !isfinite(n))
            return plume_err_set(err, PLUME_EINVAL, "midedge bending: edge %ld: reference vector not finite or zero",
                                 (long)e);
    }
    memcpy(b->r0, r0, 3 * (size_t)b->ne * sizeof *b->r0);
    return PLUME_OK;
}
