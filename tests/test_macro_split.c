/* Barb lines that split in the macro vane (macro/shell/split_lines.h; docs/unzipping.md, "The
 * macro split"): a line opened across a traction specimen holds with the hooks' compliance in
 * series with the membrane, lets go along its whole length at its strength when pulled straight,
 * unzips from the far end when peeled, with the same elastic branch and peak on two meshes; bad
 * lines are named. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../include/plume/traction.h"
#include "../lib/core/mesh.h"
#include "../macro/shell/split_lines.h"

/* A vane of the order of data/layout_hooks.json's cell (barbs along x, pulled along y across them):
 * stiff along the barbs, soft across. */
static void hooked_vane(plume_vane *v)
{
    plume_vane_default(v);
    v->moduli = (plume_ortho){1.2e9, 3.2e6, 0.0, 1.1e6};
    v->h = 1e-4;
}

/* A line of 1 N/m, its hooks opening 2 um at the strength, catching again within 5 um. */
static plume_separation_law line_law(void)
{
    plume_separation_law s;
    memset(&s, 0, sizeof s);
    s.strength = 1.0, s.stiffness = 1.0 / 2e-6, s.capture = 5e-6, s.energy = 0.01;
    return s;
}

static const double LX = 4e-3, LY = 2e-3;

static void split_run(double edge, double peel, int steps, double strain_max, double slide, plume_traction_result *r,
                      plume_index *npairs)
{
    plume_err err = {{0}};
    plume_mesh *m = NULL;
    plume_problem *p = NULL;
    plume_split_lines sl;
    memset(&sl, 0, sizeof sl);
    plume_index *barbs = NULL, nb = 0;
    plume_vane v;
    hooked_vane(&v);
    plume_separation_law law = line_law();
    if (slide > 0.0) /* the law opens `slide` further after its peak: its links soften */
        law.peak_opening = law.strength / law.stiffness, law.opening = law.peak_opening + slide;
    const double d[2] = {1.0, 0.0}, c = -0.5 * LY; /* n = (0, -1): the line y = ly / 2 */
    memset(r, 0, sizeof *r);
    CHECK(plume_patch_mesh(LX, LY, 90.0, edge, PLUME_PATCH_ALIGNED, 2, &m, &err) == PLUME_OK);
    CHECK(plume_split_lines_open(m, d, &c, 1, &sl, &err) == PLUME_OK);
    *npairs = sl.npairs;
    CHECK(plume_problem_create(sl.mesh->nv, 2, LY, &p, &err) == PLUME_OK);
    CHECK(plume_vane_add(p, sl.mesh, &v, &barbs, &nb, &err) == PLUME_OK);
    CHECK(plume_split_lines_add(p, &sl, &law, NULL, &err) == PLUME_OK);
    plume_traction_opts o;
    plume_traction_opts_default(&o);
    o.lx = LX, o.ly = LY, o.h = v.h, o.steps = steps, o.strain_max = strain_max, o.progress = 0;
    o.peel = peel;
    if (plume_traction_run(sl.mesh, p, barbs, nb, &o, r, &err) != PLUME_OK)
        fprintf(stderr, "    traction: %s\n", err.msg);
    free(barbs);
    plume_problem_destroy(&p);
    plume_split_lines_free(&sl);
    plume_mesh_destroy(&m);
}

/* Pulled straight: the membrane and the line in series until the line lets go whole at its
 * strength times its length. */
