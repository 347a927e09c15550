/* The periodic plate cell (micro/cell_plate.h): the strip laminate's exact bending tensor, the
 * patch test, convergence on the explicit-barbule cell and bad input. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "plume_tree.h"
#include "../micro/cell_linear.h"
#include "../micro/cell_plate.h"
#include "../micro/layout.h"
#include "../micro/layout_json.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The exact bending tensor of a laminate of plates normal to axis `axis` (0: layers normal to x,
 * 1: normal to y), phase i with tensor Ds[i] (cell frame) and area fraction frac[i]
 * (docs/bending-homogenisation.md): the fluctuation depends on the normal coordinate only, so the
 * curvatures t = the other two components are uniform and the moment n = M_axis is uniform:
 * D_nn = <1/D_nn>^-1, D_nt = D_nn <D_nt / D_nn>, D_tt = <D_tt - D_tn D_nt / D_nn> +
 * <D_tn / D_nn> D_nn <D_nt / D_nn>. */
static void plate_laminate(const double (*Ds)[9], const double *frac, int nl, int axis, double D[9])
{
    const int n = axis, t[2] = {axis == 0 ? 1 : 0, 2};
    double inv = 0.0, r[2] = {0, 0}, schur[2][2] = {{0, 0}, {0, 0}};
    for (int i = 0; i < nl; i++) {
        const double *Di = Ds[i], dnn = Di[4 * n];
        inv += frac[i] / dnn;
        for (int j = 0; j < 2; j++) {
            r[j] += frac[i] * Di[3 * n + t[j]] / dnn;
            for (int k = 0; k < 2; k++)
                schur[j][k] += frac[i] * (Di[3 * t[j] + t[k]] - Di[3 * t[j] + n] * Di[3 * n + t[k]] / dnn);
        }
    }
    double dnn = 1.0 / inv;
    memset(D, 0, 9 * sizeof *D);
    D[4 * n] = dnn;
    for (int j = 0; j < 2; j++) {
        D[3 * n + t[j]] = D[3 * t[j] + n] = dnn * r[j];
        for (int k = 0; k < 2; k++)
            D[3 * t[j] + t[k]] = schur[j][k] + r[j] * dnn * r[k];
    }
}

/* h^3 / 12 Q of an isotropic material */
static void plate_iso(const plume_membrane_material *m, double D[9])
{
    plume_membrane_stiffness(m, D);
    for (int k = 0; k < 9; k++)
        D[k] *= m->h * m->h * m->h / 12.0;
}

/* The cell mirrored about x = y: strips normal to x, barb directions (0, 1). The caller owns it. */
static plume_cell *transposed(const plume_cell *c)
{
    const plume_mesh *m = c->mesh;
    plume_cell *r = calloc(1, sizeof *r);
    if (!r || plume_mesh_create(m->nv, m->nt, 2, &r->mesh, NULL) != PLUME_OK)
        return free(r), NULL;
    plume_mesh *q = r->mesh;
    for (plume_index v = 0; v < m->nv; v++)
        q->X[2 * v] = m->X[2 * v + 1], q->X[2 * v + 1] = m->X[2 * v];
    for (plume_index t = 0; t < m->nt; t++) {
        q->tri[3 * t] = m->tri[3 * t], q->tri[3 * t + 1] = m->tri[3 * t + 2], q->tri[3 * t + 2] = m->tri[3 * t + 1];
        q->material[t] = m->material[t];
        q->barb_dir[2 * t] = m->barb_dir[2 * t + 1], q->barb_dir[2 * t + 1] = m->barb_dir[2 * t];
    }
    plume_mesh_reset_current(q);
    plume_err err;
    r->master = malloc((size_t)m->nv * sizeof *r->master);
    r->shift = malloc((size_t)(2 * m->nv) * sizeof *r->shift);
    if (!r->master || !r->shift || plume_mesh_build_topology(q, &err) != PLUME_OK) {
        plume_cell_destroy(&r);
        return NULL;
    }
    for (plume_index v = 0; v < m->nv; v++) {
        r->master[v] = c->master[v];
        r->shift[2 * v] = c->shift[2 * v + 1], r->shift[2 * v + 1] = c->shift[2 * v];
    }
    r->order = 1, r->a = c->b, r->b = c->a, r->nmasters = c->nmasters;
    return r;
}

