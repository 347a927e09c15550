/* ParaView output: .vtu writer and reader round trips (several zlib blocks, a full last block),
 * .pvd collections, bad input and damaged files; the per-triangle fields against closed forms
 * (uniaxial stretch, a cylinder's curvature) and finite differences (the stress). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "test_rng.h"
#include "../lib/io/vtu.h"
#include "../lib/core/membrane.h"
#include "../macro/shell/bending.h"
#include "../macro/shell/fields.h"
#include "../macro/shell/patch_mesh.h"
#include "../macro/shell/shape_bending.h"

static int make_tmpdir(char *dir)
{
    strcpy(dir, "/tmp/plume-vtu-XXXXXX");
    return mkdtemp(dir) != NULL;
}

static void remove_dir(const char *dir)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "    could not remove %s\n", dir);
}

/* a grid of n points in a row of triangles, with a random point field and cell fields */
static void roundtrip(plume_index n, const char *dir)
{
    rng64 r = {0x9e3779b97f4a7c15ULL + (uint64_t)n};
    plume_index nc = n - 2;
    double *pts = malloc(3 * (size_t)n * sizeof *pts), *pf = malloc(3 * (size_t)n * sizeof *pf);
    double *cf = malloc((size_t)nc * sizeof *cf), *ci = malloc((size_t)nc * sizeof *ci);
    plume_index *cells = malloc(3 * (size_t)nc * sizeof *cells);
    for (plume_index k = 0; k < 3 * n; k++)
        pts[k] = urange(&r, -1, 1), pf[k] = urange(&r, -1e6, 1e6);
    for (plume_index c = 0; c < nc; c++) {
        cells[3 * c] = c, cells[3 * c + 1] = c + 1, cells[3 * c + 2] = c + 2;
        cf[c] = c % 7 == 0 ? NAN : urange(&r, 0, 1);
        ci[c] = (double)(c % 5) - 2.0;
    }
    plume_vtu_field pfl[] = {{"displacement", 3, 0, pf}};
    plume_vtu_field cfl[] = {{"J", 1, 0, cf}, {"material", 1, 1, ci}};
    plume_vtu_grid g = {n, pts, PLUME_VTU_TRIANGLE, nc, cells, 1, 2, pfl, cfl, 0.125};
    char path[256];
    snprintf(path, sizeof path, "%s/g%ld.vtu", dir, (long)n);
    plume_err err = {{0}};
    CHECK(plume_vtu_write(path, &g, &err) == PLUME_OK);
    plume_vtu_data d;
    CHECK(plume_vtu_read(path, &d, &err) == PLUME_OK);
    if (d.points) {
        CHECK(d.npoints == n && d.ncells == nc && d.has_time && d.time == 0.125);
        CHECK(memcmp(d.points, pts, 3 * (size_t)n * sizeof *pts) == 0);
        int cells_ok = 1;
        for (plume_index c = 0; c < nc; c++) {
            cells_ok &= d.offsets[c] == 3 * (c + 1) && d.types[c] == PLUME_VTU_TRIANGLE;
            for (int k = 0; k < 3; k++)
                cells_ok &= d.connectivity[3 * c + k] == cells[3 * c + k];
        }
        CHECK(cells_ok);
        const plume_vtu_array *a = plume_vtu_find(&d, 1, "displacement");
        CHECK(a && a->ncomp == 3 && a->ntuples == n && memcmp(a->values, pf, 3 * (size_t)n * sizeof *pf) == 0);
        a = plume_vtu_find(&d, 0, "J");
        int same = a && a->ntuples == nc;
        for (plume_index c = 0; same && c < nc; c++)
            same = isnan(cf[c]) ? isnan(a->values[c]) : a->values[c] == cf[c];
        CHECK(same);
        a = plume_vtu_find(&d, 0, "material");
        CHECK(a && a->ntuples == nc && memcmp(a->values, ci, (size_t)nc * sizeof *ci) == 0);
        CHECK(plume_vtu_find(&d, 0, "nothing") == NULL && plume_vtu_find(&d, 1, "J") == NULL);
    }
    plume_vtu_data_free(&d);
    free(pts), free(pf), free(cf), free(ci), free(cells);
}

/* Round trips: one block, several (3 n doubles > 32 KiB), and a last block exactly full (4096
 * cell values of 8 bytes are one 32 KiB block). */
