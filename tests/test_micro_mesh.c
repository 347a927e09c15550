/* Tests of micro/layout.h and micro/cell_mesh.h: layout validation (every field, with the field
 * named in the message), periodic cells (exact areas per material, strip boundaries as edges,
 * matching periodic pairs, element size) and traction specimens (areas, barb fraction, strip
 * boundaries as edges, element size, empty space left out), and the error paths. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "../micro/cell_mesh.h"
#include "../micro/layout.h"
#include "../include/plume/traction.h"

static const double pi = 3.14159265358979323846;

static double edge_len(const plume_mesh *m, plume_index i, plume_index j)
{
    return hypot(m->X[2 * i] - m->X[2 * j], m->X[2 * i + 1] - m->X[2 * j + 1]);
}

static double max_edge(const plume_mesh *m)
{
    double mx = 0;
    for (plume_index k = 0; k < m->ne; k++)
        mx = fmax(mx, edge_len(m, m->edges[2 * k], m->edges[2 * k + 1]));
    return mx;
}

static void centroid(const plume_mesh *m, plume_index t, double c[2])
{
    const plume_index *v = m->tri + 3 * t;
    for (int k = 0; k < 2; k++)
        c[k] = (m->X[2 * v[0] + k] + m->X[2 * v[1] + k] + m->X[2 * v[2] + k]) / 3.0;
}

/* area of the triangles of material `mat` (-1: all) */
static double material_area(const plume_mesh *m, int mat)
{
    double s = 0;
    for (plume_index t = 0; t < m->nt; t++)
        if (mat < 0 || m->material[t] == mat)
            s += plume_mesh_ref_area(m, t);
    return s;
}

/* Every triangle counter-clockwise and non-degenerate, every vertex used, barb_dir as given. */
static void check_mesh_basics(const plume_mesh *m, const double d[2])
{
    CHECK(m->nv > 0 && m->nt > 0 && m->ne > 0);
    char *used = calloc((size_t)m->nv, 1);
    for (plume_index t = 0; t < m->nt; t++) {
        CHECK(plume_mesh_ref_area(m, t) > 0);
        CHECK(m->material[t] == PLUME_MAT_BARB || m->material[t] == PLUME_MAT_BARBULE);
        CHECK(m->barb_dir[2 * t] == d[0] && m->barb_dir[2 * t + 1] == d[1]);
        for (int k = 0; k < 3; k++)
            used[m->tri[3 * t + k]] = 1;
    }
    plume_index nused = 0;
    for (plume_index v = 0; v < m->nv; v++)
        nused += used[v];
    CHECK(nused == m->nv);
    free(used);
}

/* ---------------------------------------------------------------- layout */

void test_micro_mesh_layout_defaults(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {""};
    CHECK(l.kind == PLUME_LAYOUT_STRIPS);
    CHECK(l.phi == 0.16 && l.d_B == 1e-3 && l.e_rel == 0.0 && l.order == 2);
    CHECK(plume_layout_check(&l, &err) == PLUME_OK);
    CHECK_REL(plume_layout_barb_width(&l), 0.16e-3, 1e-15, 1e-300);
    l.kind = PLUME_LAYOUT_BARBULES; /* the default barbules fit their cell, for any phi up to 0.8
                                       (beyond, e = w_B is more than 4 barbule widths) */
    for (double phi = 0.01; phi < 0.8; phi += 0.07) {
        l.phi = phi;
        CHECK(plume_layout_check(&l, &err) == PLUME_OK);
    }
    plume_layout_default(&l);
    l.E_b = 3e9, l.ratio = 1e-3, l.nu_b = 0.25, l.nu_B = 0.4, l.h = 2e-4, l.kappa = 5e6;
    plume_membrane_material mats[2];
    plume_layout_materials(&l, mats);
    CHECK(mats[PLUME_MAT_BARB].moduli.E_xx == 3e9 && mats[PLUME_MAT_BARB].moduli.E_yy == 3e9);
    CHECK(mats[PLUME_MAT_BARB].moduli.nu_xy == 0.25);
    CHECK_REL(mats[PLUME_MAT_BARB].moduli.G_xy, 3e9 / 2.5, 1e-15, 1e-300);
    CHECK_REL(mats[PLUME_MAT_BARBULE].moduli.E_xx, 3e6, 1e-15, 1e-300);
    CHECK_REL(mats[PLUME_MAT_BARBULE].moduli.E_yy, 3e6, 1e-15, 1e-300);
    CHECK(mats[PLUME_MAT_BARBULE].moduli.nu_xy == 0.4);
    CHECK_REL(mats[PLUME_MAT_BARBULE].moduli.G_xy, 3e6 / 2.8, 1e-15, 1e-300);
    for (int k = 0; k < 2; k++) {
        CHECK(mats[k].h == 2e-4 && mats[k].kappa == 5e6);
        CHECK(plume_membrane_material_check(&mats[k], &err) == PLUME_OK);
    }
}

