/* Tests of the I/O modules: HDF5 curves and moduli (lib/io/curves.c), sample JSON (lib/io/sample.c),
 * gnuplot charts (lib/io/plot.c) and the progress line (lib/io/progress.c). Scratch files live in a
 * mkdtemp directory under /tmp that each test removes. Run from tests/ (data in ../data). */
#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>

#include "harness.h"
#include "h5_units.h"
#include "../lib/io/curves.h"
#include "../lib/io/plot.h"
#include "../lib/io/progress.h"
#include "../lib/io/sample.h"

#define SAMPLES "../data/samples.json"

/* ------------------------------------------------------------------ scratch helpers --- */

typedef struct {
    char dir[64];
} tmpdir;

static int tmp_open(tmpdir *t)
{
    snprintf(t->dir, sizeof t->dir, "/tmp/plume-test-io-XXXXXX");
    return mkdtemp(t->dir) != NULL;
}

static void tmp_path(const tmpdir *t, const char *name, char *out, size_t len)
{
    snprintf(out, len, "%s/%s", t->dir, name);
}

/* Number of entries whose name contains `part` (e.g. ".tmp." leftovers). */
static int tmp_count(const tmpdir *t, const char *part)
{
    int n = 0;
    DIR *d = opendir(t->dir);
    if (!d)
        return -1;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strstr(e->d_name, part))
            n++;
    closedir(d);
    return n;
}

static void tmp_close(tmpdir *t)
{
    DIR *d = opendir(t->dir);
    if (d) {
        struct dirent *e;
        char p[512];
        while ((e = readdir(d))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            snprintf(p, sizeof p, "%s/%s", t->dir, e->d_name);
            unlink(p);
        }
        closedir(d);
    }
    rmdir(t->dir);
}

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

/* Whole file into a malloc'd buffer (caller frees); *len its size. */
static char *slurp(const char *path, long *len)
{
    *len = -1;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)n + 1);
    if (b && fread(b, 1, (size_t)n, f) != (size_t)n) {
        free(b);
        b = NULL;
    }
    fclose(f);
    if (b) {
        b[n] = '\0';
        *len = n;
    }
    return b;
}

static int same_bytes(const char *a, long na, const char *path)
{
    long nb;
    char *b = slurp(path, &nb);
    int same = b && na == nb && memcmp(a, b, (size_t)na) == 0;
    free(b);
    return same;
}

/* A small curve with values that do not round-trip through decimal text. */
static double g_strain[4] = {0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0};
static double g_stress[4] = {0.0, 1.2345678901234567e5, -2.5e-300, 6.02214076e23};
static double g_wbar[4] = {0.0, -0.1, -0.2000000000000001, -0.3};
static double g_iter[4] = {0, 3, 4, 7};
static double g_sec[4] = {0.0, 0.015625, 0.1, 1e-9};

static plume_curve sample_curve(void)
{
    plume_curve c = {4, g_strain, g_stress, g_wbar, g_iter, g_sec};
    return c;
}

static int curve_equals(const plume_curve *a, const plume_curve *b)
{
    if (a->n != b->n)
        return 0;
    for (plume_index i = 0; i < a->n; i++)
        if (a->strain[i] != b->strain[i] || a->stress[i] != b->stress[i] || a->wbar[i] != b->wbar[i] ||
            a->iterations[i] != b->iterations[i] || a->seconds[i] != b->seconds[i])
            return 0;
    return 1;
}

/* Reads a double attribute straight through HDF5 (NaN if absent). */
static double h5_attr_double(const char *path, const char *obj, const char *name)
{
    double v = NAN;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return v;
    hid_t a = H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0
                  ? H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT)
                  : H5I_INVALID_HID;
    if (a >= 0) {
        if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0)
            v = NAN;
        H5Aclose(a);
    }
    H5Fclose(f);
    return v;
}

/* Compares a string attribute read straight through HDF5 with `want`. */
static int h5_attr_string_is(const char *path, const char *obj, const char *name, const char *want)
{
    int ok = 0;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return 0;
    hid_t a = H5Aopen_by_name(f, obj, name, H5P_DEFAULT, H5P_DEFAULT);
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    char *v = NULL;
    if (a >= 0 && H5Aread(a, t, &v) >= 0 && v) {
        ok = strcmp(v, want) == 0;
        H5free_memory(v);
    }
    H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
    H5Fclose(f);
    return ok;
}