/* The strip laminate (barb and barbule strips along x) against the exact tensor to 1e-8
 * relative, entry by entry (an absolute floor of 1e-8 sqrt(D_ii D_jj) for the entries that vanish):
 * equal and unequal thicknesses (barbules thinner and thicker), contrasts down to the paper's
 * 1e-6, linear and quadratic cell meshes, and the cell mirrored so that the strips run along y
 * (the fluctuation then depends on x only). */
void test_cell_plate_laminate_exact(void)
{
    const double phis[] = {0.16, 0.5, 0.8}, ratios[] = {1e-6, 1e-2, 0.3}, nub[] = {0.3, 0.0, 0.45},
                 nuB[] = {0.3, 0.4, 0.1};
    const double hb[] = {1e-4, 1e-4, 2e-4}, hB[] = {1e-4, 1e-5, 3e-4}; /* equal, thinner, thicker */
    double worst = 0.0; /* largest relative error of a nonzero entry */
    for (int run = 0; run < 9; run++) {
        const int k = run % 3, th = run / 3;
        plume_layout l;
        plume_layout_default(&l);
        l.order = run % 2 ? 1 : 2;
        l.phi = phis[k], l.ratio = ratios[k], l.nu_b = nub[k], l.nu_B = nuB[k];
        l.h_barb = hb[th], l.h_barbule = hB[th];
        l.e_rel = 0.7;
        plume_membrane_material mats[2];
        plume_layout_materials(&l, mats);
        CHECK(mats[0].h == hb[th] && mats[1].h == hB[th]);
        double Ds[2][9], frac[2] = {l.phi, 1.0 - l.phi};
        plate_iso(&mats[0], Ds[0]);
        plate_iso(&mats[1], Ds[1]);
        plume_cell *c = NULL;
        plume_err err = {{0}};
        CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_OK);
        plume_cell *ct = c ? transposed(c) : NULL;
        CHECK(ct != NULL);
        for (int axis = 1; axis >= 0 && ct; axis--) {
            double D[9], E[9];
            plume_cell_plate_info info;
            plume_status st = plume_cell_plate_tensor(axis == 1 ? c : ct, mats, 2, D, &info, &err);
            CHECK(st == PLUME_OK);
            if (st != PLUME_OK) {
                fprintf(stderr, "    %s\n", err.msg);
                continue;
            }
            CHECK(info.elements == c->mesh->nt && info.dofs > 0 && info.nnz >= info.dofs);
            plate_laminate((const double(*)[9])Ds, frac, 2, axis, E);
            for (int i = 0; i < 9; i++) {
                double floor = E[i] == 0.0 ? sqrt(E[4 * (i / 3)] * E[4 * (i % 3)]) : 0.0;
                CHECK_REL(D[i], E[i], 1e-8, floor);
                if (E[i] != 0.0)
                    worst = fmax(worst, fabs(D[i] - E[i]) / fabs(E[i]));
            }
        }
        plume_cell_destroy(&ct);
        plume_cell_destroy(&c);
    }
    fprintf(stderr, "    largest relative error against the exact laminate: %.2g\n", worst);
}

/* One phase (both materials equal, one thickness): D = h^3 / 12 Q exactly, on every mesh and in
 * both orientations (a constant curvature needs no fluctuation; Morley passes the patch test), and
 * with an orthotropic material whose fibres are tilted the rotation is honoured. */