/* One bad field: PLUME_EINVAL and a message that contains `word`. */
static void expect_bad(const plume_layout *l, const char *word)
{
    plume_err err = {""};
    plume_status st = plume_layout_check(l, &err);
    CHECK(st == PLUME_EINVAL);
    if (!strstr(err.msg, word)) {
        plume_test_failures++;
        fprintf(stderr, "    message \"%s\" does not name \"%s\"\n", err.msg, word);
    }
    /* the meshers refuse it the same way */
    plume_cell *c = (plume_cell *)l; /* anything non-NULL: must be reset */
    CHECK(plume_cell_mesh(l, &c, &err) == PLUME_EINVAL && c == NULL && strstr(err.msg, word));
    plume_mesh *m = (plume_mesh *)l;
    CHECK(plume_specimen_mesh(l, 0.01, 0.013, 45, &m, &err) == PLUME_EINVAL && m == NULL && strstr(err.msg, word));
}

void test_micro_mesh_layout_bad_fields(void)
{
    plume_layout l0, l;
    plume_layout_default(&l0);
    struct {
        double *field;
        double value;
        const char *word;
    } cases[] = {
        {&l.phi, 0.0, "phi"},          {&l.phi, 1.0, "phi"},          {&l.phi, NAN, "phi"},
        {&l.phi, -0.1, "phi"},         {&l.d_B, 0.0, "d_B"},          {&l.d_B, INFINITY, "d_B"},
        {&l.E_b, -1.0, "E_b"},         {&l.E_b, NAN, "E_b"},          {&l.nu_b, 0.5, "nu_b"},
        {&l.nu_b, -1.0, "nu_b"},       {&l.ratio, 0.0, "ratio"},      {&l.ratio, -1e-3, "ratio"},
        {&l.ratio, NAN, "ratio"},      {&l.ratio, 1e300, "ratio"},    {&l.nu_B, 0.5, "nu_B"},
        {&l.nu_B, NAN, "nu_B"},        {&l.h, 0.0, "h must"},         {&l.h, NAN, "h must"},
        {&l.kappa, -1.0, "kappa"},     {&l.kappa, INFINITY, "kappa"}, {&l.e_rel, -1e-9, "e_rel"},
        {&l.e_rel, -1.0, "e_rel"},     {&l.e_rel, NAN, "e_rel"},      {&l.e_rel, 7.0, "e_rel"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        l = l0;
        *cases[k].field = cases[k].value;
        expect_bad(&l, cases[k].word);
    }
    l = l0;
    l.kind = (plume_layout_kind)7;
    expect_bad(&l, "kind");
    l = l0;
    l.order = 3;
    expect_bad(&l, "order");
    l.order = 0;
    expect_bad(&l, "order");
    /* barbule fields: ignored for strips, checked for barbules */
    l = l0;
    l.barbule_width = -1, l.barbule_angle = 0;
    plume_err err;
    CHECK(plume_layout_check(&l, &err) == PLUME_OK);
    struct {
        double *field;
        double value;
        const char *word;
    } bcases[] = {
        {&l.barbule_width, 0.0, "barbule_width"},     {&l.barbule_width, NAN, "barbule_width"},
        {&l.barbule_spacing, 0.1e-3, "barbule_spacing"}, {&l.barbule_spacing, INFINITY, "barbule_spacing"},
        {&l.barbule_angle, 0.0, "barbule_angle"},     {&l.barbule_angle, 180.0, "barbule_angle"},
        {&l.barbule_angle, NAN, "barbule_angle"},     {&l.barbule_spacing, 0.5e-3, "cell too small"},
        {&l.barbule_angle, 20.0, "cell too small"},   {&l.barbule_width, 0.9e-3, "cell too small"},
    };
    for (size_t k = 0; k < sizeof bcases / sizeof bcases[0]; k++) {
        l = l0;
        l.kind = PLUME_LAYOUT_BARBULES;
        *bcases[k].field = bcases[k].value;
        expect_bad(&l, bcases[k].word);
    }
    /* the fit is measured with the gap d_B - w_B: a wider barb makes the same barbule fit */
    l = l0;
    l.kind = PLUME_LAYOUT_BARBULES;
    l.barbule_spacing = 0.5e-3;
    l.phi = 0.5; /* extent 0.5 cot 60 + 0.2 / sin 60 = 0.520 d_B: still too long */
    expect_bad(&l, "cell too small");
    l.phi = 0.6; /* 0.4 cot 60 + 0.231 = 0.462 d_B */
    CHECK(plume_layout_check(&l, &err) == PLUME_OK);
    CHECK(plume_layout_check(NULL, &err) == PLUME_EINVAL);
}

/* ---------------------------------------------------------------- periodic cells */

/* Periodic pairs: x = a -> x = 0, y = b -> y = 0, shifts are the lattice vectors, masters are
 * their own masters, nmasters counts them. Returns the number of vertices on y = b. */
static plume_index check_periodic(const plume_cell *c)
{
    const plume_mesh *m = c->mesh;
    plume_index nm = 0, left = 0, right = 0, top = 0;
    for (plume_index v = 0; v < m->nv; v++) {
        const double *X = m->X + 2 * v;
        plume_index mv = c->master[v];
        CHECK(mv >= 0 && mv < m->nv);
        if (mv < 0 || mv >= m->nv)
            continue;
        const double *Y = m->X + 2 * mv;
        CHECK(c->master[mv] == mv);
        double sx = X[0] == c->a ? c->a : 0.0, sy = X[1] == c->b ? c->b : 0.0;
        CHECK(c->shift[2 * v] == sx && c->shift[2 * v + 1] == sy);
        CHECK(Y[0] == X[0] - sx && Y[1] == X[1] - sy);
        CHECK((mv == v) == (sx == 0.0 && sy == 0.0));
        nm += mv == v;
        left += X[0] == 0.0, right += X[0] == c->a, top += X[1] == c->b;
        CHECK(X[0] >= 0.0 && X[0] <= c->a && X[1] >= 0.0 && X[1] <= c->b);
    }
    CHECK(nm == c->nmasters);
    CHECK(left == right && left >= 2);
    return top;
}

/* total length of the mesh edges lying on y = yline */
static double covered_on_row(const plume_mesh *m, double yline)
{
    double s = 0;
    for (plume_index k = 0; k < m->ne; k++) {
        plume_index i = m->edges[2 * k], j = m->edges[2 * k + 1];
        if (m->X[2 * i + 1] == yline && m->X[2 * j + 1] == yline)
            s += edge_len(m, i, j);
    }
    return s;
}

static const double x_axis[2] = {1.0, 0.0};

void test_micro_mesh_cell_strips(void)
{
    const double e_rels[] = {1.0, 0.25, 2.9, 0.5};
    const double phis[] = {0.16, 0.5, 0.03, 0.9};
    for (int k = 0; k < 4; k++) {
        plume_layout l;
        plume_layout_default(&l);
        l.e_rel = e_rels[k], l.phi = phis[k];
        double w = plume_layout_barb_width(&l), e = l.e_rel * w;
        plume_cell *c = NULL;
        plume_err err = {""};
        CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_OK);
        if (!c) {
            fprintf(stderr, "    %s\n", err.msg);
            continue;
        }
        const plume_mesh *m = c->mesh;
        check_mesh_basics(m, x_axis);
        CHECK_REL(c->a, 4.0 * w, 1e-15, 1e-300);
        CHECK(c->b == l.d_B);
        CHECK_REL(material_area(m, -1), c->a * c->b, 1e-12, 1e-300);
        CHECK_REL(material_area(m, PLUME_MAT_BARB), w * c->a, 1e-12, 1e-300);
        CHECK_REL(material_area(m, PLUME_MAT_BARBULE), (c->b - w) * c->a, 1e-12, 1e-300);
        for (plume_index t = 0; t < m->nt; t++) {
            double ct[2];
            centroid(m, t, ct);
            CHECK((ct[1] < w) == (m->material[t] == PLUME_MAT_BARB));
        }
        /* the strip boundary and the cell sides are covered by edges */
        CHECK_REL(covered_on_row(m, w), c->a, 1e-12, 1e-300);
        CHECK_REL(covered_on_row(m, 0.0), c->a, 1e-12, 1e-300);
        CHECK_REL(covered_on_row(m, c->b), c->a, 1e-12, 1e-300);
        plume_index top = check_periodic(c);
        plume_index bottom = 0;
        for (plume_index v = 0; v < m->nv; v++)
            bottom += m->X[2 * v + 1] == 0.0;
        CHECK(top == bottom && top >= 4);
        /* masters: everything but the images on x = a and y = b */
        plume_index images = 0;
        for (plume_index v = 0; v < m->nv; v++)
            images += m->X[2 * v] == c->a || m->X[2 * v + 1] == c->b;
        CHECK(c->nmasters == m->nv - images);
        CHECK(max_edge(m) <= 2.0 * e);
        CHECK(max_edge(m) <= 2.0 * c->a / 3.0 + 1e-15 || max_edge(m) <= 2.0 * e);
        plume_cell_destroy(&c);
        CHECK(c == NULL);
    }
    plume_cell_destroy(NULL);
}