void test_vtu_roundtrip(void)
{
    char dir[64];
    if (!make_tmpdir(dir)) {
        CHECK(0);
        return;
    }
    roundtrip(10, dir);
    roundtrip(5000, dir);
    roundtrip(4098, dir);
    remove_dir(dir);
}

/* Bad grids are refused naming what is wrong, an unwritable path names the file, and damaged or
 * foreign files are refused by the reader, naming the file. */
void test_vtu_errors(void)
{
    char dir[64], path[256];
    if (!make_tmpdir(dir)) {
        CHECK(0);
        return;
    }
    double pts[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    plume_index bad[3] = {0, 1, 3}, good[3] = {0, 1, 2};
    plume_vtu_grid g = {3, pts, PLUME_VTU_TRIANGLE, 1, bad, 0, 0, NULL, NULL, 0.0};
    plume_err err = {{0}};
    snprintf(path, sizeof path, "%s/a.vtu", dir);
    CHECK(plume_vtu_write(path, &g, &err) == PLUME_EINVAL && strstr(err.msg, "vertex 3"));
    g.cells = good;
    g.cell_type = 7;
    CHECK(plume_vtu_write(path, &g, &err) == PLUME_EINVAL && strstr(err.msg, "cell type 7"));
    g.cell_type = PLUME_VTU_TRIANGLE;
    plume_vtu_field f = {"", 1, 0, pts};
    g.ncell_fields = 1, g.cell_fields = &f;
    CHECK(plume_vtu_write(path, &g, &err) == PLUME_EINVAL && strstr(err.msg, "cell field 0"));
    g.ncell_fields = 0;
    CHECK(plume_vtu_write("/nonexistent/dir/a.vtu", &g, &err) == PLUME_EIO && strstr(err.msg, "/nonexistent/dir/a.vtu"));
    CHECK(plume_vtu_write(path, &g, &err) == PLUME_OK);

    plume_vtu_data d;
    CHECK(plume_vtu_read("/nonexistent/a.vtu", &d, &err) == PLUME_EIO && strstr(err.msg, "/nonexistent/a.vtu"));
    /* cut short inside the appended data */
    FILE *in = fopen(path, "rb");
    char buf[8192];
    size_t n = in ? fread(buf, 1, sizeof buf, in) : 0;
    if (in)
        fclose(in);
    char cut[256];
    snprintf(cut, sizeof cut, "%s/cut.vtu", dir);
    FILE *o = fopen(cut, "wb");
    const char *app = memchr(buf, '_', n) ? strstr(buf, "<AppendedData") : NULL;
    size_t keep = app ? (size_t)(app - buf) + 60 : n / 2;
    if (o) {
        fwrite(buf, 1, keep, o);
        fclose(o);
    }
    CHECK(plume_vtu_read(cut, &d, &err) == PLUME_EFORMAT && strstr(err.msg, "cut.vtu"));
    /* a block whose bytes are damaged does not decompress */
    if (app && n > keep) {
        memcpy(buf + n - 40, "XXXXXXXXXXXXXXXX", 16);
        if ((o = fopen(cut, "wb"))) {
            fwrite(buf, 1, n, o);
            fclose(o);
        }
        CHECK(plume_vtu_read(cut, &d, &err) == PLUME_EFORMAT);
    }
    if ((o = fopen(cut, "w"))) {
        fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\"></VTKFile>\n", o);
        fclose(o);
    }
    CHECK(plume_vtu_read(cut, &d, &err) == PLUME_EFORMAT && strstr(err.msg, "UnstructuredGrid"));
    remove_dir(dir);
}

/* A collection keeps its entries in order, rewritten whole at each add; a file that is not one
 * is refused naming the line. */
