/* The plate bending test of macro/shell/plate_bending.h and the homogeneous plate specimen. */
#include "plate_bending.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../lib/core/load.h"
#include "../../lib/core/opts.h"
#include "../../lib/io/progress.h"
#include "../../lib/solve/options.h"
#include "patch_mesh.h"
#include "shape_bending.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void plume_bend_opts_default_sized(plume_bend_opts *o, size_t size)
{
    static const plume_bend_opts full = {.size = sizeof full,
                                         .load = PLUME_BEND_CYLINDER,
                                         .lx = 1.0,
                                         .ly = 2.0,
                                         .moment = 1.0,
                                         .steps = 3,
                                         .loading = PLUME_BEND_EDGE_MOMENTS,
                                         .end_strip = 0.1,
                                         .window = 0.5,
                                         .max_rotation = 0.2,
                                         .solver = PLUME_SOLVER_NEWTON};
    plume_opts_give(o, size, &full, sizeof full);
}

const char *plume_bend_load_name(plume_bend_load k)
{
    return k == PLUME_BEND_TWIST ? "twist" : "cylinder";
}

plume_status plume_bend_load_parse(const char *s, plume_bend_load *k)
{
    if (s && strcmp(s, "cylinder") == 0)
        *k = PLUME_BEND_CYLINDER;
    else if (s && strcmp(s, "twist") == 0)
        *k = PLUME_BEND_TWIST;
    else
        return PLUME_EINVAL;
    return PLUME_OK;
}

void plume_bend_result_free(plume_bend_result *r)
{
    if (!r)
        return;
    plume_bend_curve_free(&r->curve);
    memset(r, 0, sizeof *r);
}

/* Solves the symmetric n x n system A z = b in place (Gaussian elimination with partial pivoting);
 * 0 when singular relative to its largest diagonal entry. */
static int solve_small(int n, double *A, double *b)
{
    double big = 0.0;
    for (int i = 0; i < n; i++)
        big = fmax(big, fabs(A[i * n + i]));
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r * n + c]) > fabs(A[piv * n + c]))
                piv = r;
        if (!(fabs(A[piv * n + c]) > 1e-13 * big))
            return 0;
        if (piv != c) {
            for (int k = 0; k < n; k++) {
                double t = A[c * n + k];
                A[c * n + k] = A[piv * n + k], A[piv * n + k] = t;
            }
            double t = b[c];
            b[c] = b[piv], b[piv] = t;
        }
        for (int r = c + 1; r < n; r++) {
            double f = A[r * n + c] / A[c * n + c];
            for (int k = c; k < n; k++)
                A[r * n + k] -= f * A[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; c--) {
        for (int k = c + 1; k < n; k++)
            b[c] -= A[c * n + k] * b[k];
        b[c] /= A[c * n + c];
    }
    return 1;
}

/* The forces of one end strip (vertices v[0..n), lumped areas area[]) whose moment is (mx, my)
 * about the strip's centroid with no resultant, written as z components into f (3 per vertex). */
static int strip_forces(const plume_mesh *m, const plume_index *v, plume_index n, const double *area, double mx,
                        double my, double *f)
{
    double A = 0.0, xc = 0.0, yc = 0.0;
    for (plume_index i = 0; i < n; i++) {
        A += area[v[i]];
        xc += area[v[i]] * m->X[2 * v[i]];
        yc += area[v[i]] * m->X[2 * v[i] + 1];
    }
    if (!(A > 0.0))
        return 0;
    xc /= A, yc /= A;
    double N[9] = {0}, b[3] = {0.0, -my, mx};
    for (plume_index i = 0; i < n; i++) {
        const double a = area[v[i]], phi[3] = {1.0, m->X[2 * v[i]] - xc, m->X[2 * v[i] + 1] - yc};
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                N[3 * r + c] += a * phi[r] * phi[c];
    }
    if (!solve_small(3, N, b))
        return 0;
    for (plume_index i = 0; i < n; i++) {
        const double a = area[v[i]];
        f[3 * i] = f[3 * i + 1] = 0.0;
        f[3 * i + 2] = a * (b[0] + b[1] * (m->X[2 * v[i]] - xc) + b[2] * (m->X[2 * v[i] + 1] - yc));
    }
    return 1;
}