/* The barbule parallelogram as documented: centred in [0, a], sides at the angle, ends on
 * y = w_B and y = b. Is (x, y), in the gap, inside it? */
static int in_barbule(const plume_layout *l, double a, double x, double y)
{
    double w = plume_layout_barb_width(l), gap = l->d_B - w, th = l->barbule_angle * pi / 180.0;
    double cot = cos(th) / sin(th), L = l->barbule_width / sin(th);
    double x0 = 0.5 * (a - gap * fabs(cot) - L) - fmin(0.0, gap * cot);
    double xl = x0 + (y - w) * cot;
    return x >= xl - 1e-12 * a && x <= xl + L + 1e-12 * a;
}

void test_micro_mesh_cell_barbules(void)
{
    const double angles[] = {60.0, 90.0, 120.0, 50.0, 135.0, 75.0};
    const double e_rels[] = {1.0, 0.5, 1.0, 2.0, 0.3, 2.9};
    for (int k = 0; k < 6; k++) {
        plume_layout l;
        plume_layout_default(&l);
        l.kind = PLUME_LAYOUT_BARBULES;
        l.barbule_angle = angles[k], l.e_rel = e_rels[k];
        if (k == 4)
            l.phi = 0.4, l.barbule_width = 0.1e-3;
        double w = plume_layout_barb_width(&l), e = l.e_rel * w, gap = l.d_B - w;
        double th = l.barbule_angle * pi / 180.0;
        plume_cell *c = NULL;
        plume_err err = {""};
        CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_OK);
        if (!c) {
            fprintf(stderr, "    %s\n", err.msg);
            continue;
        }
        const plume_mesh *m = c->mesh;
        check_mesh_basics(m, x_axis);
        CHECK(c->a == l.barbule_spacing && c->b == l.d_B);
        CHECK_REL(material_area(m, PLUME_MAT_BARB), w * c->a, 1e-12, 1e-300);
        CHECK_REL(material_area(m, PLUME_MAT_BARBULE), l.barbule_width * gap / sin(th), 1e-9, 1e-300);
        for (plume_index t = 0; t < m->nt; t++) {
            double ct[2];
            centroid(m, t, ct);
            CHECK((ct[1] < w) == (m->material[t] == PLUME_MAT_BARB));
            if (ct[1] > w)
                CHECK(in_barbule(&l, c->a, ct[0], ct[1]));
        }
        for (plume_index v = 0; v < m->nv; v++) {
            const double *X = m->X + 2 * v;
            if (X[1] > w)
                CHECK(in_barbule(&l, c->a, X[0], X[1]));
        }
        CHECK_REL(covered_on_row(m, w), c->a, 1e-12, 1e-300);
        CHECK_REL(covered_on_row(m, 0.0), c->a, 1e-12, 1e-300);
        CHECK_REL(covered_on_row(m, c->b), l.barbule_width / sin(th), 1e-12, 1e-300);
        plume_index top = check_periodic(c);
        CHECK(top >= 2);
        CHECK(max_edge(m) <= 2.0 * e);
        plume_cell_destroy(&c);
    }
}

