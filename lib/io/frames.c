/* plume: frames of a dynamic run in HDF5, appended one group at a time (see frames.h for the
 * layout and for why appends do not go through a temporary file).
 *
 * As in lib/io/curves.c, every public function silences HDF5's automatic error printing for its own
 * duration and reports failures as a status and a message naming the file and the object. */
#include "frames.h"

#include <hdf5.h>

#include "h5util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>




/* the units of /frames' numeric attributes */
#define FRAMES_UNITS "count: 1; nv: 1; ncons: 1; dt: s"
/* half the frame links a B-tree leaf of /frames holds: appends up to frame 2 FRAMES_LEAF_K write into
 * existing nodes (plume_frames_create) */
#define FRAMES_LEAF_K 256
/* bytes reserved for the frame links' names (8 each up to frame 9999999) */
#define FRAMES_NAME_HEAP 16384
/* Digits of a frame group's name: "0000000", "0000001", ... Listed by name (h5py, h5ls), the groups
 * then come in frame order. Seven digits keep every name up to frame 9999999 at 8 bytes with its
 * NUL, the heap's unit, so FRAMES_NAME_HEAP holds as many names as it did; and they cover any run:
 * 10^7 frames are 10^7 implicit steps at least, months of computing at the smallest scene's
 * 0.1 s a frame. Past them the names simply grow a digit (read by number, listed out of order). */
#define FRAME_NAME_WIDTH 7

/* The name of frame k's group, written: k zero-padded to FRAME_NAME_WIDTH digits. */
static void frame_name(long k, char name[32])
{
    snprintf(name, 32, "%0*ld", FRAME_NAME_WIDTH, k);
}

/* The name of frame k's group in g, read: the padded name, else the decimal one files written
 * before the padding have ("0", "1", ...); the padded one when neither exists. */
static void frame_name_in(hid_t g, long k, char name[32])
{
    char plain[32];
    frame_name(k, name);
    snprintf(plain, sizeof plain, "%ld", k);
    if (strcmp(name, plain) != 0 && H5Lexists(g, name, H5P_DEFAULT) <= 0 && H5Lexists(g, plain, H5P_DEFAULT) > 0)
        strcpy(name, plain);
}

static int write_attr_long(hid_t obj, const char *name, long v)
{
    return h5_write_attr(obj, name, H5T_STD_I64LE, H5T_NATIVE_LONG, &v);
}



/* Reads a scalar numeric attribute converted to mem_type; -1 when missing or not scalar. */
static int read_attr(hid_t obj, const char *name, hid_t mem_type, void *v)
{
    if (H5Aexists(obj, name) <= 0)
        return -1;
    int ok = 0;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    hid_t sp = a < 0 ? H5I_INVALID_HID : H5Aget_space(a);
    if (sp >= 0 && H5Sget_simple_extent_npoints(sp) == 1 && H5Aread(a, mem_type, v) >= 0)
        ok = 1;
    if (sp >= 0)
        H5Sclose(sp);
    if (a >= 0)
        H5Aclose(a);
    return ok ? 0 : -1;
}

/* Reads a string attribute (variable or fixed length) into buf; -1 when missing. */
static int read_attr_string(hid_t obj, const char *name, char *buf, size_t n)
{
    buf[0] = '\0';
    if (H5Aexists(obj, name) <= 0)
        return -1;
    int ok = 0;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    hid_t ft = a < 0 ? H5I_INVALID_HID : H5Aget_type(a);
    if (ft >= 0 && H5Tget_class(ft) == H5T_STRING) {
        if (H5Tis_variable_str(ft) > 0) {
            char *s = NULL; /* read in the file's own string type: no ASCII/UTF-8 conversion */
            if (H5Aread(a, ft, &s) >= 0 && s) {
                snprintf(buf, n, "%s", s);
                H5free_memory(s);
                ok = 1;
            }
        } else {
            size_t len = H5Tget_size(ft);
            char *s = calloc(len + 1, 1);
            if (s && H5Aread(a, ft, s) >= 0) {
                snprintf(buf, n, "%s", s);
                ok = 1;
            }
            free(s);
        }
    }
    if (ft >= 0)
        H5Tclose(ft);
    if (a >= 0)
        H5Aclose(a);
    return ok ? 0 : -1;
}