/* The edge moments of the uniform state (plume_bend_loading PLUME_BEND_EDGE_MOMENTS): the forces
 * f = grad_z W of the work W(z) = sum_T A_T mbar . kappa_T(z) of a uniform moment mbar (specimen
 * frame: (m_xx, m_yy, m_xy), m_xy work-conjugate to 2 k_xy) on the shell's own shape-operator
 * curvatures kappa_T (macro/shell/shape_bending.h). The discrete divergence theorem of those curvatures
 * (the patch test) puts W on the boundary: the continuum's int mbar : grad grad w dA is the edge
 * moment m_yy int w_,y dx at the two ends for the cylinder, and 2 m_xy times the alternating sum of
 * the corner deflections (the Kirchhoff corner forces) for the twist; nothing loads the interior.
 * W is built from a homogeneous stand-in plate on the same mesh, the isotropic D0 = diag(1, 1, 1/2)
 * (D_long = D_trans = 1, nu = 0, D_twist = 1/2: isotropic, so the triangles' barb directions do not
 * enter). The gradient of its energy at the uniform curvature kappa* = D0^-1 mbar is
 * sum_T A_T (D0 kappa*) . dkappa_T / dz = grad W, because the shape operator reproduces every
 * quadratic (kappa_T = kappa* in every triangle).
 * The stand-in's energy is even in z, so its gradient at eps z* is eps grad W up to O(eps^3): with
 * slopes of 1e-5 that is 1e-10 relative. W vanishes on rigid motions (a plane has no curvature),
 * so the forces have no resultant and the three held vertices carry no reaction. For a homogeneous
 * plate of any D the uniform state D^-1 mbar is then the discrete solution itself, on any mesh:
 * the distributed end-strip loads are not, and a strongly orthotropic plate (D_trans ~ 1e-5 D_long)
 * turns their small departure into large transverse modes (docs/bending-homogenisation.md).
 * With `phases` (PLUME_BEND_UNIFORM_CURVATURE) the stand-in is the specimen's own energy instead,
 * each material with its moduli: the gradient at the uniform curvature is then the work of each
 * phase's own moment D_i kappa*, the uniform-curvature state's loads. They land on the boundary,
 * plus the phase interfaces wherever the uniform curvature is not the specimen's equilibrium. */
static plume_status edge_moment_forces(const plume_mesh *mesh, const plume_bending_material *phases,
                                       plume_bend_load load, double moment, double L, double *f, plume_err *err)
{
    const plume_index nv = mesh->nv;
    int nmat = 1;
    for (plume_index t = 0; t < mesh->nt; t++)
        if (mesh->material[t] + 1 > nmat)
            nmat = mesh->material[t] + 1;
    plume_bending_material *unit = malloc((size_t)nmat * sizeof *unit);
    double *x = malloc((size_t)(3 * nv) * sizeof *x);
    plume_term t;
    memset(&t, 0, sizeof t);
    plume_status st = PLUME_OK;
    if (!unit || !x) {
        st = plume_err_set(err, PLUME_ENOMEM, "bending test: out of memory");
        goto cleanup;
    }
    for (int i = 0; i < nmat; i++)
        unit[i] = phases ? phases[i]
                         : (plume_bending_material){.D_long = 1.0, .D_trans = 1.0, .D_coupling = 0.0, .D_twist = 0.5};
    const plume_shape_bending_opts so = {.phase_aware = 1}; /* plume_shell_specimen's stencils */
    if ((st = plume_shape_bending_term_create_opts(mesh, unit, nmat, NULL, &so, &t, err)) != PLUME_OK)
        goto cleanup;
    /* z* = eps 1/2 m_yy y^2 (kappa* = (0, m_yy, 0)) or eps m_xy x y (2 k_xy = 2 m_xy), eps so that
     * the largest slope is about 1e-5 */
    const double eps = 1e-5 / (moment * L);
    for (plume_index v = 0; v < nv; v++) {
        const double X = mesh->X[2 * v], Y = mesh->X[2 * v + 1];
        x[3 * v] = X, x[3 * v + 1] = Y;
        x[3 * v + 2] = eps * moment * (load == PLUME_BEND_CYLINDER ? 0.5 * Y * Y : X * Y);
    }
    memset(f, 0, (size_t)(3 * nv) * sizeof *f);
    if ((st = t.eval(t.ctx, 3, x, NULL, f, NULL, 0)) != PLUME_OK) {
        plume_err_set(err, st, "bending test: the edge moments: the shape operator failed (%s)", plume_strerror(st));
        goto cleanup;
    }
    for (plume_index v = 0; v < nv; v++)
        f[3 * v] = f[3 * v + 1] = 0.0, f[3 * v + 2] /= eps;
cleanup:
    if (t.destroy)
        t.destroy(t.ctx);
    free(unit), free(x);
    return st;
}

/* The moment the loads f (z components) carry across the specimen's middle y = ly / 2: the moment
 * about the x axis (cylinder) or the torque about the y axis (twist) of the forces on the far half. */
static double section_moment(const plume_mesh *mesh, const plume_bend_opts *o, const double *f)
{
    const double cx = 0.5 * o->lx, cy = 0.5 * o->ly;
    double s = 0.0;
    for (plume_index v = 0; v < mesh->nv; v++)
        if (mesh->X[2 * v + 1] > cy)
            s += f[3 * v + 2] * (o->load == PLUME_BEND_TWIST ? mesh->X[2 * v] - cx : mesh->X[2 * v + 1] - cy);
    return s;
}

/* PLUME_BEND_UNIFORM_CURVATURE: f holds the edge moments on entry; on return, the uniform-curvature
 * state's loads of the specimen's own energy (o->phases) on the boundary vertices, scaled to carry
 * the same moment across the middle as the edge moments (the nominal m of the test). The interior
 * forces are not applied: *residual is the largest over the largest boundary force. */
