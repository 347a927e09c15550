/* plume: per-triangle and per-barb-edge output fields, and their ParaView series. */
#include "fields.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/problem.h"
#include "../../lib/io/vtu.h"

#define PLUME_PI 3.14159265358979323846

struct plume_fields {
    const plume_mesh *mesh;
    int dim;
    plume_index nt_el, nbarb;
    plume_membrane_material *mats;
    int nmat;
    double *tensors;         /* [9 nmat] or NULL: the materials' plane-stress tensors (plume_fields_set_tensors) */
    plume_term bending;      /* .eval == NULL: none */
    plume_index *barb;       /* [2 nbarb] */
    double *barb_len;        /* [nbarb] rest lengths */
    double *dminv;           /* [4 nt_el] inverse of the reference edge matrix [X1 - X0, X2 - X0] */
    double *area0;           /* [nt_el] reference areas */
    double *x_rest;          /* [dim nv] for the displacement */
    double *e, *bend_stencil; /* [7 nt] the per-triangle outputs below; [bending nstencil] */
    double *strain, *stress, *psi_m, *psi_b, *J, *H, *bstrain;
    double *crease;          /* [nt] the crease angles (mean_curvature) */
    double *vcurv;           /* [2 nv] per vertex: the integrated curvature and the area it is spread on */
    double *points, *disp, *mat_id, *dir3; /* [3 nv], [3 nv], [nt], [3 nt] for writing */
    double *object_id;                     /* [nt] or NULL: the scene object of each triangle */
    plume_fields_curvature_fn curv_fn;     /* NULL, or the bending operator's curvatures */
    double *kappa;                         /* [3 nt] with curv_fn */
    /* the series */
    plume_pvd *pvd;
    char *dir, *stem;
    /* plume_fields_add_links: the term of p whose stencils are written as lines */
    plume_problem *links_p;
    char *links_term;
    double *link_state, *link_energy; /* [link_cap] */
    int *link_int;                    /* [link_cap] */
    plume_index link_cap;
};

void plume_fields_destroy(plume_fields **pf)
{
    if (!pf || !*pf)
        return;
    plume_fields *f = *pf;
    if (f->bending.destroy)
        f->bending.destroy(f->bending.ctx);
    free(f->mats);
    free(f->tensors);
    free(f->barb);
    free(f->barb_len);
    free(f->dminv);
    free(f->area0);
    free(f->x_rest);
    free(f->e);
    free(f->bend_stencil);
    free(f->points);
    free(f->disp);
    free(f->mat_id);
    free(f->object_id);
    free(f->kappa);
    free(f->dir3);
    free(f->crease);
    free(f->links_term);
    free(f->link_state);
    free(f->link_energy);
    free(f->link_int);
    free(f->vcurv);
    plume_pvd_destroy(&f->pvd);
    free(f->dir);
    free(f->stem);
    free(f);
    *pf = NULL;
}

/* The checks of plume_fields_create's arguments (bending: the term it was given, or zeroed). */
static plume_status check_fields_args(const plume_mesh *mesh, int dim, plume_index nt_elastic,
                                      const plume_membrane_material *mats, int nmat, const plume_term *bending,
                                      const plume_index *barb_edges, plume_index nbarb, plume_fields **out,
                                      plume_err *err)
{
    if (!out || !mesh || !mats || nmat < 1 || (dim != 2 && dim != 3) || nt_elastic < 0 || nt_elastic > mesh->nt ||
        nbarb < 0 || (nbarb > 0 && !barb_edges))
        return plume_err_set(err, PLUME_EINVAL, "fields: invalid arguments (mesh, dim 2 or 3, materials, elastic "
                                                "triangles in [0, nt], barb edges)");
    if (dim == 3 && mesh->nt > 0 && !mesh->edge_tri) /* curvature and hinges need the edges */
        return plume_err_set(err, PLUME_EINVAL, "fields: the shell mesh's topology is not built");
    if (bending->eval && !bending->energies)
        return plume_err_set(err, PLUME_EINVAL, "fields: the bending term '%s' cannot give its energies",
                             bending->name ? bending->name : "?");
    if (bending->eval && bending->nstencil != nt_elastic && bending->nstencil != mesh->nh)
        return plume_err_set(err, PLUME_EINVAL,
                             "fields: the bending term has %ld stencils, neither the %ld triangles nor the %ld hinges",
                             (long)bending->nstencil, (long)nt_elastic, (long)mesh->nh);
    for (plume_index t = 0; t < nt_elastic; t++)
        if (mesh->material[t] < 0 || mesh->material[t] >= nmat)
            return plume_err_set(err, PLUME_EINVAL, "fields: triangle %ld has material %d, outside [0, %d)", (long)t,
                                 mesh->material[t], nmat);
    for (plume_index k = 0; k < 2 * nbarb; k++)
        if (barb_edges[k] < 0 || barb_edges[k] >= mesh->nv)
            return plume_err_set(err, PLUME_EINVAL, "fields: barb edge %ld names vertex %ld of %ld", (long)(k / 2),
                                 (long)barb_edges[k], (long)mesh->nv);
    return PLUME_OK;
}