/* Reads a 1D double dataset of exactly n values into v: 0, -1 missing/unreadable, -2 wrong size. */
/* the number of values of dataset `name` in g, or -1 when it is missing or unreadable */
static hssize_t dataset_points(hid_t g, const char *name)
{
    if (H5Lexists(g, name, H5P_DEFAULT) <= 0)
        return -1;
    hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
    hid_t sp = ds < 0 ? H5I_INVALID_HID : H5Dget_space(ds);
    hssize_t np = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    return np;
}

static int read_dataset(hid_t g, const char *name, double *v, plume_index n)
{
    if (H5Lexists(g, name, H5P_DEFAULT) <= 0)
        return -1;
    int rc = -1;
    hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
    hid_t sp = ds < 0 ? H5I_INVALID_HID : H5Dget_space(ds);
    if (sp >= 0) {
        hssize_t np = H5Sget_simple_extent_npoints(sp);
        if (np != (hssize_t)n || H5Sget_simple_extent_ndims(sp) > 1)
            rc = -2;
        else if (n == 0 || H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0)
            rc = 0;
    }
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    return rc;
}

/* fsync of a closed file, so the frame is on disk before the call returns. */
static int sync_file(const char *path)
{
    int fd = open(path, O_RDONLY);
    if (fd < 0)
        return -1;
    int rc = fsync(fd);
    close(fd);
    return rc;
}

/* Opens `path` (which must be an existing HDF5 file with a /frames group); *fid and *g open. */
static plume_status open_frames(const char *path, unsigned mode, hid_t *fid, hid_t *g, plume_err *err)
{
    struct stat st;
    h5_detail d;
    *fid = *g = H5I_INVALID_HID;
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "frames file: empty path");
    if (stat(path, &st) != 0)
        return plume_err_set(err, PLUME_EIO, "frames file '%s': cannot open: %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return plume_err_set(err, PLUME_EIO, "frames file '%s': not a regular file", path);
    if (!h5_is_hdf5(path))
        return plume_err_set(err, PLUME_EFORMAT, "frames file '%s': is not an HDF5 file", path);
    *fid = H5Fopen(path, mode, H5P_DEFAULT);
    if (*fid < 0)
        return plume_err_set(err, PLUME_EIO, "frames file '%s': cannot open%s (HDF5: %s)", path,
                             mode == H5F_ACC_RDWR ? " for writing" : "", h5_cause(&d));
    if (H5Lexists(*fid, "/frames", H5P_DEFAULT) <= 0 || (*g = H5Gopen2(*fid, "/frames", H5P_DEFAULT)) < 0)
        return plume_err_set(err, PLUME_EFORMAT, "frames file '%s': has no /frames group (not a plume frames file)",
                             path);
    return PLUME_OK;
}

static plume_status read_info(const char *path, hid_t g, plume_frames_info *info, plume_err *err)
{
    long count = -1, nv = -1, ncons = -1;
    double dt = NAN;
    memset(info, 0, sizeof *info);
    if (read_attr(g, "count", H5T_NATIVE_LONG, &count) < 0 || read_attr(g, "nv", H5T_NATIVE_LONG, &nv) < 0 ||
        read_attr(g, "ncons", H5T_NATIVE_LONG, &ncons) < 0 || read_attr(g, "dt", H5T_NATIVE_DOUBLE, &dt) < 0)
        return plume_err_set(err, PLUME_EFORMAT,
                             "frames file '%s': /frames lacks one of the attributes count, nv, ncons, dt", path);
    /* bounds before anything is sized from them (fuzzing: nv = LONG_MAX overflowed 3 nv) */
    if (count < 0 || nv < 1 || nv > 100000000L || ncons < 0 || ncons > 1000000000L || !(dt > 0) || !isfinite(dt))
        return plume_err_set(err, PLUME_EFORMAT,
                             "frames file '%s': /frames has count %ld, nv %ld, ncons %ld, dt %g (expected count >= 0, "
                             "1 <= nv <= 1e8, 0 <= ncons <= 1e9, dt > 0)",
                             path, count, nv, ncons, dt);
    info->count = count;
    info->nv = nv;
    info->ncons = ncons;
    info->dt = dt;
    read_attr_string(g, "scene", info->scene, sizeof info->scene);
    return PLUME_OK;
}

