/* Output of dynamic runs: the HDF5 frames file (round trip, append, interrupted appends, errors),
 * legacy VTK frames and PNG renders. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>

#include "harness.h"
#include "png_read.h"
#include "h5_units.h"
#include "test_rng.h"
#include "../lib/io/frames.h"
#include "../lib/core/mesh.h"
#include "../lib/io/render.h"
#include "../lib/io/vtk.h"
#include "../macro/shell/patch_mesh.h"

static int scratch_dir(char *dir)
{
    strcpy(dir, "/tmp/plume-frames-XXXXXX");
    return mkdtemp(dir) != NULL;
}

static void remove_dir(const char *dir)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

static int same(const double *a, const double *b, plume_index n)
{
    return n == 0 || memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

typedef struct {
    char (*names)[32];
    int n, max;
} name_list;

static herr_t add_name(hid_t g, const char *name, const H5L_info_t *info, void *data)
{
    (void)g, (void)info;
    name_list *l = data;
    if (l->n < l->max)
        snprintf(l->names[l->n], 32, "%s", name);
    l->n++;
    return 0;
}

/* The names of /frames' members in the order HDF5 lists them by name (h5py's and h5ls' order), at
 * most max of them kept; how many there are, or -1. */
static int list_frames(const char *path, char (*names)[32], int max)
{
    name_list l = {names, 0, max};
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t g = f < 0 ? H5I_INVALID_HID : H5Gopen2(f, "/frames", H5P_DEFAULT);
    int ok = g >= 0 && H5Literate(g, H5_INDEX_NAME, H5_ITER_INC, NULL, add_name, &l) >= 0;
    if (g >= 0)
        H5Gclose(g);
    if (f >= 0)
        H5Fclose(f);
    return ok ? l.n : -1;
}

/* The expected values of frame k of data/frames_old_names.h5 (x[i] = k + 0.1 i, v[i] = -k - 0.01 i,
 * lambda = 1000 + k, t = 0.25 k, step k; nv 3, ncons 1) */
static int old_frame_ok(const plume_frame *f, long k)
{
    int ok = f->index == k && f->step == k && f->t == 0.25 * (double)k && f->nv == 3 && f->ncons == 1 && f->x && f->v &&
             f->lambda && f->lambda[0] == 1000.0 + (double)k;
    for (int i = 0; ok && i < 9; i++)
        ok = f->x[i] == (double)k + 0.1 * i && f->v[i] == -(double)k - 0.01 * i;
    return ok;
}