void test_vtu_pvd(void)
{
    char dir[64], path[256];
    if (!make_tmpdir(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/s.pvd", dir);
    plume_pvd *p = NULL;
    plume_err err = {{0}};
    CHECK(plume_pvd_create(path, &p, &err) == PLUME_OK);
    const double times[3] = {0.0, 0.1, 1.0 / 3.0};
    for (int k = 0; k < 3; k++) {
        char f[64];
        snprintf(f, sizeof f, "a&b_%05d.vtu", k);
        CHECK(plume_pvd_add(p, times[k], k % 2, f, &err) == PLUME_OK);
    }
    CHECK(plume_pvd_add(p, NAN, 0, "x.vtu", &err) == PLUME_EINVAL);
    plume_pvd_destroy(&p);
    CHECK(p == NULL);
    plume_pvd_entries e;
    CHECK(plume_pvd_read(path, &e, &err) == PLUME_OK && e.n == 3);
    for (int k = 0; k < e.n && k < 3; k++) {
        char f[64];
        snprintf(f, sizeof f, "a&b_%05d.vtu", k);
        CHECK(e.times[k] == times[k] && e.parts[k] == k % 2 && strcmp(e.files[k], f) == 0);
    }
    plume_pvd_entries_free(&e);
    FILE *o = fopen(path, "w");
    if (o) {
        fputs("<VTKFile type=\"Collection\">\n<Collection>\n<DataSet timestep=\"zero\" file=\"a.vtu\"/>\n", o);
        fclose(o);
    }
    CHECK(plume_pvd_read(path, &e, &err) == PLUME_EFORMAT && strstr(err.msg, ":3:"));
    remove_dir(dir);
}

static plume_membrane_material test_material(double kappa)
{
    plume_membrane_material m = {{2.0e9, 3.0e7, 0.3, 1.0e7}, 1e-4, kappa, 0};
    return m;
}

/* Uniaxial stretch along the barbs of a planar sample: Green strain, stress, energy density, J
 * and the barbs' strain in closed form. */
void test_fields_uniaxial(void)
{
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 0.6, 90.0, 0.1, PLUME_PATCH_ALIGNED, 2, &m, &err) == PLUME_OK);
    if (!m)
        return;
    /* barbs at 90 deg from y: along x; the x-aligned edges are the barbs */
    plume_index nb = 0, *barbs = malloc(2 * (size_t)m->ne * sizeof *barbs);
    for (plume_index e = 0; e < m->ne; e++) {
        plume_index a = m->edges[2 * e], b = m->edges[2 * e + 1];
        if (fabs(m->X[2 * a + 1] - m->X[2 * b + 1]) < 1e-12)
            barbs[2 * nb] = a, barbs[2 * nb + 1] = b, nb++;
    }
    CHECK(nb > 10);
    plume_membrane_material mat = test_material(0.0);
    plume_fields *f = NULL;
    CHECK(plume_fields_create(m, 2, m->nt, &mat, 1, NULL, barbs, nb, &f, &err) == PLUME_OK);
    const double s = 0.02;
    double *x = malloc(2 * (size_t)m->nv * sizeof *x);
    for (plume_index v = 0; v < m->nv; v++)
        x[2 * v] = (1.0 + s) * m->X[2 * v], x[2 * v + 1] = m->X[2 * v + 1];
    plume_field_values fv;
    CHECK(f && plume_fields_compute(f, x, &fv, &err) == PLUME_OK);
    double C[9];
    plume_membrane_stiffness(&mat, C);
    const double e = 0.5 * ((1 + s) * (1 + s) - 1);
    const double Sbb = C[0] * e, Stt = C[3] * e, W = 0.5 * mat.h * e * Sbb;
    int ok = f != NULL;
    for (plume_index t = 0; ok && t < m->nt; t++) {
        ok &= fabs(fv.green_strain[3 * t] - e) < 1e-14 && fabs(fv.green_strain[3 * t + 1]) < 1e-14 &&
              fabs(fv.green_strain[3 * t + 2]) < 1e-14;
        ok &= fabs(fv.stress[3 * t] - Sbb) < 1e-9 * Sbb && fabs(fv.stress[3 * t + 1] - Stt) < 1e-9 * Sbb &&
              fabs(fv.stress[3 * t + 2]) < 1e-9 * Sbb;
        ok &= fabs(fv.membrane_energy[t] - W) < 1e-12 * W && fabs(fv.J[t] - (1 + s)) < 1e-14;
        ok &= fv.bending_energy[t] == 0.0 && fv.mean_curvature[t] == 0.0;
    }
    CHECK(ok);
    int bok = f != NULL;
    for (plume_index b = 0; bok && b < nb; b++)
        bok &= fabs(fv.barb_strain[b] - s) < 1e-13;
    CHECK(bok);
    /* bad input */
    plume_fields *g = NULL;
    CHECK(plume_fields_create(m, 4, m->nt, &mat, 1, NULL, NULL, 0, &g, &err) == PLUME_EINVAL && g == NULL);
    m->material[3] = 2;
    CHECK(plume_fields_create(m, 2, m->nt, &mat, 1, NULL, NULL, 0, &g, &err) == PLUME_EINVAL &&
          strstr(err.msg, "triangle 3"));
    m->material[3] = 0;
    barbs[1] = m->nv;
    CHECK(plume_fields_create(m, 2, m->nt, &mat, 1, NULL, barbs, nb, &g, &err) == PLUME_EINVAL &&
          strstr(err.msg, "barb edge 0"));
    CHECK(g == NULL);
    /* objects whose triangles leave the mesh, or none, are refused naming the range */
    const plume_index t0[2] = {0, m->nt / 2}, ntri[2] = {m->nt / 2, m->nt - m->nt / 2 + 1};
    CHECK(plume_fields_set_objects(f, 2, t0, ntri, &err) == PLUME_EINVAL && strstr(err.msg, "object 1") &&
          strstr(err.msg, "outside the mesh"));
    CHECK(plume_fields_set_objects(f, 0, t0, ntri, &err) == PLUME_EINVAL);
    CHECK(plume_fields_set_objects(f, 1, t0, ntri, &err) == PLUME_OK);
    plume_fields_destroy(&f);
    CHECK(f == NULL);
    free(x);
    free(barbs);
    plume_mesh_destroy(&m);
}