void test_micro_mesh_cell_bad_inputs(void)
{
    plume_layout l;
    plume_layout_default(&l);
    plume_err err = {""};
    CHECK(plume_cell_mesh(&l, NULL, &err) == PLUME_EINVAL);
    plume_cell *c = NULL;
    CHECK(plume_cell_mesh(NULL, &c, &err) == PLUME_EINVAL && c == NULL);
    l.e_rel = 1e-5; /* a 4e-4 x 1e-3 cell of 1.6e-9 m elements */
    CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_EINVAL && c == NULL && strstr(err.msg, "e_rel"));
    plume_layout_default(&l);
    l.phi = 1e-14; /* a valid layout that no mesh resolves */
    CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_EINVAL && c == NULL && strstr(err.msg, "phi"));
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES;
    l.barbule_spacing = 0.5e-3;
    CHECK(plume_cell_mesh(&l, &c, &err) == PLUME_EINVAL && c == NULL && strstr(err.msg, "cell too small"));
}

/* ---------------------------------------------------------------- specimens */

static void direction(double angle_deg, double d[2])
{
    double a = angle_deg * pi / 180.0;
    d[0] = sin(a), d[1] = cos(a);
    if (angle_deg == 0.0)
        d[0] = 0.0, d[1] = 1.0;
    if (angle_deg == 90.0)
        d[0] = 1.0, d[1] = 0.0;
}