static void h5_put_double(hid_t obj, const char *name, double v)
{
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(obj, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_DOUBLE, &v);
    H5Aclose(a);
    H5Sclose(sp);
}

/* Writes a /moduli group by hand: the first `count` of E_xx, E_yy, nu_xy, G_xy with `v`. */
static int h5_make_moduli(const char *path, const double v[4], int count)
{
    static const char *const names[4] = {"E_xx", "E_yy", "nu_xy", "G_xy"};
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (f < 0)
        return 0;
    hid_t g = H5Gcreate2(f, "/moduli", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    for (int i = 0; i < count; i++)
        h5_put_double(g, names[i], v[i]);
    H5Gclose(g);
    return H5Fclose(f) >= 0;
}

/* -------------------------------------------------------------------------- curves --- */

void test_io_curve_roundtrip(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    tmp_path(&t, "run.h5", path, sizeof path);
    plume_curve c = sample_curve();
    plume_param p[3] = {{"E_xx", 3.14159e9}, {"alpha_deg", 45.0}, {"tiny", 5e-324}};
    plume_sparam sp[2] = {{"solver", "newton"}, {"note", "barbs ⟂ grips, 'quoted'"}};
    plume_err err = {""};
    CHECK(plume_curve_write(path, "macro", "tilted", &c, p, 3, sp, 2, &err) == PLUME_OK);
    CHECK(tmp_count(&t, ".tmp.") == 0);
    char units[32] = "";
    CHECK(h5_units(path, "/curves/macro/tilted/stress", units, sizeof units) == 0 && strcmp(units, "Pa") == 0);
    CHECK(h5_units(path, "/curves/macro/tilted/strain", units, sizeof units) == 0 && strcmp(units, "1") == 0);
    CHECK(h5_units(path, "/curves/macro/tilted/seconds", units, sizeof units) == 0 && strcmp(units, "s") == 0);
    char gunits[256] = ""; /* the group's numeric parameters, each with its unit */
    CHECK(h5_units(path, "/curves/macro/tilted", gunits, sizeof gunits) == 0 &&
          strcmp(gunits, "E_xx: Pa; alpha_deg: 1; tiny: 1") == 0);
    plume_param reserved[1] = {{"units", 1.0}};
    CHECK(plume_curve_write(path, "macro", "x", &c, reserved, 1, NULL, 0, &err) == PLUME_EINVAL &&
          strstr(err.msg, "reserved"));

    plume_curve r;
    CHECK(plume_curve_read(path, "macro", "tilted", &r, &err) == PLUME_OK);
    CHECK(curve_equals(&r, &c));
    plume_curve_free(&r);
    CHECK(r.n == 0 && r.strain == NULL && r.seconds == NULL);
    plume_curve_free(&r); /* twice is harmless */
    plume_curve_free(NULL);

    CHECK(h5_attr_double(path, "/curves/macro/tilted", "E_xx") == 3.14159e9);
    CHECK(h5_attr_double(path, "/curves/macro/tilted", "alpha_deg") == 45.0);
    CHECK(h5_attr_double(path, "/curves/macro/tilted", "tiny") == 5e-324);
    CHECK(h5_attr_string_is(path, "/curves/macro/tilted", "solver", "newton"));
    CHECK(h5_attr_string_is(path, "/curves/macro/tilted", "note", "barbs ⟂ grips, 'quoted'"));

    /* Rewriting the same group replaces it (shorter curve, no leftover attribute). */
    plume_curve c2 = {2, g_strain + 2, g_stress + 2, g_wbar + 2, g_iter + 2, g_sec + 2};
    CHECK(plume_curve_write(path, "macro", "tilted", &c2, p, 1, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_curve_read(path, "macro", "tilted", &r, &err) == PLUME_OK);
    CHECK(curve_equals(&r, &c2));
    plume_curve_free(&r);
    CHECK(isnan(h5_attr_double(path, "/curves/macro/tilted", "alpha_deg")));

    /* An empty curve is a valid (if dull) result. */
    plume_curve c0 = {0, NULL, NULL, NULL, NULL, NULL};
    CHECK(plume_curve_write(path, "micro", "empty", &c0, NULL, 0, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_curve_read(path, "micro", "empty", &r, &err) == PLUME_OK);
    CHECK(r.n == 0);
    plume_curve_free(&r);
    tmp_close(&t);
}

void test_io_curve_two_scenarios(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    tmp_path(&t, "both.h5", path, sizeof path);
    plume_curve a = sample_curve();
    plume_curve b = {3, g_stress, g_strain, g_sec, g_wbar, g_iter}; /* different numbers */
    plume_param pa = {"alpha_deg", 0.0}, pb = {"alpha_deg", 90.0};
    plume_err err = {""};
    CHECK(plume_curve_write(path, "macro", "longitudinal", &a, &pa, 1, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_curve_write(path, "macro", "transverse", &b, &pb, 1, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_curve_write(path, "micro", "transverse", &a, &pa, 1, NULL, 0, &err) == PLUME_OK);
    plume_curve r;
    CHECK(plume_curve_read(path, "macro", "longitudinal", &r, &err) == PLUME_OK);
    CHECK(curve_equals(&r, &a));
    plume_curve_free(&r);
    CHECK(plume_curve_read(path, "macro", "transverse", &r, &err) == PLUME_OK);
    CHECK(curve_equals(&r, &b));
    plume_curve_free(&r);
    CHECK(plume_curve_read(path, "micro", "transverse", &r, &err) == PLUME_OK);
    CHECK(curve_equals(&r, &a));
    plume_curve_free(&r);
    CHECK(h5_attr_double(path, "/curves/macro/longitudinal", "alpha_deg") == 0.0);
    CHECK(h5_attr_double(path, "/curves/macro/transverse", "alpha_deg") == 90.0);
    CHECK(tmp_count(&t, ".tmp.") == 0);
    tmp_close(&t);
}

void test_io_moduli_roundtrip(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    tmp_path(&t, "moduli.h5", path, sizeof path);
    plume_ortho m = {2.5e9, 1.0 / 3.0 * 1e5, 0.3, 1.7e5}, r = {0, 0, 0, 0};
    plume_err err = {""};
    CHECK(plume_moduli_write(path, &m, "rve homogenisation, 64x64 cell", &err) == PLUME_OK);
    char munits[64] = "";
    CHECK(h5_units(path, "/moduli", munits, sizeof munits) == 0 && strstr(munits, "E_xx, E_yy, G_xy: Pa") != NULL);
    CHECK(plume_moduli_read(path, &r, &err) == PLUME_OK);
    CHECK(r.E_xx == m.E_xx && r.E_yy == m.E_yy && r.nu_xy == m.nu_xy && r.G_xy == m.G_xy);
    CHECK(h5_attr_string_is(path, "/moduli", "provenance", "rve homogenisation, 64x64 cell"));
    /* Rewriting replaces; a negative nu is physical for some materials and allowed. */
    plume_ortho m2 = {1e9, 1e9, -0.2, 4e8};
    CHECK(plume_moduli_write(path, &m2, NULL, &err) == PLUME_OK);
    CHECK(plume_moduli_read(path, &r, &err) == PLUME_OK);
    CHECK(r.nu_xy == -0.2 && r.G_xy == 4e8);
    CHECK(h5_attr_string_is(path, "/moduli", "provenance", "unspecified"));
    CHECK(tmp_count(&t, ".tmp.") == 0);
    tmp_close(&t);
}

void test_io_preserve_existing(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    tmp_path(&t, "run.h5", path, sizeof path);
    plume_ortho m = {1e10, 1e6, 0.0, 3e6}, r;
    plume_curve c = sample_curve(), rc;
    plume_err err = {""};
    /* moduli first, then a curve: the moduli survive */
    CHECK(plume_moduli_write(path, &m, "fit", &err) == PLUME_OK);
    CHECK(plume_curve_write(path, "macro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_moduli_read(path, &r, &err) == PLUME_OK);
    CHECK(r.E_xx == 1e10 && r.E_yy == 1e6 && r.G_xy == 3e6);
    /* and replacing the moduli keeps the curve */
    m.E_yy = 2e6;
    CHECK(plume_moduli_write(path, &m, "refit", &err) == PLUME_OK);
    CHECK(plume_curve_read(path, "macro", "tilted", &rc, &err) == PLUME_OK);
    CHECK(curve_equals(&rc, &c));
    plume_curve_free(&rc);
    CHECK(plume_moduli_read(path, &r, &err) == PLUME_OK);
    CHECK(r.E_yy == 2e6);

    /* Objects that plume does not know about are kept too. */
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t g = H5Gcreate2(f, "/frames", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    h5_put_double(g, "dt", 1e-3);
    H5Gclose(g);
    H5Fclose(f);
    CHECK(plume_curve_write(path, "micro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_OK);
    CHECK(h5_attr_double(path, "/frames", "dt") == 1e-3);
    tmp_close(&t);
}

void test_io_failed_write(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256], bad[256];
    plume_curve c = sample_curve();
    plume_ortho m = {1e9, 1e6, 0.1, 1e6};
    plume_err err = {""};

    /* A directory that does not exist: EIO naming the file, nothing created anywhere. */
    tmp_path(&t, "no/such/dir/run.h5", bad, sizeof bad);
    CHECK(plume_curve_write(bad, "macro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, bad) != NULL);
    CHECK(plume_moduli_write(bad, &m, "x", &err) == PLUME_EIO);
    CHECK(tmp_count(&t, "") == 0);

    /* An existing file whose /curves is a dataset: the write fails inside HDF5, after the
     * temporary copy is made. The original must be byte-identical and no temp file remain. */
    tmp_path(&t, "clash.h5", path, sizeof path);
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hsize_t one = 1;
    hid_t sp = H5Screate_simple(1, &one, NULL);
    hid_t ds = H5Dcreate2(f, "/curves", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(ds);
    H5Sclose(sp);
    H5Fclose(f);
    long n0;
    char *before = slurp(path, &n0);
    CHECK(before != NULL && n0 > 0);
    err.msg[0] = '\0';
    CHECK(plume_curve_write(path, "macro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, path) != NULL && strstr(err.msg, "/curves/macro/tilted") != NULL);
    CHECK(before && same_bytes(before, n0, path));
    CHECK(tmp_count(&t, ".tmp.") == 0);

    /* An existing file that is not HDF5 is refused, not clobbered. */
    tmp_path(&t, "notes.txt", path, sizeof path);
    CHECK(write_text(path, "not hdf5\n"));
    CHECK(plume_moduli_write(path, &m, "x", &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "is not an HDF5 file") != NULL);
    CHECK(same_bytes("not hdf5\n", 9, path));
    CHECK(tmp_count(&t, ".tmp.") == 0);

    /* Invalid input is rejected before anything touches the disk. */
    tmp_path(&t, "new.h5", path, sizeof path);
    plume_ortho nanm = {1e9, NAN, 0.1, 1e6};
    CHECK(plume_moduli_write(path, &nanm, "x", &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "E_yy") != NULL);
    plume_ortho indef = {1e6, 1e9, 0.5, 1e6}; /* nu^2 E_yy/E_xx = 250 */
    CHECK(plume_moduli_write(path, &indef, "x", &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "nu_xy") != NULL);
    CHECK(plume_curve_write(path, "macro", "a/b", &c, NULL, 0, NULL, 0, &err) == PLUME_EINVAL);
    CHECK(plume_curve_write(path, "", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_EINVAL);
    CHECK(plume_curve_write(path, NULL, "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_EINVAL);
    plume_param dup[2] = {{"h", 1.0}, {"h", 2.0}};
    CHECK(plume_curve_write(path, "macro", "tilted", &c, dup, 2, NULL, 0, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "given twice") != NULL);
    plume_curve holes = c;
    holes.wbar = NULL;
    CHECK(plume_curve_write(path, "macro", "tilted", &holes, NULL, 0, NULL, 0, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "wbar") != NULL);
    CHECK(access(path, F_OK) != 0);
    CHECK(tmp_count(&t, ".tmp.") == 0);
    free(before);
    tmp_close(&t);
}

void test_io_read_errors(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    plume_curve c = sample_curve(), r = {0, NULL, NULL, NULL, NULL, NULL};
    plume_ortho m;
    plume_err err = {""};

    /* missing file */
    tmp_path(&t, "absent.h5", path, sizeof path);
    CHECK(plume_curve_read(path, "macro", "tilted", &r, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, path) != NULL);
    CHECK(r.n == 0 && r.strain == NULL);
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, "absent.h5") != NULL);

    /* not an HDF5 file */
    tmp_path(&t, "text.h5", path, sizeof path);
    CHECK(write_text(path, "{\"hello\": 1}\n"));
    CHECK(plume_curve_read(path, "macro", "tilted", &r, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, path) != NULL && strstr(err.msg, "is not an HDF5 file") != NULL);
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "is not an HDF5 file") != NULL);

    /* missing groups: a file with a curve but no moduli, and the other scenario */
    tmp_path(&t, "curve.h5", path, sizeof path);
    CHECK(plume_curve_write(path, "macro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_curve_read(path, "macro", "transverse", &r, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, path) != NULL && strstr(err.msg, "no /curves/macro/transverse group") != NULL);
    CHECK(plume_curve_read(path, "micro", "tilted", &r, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "no /curves/micro/tilted group") != NULL);
    CHECK(plume_curve_read(path, "macro", "../x", &r, &err) == PLUME_EINVAL);
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EFORMAT);
    char want[512];
    snprintf(want, sizeof want, "moduli file '%s': no /moduli group", path);
    CHECK(strcmp(err.msg, want) == 0);

    /* a dataset of the wrong length */
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "/curves/macro/tilted/wbar", H5P_DEFAULT);
    hsize_t two = 2;
    hid_t sp = H5Screate_simple(1, &two, NULL);
    hid_t ds = H5Dcreate2(f, "/curves/macro/tilted/wbar", H5T_IEEE_F64LE, sp, H5P_DEFAULT,
                          H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, g_wbar);
    H5Dclose(ds);
    H5Ldelete(f, "/curves/macro/tilted/seconds", H5P_DEFAULT);
    H5Sclose(sp);
    H5Fclose(f);
    CHECK(plume_curve_read(path, "macro", "tilted", &r, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "wbar") != NULL && strstr(err.msg, "2 points") != NULL);
    CHECK(r.n == 0 && r.strain == NULL && r.stress == NULL);

    /* a missing dataset */
    c.n = 2;
    CHECK(plume_curve_write(path, "macro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_OK);
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "/curves/macro/tilted/seconds", H5P_DEFAULT);
    H5Fclose(f);
    CHECK(plume_curve_read(path, "macro", "tilted", &r, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "/curves/macro/tilted/seconds missing") != NULL);

    /* moduli: a missing attribute, NaN, negative, zero */
    double good[4] = {1e9, 1e6, 0.2, 1e6};
    tmp_path(&t, "m.h5", path, sizeof path);
    CHECK(h5_make_moduli(path, good, 3));
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EFORMAT);
    snprintf(want, sizeof want, "moduli file '%s': /moduli attribute G_xy missing", path);
    CHECK(strcmp(err.msg, want) == 0);

    double nanv[4] = {1e9, 1e6, NAN, 1e6};
    CHECK(h5_make_moduli(path, nanv, 4));
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, path) != NULL && strstr(err.msg, "nu_xy must be finite") != NULL);

    double neg[4] = {1e9, 1e6, 0.2, -1e6};
    CHECK(h5_make_moduli(path, neg, 4));
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "G_xy must be finite and > 0") != NULL);

    double zero[4] = {0.0, 1e6, 0.2, 1e6};
    CHECK(h5_make_moduli(path, zero, 4));
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "E_xx") != NULL);

    double inf[4] = {1e9, INFINITY, 0.2, 1e6};
    CHECK(h5_make_moduli(path, inf, 4));
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "E_yy") != NULL);

    CHECK(h5_make_moduli(path, good, 4)); /* and the hand-made good one reads */
    CHECK(plume_moduli_read(path, &m, &err) == PLUME_OK);
    CHECK(m.E_xx == 1e9 && m.nu_xy == 0.2);
    tmp_close(&t);
}

/* ------------------------------------------------------------------------- samples --- */

void test_io_sample_table(void)
{
    plume_sample s;
    plume_err err = {""};
    CHECK(plume_sample_load(SAMPLES, "L01", &s, &err) == PLUME_OK);
    CHECK(strcmp(s.id, "L01") == 0 && strcmp(s.scenario, "longitudinal") == 0);
    CHECK_REL(s.lx, 9e-3, 1e-15, 0);
    CHECK_REL(s.ly, 18e-3, 1e-15, 0);
    CHECK_REL(s.h, 73e-6, 1e-15, 0);

    CHECK(plume_sample_load(SAMPLES, "T14", &s, &err) == PLUME_OK);
    CHECK(strcmp(s.scenario, "transverse") == 0);
    CHECK_REL(s.lx, 11e-3, 1e-15, 0);
    CHECK_REL(s.ly, 12e-3, 1e-15, 0);
    CHECK_REL(s.h, 120e-6, 1e-15, 0);

    CHECK(plume_sample_load(SAMPLES, "L12", &s, &err) == PLUME_OK); /* the narrow one */
    CHECK_REL(s.lx, 2e-3, 1e-15, 0);
    CHECK_REL(s.h, 130e-6, 1e-15, 0);

    int n = 0;
    CHECK(plume_sample_count(SAMPLES, &n, &err) == PLUME_OK);
    CHECK(n == 27);
    /* ids L01..L13 then T01..T14, in table order, each loadable by id */
    for (int i = 0; i < n; i++) {
        char id[16];
        snprintf(id, sizeof id, "%c%02d", i < 13 ? 'L' : 'T', i < 13 ? i + 1 : i - 12);
        plume_sample a, b;
        CHECK(plume_sample_at(SAMPLES, i, &a, &err) == PLUME_OK);
        CHECK(strcmp(a.id, id) == 0);
        CHECK(strcmp(a.scenario, i < 13 ? "longitudinal" : "transverse") == 0);
        CHECK(plume_sample_load(SAMPLES, id, &b, &err) == PLUME_OK);
        CHECK(a.lx == b.lx && a.ly == b.ly && a.h == b.h);
        CHECK(a.lx > 1e-3 && a.ly > 5e-3 && a.h > 50e-6 && a.h < 200e-6);
    }
    CHECK(plume_sample_at(SAMPLES, 27, &s, &err) == PLUME_EINVAL);
    CHECK(plume_sample_at(SAMPLES, -1, &s, &err) == PLUME_EINVAL);
}

void test_io_sample_errors(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    plume_sample s;
    plume_err err = {""};

    tmp_path(&t, "absent.json", path, sizeof path);
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, path) != NULL && strstr(err.msg, "cannot open") != NULL);

    tmp_path(&t, "syntax.json", path, sizeof path);
    CHECK(write_text(path, "{\n  \"samples\": [\n    {\"id\": \"L01\" \"scenario\": \"longitudinal\"}\n  ]\n}\n"));
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EFORMAT);
    char want[300];
    snprintf(want, sizeof want, "%s:3:", path);
    CHECK(strncmp(err.msg, want, strlen(want)) == 0);

    tmp_path(&t, "nosamples.json", path, sizeof path);
    CHECK(write_text(path, "[1, 2]\n"));
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "samples") != NULL);

    tmp_path(&t, "missing.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [{\"id\": \"L01\", \"scenario\": \"longitudinal\", "
                           "\"lx_mm\": 9, \"h_um\": 73}]}\n"));
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, path) != NULL && strstr(err.msg, "L01") != NULL &&
          strstr(err.msg, "ly_mm") != NULL);

    tmp_path(&t, "string.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [{\"id\": \"L01\", \"scenario\": \"longitudinal\", "
                           "\"lx_mm\": 9, \"ly_mm\": \"18\", \"h_um\": 73}]}\n"));
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "non-numeric") != NULL && strstr(err.msg, "ly_mm") != NULL);

    tmp_path(&t, "noid.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [{\"scenario\": \"longitudinal\"}]}\n"));
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "sample 0") != NULL && strstr(err.msg, "\"id\"") != NULL);

    tmp_path(&t, "negative.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [\n"
                           "{\"id\": \"L01\", \"scenario\": \"longitudinal\", \"lx_mm\": 9, \"ly_mm\": 18, \"h_um\": 73},\n"
                           "{\"id\": \"L03\", \"scenario\": \"longitudinal\", \"lx_mm\": -1, \"ly_mm\": 18, \"h_um\": 73}]}\n"));
    CHECK(plume_sample_load(path, "L03", &s, &err) == PLUME_EINVAL);
    snprintf(want, sizeof want, "%s: sample L03: lx_mm must be > 0 (got -1)", path);
    CHECK(strcmp(err.msg, want) == 0);
    /* the bad row is reported whichever sample is asked for */
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EINVAL);

    tmp_path(&t, "zero.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [{\"id\": \"T01\", \"scenario\": \"transverse\", "
                           "\"lx_mm\": 9, \"ly_mm\": 18, \"h_um\": 0}]}\n"));
    CHECK(plume_sample_load(path, "T01", &s, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "h_um must be > 0 (got 0)") != NULL);

    tmp_path(&t, "dup.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [\n"
                           "{\"id\": \"L01\", \"scenario\": \"longitudinal\", \"lx_mm\": 9, \"ly_mm\": 18, \"h_um\": 73},\n"
                           "{\"id\": \"L01\", \"scenario\": \"longitudinal\", \"lx_mm\": 9, \"ly_mm\": 18, \"h_um\": 73}]}\n"));
    CHECK(plume_sample_load(path, "L01", &s, &err) == PLUME_EFORMAT);
    CHECK(strstr(err.msg, "twice") != NULL);

    tmp_path(&t, "scenario.json", path, sizeof path);
    CHECK(write_text(path, "{\"samples\": [{\"id\": \"X\", \"scenario\": \"sideways\", "
                           "\"lx_mm\": 9, \"ly_mm\": 18, \"h_um\": 73}]}\n"));
    CHECK(plume_sample_load(path, "X", &s, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, "sideways") != NULL);

    CHECK(plume_sample_load(SAMPLES, "L99", &s, &err) == PLUME_EINVAL);
    CHECK(strstr(err.msg, SAMPLES) != NULL && strstr(err.msg, "L99") != NULL &&
          strstr(err.msg, "not found") != NULL);
    CHECK(plume_sample_load(SAMPLES, "", &s, &err) == PLUME_EINVAL);
    tmp_close(&t);
}

