/* libFuzzer, structure-aware: the input describes an HDF5 file — which groups, attributes and
 * datasets exist, with which types, ranks, sizes and values — and the harness writes that (valid)
 * HDF5 file and hands it to plume's readers: moduli, curves, frames (restart). Raw byte mutation of
 * HDF5 would mostly exercise libhdf5's own parser; what plume must survive is a well-formed file
 * with the wrong shapes, types or values. */
#include <hdf5.h>
#include <math.h>

#include "fuzz_common.h"
#include "../../lib/io/curves.h"
#include "../../lib/io/frames.h"

typedef struct {
    const uint8_t *p;
    size_t n;
} bytes;

static unsigned take(bytes *b, unsigned range)
{
    if (!b->n || range == 0)
        return 0;
    unsigned v = b->p[0];
    b->p++, b->n--;
    return v % range;
}

static double take_double(bytes *b)
{
    static const double special[] = {0.0, 1.0, -1.0, 1e300, -1e-300, 5e-324, 3.0, 0.5, 1e6, 2.5e9};
    switch (take(b, 4)) {
    case 0: return special[take(b, 10)];
    case 1: return NAN;
    case 2: return take(b, 2) ? INFINITY : -INFINITY;
    default: {
        double v = 0.0;
        size_t k = b->n < sizeof v ? b->n : sizeof v;
        memcpy(&v, b->p, k);
        b->p += k, b->n -= k;
        return v;
    }
    }
}