/* Three frames written and read back bit for bit; the last frame and frame 1 by index. */
void test_frames_roundtrip(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/frames.h5", dir);
    const plume_index nv = 7, nc = 4;
    double x[3][21], v[3][21], l[3][4];
    rng64 rng = {12345};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < 21; i++)
            x[k][i] = urand(&rng) - 0.5, v[k][i] = 1e3 * (urand(&rng) - 0.5);
        for (int i = 0; i < 4; i++)
            l[k][i] = urand(&rng) * 1e-7;
    }
    plume_err err = {{0}};
    CHECK(plume_frames_create(path, nv, nc, 0.011, "data/feather/scene.json", &err) == PLUME_OK);
    plume_frames_info info;
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 0);
    plume_frame f;
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_EINVAL); /* no frame yet */
    for (int k = 0; k < 3; k++)
        CHECK(plume_frames_append(path, nv, nc, 0.011 * 3 * k, 3L * k, x[k], v[k], l[k], &err) == PLUME_OK);
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK);
    CHECK(info.count == 3 && info.nv == nv && info.ncons == nc && info.dt == 0.011);
    CHECK(strcmp(info.scene, "data/feather/scene.json") == 0);
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK);
    CHECK(f.index == 2 && f.step == 6 && f.t == 0.011 * 6 && f.nv == nv && f.ncons == nc);
    CHECK(f.x && same(f.x, x[2], 21) && same(f.v, v[2], 21) && same(f.lambda, l[2], 4));
    plume_frame_free(&f);
    CHECK(plume_frames_read(path, 1, &f, &err) == PLUME_OK);
    CHECK(f.index == 1 && f.step == 3 && f.t == 0.011 * 3);
    CHECK(f.x && same(f.x, x[1], 21) && same(f.v, v[1], 21) && same(f.lambda, l[1], 4));
    plume_frame_free(&f);
    CHECK(f.x == NULL);
    /* errors */
    CHECK(plume_frames_read(path, 3, &f, &err) == PLUME_EINVAL && strstr(err.msg, "no frame 3"));
    CHECK(plume_frames_append(path, nv + 1, nc, 1.0, 9, x[0], v[0], l[0], &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "7 vertices") != NULL);
    CHECK(plume_frames_read("/nonexistent/f.h5", 0, &f, &err) == PLUME_EIO && strstr(err.msg, "/nonexistent/f.h5"));
    CHECK(plume_frames_create(path, 0, 0, 0.01, NULL, &err) == PLUME_EINVAL);
    CHECK(plume_frames_create(path, 3, 0, 0.0, NULL, &err) == PLUME_EINVAL);
    char bad[128];
    snprintf(bad, sizeof bad, "%s/text.h5", dir);
    FILE *t = fopen(bad, "w");
    fputs("not hdf5\n", t);
    fclose(t);
    CHECK(plume_frames_info_read(bad, &info, &err) == PLUME_EFORMAT && strstr(err.msg, "not an HDF5 file"));
    CHECK(plume_frames_create("/nonexistent/dir/f.h5", 3, 0, 0.01, NULL, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, "/nonexistent/dir/f.h5") != NULL);
    /* no constraints: lambda may be NULL */
    snprintf(bad, sizeof bad, "%s/free.h5", dir);
    CHECK(plume_frames_create(bad, nv, 0, 0.5, "", &err) == PLUME_OK);
    CHECK(plume_frames_append(bad, nv, 0, 0.5, 1, x[0], v[0], NULL, &err) == PLUME_OK);
    CHECK(plume_frames_read(bad, 0, &f, &err) == PLUME_OK && f.lambda == NULL && same(f.x, x[0], 21));
    plume_frame_free(&f);
    /* measures: written as attributes of the frame, read back exactly; a frame without them says so */
    plume_frame_measures m = {7, 1, 0.25, 42, 3.5e-4, 0}, r;
    CHECK(plume_frames_read_measures(bad, 0, &r, &err) == PLUME_EFORMAT && strstr(err.msg, "no measures"));
    CHECK(plume_frames_append_measured(bad, nv, 0, 1.0, 2, x[1], v[1], NULL, &m, &err) == PLUME_OK);
    CHECK(plume_frames_read_measures(bad, -1, &r, &err) == PLUME_OK && memcmp(&r, &m, sizeof m) == 0);
    CHECK(plume_frames_read(bad, 1, &f, &err) == PLUME_OK && f.step == 2 && same(f.x, x[1], 21));
    plume_frame_free(&f);
    CHECK(plume_frames_read_measures(bad, 5, &r, &err) == PLUME_EINVAL);
    /* self-describing: every dataset says its units */
    char units[32] = "";
    CHECK(h5_units(path, "/frames/0000002/x", units, sizeof units) == 0 && strcmp(units, "m") == 0);
    CHECK(h5_units(path, "/frames/0000002/v", units, sizeof units) == 0 && strcmp(units, "m/s") == 0);
    CHECK(h5_units(path, "/frames/0000002/lambda", units, sizeof units) == 0 && strcmp(units, "N/m") == 0);
    /* and the numeric attributes theirs, in one "units" string beside them */
    char aunits[256] = "";
    CHECK(h5_units(path, "/frames", aunits, sizeof aunits) == 0 && strstr(aunits, "dt: s"));
    CHECK(h5_units(path, "/frames/0000002", aunits, sizeof aunits) == 0 && strcmp(aunits, "t: s; step: 1") == 0);
    CHECK(h5_units(bad, "/frames/0000001", aunits, sizeof aunits) == 0 && strstr(aunits, "t: s;") &&
          strstr(aunits, "min_distance: m") && strstr(aunits, "seconds: s") && strstr(aunits, "newton_iterations: 1"));
    remove_dir(dir);
}

