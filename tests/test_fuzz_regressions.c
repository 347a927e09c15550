/* Every crash, hang or wrong acceptance the fuzzers found (tests/fuzz/), replayed through the
 * same library calls in the regular suite (no clang needed): tests/fuzz/regressions/<harness>/ holds
 * the reproducers, each of which must now be refused with a message, quickly. A reproducer that
 * would also be refused the slow way (a hang that ended in an error) has a sidecar <name>.expect
 * holding a phrase the message must contain: the check that refuses it at once. */
#define _DEFAULT_SOURCE
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "harness.h"
#include "../lib/io/frames.h"
#include "../lib/io/vtu.h"
#include "../lib/io/progress.h"
#include "../macro/scene/scene.h"

/* copies src to dst */
static int copy(const char *src, const char *dst)
{
    FILE *in = fopen(src, "rb"), *out = in ? fopen(dst, "wb") : NULL;
    char buf[65536];
    size_t n;
    int ok = in && out;
    while (ok && (n = fread(buf, 1, sizeof buf, in)) > 0)
        ok = fwrite(buf, 1, n, out) == n;
    if (in)
        fclose(in);
    if (out && fclose(out) != 0)
        ok = 0;
    return ok;
}

/* the harnesses' feather scene in dir (tests/fuzz/fuzz_scene_common.h), loaded: its shape file a
 * copy of shape, its outline a copy of outline */
static plume_status feather_scene(const char *dir, const char *shape, const char *outline, plume_err *err)
{
    char path[512];
    snprintf(path, sizeof path, "%s/outline_in.obj", dir);
    if (!copy(outline, path))
        return PLUME_EIO;
    snprintf(path, sizeof path, "%s/shape_in.json", dir);
    if (!copy(shape, path))
        return PLUME_EIO;
    snprintf(path, sizeof path, "%s/feather_in.json", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return PLUME_EIO;
    fputs("{\"bending_model\": \"hinge\", \"mesh\": {\"feather\": \"shape_in.json\", \"outline\": \"outline_in.obj\", "
          "\"edge\": 0.02}, \"materials\": [{\"membrane\": {\"E\": 1e6, \"thickness\": 1e-4}, \"density\": 0.03, "
          "\"constraint\": true}, {\"membrane\": {\"E\": 1e9, \"thickness\": 3e-3}, \"density\": 0.5}], \"dt\": 0.01, "
          "\"duration\": 0.1}",
          f);
    fclose(f);
    plume_scene *s = NULL;
    plume_status st = plume_scene_load(path, &s, err);
    plume_scene_destroy(&s);
    return st;
}

/* the reproducer as the outline, with the shipped shape */
static plume_status feather_outline(const char *dir, const char *reproducer, plume_err *err)
{
    return feather_scene(dir, "../data/feather/feather_shape.json", reproducer, err);
}

/* the reproducer as the shape file, with the shipped outline */
static plume_status feather_shape(const char *dir, const char *reproducer, plume_err *err)
{
    return feather_scene(dir, reproducer, "../data/feather/outline.obj", err);
}

static plume_status vtu(const char *dir, const char *reproducer, plume_err *err)
{
    (void)dir;
    plume_vtu_data d;
    plume_status st = plume_vtu_read(reproducer, &d, err);
    if (st == PLUME_OK)
        plume_vtu_data_free(&d);
    return st;
}

/* fuzz_h5 reproducers are kept as the HDF5 files they describe (PLUME_FUZZ_KEEP) */
static plume_status h5(const char *dir, const char *reproducer, plume_err *err)
{
    (void)dir;
    plume_frames_info info;
    plume_status st = plume_frames_info_read(reproducer, &info, err);
    if (st != PLUME_OK)
        return st;
    plume_frame f;
    if ((st = plume_frames_read(reproducer, -1, &f, err)) == PLUME_OK)
        plume_frame_free(&f);
    return st;
}

void test_fuzz_regressions(void)
{
    static const struct {
        const char *harness;
        plume_status (*replay)(const char *dir, const char *reproducer, plume_err *err);
    } kinds[] = {{"feather_outline", feather_outline}, {"feather_shape", feather_shape}, {"vtu", vtu}, {"h5", h5}};
    char dir[64] = "/tmp/plume-fuzzreg-XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0);
        return;
    }
    int replayed = 0;
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        char sub[256];
        snprintf(sub, sizeof sub, "fuzz/regressions/%s", kinds[k].harness);
        DIR *d = opendir(sub);
        CHECK(d != NULL);
        struct dirent *e;
        while (d && (e = readdir(d))) {
            const size_t len = strlen(e->d_name);
            if (e->d_name[0] == '.' || (len > 7 && strcmp(e->d_name + len - 7, ".expect") == 0))
                continue;
            char path[600], expect_path[620], expect[256] = "";
            snprintf(path, sizeof path, "%s/%s", sub, e->d_name);
            snprintf(expect_path, sizeof expect_path, "%s.expect", path);
            FILE *xf = fopen(expect_path, "r");
            if (xf) {
                if (!fgets(expect, sizeof expect, xf))
                    expect[0] = '\0';
                expect[strcspn(expect, "\n")] = '\0';
                fclose(xf);
            }
            plume_err err = {{0}};
            double t0 = plume_wall_seconds();
            plume_status st = kinds[k].replay(dir, path, &err);
            double dt = plume_wall_seconds() - t0;
            fprintf(stderr, "    %s/%s: %s in %.3f s: %s\n", kinds[k].harness, e->d_name, plume_strerror(st), dt, err.msg);
            CHECK(st != PLUME_OK && err.msg[0] != '\0');
            if (expect[0] && !strstr(err.msg, expect)) {
                fprintf(stderr, "    expected the message to say \"%s\"\n", expect);
                CHECK(0);
            }
            replayed++;
        }
        if (d)
            closedir(d);
    }
    CHECK(replayed >= 4);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}