plume_status plume_frames_create(const char *path, plume_index nv, plume_index ncons, double dt, const char *scene,
                                 plume_err *err)
{
    if (!path || !*path)
        return plume_err_set(err, PLUME_EINVAL, "frames file: empty path");
    if (nv < 1 || ncons < 0 || !(dt > 0.0) || !isfinite(dt))
        return plume_err_set(err, PLUME_EINVAL, "frames file '%s': needs nv >= 1, ncons >= 0, dt > 0 (got %ld, %ld, %g)",
                             path, (long)nv, (long)ncons, dt);
    h5_quiet q;
    quiet_begin(&q);
    h5_detail d;
    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID;
    size_t len = strlen(path) + 32;
    char *tmp = malloc(len);
    int made = 0;
    if (!tmp) {
        s = plume_err_set(err, PLUME_ENOMEM, "frames file '%s': out of memory", path);
        goto cleanup;
    }
    snprintf(tmp, len, "%s.tmp.%ld", path, (long)getpid());
    /* created by open() first, so a bad directory gets a proper strerror */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd < 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot create '%s': %s", path, tmp, strerror(errno));
        goto cleanup;
    }
    close(fd);
    made = 1;
    /* /frames/<k> are links of one symbol-table group: their names in a local heap, the links in
     * B-tree leaves of 2 FRAMES_LEAF_K. When the heap is full it moves, and when a leaf is full it
     * splits; either is several writes, and a SIGKILL between them left a file whose count was
     * intact and whose links were lost ("/frames/0 is missing" with HDF5's defaults, at the append
     * of frame 8; found by killing apps/feather at every write of a 9-frame run,
     * test_robustness_kill_every_write). A heap of FRAMES_NAME_HEAP bytes and leaves of 512 links
     * make every append up to frame 512 a write into existing nodes. */
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    if (fcpl >= 0 && H5Pset_sym_k(fcpl, 16, FRAMES_LEAF_K) < 0) {
        H5Pclose(fcpl);
        fcpl = H5I_INVALID_HID;
    }
    fid = fcpl < 0 ? H5I_INVALID_HID : H5Fcreate(tmp, H5F_ACC_TRUNC, fcpl, H5P_DEFAULT);
    if (fcpl >= 0)
        H5Pclose(fcpl);
    hid_t gcpl = H5Pcreate(H5P_GROUP_CREATE);
    if (gcpl >= 0 && H5Pset_local_heap_size_hint(gcpl, FRAMES_NAME_HEAP) < 0) {
        H5Pclose(gcpl);
        gcpl = H5I_INVALID_HID;
    }
    if (fid >= 0 && gcpl >= 0)
        g = H5Gcreate2(fid, "/frames", H5P_DEFAULT, gcpl, H5P_DEFAULT);
    if (gcpl >= 0)
        H5Pclose(gcpl);
    if (fid < 0 || g < 0 ||
        write_attr_long(g, "count", 0) < 0 || write_attr_long(g, "nv", (long)nv) < 0 ||
        write_attr_long(g, "ncons", (long)ncons) < 0 || h5_write_attr_double(g, "dt", dt) < 0 ||
        h5_write_attr_string(g, "scene", scene ? scene : "") < 0 ||
        /* attributes carry no attributes: their units in one string beside them (docs/hdf5-layout.md) */
        h5_write_attr_string(g, "units", FRAMES_UNITS) < 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot write /frames (HDF5: %s)", path, h5_cause(&d));
        goto cleanup;
    }
    H5Gclose(g);
    g = H5I_INVALID_HID;
    herr_t closed = H5Fclose(fid);
    fid = H5I_INVALID_HID;
    if (closed < 0 || sync_file(tmp) != 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot close '%s'", path, tmp);
        goto cleanup;
    }
    if (rename(tmp, path) != 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot rename '%s' over it: %s", path, tmp,
                          strerror(errno));
        goto cleanup;
    }
    made = 0;
cleanup:
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    if (made)
        unlink(tmp);
    free(tmp);
    quiet_end(&q);
    return s;
}

/* the measures' attribute names and their fields; the units of a frame's attributes */
static const char *const measure_names[] = {"newton_iterations", "steps_halved", "seconds", "contact_pairs",
                                            "min_distance", "intersecting_pairs"};
static const size_t measure_offsets[] = {
    offsetof(plume_frame_measures, newton_iterations), offsetof(plume_frame_measures, steps_halved),
    offsetof(plume_frame_measures, seconds),           offsetof(plume_frame_measures, contact_pairs),
    offsetof(plume_frame_measures, min_distance),      offsetof(plume_frame_measures, intersecting_pairs)};