/* An append interrupted after creating its group but before the commit mark: readers ignore the
 * group, and the next append replaces it. Creating over an existing file starts afresh. */
void test_frames_interrupted_append(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/frames.h5", dir);
    double x[6] = {1, 2, 3, 4, 5, 6}, v[6] = {0}, l[1] = {0.25};
    plume_err err = {{0}};
    CHECK(plume_frames_create(path, 2, 1, 0.1, "s.json", &err) == PLUME_OK);
    CHECK(plume_frames_append(path, 2, 1, 0.0, 0, x, v, l, &err) == PLUME_OK);
    /* the crash: /frames/0000001 half written, count still 1 */
    hid_t fid = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    CHECK(fid >= 0);
    hid_t g = H5Gcreate2(fid, "/frames/0000001", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    CHECK(g >= 0);
    H5Gclose(g);
    H5Fclose(fid);
    plume_frame f;
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.index == 0 && same(f.x, x, 6));
    plume_frame_free(&f);
    CHECK(plume_frames_read(path, 1, &f, &err) == PLUME_EINVAL);
    x[0] = -1.0;
    CHECK(plume_frames_append(path, 2, 1, 0.1, 1, x, v, l, &err) == PLUME_OK);
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.index == 1 && f.step == 1 && f.x[0] == -1.0);
    plume_frame_free(&f);
    plume_frames_info info;
    CHECK(plume_frames_create(path, 3, 0, 0.2, "t.json", &err) == PLUME_OK);
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 0 && info.nv == 3);
    CHECK(strcmp(info.scene, "t.json") == 0);
    remove_dir(dir);
}

/* A frames file left by a SIGKILL during the flush of an append (tests/data/frames_killed_in_flush.h5,
 * from a kill-and-restart stress run of apps/feather on data/shell/strip_scene.json): count 5, and
 * an uncommitted /frames/5 that HDF5 cannot remove in place ("len not positive after adjustment
 * for EOA"; the restart used to fail there). The next append rebuilds the file from its committed
 * frames: frames 0-4 come back bit for bit, the new frame is frame 5. */
void test_frames_killed_in_flush(void)
{
    char dir[64], path[128], cmd[300];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/frames.h5", dir);
    snprintf(cmd, sizeof cmd, "cp data/frames_killed_in_flush.h5 %s", path);
    CHECK(system(cmd) == 0);
    plume_frames_info info;
    plume_err err = {{0}};
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 5);
    plume_frame before[5];
    memset(before, 0, sizeof before);
    for (long k = 0; k < 5; k++)
        CHECK(plume_frames_read(path, k, &before[k], &err) == PLUME_OK);
    const plume_index n = 3 * info.nv;
    double *x = malloc((size_t)n * sizeof *x);
    CHECK(x != NULL);
    if (x) {
        for (plume_index i = 0; i < n; i++)
            x[i] = before[4].x[i] + 1e-3;
        const plume_status st = plume_frames_append(path, info.nv, info.ncons, before[4].t + info.dt, before[4].step + 1,
                                                     x, before[4].v, before[4].lambda, &err);
        if (st != PLUME_OK)
            fprintf(stderr, "    append: %s\n", err.msg);
        CHECK(st == PLUME_OK);
        plume_frames_info after;
        CHECK(plume_frames_info_read(path, &after, &err) == PLUME_OK && after.count == 6 && after.nv == info.nv &&
              after.ncons == info.ncons && after.dt == info.dt && strcmp(after.scene, info.scene) == 0);
        for (long k = 0; k < 5; k++) {
            plume_frame f;
            CHECK(plume_frames_read(path, k, &f, &err) == PLUME_OK && f.t == before[k].t && f.step == before[k].step &&
                  same(f.x, before[k].x, n) && same(f.v, before[k].v, n) &&
                  same(f.lambda, before[k].lambda, info.ncons));
            plume_frame_free(&f);
        }
        plume_frame f;
        CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.index == 5 && same(f.x, x, n));
        plume_frame_free(&f);
        /* the file had decimal names: the rebuild padded them */
        char names[8][32];
        CHECK(list_frames(path, names, 8) == 6 && strcmp(names[0], "0000000") == 0 && strcmp(names[5], "0000005") == 0);
    }
    free(x);
    for (long k = 0; k < 5; k++)
        plume_frame_free(&before[k]);
    /* no temporary file left beside it */
    snprintf(cmd, sizeof cmd, "test $(ls %s | wc -l) -eq 1", dir);
    CHECK(system(cmd) == 0);
    remove_dir(dir);
}