/* Every array of f (its mesh, dim, counts and bending term set), the per-triangle outputs as slices
 * of f->e; 0 when one is missing (plume_fields_destroy frees the others). */
static int fields_alloc(plume_fields *f)
{
    const plume_index nt = f->mesh->nt, nv = f->mesh->nv, nbarb = f->nbarb, nt_elastic = f->nt_el;
    const int dim = f->dim;
    f->mats = malloc((size_t)f->nmat * sizeof *f->mats);
    f->barb = malloc((size_t)(2 * nbarb + 1) * sizeof *f->barb);
    f->barb_len = malloc((size_t)(nbarb + 1) * sizeof *f->barb_len);
    f->dminv = malloc((size_t)(4 * nt_elastic + 1) * sizeof *f->dminv);
    f->area0 = malloc((size_t)(nt_elastic + 1) * sizeof *f->area0);
    f->x_rest = malloc((size_t)(dim * nv + 1) * sizeof *f->x_rest);
    f->e = malloc((size_t)(10 * nt + nbarb + 1) * sizeof *f->e);
    f->bend_stencil = malloc((size_t)(f->bending.nstencil + 1) * sizeof *f->bend_stencil);
    f->points = malloc((size_t)(3 * nv + 1) * sizeof *f->points);
    f->disp = malloc((size_t)(3 * nv + 1) * sizeof *f->disp);
    f->mat_id = malloc((size_t)(nt + 1) * sizeof *f->mat_id);
    f->dir3 = malloc((size_t)(3 * nt + 1) * sizeof *f->dir3);
    f->crease = malloc((size_t)(nt + 1) * sizeof *f->crease);
    f->vcurv = malloc((size_t)(2 * nv + 1) * sizeof *f->vcurv);
    if (!f->mats || !f->barb || !f->barb_len || !f->dminv || !f->area0 || !f->x_rest || !f->e || !f->bend_stencil ||
        !f->points || !f->disp || !f->mat_id || !f->dir3 || !f->crease || !f->vcurv)
        return 0;
    f->strain = f->e, f->stress = f->e + 3 * nt, f->psi_m = f->e + 6 * nt, f->psi_b = f->e + 7 * nt;
    f->J = f->e + 8 * nt, f->H = f->e + 9 * nt, f->bstrain = f->e + 10 * nt;
    return 1;
}

/* The reference state f measures against: the barb edges' rest lengths, each elastic triangle's
 * inverse edge matrix and area, the rest positions, and the materials and barb directions written. */