#define NMEASURES (sizeof measure_names / sizeof *measure_names)
#define FRAME_UNITS "t: s; step: 1"
#define FRAME_MEASURES_UNITS                                                                                          \
    FRAME_UNITS "; newton_iterations: 1; steps_halved: 1; seconds: s; contact_pairs: 1; min_distance: m; "           \
                "intersecting_pairs: 1"

static int write_measures(hid_t fg, const plume_frame_measures *m)
{
    for (size_t k = 0; k < NMEASURES; k++)
        if (h5_write_attr_double(fg, measure_names[k], *(const double *)((const char *)m + measure_offsets[k])) < 0)
            return -1;
    return 0;
}

plume_status plume_frames_append(const char *path, plume_index nv, plume_index ncons, double t, long step,
                                 const double *x, const double *v, const double *lambda, plume_err *err)
{
    return plume_frames_append_arrays(path, nv, ncons, t, step, x, v, lambda, NULL, NULL, 0, err);
}

plume_status plume_frames_append_measured(const char *path, plume_index nv, plume_index ncons, double t, long step,
                                          const double *x, const double *v, const double *lambda,
                                          const plume_frame_measures *m, plume_err *err)
{
    return plume_frames_append_arrays(path, nv, ncons, t, step, x, v, lambda, m, NULL, 0, err);
}

/* Reserves the disk space a frame needs before HDF5 writes any of it. An HDF5 file whose writes
 * fail half-way can be left unreadable, and libhdf5 1.10 then crashes at exit closing it (both
 * measured with a full disk: tests/test_robustness.c). So the file is first extended by the
 * frame's data plus room for its metadata (posix_fallocate: real blocks, or ENOSPC/EFBIG now);
 * HDF5 writes into that room and trims the file to its end of allocation when it closes it. */
static plume_status reserve_room(const char *path, plume_index nv, plume_index ncons, plume_index nextra,
                                 plume_err *err)
{
    int fd = open(path, O_WRONLY);
    if (fd < 0)
        return plume_err_set(err, PLUME_EIO, "frames file '%s': cannot open for writing: %s", path, strerror(errno));
    struct stat st;
    int rc = fstat(fd, &st) != 0 ? errno : 0;
    off_t need = (off_t)(8 * (6 * (double)nv + (double)ncons + (double)nextra)) + 65536;
    if (rc == 0)
        rc = posix_fallocate(fd, st.st_size, need);
    if (rc != 0) /* nothing half-reserved left behind (a failure here changes nothing to report) */
        (void)!ftruncate(fd, st.st_size);
    close(fd);
    if (rc != 0)
        return plume_err_set(err, PLUME_EIO, "frames file '%s': no room for another frame (%ld bytes): %s; the frames "
                                             "written so far are kept", path, (long)need, strerror(rc));
    return PLUME_OK;
}

/* /materials of the old file (plume_frames_material_write), if it has one, into the new one */
static plume_status copy_materials(const char *path, hid_t ofid, hid_t nfid, const char *tmp, plume_err *err)
{
    h5_detail d;
    if (H5Lexists(ofid, "/materials", H5P_DEFAULT) > 0 &&
        H5Ocopy(ofid, "/materials", nfid, "/materials", H5P_DEFAULT, H5P_DEFAULT) < 0)
        return plume_err_set(err, PLUME_EIO, "frames file '%s': cannot copy its /materials into '%s' (HDF5: %s)", path,
                             tmp, h5_cause(&d));
    return PLUME_OK;
}

/* Writes a new `path` holding only the committed frames of the old one (its /frames attributes and
 * groups 0 .. count-1, copied whole), through a temporary file renamed over it: the old file is
 * untouched unless the new one is complete. Why not remove the uncommitted group in place, as
 * before: a SIGKILL during the flush that writes a frame's group (plume_frames_append_measured)
 * can leave the group linked on disk while the superblock's end of allocated space does not yet
 * cover it. HDF5 then cannot free its space ("len not positive after adjustment for EOA"), so the
 * restart failed (1 kill in 150, /tmp stress run of 2026-11-26; the unexplained failure of
 * test_robustness_kills), and a failed removal may leave dirty metadata for the close to write.
 * The committed frames read back whole; a copy keeps them and drops the rest. */