static plume_status uniform_curvature_forces(const plume_mesh *mesh, const plume_bend_opts *o, double *f,
                                             double *residual, plume_err *err)
{
    int nmat = 1;
    for (plume_index t = 0; t < mesh->nt; t++)
        if (mesh->material[t] + 1 > nmat)
            nmat = mesh->material[t] + 1;
    if (!o->phases || o->nphases < nmat)
        return plume_err_set(err, PLUME_EINVAL,
                             "bending test: the uniform-curvature loads need phases for the mesh's %d materials (got %d)",
                             nmat, o->phases ? o->nphases : 0);
    const plume_index nv = mesh->nv;
    double *g = malloc((size_t)(3 * nv) * sizeof *g);
    if (!g)
        return plume_err_set(err, PLUME_ENOMEM, "bending test: out of memory");
    plume_status st = edge_moment_forces(mesh, o->phases, o->load, o->moment, fmax(o->lx, o->ly), g, err);
    if (st != PLUME_OK) {
        free(g);
        return st;
    }
    const double tol = 1e-9 * fmax(o->lx, o->ly);
    double fb = 0.0, fi = 0.0;
    for (plume_index v = 0; v < nv; v++) {
        const double X = mesh->X[2 * v], Y = mesh->X[2 * v + 1];
        const int edge = X <= tol || X >= o->lx - tol || Y <= tol || Y >= o->ly - tol;
        if (edge)
            fb = fmax(fb, fabs(g[3 * v + 2]));
        else
            fi = fmax(fi, fabs(g[3 * v + 2])), g[3 * v + 2] = 0.0;
    }
    const double want = section_moment(mesh, o, f), have = section_moment(mesh, o, g);
    if (!(fb > 0.0) || !(want / have > 0.0)) {
        free(g);
        return plume_err_set(err, PLUME_EINVAL, "bending test: the uniform-curvature loads carry no %s across the "
                             "specimen (check the phases' moduli)", o->load == PLUME_BEND_TWIST ? "torque" : "moment");
    }
    for (plume_index v = 0; v < nv; v++)
        f[3 * v] = f[3 * v + 1] = 0.0, f[3 * v + 2] = g[3 * v + 2] * (want / have);
    *residual = fi / fb;
    free(g);
    return PLUME_OK;
}

/* The area-weighted quadratic fit of z over the window's vertices: k = (k_xx, k_yy, 2 k_xy). */
static int fit_curvature(const plume_mesh *m, const double *x, const double *area, const unsigned char *in,
                         double cx, double cy, double L, double k[3])
{
    double N[36] = {0}, b[6] = {0};
    for (plume_index v = 0; v < m->nv; v++) {
        if (!in[v])
            continue;
        const double X = (m->X[2 * v] - cx) / L, Y = (m->X[2 * v + 1] - cy) / L;
        const double phi[6] = {1.0, X, Y, 0.5 * X * X, X * Y, 0.5 * Y * Y};
        for (int r = 0; r < 6; r++) {
            b[r] += area[v] * phi[r] * x[3 * v + 2];
            for (int c = 0; c < 6; c++)
                N[6 * r + c] += area[v] * phi[r] * phi[c];
        }
    }
    if (!solve_small(6, N, b))
        return 0;
    k[0] = b[3] / (L * L), k[1] = b[5] / (L * L), k[2] = 2.0 * b[4] / (L * L);
    return 1;
}

/* The smallest z component of a current triangle normal over its area ratio, i.e. the cosine of
 * the largest tilt; negative once a triangle has turned over. */
static double min_normal_z(const plume_mesh *m, const double *x)
{
    double lo = 1.0;
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        double e1[3], e2[3];
        for (int a = 0; a < 3; a++)
            e1[a] = x[3 * v[1] + a] - x[3 * v[0] + a], e2[a] = x[3 * v[2] + a] - x[3 * v[0] + a];
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        lo = fmin(lo, len > 0.0 ? n[2] / len : -1.0);
    }
    return lo;
}

static plume_index nearest_vertex(const plume_mesh *m, double x, double y)
{
    plume_index best = 0;
    double bd = INFINITY;
    for (plume_index v = 0; v < m->nv; v++) {
        const double d = hypot(m->X[2 * v] - x, m->X[2 * v + 1] - y);
        if (d < bd)
            bd = d, best = v;
    }
    return best;
}

static plume_status check_opts(const plume_bend_opts *o, plume_err *err)
{
    if (!(o->lx > 0.0) || !(o->ly > 0.0) || !isfinite(o->lx) || !isfinite(o->ly))
        return plume_err_set(err, PLUME_EINVAL, "bending test: lx and ly must be finite and > 0 (got %g, %g)", o->lx,
                             o->ly);
    if (!(o->moment > 0.0) || !isfinite(o->moment))
        return plume_err_set(err, PLUME_EINVAL,
                             "bending test: the moment must be finite and > 0 (got %g; a linear test's sign carries "
                             "no information)", o->moment);
    if (o->steps < 1 || o->steps > 1000)
        return plume_err_set(err, PLUME_EINVAL, "bending test: steps must be in [1, 1000] (got %d)", o->steps);
    if (!(o->end_strip > 0.0 && o->end_strip <= 0.25))
        return plume_err_set(err, PLUME_EINVAL, "bending test: end_strip must be in (0, 0.25] (got %g)", o->end_strip);
    if (!(o->window > 0.0 && o->window <= 1.0 - 2.0 * o->end_strip))
        return plume_err_set(err, PLUME_EINVAL,
                             "bending test: window must be in (0, 1 - 2 end_strip] (got %g with end_strip %g)", o->window,
                             o->end_strip);
    if (!(o->max_rotation > 0.0) || !isfinite(o->max_rotation))
        return plume_err_set(err, PLUME_EINVAL, "bending test: max_rotation must be finite and > 0 (got %g)",
                             o->max_rotation);
    if (o->loading != PLUME_BEND_EDGE_MOMENTS && o->loading != PLUME_BEND_END_STRIPS &&
        o->loading != PLUME_BEND_UNIFORM_CURVATURE)
        return plume_err_set(err, PLUME_EINVAL, "bending test: unknown loading %d", (int)o->loading);
    if (o->load != PLUME_BEND_CYLINDER && o->load != PLUME_BEND_TWIST)
        return plume_err_set(err, PLUME_EINVAL, "bending test: unknown load %d", (int)o->load);
    return PLUME_OK;
}