/* Frame groups are named by their number padded to seven digits, so that a listing by name (h5py,
 * h5ls) gives them in frame order past frame 9 as well. */
void test_frames_padded_names(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/frames.h5", dir);
    double x[3] = {0, 0, 0}, v[3] = {0, 0, 0};
    plume_err err = {{0}};
    CHECK(plume_frames_create(path, 1, 0, 0.5, "s.json", &err) == PLUME_OK);
    for (long k = 0; k < 12; k++) {
        x[0] = (double)k;
        CHECK(plume_frames_append(path, 1, 0, 0.5 * (double)k, k, x, v, NULL, &err) == PLUME_OK);
    }
    char names[16][32];
    CHECK(list_frames(path, names, 16) == 12);
    for (int k = 0; k < 12; k++) {
        char want[32];
        snprintf(want, sizeof want, "%07d", k);
        CHECK(strcmp(names[k], want) == 0);
    }
    plume_frame f;
    CHECK(plume_frames_read(path, 10, &f, &err) == PLUME_OK && f.index == 10 && f.x[0] == 10.0 && f.t == 5.0);
    plume_frame_free(&f);
    remove_dir(dir);
}

/* A file written before the names were padded (tests/data/frames_old_names.h5: 12 frames named
 * "0" ... "11", written by plume 0.4's plume_frames_create and plume_frames_append, nv 3, ncons 1)
 * reads frame by frame; the first append rewrites it with padded names, every frame kept bit for
 * bit, and lists them in order. */
void test_frames_old_names(void)
{
    char dir[64], path[128], cmd[300];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    snprintf(path, sizeof path, "%s/frames.h5", dir);
    snprintf(cmd, sizeof cmd, "cp data/frames_old_names.h5 %s", path);
    CHECK(system(cmd) == 0);
    char names[16][32];
    CHECK(list_frames(path, names, 16) == 12 && strcmp(names[1], "1") == 0 && strcmp(names[2], "10") == 0);
    plume_frames_info info;
    plume_err err = {{0}};
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 12 && info.nv == 3 &&
          info.ncons == 1 && info.dt == 0.25 && strcmp(info.scene, "old_style_scene.json") == 0);
    plume_frame f;
    for (long k = 0; k < 12; k++) {
        CHECK(plume_frames_read(path, k, &f, &err) == PLUME_OK && old_frame_ok(&f, k));
        plume_frame_free(&f);
    }
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && old_frame_ok(&f, 11));
    plume_frame_free(&f);
    CHECK(plume_frames_read(path, 12, &f, &err) == PLUME_EINVAL && strstr(err.msg, "no frame 12"));
    /* the append: every old frame back bit for bit, padded names in frame order */
    double x[9] = {0}, v[9] = {0}, l[1] = {7.0};
    CHECK(plume_frames_append(path, 3, 1, 3.0, 12, x, v, l, &err) == PLUME_OK);
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 13 &&
          strcmp(info.scene, "old_style_scene.json") == 0);
    for (long k = 0; k < 12; k++) {
        CHECK(plume_frames_read(path, k, &f, &err) == PLUME_OK && old_frame_ok(&f, k));
        plume_frame_free(&f);
    }
    CHECK(plume_frames_read(path, -1, &f, &err) == PLUME_OK && f.index == 12 && f.lambda[0] == 7.0 && f.t == 3.0);
    plume_frame_free(&f);
    CHECK(list_frames(path, names, 16) == 13);
    for (int k = 0; k < 13; k++) {
        char want[32];
        snprintf(want, sizeof want, "%07d", k);
        CHECK(strcmp(names[k], want) == 0);
    }
    /* no temporary file left beside it */
    snprintf(cmd, sizeof cmd, "test $(ls %s | wc -l) -eq 1", dir);
    CHECK(system(cmd) == 0);
    remove_dir(dir);
}

