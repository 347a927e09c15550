/* plume: charts of curves as PNG and SVG through gnuplot.
 *
 * The data and a script go to a private mkdtemp directory; one gnuplot run draws both outputs
 * there; each is then copied beside its destination under "<dest>.tmp.<pid>" and renamed, so a
 * failed or interrupted plot never leaves a truncated image under the final name. gnuplot is run
 * with posix_spawnp (no shell, so no quoting of paths on a command line) and its exit status and
 * output are checked. */
#include "plot.h"
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


enum { PLOT_PATH_MAX = 4096 };

/* The scratch directory and the files in it. */
typedef struct {
    char dir[PLOT_PATH_MAX - 32]; /* room for the file names below */
    char data[PLOT_PATH_MAX], script[PLOT_PATH_MAX], png[PLOT_PATH_MAX], svg[PLOT_PATH_MAX],
        log[PLOT_PATH_MAX];
} scratch;

static const char *scratch_file(const scratch *s, int i)
{
    const char *f[5] = {s->data, s->script, s->png, s->svg, s->log};
    return f[i];
}

static void put_value(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.17g", v);
    else
        fputs("NaN", f); /* gnuplot skips undefined points */
}

static int write_data(const char *path, const plume_curve *curves, int ncurves, double x_scale)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    for (int c = 0; c < ncurves; c++) {
        fprintf(f, "# curve %d: strain (%%) stress (Pa) wbar\n", c + 1);
        for (plume_index i = 0; i < curves[c].n; i++) {
            put_value(f, x_scale * curves[c].strain[i]);
            fputc(' ', f);
            put_value(f, curves[c].stress[i]);
            fputc(' ', f);
            put_value(f, curves[c].wbar[i]);
            fputc('\n', f);
        }
        fputs("\n\n", f); /* two blank lines: next gnuplot "index" */
    }
    int bad = ferror(f);
    return (fclose(f) != 0 || bad) ? -1 : 0;
}

static void write_body(FILE *f, const scratch *s, const char *title, const plume_plot_axes *ax,
                       const char *const *labels, int ncurves)
{
    fputs("set multiplot layout 1,2", f);
    if (title && *title) {
        fputs(" title ", f);
        plume_gnuplot_put_quoted(f, title);
    }
    const int below = ax && ax->key_below;
    fputs(below ? "\nset grid\nset bmargin 7\nset key below Left reverse box width -2 maxrows 3"
                : "\nset grid\nset key top left Left reverse box opaque width -2", f);
    fputs(ax && ax->small_key ? " font ',8' spacing 0.8\nset xlabel " : "\nset xlabel ", f);
    plume_gnuplot_put_quoted(f, ax && ax->x_label ? ax->x_label : "nominal strain (%)");
    fputc('\n', f);
    const char *const ylabel[2] = {ax && ax->stress_label ? ax->stress_label : "nominal stress (Pa)",
                                   ax && ax->wbar_label ? ax->wbar_label : "w-bar (average relative width change)"};
    for (int panel = 0; panel < 2; panel++) {
        /* the legend where the curves are not: stress rises from the origin, so top left is free;
         * w-bar falls from 0 (the sample narrows), so bottom left is */
        if (panel == 1 && !below)
            fputs("set key bottom left\n", f);
        fputs("set ylabel ", f);
        plume_gnuplot_put_quoted(f, ylabel[panel]);
        fputs("\nplot ", f);
        for (int c = 0; c < ncurves; c++) {
            char fallback[32];
            const char *label = labels && labels[c] ? labels[c] : NULL;
            if (!label) {
                snprintf(fallback, sizeof fallback, "curve %d", c + 1);
                label = fallback;
            }
            if (c == 0)
                plume_gnuplot_put_quoted(f, s->data);
            else
                fputs(", ''", f);
            fprintf(f, " index %d using 1:%d with linespoints lc %d pt %d ps %s title ", c, panel == 0 ? 2 : 3,
                    ax && ax->color ? ax->color[c] : c + 1, ax && ax->point ? ax->point[c] : 7,
                    ax && ax->point ? "0.8" : "0.5");
            plume_gnuplot_put_quoted(f, label);
        }
        fputc('\n', f);
    }
    fputs("unset multiplot\nunset output\n", f);
}

static int write_script(const scratch *s, const char *title, const plume_plot_axes *ax, const char *const *labels,
                        int ncurves)
{
    FILE *f = fopen(s->script, "w");
    if (!f)
        return -1;
    const int height = ax && ax->key_below ? 620 : 500; /* room for the legend under the panels */
    fprintf(f,
            "# written by plume_plot_curves\nset encoding utf8\n"
            "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
            "    set terminal pngcairo size 1200,%d noenhanced\n"
            "} else {\n"
            "    set terminal png size 1200,%d noenhanced\n"
            "}\nset output ",
            height, height);
    plume_gnuplot_put_quoted(f, s->png);
    fputc('\n', f);
    write_body(f, s, title, ax, labels, ncurves);
    fprintf(f, "set terminal svg size 1200,%d noenhanced\nset output ", height);
    plume_gnuplot_put_quoted(f, s->svg);
    fputc('\n', f);
    write_body(f, s, title, ax, labels, ncurves);
    int bad = ferror(f);
    return (fclose(f) != 0 || bad) ? -1 : 0;
}

