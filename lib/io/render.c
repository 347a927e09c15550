/* plume: flat-shaded PNG pictures of a mesh state through gnuplot.
 *
 * Shading is computed here, not by gnuplot's pm3d lighting, so a picture does not depend on the
 * gnuplot version: each triangle gets one value m + s, its material id m plus its brightness s in
 * (0, 1), and the palette ramps from a dark to a light shade of the material's colour over every
 * unit interval [m, m + 1]. Coloured by a field, each triangle carries its own RGB (the map's
 * colour at its value times its brightness, "fillcolor rgb variable"), and the palette is used only
 * for the colour bar. Triangles are drawn as degenerate pm3d quadrangles (v0 v1 / v2 v2),
 * sorted back to front by "set pm3d depthorder"; "with polygons" would be the natural plot style
 * but gnuplot 5.4 ignores per-polygon colours there.
 *
 * As in lib/io/plot.c: data and script go to a private mkdtemp directory, gnuplot is run with
 * posix_spawnp (no shell, no quoting of paths), its exit status and output are checked, and the
 * picture is copied beside its destination as "<dest>.tmp.<pid>" and renamed into place. */
#include "render.h"
#include "gnuplot.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>


enum { RENDER_PATH_MAX = 4096, RENDER_MAX_MATERIALS = 64 };

void plume_render_opts_default(plume_render_opts *o)
{
    memset(o, 0, sizeof *o);
    o->rot_x = 60.0;
    o->rot_z = 30.0;
    o->width = 1000;
    o->height = 800;
    o->light[0] = -0.3;
    o->light[1] = 0.5;
    o->light[2] = 1.0;
}

typedef struct {
    char dir[RENDER_PATH_MAX - 32];
    char data[RENDER_PATH_MAX], script[RENDER_PATH_MAX], png[RENDER_PATH_MAX], log[RENDER_PATH_MAX];
} scratch;

/* Material colours: blue vane, orange rachis, then distinct others (cycled) */
enum { PALETTE_COLOURS = 12 };
static const unsigned palette_rgb[PALETTE_COLOURS] = {0x7fb2ff, 0xffb347, 0x8fd18a, 0xe88ad1, 0xd1d18a, 0x8ad1d1,
                                                      0xff8a80, 0xb39ddb, 0x80cbc4, 0xffe082, 0xbcaaa4, 0x90a4ae};

/* Palette slot of a triangle: its category (o->category) or its material (ids are >= 0 in a
 * valid mesh; anything else gets 0) */
static int slot(const plume_mesh *m, const plume_render_opts *o, plume_index t)
{
    const int c = o->category ? o->category[t] : m->material[t];
    return c < 0 ? 0 : c % RENDER_MAX_MATERIALS;
}

/* The unit normal of triangle t at x, in the camera frame of gnuplot's "set view rot_x, rot_z"
 * (rotation about z by rot_z, then about the screen's x axis by rot_x; x right, y up, z toward the
 * viewer). 0 for a degenerate triangle. */