/* The stress is dW/dE: a central difference of the energy density along random dF agrees with
 * h S : dE, in planar and shell mode, with the compression term active (J < 1). */
void test_fields_stress_fd(void)
{
    rng64 r = {12345};
    plume_membrane_material mat = test_material(5e7);
    double worst = 0.0;
    for (int trial = 0; trial < 40; trial++) {
        int dim = trial % 2 ? 3 : 2;
        double F[6], dF[6], d[2], ang = urange(&r, 0, 3.141592653589793);
        d[0] = cos(ang), d[1] = sin(ang);
        for (int k = 0; k < 2 * dim; k++)
            F[k] = urange(&r, -0.2, 0.2) + ((k == 0 || k == 3) ? 0.85 : 0.0), dF[k] = urange(&r, -1, 1);
        double E[3], S[3], J;
        CHECK(plume_membrane_strain_stress(&mat, dim, F, d, E, S, &J) == PLUME_OK);
        const double h = 1e-6;
        double Fp[6], Fm[6], Ep[3], Em[3], Sp[3], Jp;
        for (int k = 0; k < 2 * dim; k++)
            Fp[k] = F[k] + h * dF[k], Fm[k] = F[k] - h * dF[k];
        double dW = (plume_membrane_density(&mat, dim, Fp, d) - plume_membrane_density(&mat, dim, Fm, d)) / (2 * h);
        plume_membrane_strain_stress(&mat, dim, Fp, d, Ep, Sp, &Jp);
        plume_membrane_strain_stress(&mat, dim, Fm, d, Em, Sp, &Jp);
        double dE[3] = {(Ep[0] - Em[0]) / (2 * h), (Ep[1] - Em[1]) / (2 * h), (Ep[2] - Em[2]) / (2 * h)};
        double model = mat.h * (S[0] * dE[0] + S[1] * dE[1] + 2 * S[2] * dE[2]);
        double scale = mat.h * (fabs(S[0]) + fabs(S[1]) + fabs(S[2])) * (fabs(dE[0]) + fabs(dE[1]) + fabs(dE[2]));
        worst = fmax(worst, fabs(dW - model) / scale);
    }
    fprintf(stderr, "    stress against finite differences of the density: worst relative error %.2g\n", worst);
    CHECK(worst < 1e-6);
    double E[3], S[3], J, F[6] = {1, 0, 0, 1, 0, 0}, d[2] = {0, 0};
    CHECK(plume_membrane_strain_stress(&mat, 2, F, d, E, S, &J) == PLUME_EINVAL);
}

/* A flat sheet rolled into a cylinder of radius R: the mean curvature of the interior triangles
 * averages 1/(2R) when the normals (+z at rest) point outward (rolled down), -1/(2R) rolled up; the bending energy
 * densities times the areas add up to the term's energy (shape operator and hinges). */