static plume_status reference_state(plume_fields *f, const plume_membrane_material *mats,
                                    const plume_index *barb_edges, plume_err *err)
{
    const plume_mesh *mesh = f->mesh;
    const int dim = f->dim;
    memcpy(f->mats, mats, (size_t)f->nmat * sizeof *mats);
    if (f->nbarb > 0)
        memcpy(f->barb, barb_edges, (size_t)(2 * f->nbarb) * sizeof *barb_edges);
    for (plume_index b = 0; b < f->nbarb; b++) {
        plume_index a = barb_edges[2 * b], c = barb_edges[2 * b + 1];
        f->barb_len[b] = hypot(mesh->X[2 * c] - mesh->X[2 * a], mesh->X[2 * c + 1] - mesh->X[2 * a + 1]);
        if (!(f->barb_len[b] > 0.0))
            return plume_err_set(err, PLUME_EINVAL, "fields: barb edge %ld has zero rest length", (long)b);
    }
    for (plume_index t = 0; t < f->nt_el; t++) {
        const plume_index *v = mesh->tri + 3 * t;
        double a = mesh->X[2 * v[1]] - mesh->X[2 * v[0]], c = mesh->X[2 * v[2]] - mesh->X[2 * v[0]];
        double b = mesh->X[2 * v[1] + 1] - mesh->X[2 * v[0] + 1], d = mesh->X[2 * v[2] + 1] - mesh->X[2 * v[0] + 1];
        double det = a * d - b * c; /* [[a, c], [b, d]]: columns X1 - X0, X2 - X0 */
        if (!(det != 0.0))
            return plume_err_set(err, PLUME_EINVAL, "fields: triangle %ld has zero reference area", (long)t);
        f->dminv[4 * t] = d / det, f->dminv[4 * t + 1] = -c / det;
        f->dminv[4 * t + 2] = -b / det, f->dminv[4 * t + 3] = a / det;
        f->area0[t] = 0.5 * fabs(det);
    }
    for (plume_index v = 0; v < mesh->nv; v++)
        for (int i = 0; i < dim; i++)
            f->x_rest[dim * v + i] = mesh->dim == dim && mesh->x ? mesh->x[dim * v + i] : i < 2 ? mesh->X[2 * v + i] : 0.0;
    for (plume_index t = 0; t < mesh->nt; t++) {
        f->mat_id[t] = mesh->material[t];
        f->dir3[3 * t] = mesh->barb_dir[2 * t], f->dir3[3 * t + 1] = mesh->barb_dir[2 * t + 1], f->dir3[3 * t + 2] = 0.0;
    }
    return PLUME_OK;
}

plume_status plume_fields_create(const plume_mesh *mesh, int dim, plume_index nt_elastic,
                                 const plume_membrane_material *mats, int nmat, plume_term *bending,
                                 const plume_index *barb_edges, plume_index nbarb, plume_fields **out,
                                 plume_err *err)
{
    plume_term owned = {.size = sizeof(plume_term)};
    if (bending) { /* taken whatever happens */
        owned = *bending;
        memset(bending, 0, sizeof *bending);
    }
    plume_status st = PLUME_OK;
    plume_fields *f = NULL;
    if (out)
        *out = NULL;
    if ((st = check_fields_args(mesh, dim, nt_elastic, mats, nmat, &owned, barb_edges, nbarb, out, err)) != PLUME_OK)
        goto fail;
    f = calloc(1, sizeof *f);
    if (!f) {
        st = PLUME_ENOMEM;
        goto fail;
    }
    f->mesh = mesh, f->dim = dim, f->nt_el = nt_elastic, f->nbarb = nbarb, f->nmat = nmat;
    f->bending = owned;
    memset(&owned, 0, sizeof owned);
    if (!fields_alloc(f)) {
        st = PLUME_ENOMEM;
        goto fail;
    }
    if ((st = reference_state(f, mats, barb_edges, err)) != PLUME_OK)
        goto fail;
    *out = f;
    return PLUME_OK;
fail:
    if (owned.destroy)
        owned.destroy(owned.ctx);
    plume_fields_destroy(&f);
    if (st == PLUME_ENOMEM)
        plume_err_set(err, st, "fields: out of memory");
    return st;
}

static void sub3(const double *a, const double *b, double *o)
{
    o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2];
}