/* The argument, option and specimen checks of plume_bend_run, before anything is allocated. */
static plume_status check_specimen(const plume_mesh *mesh, plume_problem *p, const plume_bend_opts *o, plume_err *err)
{
    plume_status st = check_opts(o, err);
    if (st != PLUME_OK)
        return st;
    if (mesh->dim != 3 || plume_problem_dim(p) != 3 || plume_problem_nvert(p) != mesh->nv || !mesh->edges)
        return plume_err_set(err, PLUME_EINVAL, "bending test: needs a shell-mode mesh (dim 3, topology built) and its problem");
    const double tol = 1e-9 * fmax(o->lx, o->ly);
    for (plume_index v = 0; v < mesh->nv; v++)
        if (mesh->X[2 * v] < -tol || mesh->X[2 * v] > o->lx + tol || mesh->X[2 * v + 1] < -tol ||
            mesh->X[2 * v + 1] > o->ly + tol)
            return plume_err_set(err, PLUME_EINVAL, "bending test: vertex %ld at (%g, %g) lies outside [0, %g] x [0, %g]",
                                 (long)v, mesh->X[2 * v], mesh->X[2 * v + 1], o->lx, o->ly);
    return PLUME_OK;
}

/* Each vertex's lumped reference area (a third of each triangle's), into area (zeroed by the caller). */
static void lumped_areas(const plume_mesh *mesh, double *area)
{
    for (plume_index t = 0; t < mesh->nt; t++) {
        const double a = plume_mesh_ref_area(mesh, t) / 3.0;
        for (int k = 0; k < 3; k++)
            area[mesh->tri[3 * t + k]] += a;
    }
}

/* The loads of o->loading at the final moment, compacted: vertex sv[i] carries f[3 i .. 3 i + 3),
 * *ns vertices (f holds 3 nv zeros on entry, sv room for nv). */
static plume_status end_loads(const plume_mesh *mesh, const plume_bend_opts *o, const double *area, plume_index *sv,
                              double *f, plume_index *ns_out, double *load_residual, plume_err *err)
{
    const plume_index nv = mesh->nv;
    plume_index ns = 0;
    plume_status st = PLUME_OK;
    if (o->loading == PLUME_BEND_END_STRIPS) {
        /* the two end strips: lo first, then hi, in sv[0..nlo) and sv[nlo..ns) */
        const double cs = o->end_strip * o->ly;
        plume_index nlo = 0;
        for (plume_index v = 0; v < nv; v++)
            if (area[v] > 0.0 && mesh->X[2 * v + 1] <= cs)
                sv[ns++] = v;
        nlo = ns;
        for (plume_index v = 0; v < nv; v++)
            if (area[v] > 0.0 && mesh->X[2 * v + 1] >= o->ly - cs)
                sv[ns++] = v;
        const double Mend = (o->load == PLUME_BEND_CYLINDER ? 1.0 : 2.0) * o->moment * o->lx;
        const double mx = o->load == PLUME_BEND_CYLINDER ? Mend : 0.0, my = o->load == PLUME_BEND_TWIST ? -Mend : 0.0;
        if (nlo < 3 || ns - nlo < 3 || !strip_forces(mesh, sv, nlo, area, -mx, -my, f) ||
            !strip_forces(mesh, sv + nlo, ns - nlo, area, mx, my, f + 3 * nlo))
            return plume_err_set(err, PLUME_EINVAL,
                                 "bending test: an end strip (end_strip %g of ly) holds too few vertices to carry a moment "
                                 "(%ld and %ld): refine the mesh or widen the strip", o->end_strip, (long)nlo,
                                 (long)(ns - nlo));
    } else {
        /* the edge moments, compacted into (sv, f): the patch test leaves the interior vertices
         * rounding only (about 1e-10 of the largest force, measured), and forces below 1e-12 of
         * it are left out */
        if ((st = edge_moment_forces(mesh, NULL, o->load, o->moment, fmax(o->lx, o->ly), f, err)) != PLUME_OK)
            return st;
        if (o->loading == PLUME_BEND_UNIFORM_CURVATURE && (st = uniform_curvature_forces(mesh, o, f, load_residual, err)) != PLUME_OK)
            return st;
        double fmax_z = 0.0;
        for (plume_index v = 0; v < nv; v++)
            fmax_z = fmax(fmax_z, fabs(f[3 * v + 2]));
        for (plume_index v = 0; v < nv; v++)
            if (fabs(f[3 * v + 2]) > 1e-12 * fmax_z) {
                f[3 * ns] = f[3 * ns + 1] = 0.0, f[3 * ns + 2] = f[3 * v + 2];
                sv[ns++] = v;
            }
    }
    *ns_out = ns;
    return PLUME_OK;
}