/* Counts of a VTK file: POINTS nv, CELLS nt 4nt, CELL_TYPES, CELL_DATA, POINT_DATA; the
 * displacement of a displaced vertex. */
void test_frames_vtk_counts(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.3, 45.0, 0.25, PLUME_PATCH_ALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m) {
        remove_dir(dir);
        return;
    }
    m->material[0] = 1;
    double *x = malloc((size_t)(3 * m->nv) * sizeof *x);
    memcpy(x, m->x, (size_t)(3 * m->nv) * sizeof *x);
    x[3 * 2 + 2] = 0.5;
    snprintf(path, sizeof path, "%s/frame_00000.vtk", dir);
    CHECK(plume_vtk_write(path, m, x, 0.25, &err) == PLUME_OK);
    FILE *f = fopen(path, "r");
    CHECK(f != NULL);
    char line[512];
    long points = -1, cells = -1, size = -1, types = -1, cdata = -1, pdata = -1, ones = 0, lines_after_points = 0;
    int in_points = 0, in_mat = 0, saw_time = 0;
    double disp_z = 0.0;
    long pd_line = -1;
    while (f && fgets(line, sizeof line, f)) {
        if (sscanf(line, "POINTS %ld", &points) == 1) {
            in_points = 1;
            continue;
        }
        if (sscanf(line, "CELLS %ld %ld", &cells, &size) == 2) {
            in_points = 0;
            continue;
        }
        if (in_points)
            lines_after_points++;
        sscanf(line, "CELL_TYPES %ld", &types);
        sscanf(line, "CELL_DATA %ld", &cdata);
        if (sscanf(line, "POINT_DATA %ld", &pdata) == 1)
            pd_line = 0;
        if (strncmp(line, "TIME 1 1 double", 15) == 0)
            saw_time = 1;
        if (strncmp(line, "LOOKUP_TABLE", 12) == 0) {
            in_mat = 1;
            continue;
        }
        if (in_mat && strncmp(line, "VECTORS", 7) == 0)
            in_mat = 0;
        if (in_mat && strcmp(line, "1\n") == 0)
            ones++;
        if (pd_line >= 0 && strncmp(line, "VECTORS displacement", 20) != 0 && strncmp(line, "POINT_DATA", 10) != 0) {
            double a, b, c;
            if (pd_line == 2 && sscanf(line, "%lf %lf %lf", &a, &b, &c) == 3)
                disp_z = c;
            pd_line++;
        }
    }
    if (f)
        fclose(f);
    CHECK(points == m->nv && lines_after_points == m->nv);
    CHECK(cells == m->nt && size == 4 * m->nt && types == m->nt && cdata == m->nt && pdata == m->nv);
    CHECK(ones == 1);  /* one triangle of material 1 */
    CHECK(saw_time);
    CHECK(disp_z == 0.5);
    /* errors name the file */
    CHECK(plume_vtk_write("/nonexistent/dir/f.vtk", m, x, 0.0, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, "/nonexistent/dir/f.vtk") != NULL);
    CHECK(plume_vtk_write(path, NULL, x, 0.0, &err) == PLUME_EINVAL);
    free(x);
    plume_mesh_destroy(&m);
    remove_dir(dir);
}