static void cross(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* the unnormalised normal of triangle t (CCW order) at positions x (3 nv) */
static void tri_normal(const plume_mesh *m, plume_index t, const double *x, double *n)
{
    const plume_index *v = m->tri + 3 * t;
    double a[3], b[3];
    sub3(x + 3 * v[1], x + 3 * v[0], a);
    sub3(x + 3 * v[2], x + 3 * v[0], b);
    cross(a, b, n);
}

/* Mean curvature from the dihedral angles theta of the interior edges (both sides elastic): each
 * edge's integrated curvature theta |e| / 2 goes half to each of its end vertices, a vertex's
 * value is its sum over a third of the deformed area of its triangles, and a triangle's is the
 * mean of its vertices'. The total, sum of H times area, is sum theta |e| / 2 as with a division
 * by each triangle's own area, but a sliver (the outline's, where the mesher leaves thin
 * triangles) no longer divides an edge's angle by its near-zero area: on the shipped feather that
 * gave single cells 10^3 times the median. An edge whose |theta| exceeds pi / 2 is a crease (a
 * triangle folded over its neighbour), not the bend of a smooth surface: it is left out and its
 * angle reported in crease[] of both triangles (the largest; 0 elsewhere). */
static void mean_curvature(plume_fields *f, const double *x)
{
    const plume_mesh *m = f->mesh;
    for (plume_index t = 0; t < f->nt_el; t++)
        f->H[t] = 0.0, f->crease[t] = 0.0;
    for (plume_index t = f->nt_el; t < m->nt; t++)
        f->crease[t] = NAN;
    if (f->dim != 3)
        return;
    double *hv = f->vcurv, *av = f->vcurv + m->nv;
    for (plume_index v = 0; v < 2 * m->nv; v++)
        f->vcurv[v] = 0.0;
    for (plume_index t = 0; t < f->nt_el; t++) {
        double n[3];
        tri_normal(m, t, x, n);
        double third = sqrt(dot(n, n)) / 6.0;
        for (int k = 0; k < 3; k++)
            av[m->tri[3 * t + k]] += third;
    }
    for (plume_index e = 0; e < m->ne; e++) {
        plume_index t0 = m->edge_tri[2 * e], t1 = m->edge_tri[2 * e + 1];
        if (t1 < 0 || t0 >= f->nt_el || t1 >= f->nt_el)
            continue;
        plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
        /* the edge's direction as triangle t0 runs it (counter-clockwise) */
        const plume_index *v = m->tri + 3 * t0;
        int forward = (v[0] == a && v[1] == b) || (v[1] == a && v[2] == b) || (v[2] == a && v[0] == b);
        double n0[3], n1[3], ed[3], c[3];
        tri_normal(m, t0, x, n0);
        tri_normal(m, t1, x, n1);
        sub3(x + 3 * b, x + 3 * a, ed);
        double len = sqrt(dot(ed, ed)), l0 = sqrt(dot(n0, n0)), l1 = sqrt(dot(n1, n1));
        if (!(len > 0.0) || !(l0 > 0.0) || !(l1 > 0.0))
            continue;
        cross(n0, n1, c);
        /* positive where the surface bends away from its normals (a cylinder or sphere with
         * outward normals: +1/(2R) or +1/R) */
        double theta = atan2((forward ? 1.0 : -1.0) * dot(c, ed) / len, dot(n0, n1));
        if (fabs(theta) > 0.5 * PLUME_PI) {
            f->crease[t0] = fmax(f->crease[t0], fabs(theta));
            f->crease[t1] = fmax(f->crease[t1], fabs(theta));
            continue;
        }
        double share = 0.25 * theta * len;
        hv[a] += share;
        hv[b] += share;
    }
    for (plume_index t = 0; t < f->nt_el; t++) {
        double h = 0.0;
        for (int k = 0; k < 3; k++) {
            plume_index w = m->tri[3 * t + k];
            h += av[w] > 0.0 ? hv[w] / av[w] : 0.0;
        }
        f->H[t] = h / 3.0;
    }
}

plume_status plume_fields_compute(plume_fields *f, const double *x, plume_field_values *out, plume_err *err)
{
    if (!f || !x || !out)
        return plume_err_set(err, PLUME_EINVAL, "fields: invalid arguments");
    const plume_mesh *m = f->mesh;
    const int dim = f->dim;
    plume_index nt = m->nt;
    for (plume_index k = 0; k < 10 * nt; k++)
        f->e[k] = NAN;
    for (plume_index t = 0; t < f->nt_el; t++) {
        const plume_index *v = m->tri + 3 * t;
        const double *Di = f->dminv + 4 * t;
        double F[6];
        for (int i = 0; i < dim; i++) {
            double p = x[dim * v[1] + i] - x[dim * v[0] + i], q = x[dim * v[2] + i] - x[dim * v[0] + i];
            F[2 * i] = p * Di[0] + q * Di[2];
            F[2 * i + 1] = p * Di[1] + q * Di[3];
        }
        const plume_membrane_material *mat = &f->mats[m->material[t]];
        const double *d = m->barb_dir + 2 * t;
        const double *C = f->tensors ? f->tensors + 9 * m->material[t] : NULL;
        plume_status st = plume_membrane_strain_stress_tensor(mat, C, dim, F, d, f->strain + 3 * t, f->stress + 3 * t,
                                                              &f->J[t]);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "fields: triangle %ld: bad barb direction or material", (long)t);
        f->psi_m[t] = plume_membrane_density_tensor(mat, C, dim, F, d);
        f->psi_b[t] = 0.0;
    }
    if (f->bending.eval) {
        plume_status st = f->bending.energies(f->bending.ctx, dim, x, f->bend_stencil);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "fields: the bending energies are undefined here (%s)", plume_strerror(st));
        if (f->bending.nstencil == f->nt_el) {
            for (plume_index t = 0; t < f->nt_el; t++)
                f->psi_b[t] = f->bend_stencil[t] / f->area0[t];
        } else { /* hinges: the k-th interior edge, half its energy to each side */
            plume_index h = 0;
            for (plume_index e = 0; e < m->ne; e++) {
                plume_index t0 = m->edge_tri[2 * e], t1 = m->edge_tri[2 * e + 1];
                if (t1 < 0)
                    continue;
                double half = 0.5 * f->bend_stencil[h++];
                if (t0 < f->nt_el)
                    f->psi_b[t0] += half / f->area0[t0];
                if (t1 < f->nt_el)
                    f->psi_b[t1] += half / f->area0[t1];
            }
        }
    }
    mean_curvature(f, x);
    if (f->curv_fn) {
        plume_status st = f->curv_fn(f->bending.ctx, dim, x, f->kappa);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "fields: the bending curvatures are undefined here (%s)", plume_strerror(st));
        for (plume_index k = 3 * f->nt_el; k < 3 * m->nt; k++)
            f->kappa[k] = NAN;
    }
    for (plume_index b = 0; b < f->nbarb; b++) {
        const double *xa = x + dim * f->barb[2 * b], *xb = x + dim * f->barb[2 * b + 1];
        double s = 0.0;
        for (int i = 0; i < dim; i++)
            s += (xb[i] - xa[i]) * (xb[i] - xa[i]);
        f->bstrain[b] = sqrt(s) / f->barb_len[b] - 1.0;
    }
    out->nt = nt, out->nbarb = f->nbarb;
    out->green_strain = f->strain, out->stress = f->stress, out->membrane_energy = f->psi_m;
    out->bending_energy = f->psi_b, out->J = f->J, out->mean_curvature = f->H, out->barb_strain = f->bstrain;
    out->crease_angle = f->crease;
    out->curvature = f->curv_fn ? f->kappa : NULL;
    return PLUME_OK;
}