void test_fields_cylinder(void)
{
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 30.0, 0.05, PLUME_PATCH_ALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m)
        return;
    plume_membrane_material mat = test_material(0.0);
    plume_bending_material bm = {1e-3, 2e-4, 0.0, 0.0};
    const double R = 0.8;
    double *x = malloc(3 * (size_t)m->nv * sizeof *x);
    for (int model = 0; model < 2; model++) {
        plume_term term;
        plume_status st = model ? plume_bending_term_create(m, &bm, 1, NULL, &term, &err)
                                : plume_shape_bending_term_create(m, &bm, 1, NULL, &term, &err);
        CHECK(st == PLUME_OK);
        plume_fields *f = NULL;
        CHECK(plume_fields_create(m, 3, m->nt, &mat, 1, &term, NULL, 0, &f, &err) == PLUME_OK);
        CHECK(term.eval == NULL); /* taken by the fields */
        for (int sign = -1; f && sign <= 1; sign += 2) {
            for (plume_index v = 0; v < m->nv; v++) {
                double X = m->X[2 * v] - 0.5, Y = m->X[2 * v + 1];
                x[3 * v] = R * sin(X / R), x[3 * v + 1] = Y, x[3 * v + 2] = sign * R * (1 - cos(X / R));
            }
            plume_field_values fv;
            CHECK(plume_fields_compute(f, x, &fv, &err) == PLUME_OK);
            double hsum = 0.0, asum = 0.0, ebend = 0.0;
            for (plume_index t = 0; t < m->nt; t++) {
                double A = plume_mesh_ref_area(m, t);
                ebend += fv.bending_energy[t] * A;
                int interior = 1;
                for (int k = 0; k < 3; k++)
                    interior &= !m->boundary[m->tri[3 * t + k]];
                if (interior)
                    hsum += fv.mean_curvature[t] * A, asum += A;
            }
            double H = hsum / asum;
            fprintf(stderr, "    %s, rolled %s: mean curvature %.5f (1/2R = %.5f), bending energy %.6g\n",
                    model ? "hinges" : "shape operator", sign > 0 ? "up" : "down", H, 0.5 / R, ebend);
            CHECK_REL(-sign * H, 0.5 / R, 0.02, 0.0);
            /* the densities times the areas add up to the term's energy at the same state */
            plume_term t2;
            st = model ? plume_bending_term_create(m, &bm, 1, NULL, &t2, &err)
                       : plume_shape_bending_term_create(m, &bm, 1, NULL, &t2, &err);
            double E = 0.0;
            CHECK(st == PLUME_OK && t2.eval(t2.ctx, 3, x, &E, NULL, NULL, 0) == PLUME_OK);
            CHECK(E > 0.0);
            CHECK_REL(ebend, E, 1e-12, 0.0);
            if (st == PLUME_OK)
                t2.destroy(t2.ctx);
        }
        plume_fields_destroy(&f);
    }
    free(x);
    plume_mesh_destroy(&m);
}

/* Every term that offers per-stencil energies sums them to the energy eval adds. */
void test_fields_term_energies(void)
{
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 0.8, 20.0, 0.1, PLUME_PATCH_ALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m)
        return;
    rng64 r = {777};
    double *x = malloc(3 * (size_t)m->nv * sizeof *x);
    for (plume_index v = 0; v < m->nv; v++) {
        double X = m->X[2 * v], Y = m->X[2 * v + 1];
        x[3 * v] = X + 0.01 * urange(&r, -1, 1), x[3 * v + 1] = 0.9 * Y + 0.01 * urange(&r, -1, 1);
        x[3 * v + 2] = 0.2 * X * X - 0.1 * X * Y + 0.01 * urange(&r, -1, 1);
    }
    plume_membrane_material mat = test_material(5e7);
    plume_bending_material bm = {1e-3, 2e-4, 0.0, 0.0};
    for (int k = 0; k < 3; k++) {
        plume_term t;
        plume_status st = k == 0 ? plume_membrane_term_create(m, 3, &mat, 1, &t, &err)
                          : k == 1 ? plume_shape_bending_term_create(m, &bm, 1, NULL, &t, &err)
                                   : plume_bending_term_create(m, &bm, 1, NULL, &t, &err);
        CHECK(st == PLUME_OK && t.energies != NULL);
        if (st != PLUME_OK)
            continue;
        double E = 0.0, sum = 0.0, *e = malloc((size_t)(t.nstencil + 1) * sizeof *e);
        CHECK(t.eval(t.ctx, 3, x, &E, NULL, NULL, 0) == PLUME_OK);
        CHECK(t.energies(t.ctx, 3, x, e) == PLUME_OK);
        for (plume_index s = 0; s < t.nstencil; s++)
            sum += e[s];
        CHECK_REL(sum, E, 1e-12, 0.0);
        CHECK(E > 0.0);
        free(e);
        t.destroy(t.ctx);
    }
    free(x);
    plume_mesh_destroy(&m);
}