/* Length of the line {p : q.p = c} inside [0, lx] x [0, ly]. */
static double clipped_length(double lx, double ly, const double d[2], double c)
{
    double q[2] = {-d[1], d[0]}, o[2] = {c * q[0], c * q[1]}, size[2] = {lx, ly};
    double lo = -INFINITY, hi = INFINITY;
    for (int k = 0; k < 2; k++) {
        if (fabs(d[k]) < 1e-15) {
            if (o[k] <= 1e-12 || o[k] >= size[k] - 1e-12)
                return 0.0;
            continue;
        }
        double ta = -o[k] / d[k], tb = (size[k] - o[k]) / d[k];
        lo = fmax(lo, fmin(ta, tb)), hi = fmin(hi, fmax(ta, tb));
    }
    return hi > lo ? hi - lo : 0.0;
}

/* Every strip boundary (the documented phase: a barb centred on the specimen's centre) is
 * covered by mesh edges: the edges with both ends on a boundary line add up to the lines'
 * clipped lengths. Returns the number of boundary lines crossing the specimen. */
static int check_strip_boundaries(const plume_mesh *m, const plume_layout *l, double lx, double ly,
                                  const double d[2])
{
    double q[2] = {-d[1], d[0]}, w = plume_layout_barb_width(l), e = l->e_rel * w;
    double c0 = q[0] * 0.5 * lx + q[1] * 0.5 * ly - 0.5 * w, tol = 1e-9 * fmax(lx, ly);
    double expected = 0, covered = 0;
    int nlines = 0;
    for (long k = -1000; k <= 1000; k++)
        for (int up = 0; up < 2; up++) {
            double len = clipped_length(lx, ly, d, c0 + (double)k * l->d_B + (up ? w : 0.0));
            if (len > 1e-3 * e)
                expected += len, nlines++;
        }
    for (plume_index k = 0; k < m->ne; k++) {
        plume_index i = m->edges[2 * k], j = m->edges[2 * k + 1];
        double ci = q[0] * m->X[2 * i] + q[1] * m->X[2 * i + 1] - c0;
        double cj = q[0] * m->X[2 * j] + q[1] * m->X[2 * j + 1] - c0;
        double ui = ci - l->d_B * round(ci / l->d_B), uj = cj - l->d_B * round(cj / l->d_B);
        double ri = fmin(fabs(ui), fabs(ui - w)), rj = fmin(fabs(uj), fabs(uj - w));
        if (ri < tol && rj < tol && fabs(ci - cj) < 2 * tol)
            covered += edge_len(m, i, j);
    }
    CHECK_REL(covered, expected, 1e-9, 1e-300);
    return nlines;
}

static plume_layout specimen_layout(double e_rel)
{
    plume_layout l;
    plume_layout_default(&l);
    l.d_B = 0.086 * 1.3;
    l.phi = 0.16;
    l.e_rel = e_rel;
    l.barbule_width = 0.2 * l.d_B, l.barbule_spacing = l.d_B;
    return l;
}