static plume_status run_gnuplot(const scratch *s, plume_err *err)
{
    return plume_gnuplot_run(s->script, s->log, "plot", err);
}

static plume_status install_file(const char *src, const char *dst, plume_err *err)
{
    return plume_gnuplot_install(src, dst, "plot", err);
}

static int non_empty(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0;
}

plume_status plume_plot_curves(const char *png_path, const char *title, const plume_curve *curves,
                               const char *const *labels, int ncurves, plume_err *err)
{
    return plume_plot_curves_axes(png_path, title, NULL, curves, labels, ncurves, err);
}

plume_status plume_plot_curves_axes(const char *png_path, const char *title, const plume_plot_axes *axes,
                                    const plume_curve *curves, const char *const *labels, int ncurves,
                                    plume_err *err)
{
    if (!png_path || !*png_path)
        return plume_err_set(err, PLUME_EINVAL, "plot: empty output path");
    if (strlen(png_path) >= PLOT_PATH_MAX - 8)
        return plume_err_set(err, PLUME_EINVAL, "plot '%s': path too long", png_path);
    if (!curves || ncurves < 1)
        return plume_err_set(err, PLUME_EINVAL, "plot '%s': no curves to draw", png_path);
    for (int c = 0; c < ncurves; c++)
        if (curves[c].n < 1 || !curves[c].strain || !curves[c].stress || !curves[c].wbar)
            return plume_err_set(err, PLUME_EINVAL,
                                 "plot '%s': curve %d has no points or no strain/stress/wbar", png_path,
                                 c + 1);

    /* SVG beside the PNG: extension of the last path component replaced, or appended. */
    char svg_path[PLOT_PATH_MAX];
    snprintf(svg_path, sizeof svg_path, "%s", png_path);
    char *slash = strrchr(svg_path, '/');
    char *base = slash ? slash + 1 : svg_path;
    char *dot = strrchr(base, '.');
    if (dot && dot != base)
        *dot = '\0';
    strcat(svg_path, ".svg");
    if (strcmp(svg_path, png_path) == 0)
        return plume_err_set(err, PLUME_EINVAL, "plot '%s': the PNG path must not end in .svg",
                             png_path);

    scratch s;
    const char *tmpdir = getenv("TMPDIR");
    if (!tmpdir || !*tmpdir || strlen(tmpdir) > PLOT_PATH_MAX - 64)
        tmpdir = "/tmp";
    snprintf(s.dir, sizeof s.dir, "%s/plume-plot-XXXXXX", tmpdir);
    if (!mkdtemp(s.dir))
        return plume_err_set(err, PLUME_EIO, "plot: cannot create a temporary directory in %s: %s",
                             tmpdir, strerror(errno));
    snprintf(s.data, sizeof s.data, "%s/curves.dat", s.dir);
    snprintf(s.script, sizeof s.script, "%s/plot.gp", s.dir);
    snprintf(s.png, sizeof s.png, "%s/out.png", s.dir);
    snprintf(s.svg, sizeof s.svg, "%s/out.svg", s.dir);
    snprintf(s.log, sizeof s.log, "%s/gnuplot.log", s.dir);

    plume_status st = PLUME_OK;
    if (write_data(s.data, curves, ncurves, axes && axes->x_scale > 0.0 ? axes->x_scale : 100.0) != 0 || write_script(&s, title, axes, labels, ncurves) != 0) {
        st = plume_err_set(err, PLUME_EIO, "plot: cannot write gnuplot input in %s: %s", s.dir,
                           strerror(errno));
        goto cleanup;
    }
    st = run_gnuplot(&s, err);
    if (st != PLUME_OK)
        goto cleanup;
    if (!non_empty(s.png) || !non_empty(s.svg)) {
        char tail[400];
        plume_gnuplot_log_tail(s.log, tail, sizeof tail);
        st = plume_err_set(err, PLUME_EDEP, "plot '%s': gnuplot produced no image%s%s", png_path,
                           tail[0] ? ": " : "", tail);
        goto cleanup;
    }
    st = install_file(s.png, png_path, err);
    if (st == PLUME_OK)
        st = install_file(s.svg, svg_path, err);

cleanup:
    for (int i = 0; i < 5; i++)
        unlink(scratch_file(&s, i));
    rmdir(s.dir);
    return st;
}
