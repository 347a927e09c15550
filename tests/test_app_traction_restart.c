/* apps/traction --checkpoint, --stop-after and --restart as a user runs them: the shipped hooked
 * layout loaded, unloaded and reloaded, stopped after step 6 and restarted, writes the same curve and
 * the same hooks table (-o) as the run that never stopped, bit for bit; combinations that cannot
 * work are refused by flag. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hdf5.h>
#include <jansson.h>

#include "app_runner.h"
#include "harness.h"
#include "../lib/io/curves.h"

static char scratch[64];

static const char run_args[] = "--model micro --layout-config ../data/layout_hooks.json --lx 4e-3 --ly 5.2e-3 "
                               "--thickness 1e-4 --steps 4 --path 0.003,0,0.003 --no-convergence --json --quiet";

/* apps/traction with run_args and `more`; its JSON summary (NULL if none). */
static json_t *traction(const char *more, int *rc, char *err, size_t nerr)
{
    char out[16384], args[1024];
    snprintf(args, sizeof args, "%s %s", run_args, more);
    *rc = app_run(scratch, "traction", args, out, sizeof out, err, nerr);
    json_error_t je;
    return *rc == 0 ? json_loads(out, 0, &je) : NULL;
}

/* A dataset of `file` (in scratch) as doubles (allocated), its size in *n; NULL if missing. */
static double *dataset(const char *file, const char *name, size_t *n)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", scratch, file);
    double *v = NULL;
    *n = 0;
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t ds = f >= 0 ? H5Dopen2(f, name, H5P_DEFAULT) : -1;
    hid_t sp = ds >= 0 ? H5Dget_space(ds) : -1;
    if (sp >= 0) {
        *n = (size_t)H5Sget_simple_extent_npoints(sp);
        v = malloc((*n + 1) * sizeof *v);
        if (v && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0) {
            free(v);
            v = NULL;
        }
        H5Sclose(sp);
    }
    if (ds >= 0)
        H5Dclose(ds);
    if (f >= 0)
        H5Fclose(f);
    return v;
}

/* The same dataset in two files, bit for bit. */
static int same_dataset(const char *a, const char *b, const char *name)
{
    size_t na, nb;
    double *va = dataset(a, name, &na), *vb = dataset(b, name, &nb);
    const int same = va && vb && na == nb && na > 0 && memcmp(va, vb, na * sizeof *va) == 0;
    if (!same)
        fprintf(stderr, "    %s differs between %s (%zu values) and %s (%zu values)\n", name, a, na, b, nb);
    free(va);
    free(vb);
    return same;
}

void test_app_traction_restart(void)
{
    strcpy(scratch, "/tmp/plume-app-XXXXXX");
    if (!mkdtemp(scratch)) {
        CHECK(0);
        return;
    }
    char err[8192], more[512];
    int rc;
    snprintf(more, sizeof more, "-o %s/whole.h5", scratch);
    json_t *whole = traction(more, &rc, err, sizeof err);
    CHECK(rc == 0 && whole);
    snprintf(more, sizeof more, "-o %s/part.h5 --checkpoint %s/ck.h5 --stop-after 6", scratch, scratch);
    json_t *part = traction(more, &rc, err, sizeof err);
    CHECK(rc == 0 && part);
    snprintf(more, sizeof more, "-o %s/rest.h5 --restart %s/ck.h5", scratch, scratch);
    json_t *rest = traction(more, &rc, err, sizeof err);
    CHECK(rc == 0 && rest);
    if (whole && part && rest) {
        CHECK(json_integer_value(json_object_get(part, "stopped_after")) == 6);
        CHECK(json_object_get(whole, "stopped_after") == NULL && json_object_get(rest, "stopped_after") == NULL);
        CHECK(json_is_string(json_object_get(rest, "restarted_from")));
        const char *keys[] = {"hooks_released", "hooks_reengaged", "newton_iterations", "step_cuts"};
        for (int k = 0; k < 4; k++)
            CHECK(json_integer_value(json_object_get(whole, keys[k])) ==
                  json_integer_value(json_object_get(rest, keys[k])));
        const char *reals[] = {"dissipated_energy", "work", "energy_balance_error", "peak_stress", "initial_slope"};
        for (int k = 0; k < 5; k++)
            CHECK(json_real_value(json_object_get(whole, reals[k])) == json_real_value(json_object_get(rest, reals[k])));
        printf("    whole run: %lld let go, %lld caught again, %.6e J dissipated; stopped after step %lld and "
               "restarted: %lld, %lld, %.6e J\n",
               json_integer_value(json_object_get(whole, "hooks_released")),
               json_integer_value(json_object_get(whole, "hooks_reengaged")),
               json_real_value(json_object_get(whole, "dissipated_energy")),
               json_integer_value(json_object_get(part, "stopped_after")),
               json_integer_value(json_object_get(rest, "hooks_released")),
               json_integer_value(json_object_get(rest, "hooks_reengaged")),
               json_real_value(json_object_get(rest, "dissipated_energy")));
    }
    /* -o of the restarted run: the whole curve and the hooks table from rest */
    CHECK(same_dataset("whole.h5", "rest.h5", "/curves/micro/tilted/strain"));
    CHECK(same_dataset("whole.h5", "rest.h5", "/curves/micro/tilted/stress"));
    CHECK(same_dataset("whole.h5", "rest.h5", "/curves/micro/tilted/wbar"));
    CHECK(same_dataset("whole.h5", "rest.h5", "/curves/micro/tilted/hooks"));
    size_t n = 0;
    double *stopped = dataset("part.h5", "/curves/micro/tilted/stress", &n);
    CHECK(stopped && n == 7); /* the stopped run's curve: the rest state and 6 steps */
    free(stopped);
    json_decref(whole), json_decref(part), json_decref(rest);

    /* refused: a checkpoint of another schedule (named), a series not continued, a stop without a
     * checkpoint, two models */
    snprintf(more, sizeof more, "--steps 5 --restart %s/ck.h5", scratch);
    json_decref(traction(more, &rc, err, sizeof err));
    CHECK(rc != 0 && strstr(err, "steps = 4") && strstr(err, "ck.h5"));
    snprintf(more, sizeof more, "--restart %s/ck.h5 --vtk %s/vtk", scratch, scratch);
    json_decref(traction(more, &rc, err, sizeof err));
    CHECK(rc != 0 && strstr(err, "--restart") && strstr(err, "--vtk"));
    json_decref(traction("--stop-after 3", &rc, err, sizeof err));
    CHECK(rc != 0 && strstr(err, "--stop-after needs --checkpoint"));
    snprintf(more, sizeof more, "--model both --checkpoint %s/ck2.h5", scratch);
    json_decref(traction(more, &rc, err, sizeof err));
    CHECK(rc != 0 && strstr(err, "--checkpoint needs one model"));
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
    CHECK(system(cmd) == 0);
}