static plume_status rebuild_committed(const char *path, const plume_frames_info *info, plume_err *err)
{
    h5_detail d;
    size_t len = strlen(path) + 40;
    char *tmp = malloc(len);
    if (!tmp)
        return plume_err_set(err, PLUME_ENOMEM, "frames file '%s': out of memory", path);
    snprintf(tmp, len, "%s.rebuild.%ld", path, (long)getpid());
    plume_status s = plume_frames_create(tmp, info->nv, info->ncons, info->dt, info->scene, err);
    hid_t ofid = H5I_INVALID_HID, og = H5I_INVALID_HID, nfid = H5I_INVALID_HID, ng = H5I_INVALID_HID;
    if (s == PLUME_OK)
        s = open_frames(path, H5F_ACC_RDONLY, &ofid, &og, err);
    if (s == PLUME_OK)
        s = open_frames(tmp, H5F_ACC_RDWR, &nfid, &ng, err);
    for (long k = 0; s == PLUME_OK && k < info->count; k++) {
        char from[32], to[32]; /* an older file's decimal names become padded ones */
        frame_name_in(og, k, from);
        frame_name(k, to);
        if (H5Ocopy(og, from, ng, to, H5P_DEFAULT, H5P_DEFAULT) < 0)
            s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot copy its committed /frames/%s into '%s' (HDF5: %s)",
                              path, from, tmp, h5_cause(&d));
    }
    if (s == PLUME_OK)
        s = copy_materials(path, ofid, nfid, tmp, err);
    if (s == PLUME_OK) {
        hid_t a = H5Aopen(ng, "count", H5P_DEFAULT);
        long count = info->count;
        if (a < 0 || H5Awrite(a, H5T_NATIVE_LONG, &count) < 0)
            s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot write the count of '%s' (HDF5: %s)", path, tmp,
                              h5_cause(&d));
        if (a >= 0)
            H5Aclose(a);
    }
    if (ng >= 0)
        H5Gclose(ng);
    if (nfid >= 0 && H5Fclose(nfid) < 0 && s == PLUME_OK)
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot close '%s'", path, tmp);
    if (og >= 0)
        H5Gclose(og);
    if (ofid >= 0)
        H5Fclose(ofid);
    if (s == PLUME_OK && sync_file(tmp) != 0)
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot sync '%s': %s", path, tmp, strerror(errno));
    if (s == PLUME_OK && rename(tmp, path) != 0)
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot rename '%s' over it: %s", path, tmp,
                          strerror(errno));
    if (s != PLUME_OK)
        unlink(tmp);
    free(tmp);
    return s;
}