/* A render is a non-empty PNG; bad views and unwritable places are refused with a message. */
void test_frames_render_png(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 0.0, 0.25, PLUME_PATCH_ALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m) {
        remove_dir(dir);
        return;
    }
    for (plume_index v = 0; v < m->nv; v++) /* a bump, so the shading varies */
        m->x[3 * v + 2] = 0.2 * sin(3.0 * m->X[2 * v]) * m->X[2 * v + 1];
    for (plume_index t = 0; t < m->nt; t += 2)
        m->material[t] = 1;
    snprintf(path, sizeof path, "%s/mesh.png", dir);
    plume_render_opts o;
    plume_render_opts_default(&o);
    o.title = "a 'quoted' title";
    CHECK(plume_render_png(path, m, NULL, &o, &err) == PLUME_OK);
    if (err.msg[0])
        fprintf(stderr, "    render: %s\n", err.msg);
    FILE *f = fopen(path, "rb");
    unsigned char sig[8] = {0};
    CHECK(f && fread(sig, 1, 8, f) == 8 && memcmp(sig, "\x89PNG\r\n\x1a\n", 8) == 0);
    if (f)
        fclose(f);
    struct stat st;
    CHECK(stat(path, &st) == 0 && st.st_size > 1000);
    o.rot_x = 200.0;
    CHECK(plume_render_png(path, m, NULL, &o, &err) == PLUME_EINVAL && strstr(err.msg, "rot_x"));
    CHECK(plume_render_png("/nonexistent/dir/m.png", m, NULL, NULL, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, "/nonexistent/dir/m.png") != NULL);
    plume_mesh_destroy(&m);
    remove_dir(dir);
}

/* Pixel classes of the render tests: 1 the left colour, 2 the right one, 0 neither */
static int purple_or_yellow(const unsigned char *c)
{
    return c[0] > 150 && c[1] > 150 && c[2] < 80 ? 2 : c[2] > 50 && c[2] > c[0] && c[1] < 30 ? 1 : 0;
}

static int blue_or_red(const unsigned char *c)
{
    return c[2] > c[0] + 60 ? 1 : c[0] > c[2] + 60 ? 2 : 0;
}

/* The PNG at path, its left width_pct % of columns scanned: more than 500 pixels of each class,
 * and the mean column of class 2 a fifth of the width right of class 1's. */
static void check_left_right(const char *path, int width_pct, int (*classify)(const unsigned char *), const char *left,
                             const char *right)
{
    test_png png;
    CHECK(test_png_read(path, &png) == 0);
    if (!png.rgb)
        return;
    double sum[3] = {0, 0, 0};
    long n[3] = {0, 0, 0};
    for (int y = 0; y < png.height; y++)
        for (int x = 0; x < png.width * width_pct / 100; x++) {
            int k = classify(png.rgb + 3 * ((size_t)y * (size_t)png.width + (size_t)x));
            sum[k] += x, n[k]++;
        }
    fprintf(stderr, "    %s pixels %ld, %s %ld\n", left, n[1], right, n[2]);
    CHECK(n[1] > 500 && n[2] > 500);
    CHECK(n[1] > 0 && n[2] > 0 && sum[2] / (double)n[2] > sum[1] / (double)n[1] + 0.2 * png.width);
    free(png.rgb);
}

/* Coloured by a field: a flat sheet seen from above with the field x, on a fixed colour bar [0, 1],
 * is dark blue-purple on the left and yellow on the right (the map's ends, shaded by the light);
 * NaN triangles come out grey; the automatic range also draws. */
void test_frames_render_field(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 0.0, 0.05, PLUME_PATCH_ALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m) {
        remove_dir(dir);
        return;
    }
    double *field = malloc((size_t)m->nt * sizeof *field);
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        field[t] = (m->X[2 * v[0]] + m->X[2 * v[1]] + m->X[2 * v[2]]) / 3.0;
    }
    snprintf(path, sizeof path, "%s/field.png", dir);
    plume_render_opts o;
    plume_render_opts_default(&o);
    o.rot_x = 0.0, o.rot_z = 0.0; /* from above: x to the right */
    o.field = field, o.field_label = "x (m)", o.field_min = 0.0, o.field_max = 1.0;
    CHECK(plume_render_png(path, m, NULL, &o, &err) == PLUME_OK);
    /* the mean column of yellow pixels right of the mean column of purple ones, the colour bar
     * (the right tenth of the picture) left out */
    check_left_right(path, 85, purple_or_yellow, "purple", "yellow");
    /* NaN (a kinematic body) is grey, the automatic range draws too */
    for (plume_index t = 0; t < m->nt; t += 3)
        field[t] = NAN;
    o.field_min = o.field_max = 0.0;
    CHECK(plume_render_png(path, m, NULL, &o, &err) == PLUME_OK);
    free(field);
    plume_mesh_destroy(&m);
    remove_dir(dir);
}