plume_status plume_fields_series_start(plume_fields *f, const char *dir, const char *pvd_name, const char *stem,
                                       double resume_until, plume_err *err)
{
    if (!f || !dir || !*dir || !stem || !*stem || strchr(stem, '/') || !pvd_name || !*pvd_name)
        return plume_err_set(err, PLUME_EINVAL, "fields: a directory, a collection name and a stem without '/' are needed");
    plume_pvd_destroy(&f->pvd);
    free(f->dir);
    free(f->stem);
    f->dir = strdup(dir), f->stem = strdup(stem);
    size_t len = strlen(dir) + strlen(pvd_name) + 8;
    char *path = malloc(len);
    if (!f->dir || !f->stem || !path) {
        free(path);
        return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
    }
    snprintf(path, len, "%s/%s", dir, pvd_name);
    plume_status st = plume_pvd_create(path, &f->pvd, err);
    if (st == PLUME_OK && resume_until >= 0.0) {
        plume_pvd_entries old;
        plume_err e2 = {{0}};
        if (plume_pvd_read(path, &old, &e2) == PLUME_OK) { /* no collection yet: nothing to keep */
            for (int i = 0; i < old.n && st == PLUME_OK; i++)
                if (old.times[i] <= resume_until * (1.0 + 1e-12) + 1e-300)
                    st = plume_pvd_add(f->pvd, old.times[i], old.parts[i], old.files[i], err);
            plume_pvd_entries_free(&old);
        }
    }
    free(path);
    return st;
}