void test_micro_mesh_specimen_strips(void)
{
    const double angles[] = {0.0, 45.0, 90.0, 30.0, 180.0};
    for (int k = 0; k < 5; k++) {
        double lx = 1.0, ly = 1.3;
        plume_layout l = specimen_layout(k == 3 ? 2.9 : 1.0);
        double w = plume_layout_barb_width(&l), e = l.e_rel * w, d[2];
        direction(angles[k], d);
        plume_mesh *m = NULL;
        plume_err err = {""};
        CHECK(plume_specimen_mesh(&l, lx, ly, angles[k], &m, &err) == PLUME_OK);
        if (!m) {
            fprintf(stderr, "    angle %g: %s\n", angles[k], err.msg);
            continue;
        }
        if (angles[k] == 180.0) /* the direction of a barb line, not checked for orientation */
            d[0] = 0.0, d[1] = -1.0;
        check_mesh_basics(m, d);
        CHECK_REL(material_area(m, -1), lx * ly, 1e-12, 1e-300);
        double frac = material_area(m, PLUME_MAT_BARB) / (lx * ly);
        CHECK(fabs(frac - l.phi) < 0.05);
        CHECK(max_edge(m) <= 1.01 * e);
        int nlines = check_strip_boundaries(m, &l, lx, ly, d);
        CHECK(nlines >= 14);
        for (plume_index t = 0; t < m->nt; t++) { /* material from the centroid's position */
            double ct[2], q[2] = {-d[1], d[0]};
            centroid(m, t, ct);
            double u = q[0] * ct[0] + q[1] * ct[1] - (q[0] * 0.5 * lx + q[1] * 0.5 * ly - 0.5 * w);
            u -= l.d_B * floor(u / l.d_B);
            CHECK((u < w) == (m->material[t] == PLUME_MAT_BARB));
        }
        plume_mesh_destroy(&m);
    }
    /* symmetric phase: at 0 deg the barb area is the same on both halves of the specimen */
    plume_layout l = specimen_layout(1.0);
    plume_mesh *m = NULL;
    plume_err err;
    CHECK(plume_specimen_mesh(&l, 1.0, 1.3, 0.0, &m, &err) == PLUME_OK);
    if (m) {
        double half[2] = {0, 0};
        for (plume_index t = 0; t < m->nt; t++) {
            double ct[2];
            centroid(m, t, ct);
            if (m->material[t] == PLUME_MAT_BARB)
                half[ct[0] > 0.5] += plume_mesh_ref_area(m, t);
        }
        CHECK_REL(half[0], half[1], 1e-9, 1e-300);
        plume_mesh_destroy(&m);
    }
}

static plume_index root(plume_index *p, plume_index i)
{
    while (p[i] != i)
        i = p[i] = p[p[i]];
    return i;
}

/* Every connected piece of the mesh has a vertex on a grip (y = 0 or y = ly). */
static int every_piece_gripped(const plume_mesh *m, double ly)
{
    plume_index *p = malloc((size_t)m->nv * sizeof *p);
    char *held = calloc((size_t)m->nv, 1);
    for (plume_index v = 0; v < m->nv; v++)
        p[v] = v;
    for (plume_index k = 0; k < m->ne; k++)
        p[root(p, m->edges[2 * k])] = root(p, m->edges[2 * k + 1]);
    for (plume_index v = 0; v < m->nv; v++)
        if (m->X[2 * v + 1] == 0.0 || m->X[2 * v + 1] == ly)
            held[root(p, v)] = 1;
    int ok = 1;
    for (plume_index v = 0; v < m->nv; v++)
        ok &= held[root(p, v)];
    free(p);
    free(held);
    return ok;
}