/* Adds the loads (sv, f) to p; *load keeps a handle that scales them (the problem owns the context,
 * and frees it if it refuses it: *load is then zeroed). */
static plume_status add_loads(plume_problem *p, const plume_index *sv, plume_index ns, const double *f,
                              plume_term *load, plume_err *err)
{
    plume_status st = plume_load_term_create(sv, ns, 3, f, load, err);
    if (st != PLUME_OK)
        return st;
    plume_term copy = *load;
    if ((st = plume_problem_add_term(p, &copy, err)) != PLUME_OK) {
        memset(load, 0, sizeof *load);
        plume_err_set(err, st, "bending test: cannot add the end loads");
    }
    return st;
}

/* Marks in in[] the vertices of the central window whose curvature is fitted (in zeroed by the caller). */
static plume_status central_window(const plume_mesh *mesh, const plume_bend_opts *o, const double *area,
                                   unsigned char *in, plume_err *err)
{
    const double cx = 0.5 * o->lx, cy = 0.5 * o->ly;
    plume_index nin = 0;
    for (plume_index v = 0; v < mesh->nv; v++)
        if (area[v] > 0.0 && fabs(mesh->X[2 * v] - cx) <= 0.5 * o->window * o->lx &&
            fabs(mesh->X[2 * v + 1] - cy) <= 0.5 * o->window * o->ly)
            in[v] = 1, nin++;
    if (nin < 6)
        return plume_err_set(err, PLUME_EINVAL, "bending test: the central window (window %g) holds %ld vertices, too few to "
                             "fit a curvature", o->window, (long)nin);
    return PLUME_OK;
}

/* The flat rest state of the specimen into the shell positions x. */
static void set_rest_state(const plume_mesh *mesh, double *x)
{
    for (plume_index v = 0; v < mesh->nv; v++)
        x[3 * v] = mesh->X[2 * v], x[3 * v + 1] = mesh->X[2 * v + 1], x[3 * v + 2] = 0.0;
}

/* Puts p at rest and fixes its rigid motion: three vertices near the centre, six coordinates, no
 * reaction (the loads balance). */
static plume_status hold_rigid_motion(const plume_mesh *mesh, plume_problem *p, const plume_bend_opts *o, plume_err *err)
{
    const double cx = 0.5 * o->lx, cy = 0.5 * o->ly;
    set_rest_state(mesh, plume_problem_x(p));
    const plume_index va = nearest_vertex(mesh, cx, cy), vb = nearest_vertex(mesh, cx, cy + 0.25 * o->ly),
                      vc = nearest_vertex(mesh, cx + 0.25 * o->lx, cy);
    if (va == vb || va == vc || vb == vc)
        return plume_err_set(err, PLUME_EINVAL, "bending test: the mesh is too coarse to hold the specimen at three vertices");
    const plume_index fixed[6] = {3 * va, 3 * va + 1, 3 * va + 2, 3 * vb, 3 * vb + 2, 3 * vc + 2};
    for (int k = 0; k < 6; k++) {
        const plume_status st = plume_problem_fix_dof(p, fixed[k], err);
        if (st != PLUME_OK)
            return plume_err_set(err, st, "bending test: cannot fix the rigid motion");
    }
    return PLUME_OK;
}

/* The KKT residual is measured against the problem's round-off floor (1e-6 of its stiffest
 * diagonal times its size: lib/core/problem.h), which a stiff membrane sets. The end loads of a soft
 * direction sit far below it (bent across the barbs at the default contrast: forces ~1e-11 N
 * against a floor ~2e-2 N), and the solver would stop at the rest state. The tolerance is
 * therefore taken relative to the loads; where round-off keeps the residual above it, the
 * step criterion (tol_step) ends the solve. Native solvers only: Ipopt scales its objective
 * by the same reference and stops on its own scaled criterion, which reaches the solution at
 * every angle (measured at the default contrast), whereas a tolerance this tight has it iterate
 * against round-off (bent along the barbs it did not converge). */
static plume_status tolerance_of_loads(plume_solver *solver, const plume_problem *p, const plume_bend_opts *o,
                                       const double *f, plume_index ns, plume_err *err)
{
    if (o->solver == PLUME_SOLVER_IPOPT)
        return PLUME_OK;
    double fl = 0.0;
    for (plume_index i = 0; i < 3 * ns; i++)
        fl = fmax(fl, fabs(f[i]));
    const double floor = plume_problem_force_scale(p);
    plume_status st = PLUME_OK;
    if (floor > fl && fl > 0.0 &&
        (st = plume_solver_set_tol_kkt(solver, o->solver_opts->tol_kkt * fl / floor, err)) != PLUME_OK)
        plume_err_set(err, st, "bending test: cannot set the solver tolerance");
    return st;
}

/* What a converged step k (load factor `factor`, state in p) measures: the window's fitted
 * curvatures kf and the elastic energy *e (the objective with the loads off; u is scratch). Refuses
 * a state beyond linear plate theory or with an element turned over. */