/* A series written by the raw API and read back by ParaView's own PVD and VTU readers (pvbatch,
 * tests/python/paraview_check.py) when ParaView is installed, and by plume's reader always: times,
 * points, connectivity and fields equal what was written. */
void test_vtu_paraview(void)
{
    char dir[64], path[300], name[64];
    if (!make_tmpdir(dir)) {
        CHECK(0);
        return;
    }
    enum { NP = 40, NF = 3 };
    double pts[3 * NP], disp[3 * NP], J[NP], strain[NP];
    plume_index tri[3 * NP], lines[2 * NP];
    for (int c = 0; c < NP - 2; c++)
        tri[3 * c] = c, tri[3 * c + 1] = c + 1, tri[3 * c + 2] = c + 2;
    for (int c = 0; c < NP - 1; c++)
        lines[2 * c] = c, lines[2 * c + 1] = c + 1;
    snprintf(path, sizeof path, "%s/s.pvd", dir);
    plume_pvd *pvd = NULL;
    plume_err err = {{0}};
    CHECK(plume_pvd_create(path, &pvd, &err) == PLUME_OK);
    for (int k = 0; k < NF && pvd; k++) {
        double t = 0.25 * k;
        for (int v = 0; v < NP; v++) {
            pts[3 * v] = v, pts[3 * v + 1] = v * v / 10.0, pts[3 * v + 2] = t;
            disp[3 * v] = disp[3 * v + 1] = 0.0, disp[3 * v + 2] = t;
        }
        for (int c = 0; c < NP - 2; c++)
            J[c] = 1.0 + t + c / 100.0;
        for (int c = 0; c < NP - 1; c++)
            strain[c] = t;
        plume_vtu_field pf[] = {{"displacement", 3, 0, disp}};
        plume_vtu_field cf[] = {{"J", 1, 0, J}};
        plume_vtu_field bf[] = {{"barb_strain", 1, 0, strain}};
        plume_vtu_grid g = {NP, pts, PLUME_VTU_TRIANGLE, NP - 2, tri, 1, 1, pf, cf, t};
        plume_vtu_grid gb = {NP, pts, PLUME_VTU_LINE, NP - 1, lines, 1, 1, pf, bf, t};
        snprintf(name, sizeof name, "s_%05d.vtu", k);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        CHECK(plume_vtu_write(path, &g, &err) == PLUME_OK && plume_pvd_add(pvd, t, 0, name, &err) == PLUME_OK);
        snprintf(name, sizeof name, "s_barbs_%05d.vtu", k);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        CHECK(plume_vtu_write(path, &gb, &err) == PLUME_OK && plume_pvd_add(pvd, t, 1, name, &err) == PLUME_OK);
    }
    plume_pvd_destroy(&pvd);
    /* plume's reader */
    plume_pvd_entries e;
    snprintf(path, sizeof path, "%s/s.pvd", dir);
    CHECK(plume_pvd_read(path, &e, &err) == PLUME_OK && e.n == 2 * NF);
    for (int i = 0; i < e.n; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, e.files[i]);
        plume_vtu_data d;
        CHECK(plume_vtu_read(path, &d, &err) == PLUME_OK);
        CHECK(d.has_time && d.time == e.times[i] && d.npoints == NP && d.points && d.points[3 * 7 + 1] == 4.9 &&
              d.points[3 * 7 + 2] == e.times[i]);
        plume_vtu_data_free(&d);
    }
    plume_pvd_entries_free(&e);
    /* ParaView's */
    if (system("command -v pvbatch >/dev/null 2>&1") == 0) {
        char cmd[600], out[4096] = "";
        snprintf(cmd, sizeof cmd, "pvbatch python/paraview_check.py %s/s.pvd %d %d 2>&1", dir, NF, NP);
        FILE *p = popen(cmd, "r");
        size_t n = p ? fread(out, 1, sizeof out - 1, p) : 0;
        out[n] = '\0';
        int rc = p ? pclose(p) : -1;
        CHECK(rc == 0 && strstr(out, "paraview: 3 frames ok"));
        const char *line = strstr(out, "paraview:");
        fprintf(stderr, "    ParaView's reader (pvbatch): %.*s\n", line ? (int)strcspn(line, "\n") : 60, line ? line : out);
    } else {
        fprintf(stderr, "    pvbatch not installed: checked by plume's reader only\n");
    }
    remove_dir(dir);
}