plume_status plume_frames_append_arrays(const char *path, plume_index nv, plume_index ncons, double t, long step,
                                        const double *x, const double *v, const double *lambda,
                                        const plume_frame_measures *m, const plume_frame_array *arrays, int narrays,
                                        plume_err *err)
{
    if (!x || !v || (ncons > 0 && !lambda) || !isfinite(t) || narrays < 0 || (narrays > 0 && !arrays))
        return plume_err_set(err, PLUME_EINVAL, "frames file '%s': append needs x, v, lambda and a finite time",
                             path ? path : "(null)");
    plume_index nextra = 0;
    for (int i = 0; i < narrays; i++) {
        if (!arrays[i].name || !*arrays[i].name || arrays[i].n < 0 || (arrays[i].n > 0 && !arrays[i].v))
            return plume_err_set(err, PLUME_EINVAL, "frames file '%s': extra array %d needs a name and its values",
                                 path ? path : "(null)", i);
        nextra += arrays[i].n;
    }
    h5_quiet q;
    quiet_begin(&q);
    h5_detail d;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID, fg = H5I_INVALID_HID;
    plume_frames_info info;
    plume_status s = reserve_room(path, nv, ncons, nextra, err);
    if (s == PLUME_OK)
        s = open_frames(path, H5F_ACC_RDWR, &fid, &g, err);
    if (s == PLUME_OK)
        s = read_info(path, g, &info, err);
    char name[32], stale[32];
    frame_name(s == PLUME_OK ? info.count : 0L, name);
    if (s == PLUME_OK)
        frame_name_in(g, info.count, stale);
    /* a group at `count` is the remains of an interrupted append, never committed: the file,
     * closed unchanged, is rebuilt from its committed frames (rebuild_committed), since HDF5 may be
     * unable to free that group's space. A file with the decimal names of before the padding is
     * rebuilt too, once, so that its groups keep one naming and list in frame order. */
    if (s == PLUME_OK && (H5Lexists(g, stale, H5P_DEFAULT) > 0 || H5Lexists(g, "0", H5P_DEFAULT) > 0)) {
        H5Gclose(g);
        H5Fclose(fid);
        g = fid = H5I_INVALID_HID;
        s = rebuild_committed(path, &info, err);
        if (s == PLUME_OK)
            s = reserve_room(path, nv, ncons, nextra, err);
        if (s == PLUME_OK)
            s = open_frames(path, H5F_ACC_RDWR, &fid, &g, err);
    }
    if (s != PLUME_OK)
        goto cleanup;
    if (info.nv != nv || info.ncons != ncons) {
        s = plume_err_set(err, PLUME_EFORMAT,
                          "frames file '%s': holds frames of %ld vertices and %ld constraints, not %ld and %ld "
                          "(another scene?)",
                          path, (long)info.nv, (long)info.ncons, (long)nv, (long)ncons);
        goto cleanup;
    }
    if ((fg = H5Gcreate2(g, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 || h5_write_dataset(fg, "x", x, 3 * nv, "m") < 0 ||
        h5_write_dataset(fg, "v", v, 3 * nv, "m/s") < 0 || h5_write_dataset(fg, "lambda", lambda, ncons, "N/m") < 0 ||
        h5_write_attr_double(fg, "t", t) < 0 || write_attr_long(fg, "step", step) < 0 ||
        (m && write_measures(fg, m) < 0) || h5_write_attr_string(fg, "units", m ? FRAME_MEASURES_UNITS : FRAME_UNITS) < 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot write /frames/%s (HDF5: %s)", path, name,
                          h5_cause(&d));
        goto cleanup;
    }
    for (int i = 0; i < narrays; i++)
        if (arrays[i].n > 0 && h5_write_dataset(fg, arrays[i].name, arrays[i].v, arrays[i].n, arrays[i].units) < 0) {
            s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot write /frames/%s/%s (HDF5: %s)", path, name,
                              arrays[i].name, h5_cause(&d));
            goto cleanup;
        }
    H5Gclose(fg);
    fg = H5I_INVALID_HID;
    /* The frame's group goes into the file before the commit mark changes. Without this flush both
     * reached the file only in H5Fclose, in the metadata cache's order: a SIGKILL during that close
     * left a file whose count said 2 without a /frames/1 (test_robustness_kills, 1 in 14 kills on a
     * loaded machine). A kill after the flush (or during it) leaves the group uncommitted, which
     * the next append drops. */
    if (H5Fflush(fid, H5F_SCOPE_LOCAL) < 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot flush /frames/%s (HDF5: %s)", path, name,
                          h5_cause(&d));
        goto cleanup;
    }
    /* the commit mark, last */
    long count = info.count + 1;
    hid_t a = H5Aopen(g, "count", H5P_DEFAULT);
    herr_t w = a < 0 ? -1 : H5Awrite(a, H5T_NATIVE_LONG, &count);
    if (a >= 0)
        H5Aclose(a);
    if (w < 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot update /frames count (HDF5: %s)", path,
                          h5_cause(&d));
        goto cleanup;
    }
cleanup:
    if (fg >= 0)
        H5Gclose(fg);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0) {
        herr_t closed = H5Fclose(fid);
        if (s == PLUME_OK && (closed < 0 || sync_file(path) != 0))
            s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot close after writing a frame", path);
    }
    quiet_end(&q);
    return s;
}

plume_status plume_frames_info_read(const char *path, plume_frames_info *info, plume_err *err)
{
    if (!info)
        return plume_err_set(err, PLUME_EINVAL, "frames file: no info struct");
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid, g;
    plume_status s = open_frames(path, H5F_ACC_RDONLY, &fid, &g, err);
    if (s == PLUME_OK)
        s = read_info(path, g, info, err);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
    quiet_end(&q);
    return s;
}

void plume_frame_free(plume_frame *f)
{
    if (!f)
        return;
    free(f->x);
    free(f->v);
    free(f->lambda);
    f->x = f->v = f->lambda = NULL;
}

static void close_frame(hid_t fid, hid_t g, hid_t fg)
{
    if (fg >= 0)
        H5Gclose(fg);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0)
        H5Fclose(fid);
}