static plume_status measure_step(const plume_mesh *mesh, plume_problem *p, const plume_bend_opts *o, plume_term *load,
                                 const double *area, const unsigned char *in, int k, double factor, double *u,
                                 double kf[3], double *e, plume_err *err)
{
    const double cx = 0.5 * o->lx, cy = 0.5 * o->ly, L = fmax(o->lx, o->ly);
    const double *x = plume_problem_x(p);
    if (!fit_curvature(mesh, x, area, in, cx, cy, L, kf))
        return plume_err_set(err, PLUME_EINVAL, "bending test: the central window's vertices do not determine a "
                             "quadratic (too few or collinear)");
    const double kmax = fmax(fabs(kf[0]), fmax(fabs(kf[1]), 0.5 * fabs(kf[2])));
    if (min_normal_z(mesh, x) <= 0.0 || kmax * L > o->max_rotation)
        return plume_err_set(err, PLUME_EINFEASIBLE,
                             "bending test: the moment %g N m/m %s (curvature %g 1/m over %g m: %.3g rad, the test "
                             "accepts %g); use a smaller moment or curvature", o->moment * factor,
                             min_normal_z(mesh, x) <= 0.0 ? "inverts an element" : "bends the specimen beyond linear plate theory",
                             kmax, L, kmax * L, o->max_rotation);
    *e = 0.0;
    plume_load_scale(load, 0.0);
    plume_problem_gather(p, u);
    const plume_status st = plume_problem_objective(p, u, e, NULL);
    plume_load_scale(load, factor);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "bending test: step %d: energy evaluation failed", k);
    return PLUME_OK;
}

/* The least-squares slope of moment over curvature through the origin, over the curve's points. */
static double curve_stiffness(const plume_bend_curve *c)
{
    double sxy = 0.0, sxx = 0.0;
    for (plume_index i = 1; i < c->n; i++)
        sxy += c->moment[i] * c->curvature[i], sxx += c->curvature[i] * c->curvature[i];
    return sxx > 0.0 ? sxy / sxx : NAN;
}

plume_status plume_bend_run(const plume_mesh *mesh, plume_problem *p, const plume_bend_opts *given,
                            plume_bend_result *r, plume_err *err)
{
    if (!mesh || !p || !given || !r)
        return plume_err_set(err, PLUME_EINVAL, "bending test: invalid arguments");
    memset(r, 0, sizeof *r);
    /* the caller's options over this library's defaults, their solver options never NULL below */
    plume_bend_opts full;
    plume_solver_opts so;
    const plume_bend_opts *o = &full;
    plume_bend_opts_default(&full);
    if (plume_opts_take(&full, sizeof full, given, "plume_bend_opts", err) != PLUME_OK ||
        plume_solver_opts_take(&so, full.solver_opts, err) != PLUME_OK)
        return PLUME_EINVAL;
    full.solver_opts = &so;
    plume_status st = check_specimen(mesh, p, o, err);
    if (st != PLUME_OK)
        return st;

    const double t0 = plume_wall_seconds();
    const plume_index nv = mesh->nv;
    double *area = calloc((size_t)nv, sizeof *area), *f = NULL, *u = NULL, *lambda = NULL;
    plume_index *sv = malloc((size_t)nv * sizeof *sv);
    unsigned char *in = calloc((size_t)nv, 1);
    plume_solver *solver = NULL;
    plume_term load;
    memset(&load, 0, sizeof load);
    const size_t np = (size_t)o->steps + 1;
    plume_bend_curve *c = &r->curve;
    double **fields[8] = {&c->curvature, &c->moment, &c->k_xx, &c->k_yy, &c->twist, &c->energy, &c->iterations,
                          &c->seconds};
    int fields_ok = 1;
    for (int i = 0; i < 8; i++)
        fields_ok &= (*fields[i] = calloc(np, sizeof(double))) != NULL;
    if (!area || !sv || !in || !fields_ok || !(f = calloc((size_t)(3 * nv), sizeof *f))) {
        st = plume_err_set(err, PLUME_ENOMEM, "bending test: out of memory");
        goto cleanup;
    }
    lumped_areas(mesh, area);
    plume_index ns = 0;
    if ((st = end_loads(mesh, o, area, sv, f, &ns, &r->load_residual, err)) != PLUME_OK ||
        (st = add_loads(p, sv, ns, f, &load, err)) != PLUME_OK || (st = central_window(mesh, o, area, in, err)) != PLUME_OK ||
        (st = hold_rigid_motion(mesh, p, o, err)) != PLUME_OK || (st = plume_problem_finalize(p, err)) != PLUME_OK)
        goto cleanup;
    const plume_index n = plume_problem_nfree(p), m = plume_problem_ncons(p);
    u = malloc((size_t)(n + 1) * sizeof *u);
    lambda = calloc((size_t)(m + 1), sizeof *lambda);
    if (!u || !lambda) {
        st = plume_err_set(err, PLUME_ENOMEM, "bending test: out of memory");
        goto cleanup;
    }
    plume_err why = {{0}};
    if ((st = plume_solver_create(o->solver, p, o->solver_opts, &solver, &why)) != PLUME_OK) {
        plume_err_set(err, st, "bending test: could not create the %s solver: %s", plume_solver_kind_name(o->solver),
                      why.msg);
        goto cleanup;
    }
    if ((st = tolerance_of_loads(solver, p, o, f, ns, err)) != PLUME_OK)
        goto cleanup;
    c->n = 1;
    r->converged = 1;
    for (int k = 1; k <= o->steps; k++) {
        const double factor = (double)k / o->steps;
        plume_load_scale(&load, factor);
        /* linearized is the linear plate: every step is solved from the rest state (a step from the
         * last one would linearise about a bent shell whose membrane has not relaxed) */
        if (o->solver == PLUME_SOLVER_LINEARIZED)
            set_rest_state(mesh, plume_problem_x(p));
        plume_problem_gather(p, u);
        plume_solve_report rep;
        if ((st = plume_solver_solve(solver, u, lambda, &rep)) != PLUME_OK) {
            plume_err_set(err, st, "bending test: step %d: solver error (%s)", k, plume_strerror(st));
            goto cleanup;
        }
        if (!rep.converged && rep.reason != PLUME_REASON_SINGLE_STEP) { /* linearized: the linear plate */
            r->converged = 0;
            break;
        }
        double kf[3] = {0.0, 0.0, 0.0}, e = 0.0;
        if ((st = measure_step(mesh, p, o, &load, area, in, k, factor, u, kf, &e, err)) != PLUME_OK)
            goto cleanup;
        const plume_index i = c->n++;
        c->curvature[i] = o->load == PLUME_BEND_CYLINDER ? kf[1] : kf[2];
        c->moment[i] = o->moment * factor;
        c->k_xx[i] = kf[0], c->k_yy[i] = kf[1], c->twist[i] = kf[2];
        c->energy[i] = e;
        c->iterations[i] = rep.iterations;
        c->seconds[i] = rep.seconds;
    }
    r->stiffness = curve_stiffness(c);

cleanup:
    plume_solver_destroy(&solver);
    free(area), free(sv), free(in), free(f), free(u), free(lambda);
    r->seconds = plume_wall_seconds() - t0;
    if (st != PLUME_OK)
        plume_bend_result_free(r);
    return st;
}