/* Coloured by category (o.category, the scene objects of apps/feather): a flat sheet seen from
 * above whose left half is category 0 and right half category 6 comes out blue on the left and
 * red on the right (palette slots 0 and 6), whatever the triangles' materials. */
void test_frames_render_category(void)
{
    char dir[64], path[128];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    plume_mesh *m = NULL;
    plume_err err = {{0}};
    CHECK(plume_patch_mesh(1.0, 1.0, 0.0, 0.05, PLUME_PATCH_ALIGNED, 3, &m, &err) == PLUME_OK);
    if (!m) {
        remove_dir(dir);
        return;
    }
    int *category = malloc((size_t)m->nt * sizeof *category);
    for (plume_index t = 0; t < m->nt; t++) {
        const plume_index *v = m->tri + 3 * t;
        category[t] = m->X[2 * v[0]] + m->X[2 * v[1]] + m->X[2 * v[2]] < 1.5 ? 0 : 6;
        m->material[t] = (int)(t % 2); /* ignored */
    }
    snprintf(path, sizeof path, "%s/category.png", dir);
    plume_render_opts o;
    plume_render_opts_default(&o);
    o.rot_x = 0.0, o.rot_z = 0.0;
    o.category = category;
    CHECK(plume_render_png(path, m, NULL, &o, &err) == PLUME_OK);
    check_left_right(path, 100, blue_or_red, "blue", "red");
    free(category);
    plume_mesh_destroy(&m);
    remove_dir(dir);
}

/* Arrays of the state beyond the vertices (plume_frames_append_arrays): written with the frame and
 * read back bit for bit by name; a frame without one, a wrong count, and an array without a name
 * are refused, naming them; a frame written with none reads as before. */
void test_frames_state_arrays(void)
{
    char dir[64];
    if (!scratch_dir(dir)) {
        CHECK(0);
        return;
    }
    char path[128];
    snprintf(path, sizeof path, "%s/arrays.h5", dir);
    plume_err err = {{0}};
    const double x[6] = {0, 0, 0, 1, 0, 0}, v[6] = {0}, angles[3] = {0.1, -0.2, 1.0 / 3.0};
    const double frames[9] = {0, 0, 1, 0, 1, 0, 1, 0, 0};
    const plume_frame_array arrays[2] = {{"edge_angles", angles, 3, "m"}, {"edge_frames", frames, 9, "1"}};
    CHECK(plume_frames_create(path, 2, 0, 0.01, "test", &err) == PLUME_OK);
    CHECK(plume_frames_append(path, 2, 0, 0.0, 0, x, v, NULL, &err) == PLUME_OK);
    CHECK(plume_frames_append_arrays(path, 2, 0, 0.01, 1, x, v, NULL, NULL, arrays, 2, &err) == PLUME_OK);
    double back[9];
    CHECK(plume_frames_read_array(path, -1, "edge_frames", back, 9, &err) == PLUME_OK && memcmp(back, frames, sizeof frames) == 0);
    CHECK(plume_frames_read_array(path, 1, "edge_angles", back, 3, &err) == PLUME_OK && memcmp(back, angles, sizeof angles) == 0);
    CHECK(plume_frames_read_array(path, 1, "edge_angles", back, 4, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "edge_angles is of the wrong size (expected 4 values)"));
    CHECK(plume_frames_read_array(path, 0, "edge_angles", back, 3, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "/frames/0000000/edge_angles is missing"));
    const plume_frame_array unnamed = {NULL, angles, 3, "m"};
    CHECK(plume_frames_append_arrays(path, 2, 0, 0.02, 2, x, v, NULL, NULL, &unnamed, 1, &err) == PLUME_EINVAL &&
          strstr(err.msg, "extra array 0 needs a name"));
    plume_frames_info info;
    CHECK(plume_frames_info_read(path, &info, &err) == PLUME_OK && info.count == 2);
    plume_frame f = {0};
    CHECK(plume_frames_read(path, 1, &f, &err) == PLUME_OK && f.t == 0.01 && f.x[3] == 1.0);
    plume_frame_free(&f);
    remove_dir(dir);
}