void test_macro_split_straight(void)
{
    plume_vane v;
    hooked_vane(&v);
    const plume_separation_law law = line_law();
    plume_traction_result r;
    plume_index n = 0;
    split_run(2.5e-4, 0.0, 10, 0.01, 0.0, &r, &n);
    const double F = r.peak_stress * LX * v.h;
    printf("    %ld pairs: converged %d, peak %.4g N (strength x length %.4g N), %ld released, largest cascade %d, "
           "balance %.2e, dissipated %.3g J\n", (long)n, r.converged, F, law.strength * LX, r.released,
           r.largest_cascade, r.energy_balance_error, r.dissipated_energy);
    CHECK(r.converged);
    CHECK(r.released == n);
    CHECK(F >= 0.98 * law.strength * LX && F <= PLUME_SPLIT_OVERSHOOT * law.strength * LX);
    CHECK(fabs(r.energy_balance_error) < 1e-2);
    /* everything the specimen held at the peak is lost when the line lets go whole: the membrane
     * and the line in series, D = F^2 / 2 (ly / (E_yy h) + 1 / K) / lx */
    const double D = 0.5 * F * F * (LY / (v.moduli.E_yy * v.h) + 1.0 / law.stiffness) / LX;
    CHECK_REL(r.dissipated_energy, D, 0.01, 0.0);
    /* before it lets go: the membrane across ly and the line in series, T = e ly / (ly / (E_yy h) + 1 / K) */
    const double e = r.curve.strain[1], T = r.curve.stress[1] * v.h;
    const double Tseries = e * LY / (LY / (v.moduli.E_yy * v.h) + 1.0 / law.stiffness);
    printf("    first step: traction %.6g N/m, series %.6g N/m\n", T, Tseries);
    CHECK_REL(T, Tseries, 0.01, 0.0);
    plume_traction_result_free(&r);
}

/* Peeled (the top grip turning about its x = 0 end): the line unzips from the far end in events,
 * the barbs' stiffness spreading the load so that most of it lets go in one cascade.
 *  - Brittle links (the law of a cell whose hooks do not slide), on meshes of 0.25 and 0.125 mm: the
 *    elastic branch and the peak force agree within 1 %; the dissipated energy, most of it lost in
 *    the cascade's snaps, falls with the mesh at first order (docs/unzipping.md: 9.48, 8.33, 7.74,
 *    7.46 nJ at 0.25 to 0.03125 mm).
 *  - Softening links (a law that slides 1 um past its peak: the bilinear law of the same energy,
 *    zero force at 4 um): the cohesive zone is resolved, and the peak and dissipated energy agree
 *    within 5 % on the same two meshes (measured 1.3 % and 3.0 %; 0.4 % and 0.02 % from 0.125 to
 *    0.0625 mm). Every link lets go, so at least the law's energy under the whole line is
 *    dissipated: (r / 2) strength d0 lx. */
void test_macro_split_zipper_meshes(void)
{
    double peak[2][2], dis[2][2], branch[2][2];
    const double slide[2] = {0.0, 1e-6};
    const plume_separation_law law = line_law();
    const double d0 = law.strength / law.stiffness, r_soft = 1.0 + 2.0 * slide[1] / d0;
    plume_separation_law sliding = law;
    sliding.peak_opening = d0, sliding.opening = d0 + slide[1];
    CHECK(plume_split_softening(&law) == 1.0 && fabs(plume_split_softening(&sliding) - 2.0) < 1e-12);
    sliding.opening = d0; /* the peak at the opening: brittle */
    CHECK(plume_split_softening(&sliding) == 1.0);
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 2; k++) {
            const double edge = k ? 1.25e-4 : 2.5e-4;
            plume_traction_result r;
            plume_index n = 0;
            split_run(edge, 1.0, 40, 0.02, slide[s], &r, &n);
            plume_vane v;
            hooked_vane(&v);
            peak[s][k] = r.peak_stress * LX * v.h;
            dis[s][k] = r.dissipated_energy;
            branch[s][k] = r.curve.n > 4 ? r.curve.stress[4] : 0.0;
            printf("    %s, edge %.3g mm, %ld pairs: converged %d, peak %.4g N, %ld released in %d events (largest %d), "
                   "dissipated %.4g J, balance %.2e, %d iterations\n", s ? "softening" : "brittle", 1e3 * edge, (long)n,
                   r.converged, peak[s][k], r.released, r.release_events, r.largest_cascade, dis[s][k],
                   r.energy_balance_error, r.newton_iterations);
            CHECK(r.converged);
            CHECK(r.released >= n);
            CHECK(r.release_events >= 5 && r.largest_cascade < n);
            CHECK(fabs(r.energy_balance_error) < 1e-2);
            plume_traction_result_free(&r);
        }
    CHECK_REL(branch[0][1], branch[0][0], 0.01, 0.0);
    CHECK_REL(peak[0][1], peak[0][0], 0.01, 0.0);
    CHECK(dis[0][1] < dis[0][0] && dis[0][1] > 0.8 * dis[0][0]);
    CHECK_REL(branch[1][1], branch[1][0], 0.01, 0.0);
    CHECK_REL(peak[1][1], peak[1][0], 0.05, 0.0);
    CHECK_REL(dis[1][1], dis[1][0], 0.05, 0.0);
    const double line = 0.5 * r_soft * law.strength * d0 * LX;
    printf("    softening r = %g: the law's energy under the line %.4g J\n", r_soft, line);
    CHECK(dis[1][0] >= line && dis[1][1] >= line);
}