void plume_plate_of_membrane(const plume_membrane_material *m, plume_bending_material *b)
{
    double C[9];
    plume_membrane_stiffness(m, C);
    const double f = m->h * m->h * m->h / 12.0;
    b->D_long = f * C[0], b->D_trans = f * C[4], b->D_coupling = f * C[1], b->D_twist = f * C[8];
}

plume_status plume_shell_specimen(const plume_mesh *planar, const plume_membrane_material *mem,
                                  const plume_bending_material *bend, int nmat, plume_mesh **mesh, plume_problem **p,
                                  plume_err *err)
{
    if (!planar || !mem || !bend || nmat < 1 || !mesh || !p)
        return plume_err_set(err, PLUME_EINVAL, "shell specimen: invalid arguments");
    *mesh = NULL, *p = NULL;
    plume_term tm, tb;
    plume_status st = plume_mesh_create(planar->nv, planar->nt, 3, mesh, err);
    if (st != PLUME_OK)
        return plume_err_set(err, st, "shell specimen: out of memory");
    memcpy((*mesh)->X, planar->X, (size_t)(2 * planar->nv) * sizeof *planar->X);
    memcpy((*mesh)->tri, planar->tri, (size_t)(3 * planar->nt) * sizeof *planar->tri);
    memcpy((*mesh)->barb_dir, planar->barb_dir, (size_t)(2 * planar->nt) * sizeof *planar->barb_dir);
    memcpy((*mesh)->material, planar->material, (size_t)planar->nt * sizeof *planar->material);
    plume_mesh_reset_current(*mesh);
    if ((st = plume_mesh_build_topology(*mesh, err)) != PLUME_OK)
        goto fail;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (plume_index v = 0; v < planar->nv; v++)
        for (int a = 0; a < 2; a++)
            lo[a] = fmin(lo[a], planar->X[2 * v + a]), hi[a] = fmax(hi[a], planar->X[2 * v + a]);
    if ((st = plume_problem_create((*mesh)->nv, 3, fmax(hi[0] - lo[0], hi[1] - lo[1]), p, err)) != PLUME_OK) {
        plume_err_set(err, st, "shell specimen: cannot create the problem");
        goto fail;
    }
    if ((st = plume_membrane_term_create(*mesh, 3, mem, nmat, &tm, err)) != PLUME_OK)
        goto fail;
    if ((st = plume_problem_add_term(*p, &tm, err)) != PLUME_OK) {
        plume_err_set(err, st, "shell specimen: cannot add the membrane");
        goto fail;
    }
    /* phase-aware stencils: a fit through a stiff barb and a soft matrix would smear the curvature
     * jump between them (docs/bending-homogenisation.md, "Both scales in bending") */
    const plume_shape_bending_opts so = {.phase_aware = 1};
    if ((st = plume_shape_bending_term_create_opts(*mesh, bend, nmat, NULL, &so, &tb, err)) != PLUME_OK)
        goto fail;
    if ((st = plume_problem_add_term(*p, &tb, err)) != PLUME_OK) {
        plume_err_set(err, st, "shell specimen: cannot add the bending");
        goto fail;
    }
    return PLUME_OK;
fail:
    plume_problem_destroy(p);
    plume_mesh_destroy(mesh);
    return st;
}

plume_status plume_plate_specimen(double lx, double ly, double angle_deg, double edge, const plume_membrane_material *mem,
                                  const plume_bending_material *bend, plume_mesh **mesh, plume_problem **p,
                                  plume_err *err)
{
    if (!mem || !bend || !mesh || !p)
        return plume_err_set(err, PLUME_EINVAL, "plate specimen: invalid arguments");
    *mesh = NULL, *p = NULL;
    plume_mesh *planar = NULL;
    plume_status st = plume_patch_mesh(lx, ly, angle_deg, edge, PLUME_PATCH_UNALIGNED, 2, &planar, err);
    if (st == PLUME_OK)
        st = plume_shell_specimen(planar, mem, bend, 1, mesh, p, err);
    plume_mesh_destroy(&planar);
    return st;
}