plume_status plume_fields_set_tensors(plume_fields *f, const double *tensors, plume_err *err)
{
    if (!f || !tensors)
        return plume_err_set(err, PLUME_EINVAL, "fields: no tensors given");
    double *t = realloc(f->tensors, (size_t)(9 * f->nmat) * sizeof *t);
    if (!t)
        return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
    memcpy(t, tensors, (size_t)(9 * f->nmat) * sizeof *t);
    f->tensors = t;
    return PLUME_OK;
}

plume_status plume_fields_set_objects(plume_fields *f, int nobjects, const plume_index *t0, const plume_index *nt,
                                      plume_err *err)
{
    if (!f || nobjects < 1 || !t0 || !nt)
        return plume_err_set(err, PLUME_EINVAL, "fields: invalid object arguments");
    const plume_index ntri = f->mesh->nt;
    for (int i = 0; i < nobjects; i++)
        if (t0[i] < 0 || nt[i] < 0 || t0[i] + nt[i] > ntri)
            return plume_err_set(err, PLUME_EINVAL, "fields: object %d's triangles [%ld, %ld) are outside the mesh's %ld",
                                 i, (long)t0[i], (long)(t0[i] + nt[i]), (long)ntri);
    double *id = malloc((size_t)(ntri + 1) * sizeof *id);
    if (!id)
        return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
    for (plume_index t = 0; t < ntri; t++)
        id[t] = -1.0;
    for (int i = 0; i < nobjects; i++)
        for (plume_index t = t0[i]; t < t0[i] + nt[i]; t++)
            id[t] = (double)i;
    free(f->object_id);
    f->object_id = id;
    return PLUME_OK;
}

plume_status plume_fields_set_curvatures(plume_fields *f, plume_fields_curvature_fn fn, plume_err *err)
{
    if (!f || !fn || !f->bending.eval)
        return plume_err_set(err, PLUME_EINVAL, "fields: curvatures need a bending term and a function");
    double *k = malloc((size_t)(3 * f->mesh->nt + 1) * sizeof *k);
    if (!k)
        return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
    free(f->kappa);
    f->kappa = k, f->curv_fn = fn;
    return PLUME_OK;
}

plume_status plume_fields_add_links(plume_fields *f, plume_problem *p, const char *term, plume_err *err)
{
    if (!f || !p || !term)
        return plume_err_set(err, PLUME_EINVAL, "fields: links need a problem and a term name");
    const plume_term *tt = plume_problem_term(p, term);
    if (!tt || tt->arity != 2)
        return plume_err_set(err, PLUME_EINVAL, "fields: the problem has no term \"%s\" of arity 2 to write as links",
                             term);
    free(f->links_term);
    if (!(f->links_term = strdup(term)))
        return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
    f->links_p = p;
    return PLUME_OK;
}

/* The links' file of a frame (plume_fields_add_links): the term's stencils (as they are at this
 * frame) as lines, with their states and energies at x. */
static plume_status write_links(plume_fields *f, long index, double t, const double *x, const plume_vtu_field *pf,
                                char *path, char *name, size_t len, plume_err *err)
{
    const plume_term *tt = plume_problem_term(f->links_p, f->links_term);
    if (!tt)
        return plume_err_set(err, PLUME_EINVAL, "fields: the links' term \"%s\" is gone", f->links_term);
    const plume_index n = tt->nstencil;
    if (n + 1 > f->link_cap) {
        double *s = realloc(f->link_state, (size_t)(n + 1) * sizeof *s);
        if (s)
            f->link_state = s;
        double *e = realloc(f->link_energy, (size_t)(n + 1) * sizeof *e);
        if (e)
            f->link_energy = e;
        int *k = realloc(f->link_int, (size_t)(n + 1) * sizeof *k);
        if (k)
            f->link_int = k;
        if (!s || !e || !k)
            return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
        f->link_cap = n + 1;
    }
    plume_status st = PLUME_OK;
    for (plume_index i = 0; i < n; i++)
        f->link_int[i] = 1, f->link_energy[i] = 0.0;
    if (tt->states && (st = tt->states(tt->ctx, f->link_int)) != PLUME_OK)
        return plume_err_set(err, st, "fields: the states of term \"%s\" failed", f->links_term);
    if (tt->energies && (st = tt->energies(tt->ctx, f->dim, x, f->link_energy)) != PLUME_OK)
        return plume_err_set(err, st, "fields: the energies of term \"%s\" failed", f->links_term);
    for (plume_index i = 0; i < n; i++)
        f->link_state[i] = f->link_int[i];
    const plume_vtu_field lf[] = {{"state", 1, 1, f->link_state}, {"energy", 1, 0, f->link_energy}};
    plume_vtu_grid gl = {f->mesh->nv, f->points, PLUME_VTU_LINE, n, tt->stencil, 1, 2, pf, lf, t};
    snprintf(name, len, "%s_%s_%05ld.vtu", f->stem, f->links_term, index);
    snprintf(path, len, "%s/%s", f->dir, name);
    if ((st = plume_vtu_write(path, &gl, err)) != PLUME_OK)
        return st;
    return plume_pvd_add(f->pvd, t, 2, name, err);
}