void test_micro_mesh_specimen_barbules(void)
{
    const double angles[] = {0.0, 45.0, 90.0, 120.0};
    for (int k = 0; k < 4; k++) {
        double lx = 1.0, ly = 1.3;
        plume_layout l = specimen_layout(1.0);
        l.kind = PLUME_LAYOUT_BARBULES;
        double w = plume_layout_barb_width(&l), e = l.e_rel * w, d[2];
        direction(angles[k], d);
        plume_mesh *m = NULL;
        plume_err err = {""};
        CHECK(plume_specimen_mesh(&l, lx, ly, angles[k], &m, &err) == PLUME_OK);
        if (!m) {
            fprintf(stderr, "    angle %g: %s\n", angles[k], err.msg);
            continue;
        }
        check_mesh_basics(m, d);
        double total = material_area(m, -1), barb = material_area(m, PLUME_MAT_BARB);
        double barbule = material_area(m, PLUME_MAT_BARBULE);
        CHECK(total < lx * ly && total > barb && barbule > 0);
        /* barbules fill about width / (spacing sin) of the gaps */
        double th = l.barbule_angle * pi / 180.0;
        double expect = (1 - l.phi) * l.barbule_width / (l.barbule_spacing * sin(th));
        CHECK(fabs(barbule / (lx * ly) - expect) < 0.05);
        CHECK(fabs(barb / (lx * ly) - l.phi) < 0.05);
        CHECK(max_edge(m) <= 1.01 * e);
        /* no triangle in the empty space: its centroid lies in a barb or in a barbule, in the
         * barb frame with the documented phase */
        double q[2] = {-d[1], d[0]}, gap = l.d_B - w, cot = cos(th) / sin(th), L = l.barbule_width / sin(th);
        double c0 = q[0] * 0.5 * lx + q[1] * 0.5 * ly - 0.5 * w;
        double s0 = d[0] * 0.5 * lx + d[1] * 0.5 * ly - 0.5 * (gap * cot + L);
        for (plume_index t = 0; t < m->nt; t++) {
            double ct[2];
            centroid(m, t, ct);
            double u = q[0] * ct[0] + q[1] * ct[1] - c0, s = d[0] * ct[0] + d[1] * ct[1];
            u -= l.d_B * floor(u / l.d_B);
            if (u < w) {
                CHECK(m->material[t] == PLUME_MAT_BARB);
                continue;
            }
            double v = s - (s0 + (u - w) * cot);
            v -= l.barbule_spacing * floor(v / l.barbule_spacing);
            CHECK(v < L && m->material[t] == PLUME_MAT_BARBULE);
        }
        CHECK(every_piece_gripped(m, ly));
        plume_mesh_destroy(&m);
    }
}

void test_micro_mesh_specimen_bad_inputs(void)
{
    plume_layout l = specimen_layout(1.0);
    plume_err err = {""};
    plume_mesh *m = NULL;
    CHECK(plume_specimen_mesh(&l, 1, 1.3, 45, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_specimen_mesh(NULL, 1, 1.3, 45, &m, &err) == PLUME_EINVAL && m == NULL);
    const double bad_size[][2] = {{0, 1}, {1, 0}, {-1, 1}, {NAN, 1}, {1, INFINITY}};
    for (int k = 0; k < 5; k++) {
        CHECK(plume_specimen_mesh(&l, bad_size[k][0], bad_size[k][1], 45, &m, &err) == PLUME_EINVAL);
        CHECK(m == NULL && strstr(err.msg, "lx"));
    }
    const double bad_angle[] = {-1.0, 180.5, NAN};
    for (int k = 0; k < 3; k++) {
        CHECK(plume_specimen_mesh(&l, 1, 1.3, bad_angle[k], &m, &err) == PLUME_EINVAL);
        CHECK(m == NULL && strstr(err.msg, "angle"));
    }
    l.e_rel = 0.01; /* 1.8e-4 m elements on 1.3 m^2: ~9e7 triangles */
    CHECK(plume_specimen_mesh(&l, 1, 1.3, 45, &m, &err) == PLUME_EINVAL && m == NULL && strstr(err.msg, "e_rel"));
    l = specimen_layout(1.0);
    l.kind = PLUME_LAYOUT_BARBULES;
    l.barbule_width = 1e-7, l.barbule_spacing = 2e-7; /* millions of barbules, each resolved */
    CHECK(plume_specimen_mesh(&l, 1, 1.3, 45, &m, &err) == PLUME_EINVAL && m == NULL &&
          (strstr(err.msg, "barbule_spacing") || strstr(err.msg, "narrower than an element")));
}

/* The issue's bad inputs, each a clear error naming what is wrong. */
void test_micro_mesh_issue_bad_inputs(void)
{
    plume_layout l;
    plume_err err = {""};
    plume_layout_default(&l);
    l.phi = 1.0;
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "phi"));
    plume_layout_default(&l);
    l.ratio = -1.0;
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "ratio"));
    plume_layout_default(&l);
    l.e_rel = 4.5; /* barbs narrower than a quarter of an element */
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "narrower than an element"));
    plume_layout_default(&l);
    l.kind = PLUME_LAYOUT_BARBULES;
    l.barbule_spacing = 0.3e-3; /* the default barbule needs more room along the barbs */
    CHECK(plume_layout_check(&l, &err) == PLUME_EINVAL && strstr(err.msg, "cell too small"));
}