/* D rotated into the specimen frame (x across, y along the specimen) for barbs at angle_deg from y:
 * the barb frame's axis 1 is d = (sin a, cos a). Curvature transforms as a strain (Voigt with 2 k12). */
static void rotate_plate(const double D[9], double angle_deg, double Ds[9])
{
    const double a = angle_deg * M_PI / 180.0, d0 = sin(a), d1 = cos(a), q0 = -d1, q1 = d0;
    /* kappa_barb = T kappa_spec with T the strain transformation for the frame (d, q) */
    const double T[9] = {d0 * d0, d1 * d1, d0 * d1,
                         q0 * q0, q1 * q1, q0 * q1,
                         2.0 * d0 * q0, 2.0 * d1 * q1, d0 * q1 + d1 * q0};
    double DT[9] = {0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++)
                DT[3 * i + j] += D[3 * i + k] * T[3 * k + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            Ds[3 * i + j] = 0.0;
            for (int k = 0; k < 3; k++)
                Ds[3 * i + j] += T[3 * k + i] * DT[3 * k + j];
        }
}

plume_status plume_bend_expected(const double D[9], double angle_deg, plume_bend_load load, double curvature,
                                 double *moment, double *stiffness, plume_err *err)
{
    if (!D || !moment || !isfinite(angle_deg) || !isfinite(curvature))
        return plume_err_set(err, PLUME_EINVAL, "bending prediction: invalid arguments");
    double Ds[9], b[3] = {0.0, 0.0, 0.0};
    rotate_plate(D, angle_deg, Ds);
    const int j = load == PLUME_BEND_TWIST ? 2 : 1;
    b[j] = 1.0;
    double A[9];
    memcpy(A, Ds, sizeof A);
    const double det = Ds[0] * (Ds[4] * Ds[8] - Ds[5] * Ds[7]) - Ds[1] * (Ds[3] * Ds[8] - Ds[5] * Ds[6]) +
                       Ds[2] * (Ds[3] * Ds[7] - Ds[4] * Ds[6]);
    if (!(Ds[0] > 0.0) || !(Ds[0] * Ds[4] - Ds[1] * Ds[3] > 0.0) || !(det > 0.0) || !solve_small(3, A, b) || !(b[j] > 0.0))
        return plume_err_set(err, PLUME_EINVAL, "bending prediction: the plate tensor is not positive definite");
    const double s = 1.0 / b[j];
    *moment = s * curvature;
    if (stiffness)
        *stiffness = s;
    return PLUME_OK;
}

plume_status plume_plate_model_curve(void *ctx, const plume_bending_material *bm, int icurve, plume_curve *out,
                                     plume_err *err)
{
    const plume_plate_model *pm = ctx;
    if (!pm || !bm || !out || icurve < 0 || icurve >= pm->ncurves)
        return plume_err_set(err, PLUME_EINVAL, "plate model: invalid arguments");
    memset(out, 0, sizeof *out);
    const plume_bending_material b = *bm;
    if (!(b.D_coupling * b.D_coupling < b.D_long * b.D_trans) || !(b.D_twist > 0.0))
        return plume_err_set(err, PLUME_EINFEASIBLE, "plate model: moduli out of the plate's range");
    plume_mesh *mesh = NULL;
    plume_problem *p = NULL;
    plume_bend_result r;
    memset(&r, 0, sizeof r);
    plume_status st = plume_plate_specimen(pm->lx, pm->ly, pm->angles[icurve], pm->edge, &pm->membrane, &b, &mesh, &p, err);
    if (st == PLUME_OK) {
        plume_bend_opts o;
        plume_bend_opts_default(&o);
        o.load = pm->loads[icurve];
        o.lx = pm->lx, o.ly = pm->ly;
        o.moment = pm->moments[icurve];
        o.steps = pm->steps;
        o.solver = pm->solver;
        st = plume_bend_run(mesh, p, &o, &r, err);
        if (st == PLUME_OK && !r.converged)
            st = plume_err_set(err, PLUME_EINFEASIBLE, "plate model: curve %d did not converge", icurve);
        else if (st == PLUME_EINFEASIBLE)
            st = PLUME_EINFEASIBLE;
    }
    if (st == PLUME_OK) {
        const size_t np = (size_t)r.curve.n;
        out->strain = r.curve.curvature, r.curve.curvature = NULL;
        out->stress = r.curve.moment, r.curve.moment = NULL;
        out->iterations = r.curve.iterations, r.curve.iterations = NULL;
        out->seconds = r.curve.seconds, r.curve.seconds = NULL;
        out->wbar = calloc(np, sizeof *out->wbar);
        out->n = r.curve.n;
        if (!out->wbar) {
            plume_curve_free(out);
            st = plume_err_set(err, PLUME_ENOMEM, "plate model: out of memory");
        }
    }
    plume_bend_result_free(&r);
    plume_problem_destroy(&p);
    plume_mesh_destroy(&mesh);
    return st;
}