/* ---------------------------------------------------------------------------- plot --- */

static int gnuplot_present(void)
{
    return system("command -v gnuplot >/dev/null 2>&1") == 0;
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

void test_io_plot(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char png[256], svg[256];
    plume_curve c[2] = {sample_curve(), sample_curve()};
    c[1].stress = g_sec;
    c[1].n = 3;
    const char *labels[2] = {"macro, it's_alpha=45^", "micro"};
    plume_err err = {""};

    if (!gnuplot_present()) {
        printf("    note: gnuplot absent, plot output not checked\n");
        tmp_close(&t);
        return;
    }
    tmp_path(&t, "chart.png", png, sizeof png);
    tmp_path(&t, "chart.svg", svg, sizeof svg);
    plume_status s = plume_plot_curves(png, "tilted 'traction'", c, labels, 2, &err);
    CHECK(s == PLUME_OK);
    if (s != PLUME_OK)
        fprintf(stderr, "    plot: %s\n", err.msg);
    CHECK(file_size(png) > 1000);
    CHECK(file_size(svg) > 1000);
    long n;
    char *b = slurp(png, &n);
    CHECK(b && n > 8 && memcmp(b, "\x89PNG", 4) == 0);
    free(b);
    b = slurp(svg, &n);
    CHECK(b && strstr(b, "<svg") != NULL && strstr(b, "micro") != NULL);
    free(b);
    CHECK(tmp_count(&t, ".tmp.") == 0);

    /* no extension: ".svg" appended; labels optional */
    char bare[256], bare_svg[256];
    tmp_path(&t, "chart2", bare, sizeof bare);
    tmp_path(&t, "chart2.svg", bare_svg, sizeof bare_svg);
    CHECK(plume_plot_curves(bare, NULL, c, NULL, 1, &err) == PLUME_OK);
    CHECK(file_size(bare) > 0 && file_size(bare_svg) > 0);

    /* bad destination: an error, not a crash, and nothing left behind */
    char bad[256];
    tmp_path(&t, "missing/dir/chart.png", bad, sizeof bad);
    CHECK(plume_plot_curves(bad, "x", c, labels, 2, &err) == PLUME_EIO);
    CHECK(strstr(err.msg, bad) != NULL);
    CHECK(plume_plot_curves("", "x", c, labels, 2, &err) == PLUME_EINVAL);
    CHECK(plume_plot_curves(png, "x", c, labels, 0, &err) == PLUME_EINVAL);
    CHECK(plume_plot_curves(svg, "x", c, labels, 1, &err) == PLUME_EINVAL);
    plume_curve empty = {0, NULL, NULL, NULL, NULL, NULL};
    CHECK(plume_plot_curves(png, "x", &empty, NULL, 1, &err) == PLUME_EINVAL);

    /* gnuplot missing from PATH: PLUME_EDEP with the install hint */
    const char *old = getenv("PATH");
    char *saved = old ? strdup(old) : NULL;
    setenv("PATH", "/nonexistent-plume-test", 1);
    CHECK(plume_plot_curves(png, "x", c, labels, 2, &err) == PLUME_EDEP);
    CHECK(strstr(err.msg, "gnuplot not found") != NULL);
    if (saved) {
        setenv("PATH", saved, 1);
        free(saved);
    } else {
        unsetenv("PATH");
    }
    CHECK(tmp_count(&t, ".tmp.") == 0);
    tmp_close(&t);
}

/* ------------------------------------------------------------------------ progress --- */

void test_io_progress(void)
{
    double t0 = plume_wall_seconds();
    CHECK(t0 > 0.0);
    CHECK(plume_wall_seconds() >= t0);

    tmpdir t;
    CHECK(tmp_open(&t));
    char path[256];
    tmp_path(&t, "stderr.txt", path, sizeof path);
    /* capture stderr in a file */
    fflush(stderr);
    int saved = dup(2);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    CHECK(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);

    plume_progress quiet;
    plume_progress_start(&quiet, "silent", 3, 0); /* stderr is a file: disabled */
    plume_progress_update(&quiet, 1, "x");
    plume_progress_finish(&quiet);

    plume_progress p;
    plume_progress_start(&p, "traction", 4, 1);
    plume_progress_update(&p, 0, NULL);
    plume_progress_update(&p, 2, "newton 5 it");
    plume_progress_finish(&p);
    plume_progress_finish(&p);

    fflush(stderr);
    dup2(saved, 2);
    close(saved);

    CHECK(!quiet.enabled);
    long n;
    char *b = slurp(path, &n);
    CHECK(b != NULL);
    if (b) {
        CHECK(strstr(b, "silent") == NULL);
        CHECK(strncmp(b, "\rtraction step 0/4  elapsed ", 28) == 0);
        CHECK(strstr(b, "eta ? s") != NULL);
        CHECK(strstr(b, "\rtraction step 2/4 newton 5 it  elapsed ") != NULL);
        CHECK(strstr(b, " s  eta ") != NULL);
        /* each update fills at least 79 columns; one newline at the end, only one */
        char *second = strstr(b + 1, "\r");
        CHECK(second && second - b >= 80);
        CHECK(n > 0 && b[n - 1] == '\n' && strchr(b, '\n') == b + n - 1);
    }
    free(b);
    tmp_close(&t);
}

/* plume_curve_write_states: a table beside a curve, read back as written; refused without the
 * curve's group, with a name holding '/', or without values */
void test_io_curve_states(void)
{
    tmpdir t;
    CHECK(tmp_open(&t));
    char path[512];
    tmp_path(&t, "states.h5", path, sizeof path);
    plume_err err = {{0}};
    const int v[6] = {1, 1, 1, 1, 0, 1};
    CHECK(plume_curve_write_states(path, "micro", "tilted", "hooks", 2, 3, v, &err) == PLUME_EFORMAT &&
          strstr(err.msg, "/curves/micro/tilted")); /* no file, no curve yet */
    plume_curve c = sample_curve();
    CHECK(plume_curve_write(path, "micro", "tilted", &c, NULL, 0, NULL, 0, &err) == PLUME_OK);
    CHECK(plume_curve_write_states(path, "micro", "tilted", "hooks", 2, 3, v, &err) == PLUME_OK);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t ds = f >= 0 ? H5Dopen2(f, "/curves/micro/tilted/hooks", H5P_DEFAULT) : -1;
    int back[6] = {9, 9, 9, 9, 9, 9};
    CHECK(ds >= 0 && H5Dread(ds, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, back) >= 0);
    CHECK(memcmp(back, v, sizeof v) == 0);
    if (ds >= 0)
        H5Dclose(ds);
    if (f >= 0)
        H5Fclose(f);
    CHECK(plume_curve_write_states(path, "micro", "tilted", "a/b", 2, 3, v, &err) == PLUME_EINVAL);
    CHECK(plume_curve_write_states(path, "micro", "tilted", "hooks", 2, 3, NULL, &err) == PLUME_EINVAL);
    tmp_close(&t);
}