void test_cell_plate_patch(void)
{
    const double e_rels[] = {0.35, 0.7, 1.9};
    for (int run = 0; run < 6; run++) {
        plume_layout l;
        plume_layout_default(&l);
        l.ratio = 1.0, l.nu_B = l.nu_b, l.phi = 0.3, l.h = 2e-4;
        l.e_rel = e_rels[run % 3];
        l.order = run < 3 ? 1 : 2;
        plume_membrane_material mats[2];
        plume_layout_materials(&l, mats);
        if (run == 5) { /* orthotropic, the same in both phases */
            for (int k = 0; k < 2; k++)
                mats[k].moduli.E_xx = 3e9, mats[k].moduli.E_yy = 1e8, mats[k].moduli.nu_xy = 0.25, mats[k].moduli.G_xy = 4e7;
        }
        plume_cell *c = NULL;
        plume_err err = {{0}};
        CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_OK);
        if (!c)
            continue;
        if (run == 5) /* fibres at 30 deg in every triangle */
            for (plume_index t = 0; t < c->mesh->nt; t++)
                c->mesh->barb_dir[2 * t] = cos(M_PI / 6), c->mesh->barb_dir[2 * t + 1] = sin(M_PI / 6);
        double D[9], E[9], Q[9], d[2] = {cos(M_PI / 6), sin(M_PI / 6)};
        plate_iso(&mats[0], Q);
        if (run == 5)
            plume_cell_rotate_stiffness(Q, d, E);
        else
            memcpy(E, Q, sizeof E);
        CHECK(plume_cell_plate_tensor(c, mats, 2, D, NULL, &err) == PLUME_OK);
        double scale = sqrt(E[0] * E[4]);
        for (int i = 0; i < 9; i++)
            CHECK_REL(D[i], E[i], 1e-10, 1e-10 * scale);
        plume_cell *ct = transposed(c);
        CHECK(ct && plume_cell_plate_tensor(ct, mats, 2, D, NULL, &err) == PLUME_OK);
        if (ct && run != 5) {
            const int sw[9] = {4, 3, 5, 1, 0, 2, 7, 6, 8}; /* x <-> y */
            for (int i = 0; i < 9; i++)
                CHECK_REL(D[i], E[sw[i]], 1e-10, 1e-10 * scale);
        }
        plume_cell_destroy(&ct);
        plume_cell_destroy(&c);
    }
}

/* The explicit-barbule cell of data/layout_barbules.json under refinement: D_long, D_trans and
 * D_twist change monotonically as the elements shrink (from below: Morley is nonconforming and
 * softer than the plate, docs/bending-homogenisation.md), the changes shrink, and the finest two
 * meshes agree to 0.5 %. */
void test_cell_plate_barbule_convergence(void)
{
    plume_layout base;
    plume_layout_default(&base);
    plume_err err = {{0}};
    CHECK(plume_layout_load_json("../data/layout_barbules.json", &base, &err) == PLUME_OK);
    base.order = 1;
    const double e_rels[] = {0.4, 0.2, 0.1, 0.05, 0.025, 0.0125};
    const int n = 6;
    double v[6][3];
    for (int k = 0; k < n; k++) {
        plume_layout l = base;
        l.e_rel = e_rels[k];
        plume_membrane_material mats[2];
        plume_layout_materials(&l, mats);
        plume_cell *c = NULL;
        double D[9] = {0};
        plume_cell_plate_info info = {0, 0, 0};
        CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_OK && plume_cell_plate_tensor(c, mats, 2, D, &info, &err) == PLUME_OK);
        v[k][0] = D[0], v[k][1] = D[4], v[k][2] = D[8];
        fprintf(stderr, "    e_rel %.3g: %ld triangles, %ld dofs: D_long %.8g, D_trans %.8g, D_twist %.8g, D_coupling %.6g N m\n",
                e_rels[k], (long)info.elements, (long)info.dofs, D[0], D[4], D[8], D[1]);
        plume_cell_destroy(&c);
    }
    for (int j = 0; j < 3; j++) {
        for (int k = 1; k < n; k++) {
            CHECK(v[k][j] > v[k - 1][j]); /* from below */
            if (k > 1)
                CHECK(v[k][j] - v[k - 1][j] < v[k - 1][j] - v[k - 2][j]);
        }
        CHECK_REL(v[n - 1][j], v[n - 2][j], 0.005, 0.0);
    }
}

/* Bad input: NULL arguments, an invalid material, a material id out of range, a mesh without
 * topology. */
void test_cell_plate_bad_input(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_membrane_material mats[2];
    plume_layout_materials(&l, mats);
    plume_cell *c = NULL;
    plume_err err = {{0}};
    CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_OK);
    if (!c)
        return;
    double D[9];
    CHECK(plume_cell_plate_tensor(NULL, mats, 2, D, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_cell_plate_tensor(c, NULL, 2, D, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_cell_plate_tensor(c, mats, 2, NULL, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_cell_plate_tensor(c, mats, 1, D, NULL, &err) == PLUME_EINVAL && strstr(err.msg, "material 1 outside"));
    plume_membrane_material bad[2] = {mats[0], mats[1]};
    bad[1].h = 0.0;
    CHECK(plume_cell_plate_tensor(c, bad, 2, D, NULL, &err) == PLUME_EINVAL);
    plume_cell_destroy(&c);
}
