/* The atomic-write protocol for HDF5 files (docs/design.md): a file is edited as a copy and renamed
 * over the original, so a crash at any moment leaves either the old file or the new one, whole. */
#include "h5_atomic.h"
#include "h5util.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Copies the bytes of `src` into a new file `dst` (created with src's permission bits). */
static plume_status copy_file(const char *src, const char *dst, mode_t mode, const char *what,
                              plume_err *err)
{
    plume_status s = PLUME_OK;
    int in = open(src, O_RDONLY);
    int out = -1;
    if (in < 0) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot open: %s", what, src, strerror(errno));
        goto cleanup;
    }
    out = open(dst, O_WRONLY | O_CREAT | O_TRUNC, mode);
    if (out < 0) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot create temporary file '%s': %s", what,
                          src, dst, strerror(errno));
        goto cleanup;
    }
    char buf[65536];
    for (;;) {
        ssize_t r = read(in, buf, sizeof buf);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0) {
            s = plume_err_set(err, PLUME_EIO, "%s '%s': read error: %s", what, src, strerror(errno));
            goto cleanup;
        }
        if (r == 0)
            break;
        for (ssize_t off = 0; off < r;) {
            ssize_t w = write(out, buf + off, (size_t)(r - off));
            if (w < 0 && errno == EINTR)
                continue;
            if (w < 0) {
                s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot write temporary file '%s': %s",
                                  what, src, dst, strerror(errno));
                goto cleanup;
            }
            off += w;
        }
    }
cleanup:
    if (out >= 0 && close(out) != 0 && s == PLUME_OK)
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot write temporary file '%s': %s", what,
                          src, dst, strerror(errno));
    if (in >= 0)
        close(in);
    return s;
}

/* The atomic-write protocol of docs/design.md: build "<path>.tmp.<pid>" (a byte copy of `path` when
 * it exists, so its other content survives), let `fill` edit it, close, fsync and rename over
 * `path`. On any failure the temporary file is removed and `path` is untouched. */
static plume_status atomic_write(const char *path, const char *what, plume_h5_fill_fn fill, const void *ctx,
                                 int keep, plume_err *err)
{
    plume_status s = PLUME_OK;
    hid_t fid = H5I_INVALID_HID;
    int tmp_made = 0;
    char *tmp = NULL;
    h5_detail d;

    struct stat st;
    int exists = stat(path, &st) == 0;
    if (!exists && errno != ENOENT) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot access: %s", what, path, strerror(errno));
        goto cleanup;
    }
    if (exists && !S_ISREG(st.st_mode)) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': exists and is not a regular file", what, path);
        goto cleanup;
    }
    if (exists && !h5_is_hdf5(path)) {
        s = plume_err_set(err, PLUME_EFORMAT, "%s '%s': is not an HDF5 file (refusing to overwrite it)",
                          what, path);
        goto cleanup;
    }

    size_t len = strlen(path) + 32;
    tmp = malloc(len);
    if (!tmp) {
        s = plume_err_set(err, PLUME_ENOMEM, "%s '%s': out of memory", what, path);
        goto cleanup;
    }
    snprintf(tmp, len, "%s.tmp.%ld", path, (long)getpid());

    if (exists && keep) {
        s = copy_file(path, tmp, st.st_mode & 07777, what, err);
        tmp_made = 1; /* copy_file may have created it before failing */
        if (s != PLUME_OK)
            goto cleanup;
        fid = H5Fopen(tmp, H5F_ACC_RDWR, H5P_DEFAULT);
    } else {
        /* Create the file ourselves first so a bad directory gets a proper strerror. */
        int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0666);
        if (fd < 0) {
            s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot create temporary file '%s': %s",
                              what, path, tmp, strerror(errno));
            goto cleanup;
        }
        close(fd);
        tmp_made = 1;
        fid = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    }
    if (fid < 0) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot open temporary file '%s' (HDF5: %s)",
                          what, path, tmp, h5_cause(&d));
        goto cleanup;
    }

    s = fill(fid, path, ctx, err);
    if (s != PLUME_OK)
        goto cleanup;

    herr_t closed = H5Fclose(fid);
    fid = H5I_INVALID_HID;
    if (closed < 0) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot close temporary file '%s' (HDF5: %s)",
                          what, path, tmp, h5_cause(&d));
        goto cleanup;
    }
    /* Data on disk before the rename makes it visible: a crash leaves either file, never half. */
    int fd = open(tmp, O_RDONLY);
    if (fd < 0 || fsync(fd) != 0) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot sync temporary file '%s': %s", what,
                          path, tmp, strerror(errno));
        if (fd >= 0)
            close(fd);
        goto cleanup;
    }
    close(fd);
    if (rename(tmp, path) != 0) {
        s = plume_err_set(err, PLUME_EIO, "%s '%s': cannot rename '%s' over it: %s", what, path,
                          tmp, strerror(errno));
        goto cleanup;
    }
    tmp_made = 0;

cleanup:
    if (fid >= 0)
        H5Fclose(fid);
    if (tmp_made)
        unlink(tmp);
    free(tmp);
    return s;
}

plume_status plume_h5_atomic_write(const char *path, const char *what, plume_h5_fill_fn fill, const void *ctx,
                                   plume_err *err)
{
    return atomic_write(path, what, fill, ctx, 1, err);
}

plume_status plume_h5_atomic_replace(const char *path, const char *what, plume_h5_fill_fn fill, const void *ctx,
                                     plume_err *err)
{
    return atomic_write(path, what, fill, ctx, 0, err);
}