plume_status plume_fields_series_frame(plume_fields *f, long index, double t, const double *x, plume_err *err)
{
    if (!f || !x || index < 0 || !isfinite(t))
        return plume_err_set(err, PLUME_EINVAL, "fields: invalid frame arguments");
    if (!f->pvd)
        return plume_err_set(err, PLUME_EINVAL, "fields: no series started (plume_fields_series_start)");
    plume_field_values fv;
    plume_status st = plume_fields_compute(f, x, &fv, err);
    if (st != PLUME_OK)
        return st;
    const plume_mesh *m = f->mesh;
    const int dim = f->dim;
    for (plume_index v = 0; v < m->nv; v++)
        for (int i = 0; i < 3; i++) {
            f->points[3 * v + i] = i < dim ? x[dim * v + i] : 0.0;
            f->disp[3 * v + i] = i < dim ? x[dim * v + i] - f->x_rest[dim * v + i] : 0.0;
        }
    const plume_vtu_field pf[] = {{"displacement", 3, 0, f->disp}};
    plume_vtu_field cf[11] = {{"material", 1, 1, f->mat_id},
                              {"barb_direction", 3, 0, f->dir3},
                              {"green_strain_barb", 3, 0, fv.green_strain},
                              {"stress_barb", 3, 0, fv.stress},
                              {"membrane_energy_density", 1, 0, fv.membrane_energy},
                              {"bending_energy_density", 1, 0, fv.bending_energy},
                              {"J", 1, 0, fv.J},
                              {"mean_curvature", 1, 0, fv.mean_curvature},
                              {"crease_angle", 1, 0, fv.crease_angle}};
    int ncf = 9; /* then the bending operator's curvature and the objects, when there are */
    if (fv.curvature)
        cf[ncf++] = (plume_vtu_field){"curvature_barb", 3, 0, fv.curvature};
    if (f->object_id)
        cf[ncf++] = (plume_vtu_field){"object", 1, 1, f->object_id};
    plume_vtu_grid g = {m->nv, f->points, PLUME_VTU_TRIANGLE, m->nt, m->tri, 1, ncf, pf, cf, t};
    size_t len = strlen(f->dir) + strlen(f->stem) + (f->links_term ? strlen(f->links_term) : 0) + 64;
    char *path = malloc(len), *name = malloc(len);
    if (!path || !name) {
        free(path);
        free(name);
        return plume_err_set(err, PLUME_ENOMEM, "fields: out of memory");
    }
    snprintf(name, len, "%s_%05ld.vtu", f->stem, index);
    snprintf(path, len, "%s/%s", f->dir, name);
    st = plume_vtu_write(path, &g, err);
    if (st == PLUME_OK)
        st = plume_pvd_add(f->pvd, t, 0, name, err);
    if (st == PLUME_OK && f->nbarb > 0) {
        const plume_vtu_field bf[] = {{"barb_strain", 1, 0, fv.barb_strain}};
        plume_vtu_grid gb = {m->nv, f->points, PLUME_VTU_LINE, f->nbarb, f->barb, 1, 1, pf, bf, t};
        snprintf(name, len, "%s_barbs_%05ld.vtu", f->stem, index);
        snprintf(path, len, "%s/%s", f->dir, name);
        st = plume_vtu_write(path, &gb, err);
        if (st == PLUME_OK)
            st = plume_pvd_add(f->pvd, t, 1, name, err);
    }
    if (st == PLUME_OK && f->links_p)
        st = write_links(f, index, t, x, pf, path, name, len, err);
    free(path);
    free(name);
    return st;
}