void test_macro_split_bad_input(void)
{
    plume_err err = {{0}};
    plume_mesh *m = NULL;
    plume_split_lines sl;
    const double d[2] = {1.0, 0.0};
    CHECK(plume_patch_mesh(LX, LY, 90.0, 5e-4, PLUME_PATCH_ALIGNED, 2, &m, &err) == PLUME_OK);
    const double edge_c = 0.0; /* the bottom side */
    CHECK(plume_split_lines_open(m, d, &edge_c, 1, &sl, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "crosses") || strstr(err.msg, "cross the vane"));
    const double twice[2] = {-0.5 * LY, -0.5 * LY - 1e-9};
    CHECK(plume_split_lines_open(m, d, twice, 2, &sl, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "same line") != NULL);
    plume_mesh_destroy(&m);
    /* an unaligned mesh has no chain of edges along the barbs */
    CHECK(plume_patch_mesh(LX, LY, 90.0, 5e-4, PLUME_PATCH_UNALIGNED, 2, &m, &err) == PLUME_OK);
    const double c = -0.37 * LY;
    plume_status st = plume_split_lines_open(m, d, &c, 1, &sl, &err);
    CHECK(st == PLUME_EINVAL);
    CHECK(strstr(err.msg, "aligned") != NULL || strstr(err.msg, "no line") != NULL);
    plume_mesh_destroy(&m);
    /* a law without strength or stiffness */
    CHECK(plume_patch_mesh(LX, LY, 90.0, 5e-4, PLUME_PATCH_ALIGNED, 2, &m, &err) == PLUME_OK);
    const double mid = -0.5 * LY;
    CHECK(plume_split_lines_open(m, d, &mid, 1, &sl, &err) == PLUME_OK);
    plume_problem *p = NULL;
    CHECK(plume_problem_create(sl.mesh->nv, 2, LY, &p, &err) == PLUME_OK);
    plume_separation_law law = line_law();
    law.stiffness = 0.0;
    CHECK(plume_split_lines_add(p, &sl, &law, NULL, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "stiffness") != NULL);
    plume_problem_destroy(&p);
    plume_split_lines_free(&sl);
    plume_mesh_destroy(&m);
}

/* plume_mesh_edge, the lookup the lines use: every edge found at its index, either order; a pair
 * of vertices that is no edge gives -1. */
void test_macro_split_edge_lookup(void)
{
    plume_err err = {{0}};
    plume_mesh *m = NULL;
    CHECK(plume_patch_mesh(LX, LY, 30.0, 5e-4, PLUME_PATCH_ALIGNED, 2, &m, &err) == PLUME_OK);
    int bad = 0;
    for (plume_index e = 0; m && e < m->ne; e++)
        bad += plume_mesh_edge(m, m->edges[2 * e], m->edges[2 * e + 1]) != e ||
               plume_mesh_edge(m, m->edges[2 * e + 1], m->edges[2 * e]) != e;
    CHECK(bad == 0);
    /* vertex 0 and a vertex not joined to it */
    plume_index far = -1;
    for (plume_index v = 1; m && v < m->nv && far < 0; v++) {
        int joined = 0;
        for (plume_index e = 0; e < m->ne; e++)
            joined |= (m->edges[2 * e] == 0 && m->edges[2 * e + 1] == v);
        if (!joined)
            far = v;
    }
    CHECK(far > 0 && plume_mesh_edge(m, 0, far) == -1 && plume_mesh_edge(m, far, 0) == -1);
    plume_mesh_destroy(&m);
}