/* Opens committed frame k (k < 0: the last) of `path` read-only: *fid, *g (/frames), *fg (/frames/k),
 * *info and the group's name; on failure the ones opened are set and the caller closes them
 * (close_frame). */
static plume_status open_frame(const char *path, long *k, hid_t *fid, hid_t *g, hid_t *fg, plume_frames_info *info,
                               char name[32], plume_err *err)
{
    *fg = H5I_INVALID_HID;
    plume_status s = open_frames(path, H5F_ACC_RDONLY, fid, g, err);
    if (s == PLUME_OK)
        s = read_info(path, *g, info, err);
    if (s != PLUME_OK)
        return s;
    if (info->count == 0)
        return plume_err_set(err, PLUME_EINVAL, "frames file '%s': holds no frame", path);
    if (*k < 0)
        *k = info->count - 1;
    if (*k >= info->count)
        return plume_err_set(err, PLUME_EINVAL, "frames file '%s': has no frame %ld (it holds %ld)", path, *k, info->count);
    frame_name_in(*g, *k, name);
    if (H5Lexists(*g, name, H5P_DEFAULT) <= 0 || (*fg = H5Gopen2(*g, name, H5P_DEFAULT)) < 0)
        return plume_err_set(err, PLUME_EFORMAT, "frames file '%s': /frames/%s is missing", path, name);
    return PLUME_OK;
}

plume_status plume_frames_read(const char *path, long k, plume_frame *f, plume_err *err)
{
    if (!f)
        return plume_err_set(err, PLUME_EINVAL, "frames file: no frame struct");
    memset(f, 0, sizeof *f);
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid, g, fg;
    plume_frames_info info;
    char name[32];
    plume_status s = open_frame(path, &k, &fid, &g, &fg, &info, name, err);
    if (s != PLUME_OK)
        goto cleanup;
    f->index = k;
    f->nv = info.nv;
    f->ncons = info.ncons;
    const char *names[3] = {"x", "v", "lambda"};
    double **dst[3] = {&f->x, &f->v, &f->lambda};
    plume_index sizes[3] = {3 * info.nv, 3 * info.nv, info.ncons};
    for (int i = 0; i < 3; i++) {
        /* the dataset's size is checked before its memory is allocated */
        hssize_t np = dataset_points(fg, names[i]);
        int rc = np < 0 ? -1 : np != (hssize_t)sizes[i] ? -2 : 0;
        if (rc == 0 && sizes[i] > 0 && !(*dst[i] = malloc((size_t)sizes[i] * sizeof **dst[i]))) {
            s = plume_err_set(err, PLUME_ENOMEM, "frames file '%s': out of memory", path);
            goto cleanup;
        }
        if (rc == 0)
            rc = read_dataset(fg, names[i], *dst[i], sizes[i]);
        if (rc < 0) {
            s = plume_err_set(err, PLUME_EFORMAT, "frames file '%s': /frames/%s/%s is %s (expected %ld values)", path,
                              name, names[i], rc == -2 ? "of the wrong size" : "missing or unreadable",
                              (long)sizes[i]);
            goto cleanup;
        }
    }
    if (read_attr(fg, "t", H5T_NATIVE_DOUBLE, &f->t) < 0 || read_attr(fg, "step", H5T_NATIVE_LONG, &f->step) < 0) {
        s = plume_err_set(err, PLUME_EFORMAT, "frames file '%s': /frames/%s lacks its t or step attribute", path, name);
        goto cleanup;
    }
cleanup:
    if (s != PLUME_OK)
        plume_frame_free(f);
    close_frame(fid, g, fg);
    quiet_end(&q);
    return s;
}

plume_status plume_frames_read_array(const char *path, long k, const char *name, double *out, plume_index n,
                                     plume_err *err)
{
    if (!name || (n > 0 && !out) || n < 0)
        return plume_err_set(err, PLUME_EINVAL, "frames file: read_array needs a name and room for its values");
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid, g, fg;
    plume_frames_info info;
    char group[32];
    plume_status s = open_frame(path, &k, &fid, &g, &fg, &info, group, err);
    int rc = s == PLUME_OK ? read_dataset(fg, name, out, n) : 0;
    if (rc < 0)
        s = plume_err_set(err, PLUME_EFORMAT, "frames file '%s': /frames/%s/%s is %s (expected %ld values)", path, group,
                          name, rc == -2 ? "of the wrong size" : "missing or unreadable", (long)n);
    close_frame(fid, g, fg);
    quiet_end(&q);
    return s;
}

