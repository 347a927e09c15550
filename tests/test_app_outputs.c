/* Every app prepares its outputs before it solves: an output into folders that do not exist yet
 * creates them, and an output that cannot be written (here under a path whose parent is a regular
 * file, which stops root too) fails at once, exit code 2, with a message naming the flag and the
 * path, and nothing on stdout. That the check comes before the work is shown where a later check
 * would have failed otherwise (traction: barbs spanning both grips). */
#define _DEFAULT_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app_runner.h"
#include "harness.h"

static char dir[64];

static int scratch(void)
{
    strcpy(dir, "/tmp/plume-outputs-XXXXXX");
    if (!mkdtemp(dir))
        return 0;
    char path[128];
    snprintf(path, sizeof path, "%s/file", dir); /* a regular file, used as a folder below */
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    fclose(f);
    return 1;
}

static void cleanup(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    CHECK(system(cmd) == 0);
}

static int exists(const char *fmt, const char *a)
{
    char path[512];
    snprintf(path, sizeof path, fmt, dir, a);
    return access(path, F_OK) == 0;
}

/* app args (with %s for the scratch directory, once or twice) fails before any work, naming flag
 * and the unwritable path */
static void unwritable(const char *app, const char *args_fmt, const char *flag)
{
    char args[1024], out[8192], err[8192], needle[256];
    snprintf(args, sizeof args, args_fmt, dir, dir);
    int rc = app_run(dir, app, args, out, sizeof out, err, sizeof err);
    snprintf(needle, sizeof needle, "%s %s/file/", flag, dir);
    int ok = rc == 2 && strstr(err, needle) && strstr(err, "Not a directory") && out[0] == 0;
    if (!ok)
        fprintf(stderr, "    %s %s: exit %d, stderr: %s    stdout: %.200s\n", app, args, rc, err, out);
    CHECK(ok);
}

void test_app_outputs_unwritable(void)
{
    if (!scratch()) {
        CHECK(0);
        return;
    }
    /* barbs spanning both grips fail the run's setup: the output is refused before that */
    unwritable("traction", "--scenario longitudinal --edge 0.2 -o %s/file/a/t.h5 --json --quiet", "-o");
    unwritable("traction", "--edge 0.1 --steps 2 --plot %s/file/t.png --json --quiet", "--plot");
    unwritable("traction", "--edge 0.1 --steps 2 --vtk %s/file/v --json --quiet", "--vtk");
    unwritable("homogenize", "--steps 2 --strain-max 0.01 -o %s/file/m.h5 --json", "-o");
    unwritable("homogenize", "--steps 2 --strain-max 0.01 --vtk %s/file/v --json", "--vtk");
    unwritable("fit", "--target ../tests/data/none.txt --angle 45 -o %s/file/f.h5 --json", "-o");
    unwritable("shell", "../data/benchmarks/cantilever_shear.json --edge 0.5 --steps 2 -o %s/file/s --json", "-o");
    unwritable("feather", "../data/shell/strip_scene.json -o %s/file/f --frames 1 --json --quiet", "-o");
    unwritable("study", "-o %s/file/s --quick --json", "-o");
    unwritable("sweep", "../data/sweeps/mesh_angles.json -o %s/file/r.h5 --json --quiet", "-o");
    unwritable("sweep", "../data/sweeps/mesh_angles.json -o %s/r.h5 --summary %s/file/r.md --json --quiet", "--summary");
    cleanup();
}

/* runs into nested folders that do not exist: created, the outputs there */
void test_app_outputs_nested(void)
{
    if (!scratch()) {
        CHECK(0);
        return;
    }
    char args[1024], out[16384], err[8192];
    snprintf(args, sizeof args, "--edge 0.1 --steps 2 -o %s/a/b/t.h5 --plot %s/c/d/t.png --vtk %s/e/f --quiet", dir, dir,
             dir);
    CHECK(app_run(dir, "traction", args, out, sizeof out, err, sizeof err) == 0);
    CHECK(exists("%s/a/b/t.h5%s", "") && exists("%s/e/f/%s", "macro/steps.pvd"));
    snprintf(args, sizeof args, "--steps 2 --strain-max 0.01 -o %s/g/h/m.h5 --vtk %s/i/j", dir, dir);
    CHECK(app_run(dir, "homogenize", args, out, sizeof out, err, sizeof err) == 0);
    CHECK(exists("%s/g/h/m.h5%s", "") && exists("%s/i/j/%s", "shear/steps.pvd"));
    snprintf(args, sizeof args, "../data/benchmarks/cantilever_shear.json --edge 0.5 --steps 2 -o %s/k/l", dir);
    CHECK(app_run(dir, "shell", args, out, sizeof out, err, sizeof err) == 0);
    CHECK(exists("%s/k/l/%s", "steps.pvd"));
    snprintf(args, sizeof args, "../data/shell/strip_scene.json -o %s/m/n --frames 1 --quiet", dir);
    CHECK(app_run(dir, "feather", args, out, sizeof out, err, sizeof err) == 0);
    CHECK(exists("%s/m/n/%s", "frames.h5") && exists("%s/m/n/%s", "frames.pvd"));
    cleanup();
}