static int camera_normal(const plume_mesh *m, const double *x, plume_index t, double cx, double sx, double cz,
                         double sz, double n[3])
{
    const double *a = x + 3 * m->tri[3 * t], *b = x + 3 * m->tri[3 * t + 1], *c = x + 3 * m->tri[3 * t + 2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double len = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (!(len > 0.0) || !isfinite(len))
        return 0;
    for (int k = 0; k < 3; k++)
        w[k] /= len;
    double x1 = w[0] * cz + w[1] * sz, y1 = -w[0] * sz + w[1] * cz, z1 = w[2];
    n[0] = x1;
    n[1] = y1 * cx + z1 * sx;
    n[2] = -y1 * sx + z1 * cx;
    return 1;
}

/* A perceptual blue-green-yellow map (stops sampled from matplotlib's viridis), t in [0, 1]. */
static const double field_map[9][3] = {{0.267, 0.005, 0.329}, {0.278, 0.175, 0.483}, {0.231, 0.322, 0.546},
                                       {0.173, 0.449, 0.558}, {0.128, 0.567, 0.551}, {0.153, 0.680, 0.506},
                                       {0.361, 0.788, 0.388}, {0.668, 0.862, 0.196}, {0.993, 0.906, 0.144}};

static void field_colour(double t, double rgb[3])
{
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    double u = t * 8.0;
    int i = (int)u;
    if (i > 7)
        i = 7;
    u -= i;
    for (int k = 0; k < 3; k++)
        rgb[k] = (1.0 - u) * field_map[i][k] + u * field_map[i + 1][k];
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The colour bar's range: o's if set, else the 2nd to 98th percentile of the finite values (a
 * field constant to round-off gets a range of its magnitude, at least 1, around its value). -1 when out of memory. */
static int field_range(const plume_mesh *m, const plume_render_opts *o, double *lo, double *hi)
{
    if (o->field_max > o->field_min) {
        *lo = o->field_min, *hi = o->field_max;
        return 0;
    }
    double *v = malloc((size_t)m->nt * sizeof *v);
    if (!v)
        return -1;
    plume_index n = 0;
    for (plume_index t = 0; t < m->nt; t++)
        if (isfinite(o->field[t]))
            v[n++] = o->field[t];
    *lo = 0.0, *hi = 1.0;
    if (n > 0) {
        qsort(v, (size_t)n, sizeof *v, cmp_double);
        *lo = v[(plume_index)(0.02 * (double)(n - 1))], *hi = v[(plume_index)(0.98 * (double)(n - 1))];
    }
    free(v);
    if (!(*hi - *lo > 1e-6 * fmax(fabs(*lo), fabs(*hi)))) { /* constant, to round-off */
        double c = 0.5 * (*lo + *hi), w = fmax(fabs(c), 1.0) * 0.5;
        *lo = c - w, *hi = c + w;
    }
    return 0;
}

static int write_data(const scratch *s, const plume_mesh *m, const double *x, const plume_render_opts *o,
                      double flo, double fhi)
{
    FILE *f = fopen(s->data, "w");
    if (!f)
        return -1;
    const double deg = acos(-1.0) / 180.0;
    double cx = cos(o->rot_x * deg), sx = sin(o->rot_x * deg), cz = cos(o->rot_z * deg), sz = sin(o->rot_z * deg);
    double L[3] = {o->light[0], o->light[1], o->light[2]};
    double ll = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
    for (int k = 0; k < 3; k++)
        L[k] /= ll;
    for (plume_index t = 0; t < m->nt; t++) {
        double n[3];
        double shade = 0.5;
        if (camera_normal(m, x, t, cx, sx, cz, sz, n))
            shade = 0.18 + 0.8 * fabs(n[0] * L[0] + n[1] * L[1] + n[2] * L[2]);
        const plume_index *v = m->tri + 3 * t;
        const plume_index order[4] = {v[0], v[1], v[2], v[2]};
        char colour[32];
        if (o->field) { /* the field's colour times the shade, as 0xRRGGBB for "fillcolor rgb variable" */
            double rgb[3] = {0.62, 0.62, 0.62};
            if (isfinite(o->field[t]))
                field_colour((o->field[t] - flo) / (fhi - flo), rgb);
            double k = 0.25 + 0.75 * shade;
            unsigned r = (unsigned)lround(255.0 * fmin(1.0, rgb[0] * k)), g = (unsigned)lround(255.0 * fmin(1.0, rgb[1] * k)),
                     b = (unsigned)lround(255.0 * fmin(1.0, rgb[2] * k));
            snprintf(colour, sizeof colour, "%u", (r << 16) | (g << 8) | b);
        } else
            snprintf(colour, sizeof colour, "%.6f", (double)slot(m, o, t) + shade);
        for (int k = 0; k < 4; k++) {
            const double *p = x + 3 * order[k];
            fprintf(f, "%.9g %.9g %.9g %s\n", p[0], p[1], p[2], colour);
            if (k == 1)
                fputc('\n', f);
        }
        fputs("\n\n", f);
    }
    int bad = ferror(f);
    return (fclose(f) != 0 || bad) ? -1 : 0;
}

static int write_script(const scratch *s, const plume_mesh *m, const double *x, const plume_render_opts *o,
                        double flo, double fhi)
{
    FILE *f = fopen(s->script, "w");
    if (!f)
        return -1;
    fprintf(f,
            "# written by plume_render_png\nset encoding utf8\n"
            "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
            "    set terminal pngcairo size %d,%d noenhanced\n"
            "} else {\n"
            "    set terminal png size %d,%d noenhanced\n"
            "}\nset output ",
            o->width, o->height, o->width, o->height);
    plume_gnuplot_put_quoted(f, s->png);
    fputc('\n', f);
    if (o->title && *o->title) {
        fputs("set title ", f);
        plume_gnuplot_put_quoted(f, o->title);
        fputc('\n', f);
    }
    /* ranges: the bounding box, padded so that a flat or degenerate axis still has a range; with
     * equal units the box fits gnuplot's unit cube, and a view scale of 1.6 keeps any rotation of
     * a flat-ish shell inside the picture while using more of it than the default */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, ext = 0.0;
    for (plume_index v = 0; v < m->nv; v++)
        for (int a = 0; a < 3; a++)
            lo[a] = fmin(lo[a], x[3 * v + a]), hi[a] = fmax(hi[a], x[3 * v + a]);
    for (int a = 0; a < 3; a++)
        ext = fmax(ext, hi[a] - lo[a]);
    if (!(ext > 0.0))
        ext = 1.0;
    const char axis[3] = {'x', 'y', 'z'};
    for (int a = 0; a < 3; a++) {
        double pad = 0.02 * ext + 0.5 * fmax(0.0, 0.1 * ext - (hi[a] - lo[a]));
        fprintf(f, "set %crange [%.9g:%.9g]\n", axis[a], lo[a] - pad, hi[a] + pad);
    }
    fprintf(f, "set view %.6g, %.6g, 1.6\nset view equal xyz\nset xyplane 0\nunset key\n", o->rot_x, o->rot_z);
    fputs("set pm3d depthorder corners2color c1\nset pm3d border retrace\nset style fill solid 1.0\n", f);
    fputs("set tics font ',8'\nset xlabel 'x (m)'\nset ylabel 'y (m)'\nset zlabel 'z (m)'\n", f);
    if (o->field) {
        /* the triangles carry their shaded colours; the palette only draws the colour bar (through a
         * plot of no points that uses it) */
        fputs("set palette defined (", f);
        for (int k = 0; k < 9; k++)
            fprintf(f, "%s%g '#%02x%02x%02x'", k ? ", " : "", k / 8.0, (unsigned)lround(255 * field_map[k][0]),
                    (unsigned)lround(255 * field_map[k][1]), (unsigned)lround(255 * field_map[k][2]));
        fprintf(f, ")\nset cbrange [%.9g:%.9g]\nset origin 0.05, 0\nset size 0.82, 1\nset colorbox vertical user origin 0.875, 0.2 size 0.022, 0.6\n"
                   "set cbtics font ',9'\nset format cb '%%g'\n", flo, fhi);
        if (o->field_label && *o->field_label) {
            fputs("set cblabel ", f);
            plume_gnuplot_put_quoted(f, o->field_label);
            fputc('\n', f);
        }
        fputs("splot ", f);
        plume_gnuplot_put_quoted(f, s->data);
        fputs(" using 1:2:3:4 with pm3d fillcolor rgb variable, ", f);
        plume_gnuplot_put_quoted(f, s->data);
        fputs(" using 1:2:(NaN):(0) with points palette\nunset output\n", f);
    } else {
        int nmat = 1;
        for (plume_index t = 0; t < m->nt; t++)
            if (slot(m, o, t) + 1 > nmat)
                nmat = slot(m, o, t) + 1;
        fputs("unset colorbox\nset palette defined (", f);
        for (int k = 0; k < nmat; k++) {
            unsigned rgb = palette_rgb[k % PALETTE_COLOURS];
            unsigned r = (rgb >> 16) & 255, g = (rgb >> 8) & 255, b = rgb & 255;
            fprintf(f, "%s%d '#%02x%02x%02x', %d '#%02x%02x%02x'", k ? ", " : "", k, r / 8, g / 8, b / 8, k + 1, r, g,
                    b);
        }
        fprintf(f, ")\nset cbrange [0:%d]\n", nmat);
        fputs("splot ", f);
        plume_gnuplot_put_quoted(f, s->data);
        fputs(" using 1:2:3:4 with pm3d\nunset output\n", f);
    }
    int bad = ferror(f);
    return (fclose(f) != 0 || bad) ? -1 : 0;
}

static plume_status run_gnuplot(const scratch *s, plume_err *err)
{
    return plume_gnuplot_run(s->script, s->log, "render", err);
}

static plume_status install_file(const char *src, const char *dst, plume_err *err)
{
    return plume_gnuplot_install(src, dst, "render", err);
}

plume_status plume_render_png(const char *png_path, const plume_mesh *m, const double *x,
                              const plume_render_opts *opts, plume_err *err)
{
    plume_render_opts o;
    if (opts)
        o = *opts;
    else
        plume_render_opts_default(&o);
    if (!png_path || !*png_path)
        return plume_err_set(err, PLUME_EINVAL, "render: empty output path");
    if (strlen(png_path) >= RENDER_PATH_MAX - 8)
        return plume_err_set(err, PLUME_EINVAL, "render '%s': path too long", png_path);
    if (!m || m->nt < 1 || m->nv < 3 || (m->dim != 2 && m->dim != 3))
        return plume_err_set(err, PLUME_EINVAL, "render '%s': no triangles to draw", png_path);
    if (!(o.rot_x >= 0.0 && o.rot_x <= 180.0) || !(o.rot_z >= 0.0 && o.rot_z <= 360.0))
        return plume_err_set(err, PLUME_EINVAL,
                             "render '%s': view angles must be rot_x in [0, 180] and rot_z in [0, 360] (got %g, %g)",
                             png_path, o.rot_x, o.rot_z);
    if (o.width < 16 || o.height < 16 || o.width > 10000 || o.height > 10000)
        return plume_err_set(err, PLUME_EINVAL, "render '%s': size %d x %d out of [16, 10000]", png_path, o.width,
                             o.height);
    double ll = sqrt(o.light[0] * o.light[0] + o.light[1] * o.light[1] + o.light[2] * o.light[2]);
    if (!(ll > 0.0) || !isfinite(ll))
        return plume_err_set(err, PLUME_EINVAL, "render '%s': the light direction must be a non-zero vector",
                             png_path);
    /* 3D positions: a planar mesh gets z = 0 */
    double *pos = NULL;
    const double *x3 = x;
    if (!x3 && m->dim == 3)
        x3 = m->x;
    if (!x3) {
        pos = calloc((size_t)(3 * m->nv), sizeof *pos);
        if (!pos)
            return plume_err_set(err, PLUME_ENOMEM, "render '%s': out of memory", png_path);
        for (plume_index v = 0; v < m->nv; v++)
            pos[3 * v] = m->x[2 * v], pos[3 * v + 1] = m->x[2 * v + 1];
        x3 = pos;
    }
    for (plume_index i = 0; i < 3 * m->nv; i++)
        if (!isfinite(x3[i])) {
            free(pos);
            return plume_err_set(err, PLUME_EINVAL, "render '%s': vertex %ld has a non-finite position", png_path,
                                 (long)(i / 3));
        }

    scratch s;
    const char *tmpdir = getenv("TMPDIR");
    if (!tmpdir || !*tmpdir || strlen(tmpdir) > RENDER_PATH_MAX - 64)
        tmpdir = "/tmp";
    snprintf(s.dir, sizeof s.dir, "%s/plume-render-XXXXXX", tmpdir);
    if (!mkdtemp(s.dir)) {
        free(pos);
        return plume_err_set(err, PLUME_EIO, "render: cannot create a temporary directory in %s: %s", tmpdir,
                             strerror(errno));
    }
    snprintf(s.data, sizeof s.data, "%s/mesh.dat", s.dir);
    snprintf(s.script, sizeof s.script, "%s/render.gp", s.dir);
    snprintf(s.png, sizeof s.png, "%s/out.png", s.dir);
    snprintf(s.log, sizeof s.log, "%s/gnuplot.log", s.dir);

    plume_status st = PLUME_OK;
    double flo = 0.0, fhi = 1.0;
    if (o.field && field_range(m, &o, &flo, &fhi) != 0) {
        st = plume_err_set(err, PLUME_ENOMEM, "render '%s': out of memory", png_path);
        goto cleanup;
    }
    if (write_data(&s, m, x3, &o, flo, fhi) != 0 || write_script(&s, m, x3, &o, flo, fhi) != 0) {
        st = plume_err_set(err, PLUME_EIO, "render: cannot write gnuplot input in %s: %s", s.dir, strerror(errno));
        goto cleanup;
    }
    if ((st = run_gnuplot(&s, err)) != PLUME_OK)
        goto cleanup;
    struct stat sb;
    if (stat(s.png, &sb) != 0 || sb.st_size == 0) {
        char tail[400];
        plume_gnuplot_log_tail(s.log, tail, sizeof tail);
        st = plume_err_set(err, PLUME_EDEP, "render '%s': gnuplot produced no picture%s%s", png_path,
                           tail[0] ? ": " : "", tail);
        goto cleanup;
    }
    st = install_file(s.png, png_path, err);
cleanup:
    unlink(s.data);
    unlink(s.script);
    unlink(s.png);
    unlink(s.log);
    rmdir(s.dir);
    free(pos);
    return st;
}