/* an attribute `name` on obj: absent, a double, a long, a string, or a 2-element double array */
static void put_attr(hid_t obj, const char *name, bytes *b, double typical)
{
    unsigned kind = take(b, 6);
    hid_t sp = H5I_INVALID_HID, a = H5I_INVALID_HID;
    if (kind == 0)
        return;
    if (kind == 4) { /* a string */
        hid_t t = H5Tcopy(H5T_C_S1);
        H5Tset_size(t, H5T_VARIABLE);
        sp = H5Screate(H5S_SCALAR);
        a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
        const char *s = take(b, 2) ? "12" : "";
        H5Awrite(a, t, &s);
        H5Tclose(t);
    } else if (kind == 5) { /* an array */
        hsize_t dims[1] = {2};
        double v[2] = {take_double(b), typical};
        sp = H5Screate_simple(1, dims, NULL);
        a = H5Acreate2(obj, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
        H5Awrite(a, H5T_NATIVE_DOUBLE, v);
    } else if (kind == 3) { /* a long */
        long v = take(b, 2) ? (long)typical : (long)(int8_t)take(b, 256);
        sp = H5Screate(H5S_SCALAR);
        a = H5Acreate2(obj, name, H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
        H5Awrite(a, H5T_NATIVE_LONG, &v);
    } else { /* a double, usually the typical value */
        double v = kind == 1 ? typical : take_double(b);
        sp = H5Screate(H5S_SCALAR);
        a = H5Acreate2(obj, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
        H5Awrite(a, H5T_NATIVE_DOUBLE, &v);
    }
    if (a >= 0)
        H5Aclose(a);
    if (sp >= 0)
        H5Sclose(sp);
}

/* a dataset `name` in g: absent, or of n values (rank 1 or 2, doubles, floats or ints) */
static void put_dataset(hid_t g, const char *name, bytes *b, size_t typical_n)
{
    unsigned kind = take(b, 8);
    if (kind == 0)
        return;
    size_t n = kind <= 4 ? typical_n : take(b, 40);
    double *v = malloc((n + 1) * sizeof *v);
    for (size_t i = 0; i < n; i++)
        v[i] = take(b, 3) ? 0.01 * (double)i : take_double(b);
    hsize_t dims[2] = {n, 1};
    int rank = kind == 5 ? 2 : 1;
    hid_t ft = kind == 6 ? H5T_IEEE_F32LE : kind == 7 ? H5T_STD_I32LE : H5T_IEEE_F64LE;
    hid_t sp = H5Screate_simple(rank, dims, NULL);
    hid_t d = H5Dcreate2(g, name, ft, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d >= 0) {
        H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v);
        H5Dclose(d);
    }
    H5Sclose(sp);
    free(v);
}

static hid_t group(hid_t at, const char *name)
{
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    H5Pset_create_intermediate_group(lcpl, 1);
    hid_t g = H5Gcreate2(at, name, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    H5Pclose(lcpl);
    return g;
}

static void write_file(const char *path, bytes *b)
{
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (f < 0)
        abort();
    if (take(b, 4)) { /* /moduli */
        hid_t g = group(f, "/moduli");
        static const char *const m[] = {"E_xx", "E_yy", "nu_xy", "G_xy"};
        for (int k = 0; k < 4; k++)
            put_attr(g, m[k], b, k == 2 ? 0.3 : 1e6);
        H5Gclose(g);
    }
    if (take(b, 4)) { /* /curves/macro/tilted */
        hid_t g = group(f, "/curves/macro/tilted");
        size_t n = take(b, 12);
        static const char *const c[] = {"strain", "stress", "wbar", "iterations", "seconds"};
        for (int k = 0; k < 5; k++)
            put_dataset(g, c[k], b, n);
        H5Gclose(g);
    }
    if (take(b, 4)) { /* /frames */
        hid_t g = group(f, "/frames");
        long nv = 1 + (long)take(b, 4), ncons = (long)take(b, 3), count = (long)take(b, 4);
        put_attr(g, "count", b, (double)count);
        put_attr(g, "nv", b, (double)nv);
        put_attr(g, "ncons", b, (double)ncons);
        put_attr(g, "dt", b, 0.01);
        put_attr(g, "scene", b, 0.0);
        for (long k = 0; k < count + 1 && b->n; k++) {
            char name[16];
            snprintf(name, sizeof name, "%ld", k);
            hid_t fg = group(g, name);
            put_dataset(fg, "x", b, (size_t)(3 * nv));
            put_dataset(fg, "v", b, (size_t)(3 * nv));
            put_dataset(fg, "lambda", b, (size_t)ncons);
            put_attr(fg, "t", b, 0.01 * (double)k);
            put_attr(fg, "step", b, (double)k);
            static const char *const ms[] = {"newton_iterations", "steps_halved", "seconds", "contact_pairs",
                                             "min_distance", "intersecting_pairs"};
            for (int i = 0; i < 6 && take(b, 2); i++)
                put_attr(fg, ms[i], b, 1.0);
            H5Gclose(fg);
        }
        H5Gclose(g);
    }
    H5Fclose(f);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* the readers report through their own messages */
    /* every file open callocs HDF5's metadata cache (H5C_create), larger than a free list keeps by
     * default: it went back to ASan's allocator each time, and the fresh pages' faults and zeroing
     * were half of each input's time. Unlimited free lists reuse it (plume's own memory is
     * unaffected; the harness's RSS levels off near 430 MB, most of it ASan's quarantine). */
    H5set_free_list_limits(-1, -1, -1, -1, -1, -1);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes b = {data, size};
    char path[128];
    snprintf(path, sizeof path, "%s/in.h5", fuzz_scratch());
    write_file(path, &b);
    const char *keep = getenv("PLUME_FUZZ_KEEP"); /* the HDF5 file of a reproducer, for the regressions */
    if (keep) {
        char cmd[512];
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", path, keep);
        if (system(cmd) != 0)
            abort();
    }
    plume_err err = {{0}};
    plume_ortho m;
    if (plume_moduli_read(path, &m, &err) != PLUME_OK && !err.msg[0])
        abort();
    plume_curve c;
    err.msg[0] = 0;
    if (plume_curve_read(path, "macro", "tilted", &c, &err) == PLUME_OK)
        plume_curve_free(&c);
    else if (!err.msg[0])
        abort();
    plume_frames_info info;
    if (plume_frames_info_read(path, &info, &err) == PLUME_OK) {
        for (long k = -1; k < info.count && k < 8; k++) {
            plume_frame fr;
            if (plume_frames_read(path, k, &fr, &err) == PLUME_OK) {
                if (fr.nv != info.nv || (fr.ncons > 0 && !fr.lambda))
                    abort(); /* a frame read must have the file's shape */
                plume_frame_free(&fr);
            }
            plume_frame_measures fm;
            plume_frames_read_measures(path, k, &fm, &err);
        }
    }
    return 0;
}