plume_status plume_frames_read_measures(const char *path, long k, plume_frame_measures *m, plume_err *err)
{
    if (!m)
        return plume_err_set(err, PLUME_EINVAL, "frames file: no measures struct");
    memset(m, 0, sizeof *m);
    h5_quiet q;
    quiet_begin(&q);
    hid_t fid, g, fg;
    plume_frames_info info;
    char name[32];
    plume_status s = open_frame(path, &k, &fid, &g, &fg, &info, name, err);
    if (s != PLUME_OK)
        goto cleanup;
    for (size_t i = 0; i < NMEASURES; i++)
        if (read_attr(fg, measure_names[i], H5T_NATIVE_DOUBLE, (char *)m + measure_offsets[i]) < 0) {
            s = plume_err_set(err, PLUME_EFORMAT, "frames file '%s': /frames/%s has no %s attribute (no measures)", path,
                              name, measure_names[i]);
            goto cleanup;
        }
cleanup:
    close_frame(fid, g, fg);
    quiet_end(&q);
    return s;
}

plume_status plume_frames_material_write(const char *path, int k, const plume_param *params, int nparams,
                                         const plume_sparam *sparams, int nsparams, const char *units, plume_err *err)
{
    if (k < 0 || nparams < 0 || nsparams < 0 || (nparams > 0 && !params) || (nsparams > 0 && !sparams))
        return plume_err_set(err, PLUME_EINVAL, "frames file '%s': material %d: invalid arguments", path ? path : "(null)", k);
    for (int i = 0; i < nparams + nsparams; i++) {
        const char *name = i < nparams ? params[i].name : sparams[i - nparams].name;
        if (!name || !*name || strcmp(name, "units") == 0 || (i >= nparams && !sparams[i - nparams].value))
            return plume_err_set(err, PLUME_EINVAL, "frames file '%s': material %d: attribute %d has no name or value, "
                                                    "or is named units", path ? path : "(null)", k, i);
        for (int j = 0; j < i; j++)
            if (strcmp(name, j < nparams ? params[j].name : sparams[j - nparams].name) == 0)
                return plume_err_set(err, PLUME_EINVAL, "frames file '%s': material %d: attribute %s given twice",
                                     path ? path : "(null)", k, name);
    }
    h5_quiet q;
    quiet_begin(&q);
    h5_detail d;
    hid_t fid = H5I_INVALID_HID, g = H5I_INVALID_HID, mg = H5I_INVALID_HID, kg = H5I_INVALID_HID;
    char name[48];
    snprintf(name, sizeof name, "/materials/%d", k);
    plume_status s = open_frames(path, H5F_ACC_RDWR, &fid, &g, err);
    if (s != PLUME_OK)
        goto cleanup;
    if (H5Lexists(fid, "/materials", H5P_DEFAULT) > 0)
        mg = H5Gopen2(fid, "/materials", H5P_DEFAULT);
    else
        mg = H5Gcreate2(fid, "/materials", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (mg >= 0 && H5Lexists(fid, name, H5P_DEFAULT) > 0 && H5Ldelete(fid, name, H5P_DEFAULT) < 0)
        kg = H5I_INVALID_HID;
    else if (mg >= 0)
        kg = H5Gcreate2(fid, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int bad = kg < 0;
    for (int i = 0; !bad && i < nparams; i++)
        bad = h5_write_attr_double(kg, params[i].name, params[i].value) < 0;
    for (int i = 0; !bad && i < nsparams; i++)
        bad = h5_write_attr_string(kg, sparams[i].name, sparams[i].value) < 0;
    if (bad || h5_write_attr_string(kg, "units", units ? units : "") < 0) {
        s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot write %s (HDF5: %s)", path, name, h5_cause(&d));
        goto cleanup;
    }
cleanup:
    if (kg >= 0)
        H5Gclose(kg);
    if (mg >= 0)
        H5Gclose(mg);
    if (g >= 0)
        H5Gclose(g);
    if (fid >= 0) {
        herr_t closed = H5Fclose(fid);
        if (s == PLUME_OK && (closed < 0 || sync_file(path) != 0))
            s = plume_err_set(err, PLUME_EIO, "frames file '%s': cannot close after writing %s", path, name);
    }
    quiet_end(&q);
    return s;
}
