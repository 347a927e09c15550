/* Faults rehearsed: inputs that are FIFOs or directories are refused, not read forever;
 * a full disk during every kind of output (curves, moduli, frames, VTU series, charts) leaves the
 * previous file intact and the app exits non-zero naming it; kills at random moments leave every
 * output readable and a restart continues from the last committed frame; the library never calls
 * exit or abort and never writes to stdout. */
#define _DEFAULT_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "app_runner.h"
#include "harness.h"
#include "test_rng.h"
#include "../lib/io/curves.h"
#include "../lib/io/frames.h"
#include "../lib/io/vtu.h"
#include "../lib/io/sample.h"
#include "../macro/feather/obj_outline.h"
#include "../macro/scene/scene.h"
#include "../micro/fit.h"
#include "../micro/layout_json.h"

static int scratch_dir(char *dir, const char *name)
{
    snprintf(dir, 64, "/tmp/plume-%s-XXXXXX", name);
    return mkdtemp(dir) != NULL;
}

static void remove_tree(const char *dir)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "    could not remove %s\n", dir);
}

/* the whole file into a malloc'ed buffer (*n bytes), or NULL */
static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *b = NULL;
    size_t cap = 0;
    *n = 0;
    for (;;) {
        if (*n + 65536 > cap) {
            unsigned char *nb = realloc(b, cap = 2 * cap + 65536);
            if (!nb) {
                free(b);
                fclose(f);
                return NULL;
            }
            b = nb;
        }
        size_t got = fread(b + *n, 1, 65536, f);
        *n += got;
        if (!got)
            break;
    }
    fclose(f);
    return b;
}

/* Every reader a user hands a path to refuses a FIFO (and a directory) at once. Run in a child with
 * a time limit: a reader that opened the FIFO would block until killed. */
void test_robustness_fifo_inputs(void)
{
    char dir[64], fifo[128];
    if (!scratch_dir(dir, "fifo")) {
        CHECK(0);
        return;
    }
    snprintf(fifo, sizeof fifo, "%s/input", dir);
    CHECK(mkfifo(fifo, 0600) == 0);
    pid_t pid = fork();
    if (pid == 0) {
        alarm(20);
        int bad = 0;
        plume_err err = {{0}};
#define REFUSED(call)                                                                                              \
    do {                                                                                                           \
        err.msg[0] = 0;                                                                                            \
        if ((call) == PLUME_OK || !strstr(err.msg, "regular file")) {                                              \
            fprintf(stderr, "    not refused: %s (%s)\n", #call, err.msg);                                          \
            bad++;                                                                                                 \
        }                                                                                                          \
    } while (0)
        plume_scene *s = NULL;
        REFUSED(plume_scene_load(fifo, &s, &err));
        plume_layout l;
        plume_layout_default(&l);
        REFUSED(plume_layout_load_json(fifo, &l, &err));
        plume_sample smp;
        REFUSED(plume_sample_load(fifo, "T01", &smp, &err));
        plume_curve c;
        REFUSED(plume_curve_read_text(fifo, &c, &err));
        REFUSED(plume_curve_read(fifo, "macro", "tilted", &c, &err));
        plume_ortho m;
        REFUSED(plume_moduli_read(fifo, &m, &err));
        plume_frames_info fi;
        REFUSED(plume_frames_info_read(fifo, &fi, &err));
        plume_vtu_data d;
        REFUSED(plume_vtu_read(fifo, &d, &err));
        plume_pvd_entries e;
        REFUSED(plume_pvd_read(fifo, &e, &err));
        double *pts = NULL;
        plume_index np = 0;
        REFUSED(plume_obj_outline(fifo, &pts, &np, &err));
        REFUSED(plume_scene_load(dir, &s, &err)); /* a directory */
#undef REFUSED
        _exit(bad ? 1 : 0);
    }
    int status = 0;
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    if (WIFSIGNALED(status))
        fprintf(stderr, "    the readers' child was killed by signal %d (a FIFO read blocked?)\n", WTERMSIG(status));
    remove_tree(dir);
}

/* The library never exits, aborts or prints to stdout: no object of libplume.a references exit,
 * abort, printf, puts, putchar or stdout (nm), except the CGAL shims, whose exit/abort come from
 * CGAL's header templates (its error handlers for the EXIT and ABORT behaviours; CGAL's default is
 * to throw, and both shims catch every exception). */
void test_robustness_library_no_exit_or_stdout(void)
{
    char exe[PATH_MAX], cmd[PATH_MAX + 64];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) {
        CHECK(0);
        return;
    }
    exe[n] = 0;
    char *slash = strrchr(exe, '/');
    *slash = 0;
    snprintf(cmd, sizeof cmd, "nm -A '%s/libplume.a' 2>/dev/null", exe);
    FILE *p = popen(cmd, "r");
    char line[512];
    int objects = 0, bad = 0;
    static const char *const banned[] = {"exit", "_exit", "abort", "printf", "__printf_chk", "puts", "putchar",
                                         "stdout", "vprintf", "__vprintf_chk", NULL};
    while (p && fgets(line, sizeof line, p)) {
        objects += strstr(line, ".o:") != NULL && strstr(line, " T ") != NULL;
        char *u = strstr(line, " U ");
        if (!u)
            continue;
        char sym[128];
        if (sscanf(u + 3, "%127s", sym) != 1)
            continue;
        for (int k = 0; banned[k]; k++)
            if (strcmp(sym, banned[k]) == 0) {
                int cgal = strstr(line, "cdt.o:") || strstr(line, "contact_cgal.o:");
                if (!(cgal && (strcmp(sym, "exit") == 0 || strcmp(sym, "abort") == 0))) {
                    fprintf(stderr, "    %s", line);
                    bad++;
                }
            }
    }
    CHECK(p && pclose(p) == 0);
    CHECK(objects > 50); /* nm read the archive */
    CHECK(bad == 0);
}

/* Runs ../apps/APP ARGS with files limited to fsize bytes (RLIMIT_FSIZE, SIGXFSZ ignored: a write
 * past it fails with EFBIG, as one on a full disk fails with ENOSPC); 0 = no limit. Exit code. */
static int run_limited(const char *scratch, const char *app, const char *args, long fsize, char *errs, size_t nerr)
{
    char cmd[4096], path[256];
    snprintf(cmd, sizeof cmd, "exec ../apps/%s %s >%s/out.txt 2>%s/err.txt", app, args, scratch, scratch);
    pid_t pid = fork();
    if (pid == 0) {
        if (fsize > 0) {
            struct rlimit rl = {(rlim_t)fsize, (rlim_t)fsize};
            signal(SIGXFSZ, SIG_IGN);
            setrlimit(RLIMIT_FSIZE, &rl);
        }
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    snprintf(path, sizeof path, "%s/err.txt", scratch);
    app_slurp(path, errs, nerr);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* one output kind: a run that writes `file`, then the same with other values on a full disk */
typedef struct {
    const char *what, *app, *args_ok, *args_full, *file;
    long limit; /* bytes the full-disk run may write */
} disk_case;

void test_robustness_full_disk(void)
{
    char dir[64];
    if (!scratch_dir(dir, "disk")) {
        CHECK(0);
        return;
    }
    char a[8][2][600], f[8][300];
    /* the previous outputs, then the same outputs with other values written on a "full disk" */
    snprintf(a[0][0], 600, "--steps 2 -o %s/c.h5 --quiet", dir);
    snprintf(a[0][1], 600, "--steps 3 -o %s/c.h5 --quiet", dir);
    snprintf(f[0], 300, "%s/c.h5", dir);
    snprintf(a[1][0], 600, "--strain-max 0 -o %s/m.h5", dir);
    snprintf(a[1][1], 600, "--strain-max 0 --phi 0.2 -o %s/m.h5", dir);
    snprintf(f[1], 300, "%s/m.h5", dir);
    snprintf(a[2][0], 600, "--steps 2 --plot %s/p.png --quiet", dir);
    snprintf(a[2][1], 600, "--steps 3 --plot %s/p.png --quiet", dir);
    snprintf(f[2], 300, "%s/p.png", dir);
    snprintf(a[3][0], 600, "--steps 2 --vtk %s/v --quiet", dir);
    snprintf(a[3][1], 600, "--steps 2 --Eyy 2 --vtk %s/v --quiet", dir);
    snprintf(f[3], 300, "%s/v/macro/step_00002.vtu", dir);
    snprintf(a[4][0], 600, "../data/shell/strip_scene.json -o %s/fr --frames 2 --quiet", dir);
    snprintf(a[4][1], 600, "../data/shell/strip_scene.json --restart %s/fr/frames.h5 --frames 3 --quiet", dir);
    snprintf(f[4], 300, "%s/fr/frames.h5", dir);
    snprintf(a[5][0], 600, "../data/shell/strip_scene.json -o %s/fv --frames 2 --quiet", dir);
    snprintf(a[5][1], 600, "../data/shell/strip_scene.json --restart %s/fv/frames.h5 --frames 2 --quiet", dir);
    snprintf(f[5], 300, "%s/fv/frames.pvd", dir);
    const disk_case cases[] = {
        {"curves (HDF5)", "traction", a[0][0], a[0][1], f[0], 2048},
        {"moduli (HDF5)", "homogenize", a[1][0], a[1][1], f[1], 2048},
        {"chart (PNG)", "traction", a[2][0], a[2][1], f[2], 4096},
        {"VTU series", "traction", a[3][0], a[3][1], f[3], 4096},
        {"frames (HDF5, appended)", "feather", a[4][0], a[4][1], f[4], 0 /* set below: its size */},
        {"a scene's series (.pvd)", "feather", a[5][0], a[5][1], f[5], 4096},
    };
    int ncases = (int)(sizeof cases / sizeof cases[0]);
    for (int k = 0; k < ncases; k++) {
        const disk_case *c = &cases[k];
        char errs[8192];
        int rc = run_limited(dir, c->app, c->args_ok, 0, errs, sizeof errs);
        CHECK(rc == 0);
        size_t n0 = 0, n1 = 0;
        unsigned char *before = slurp(c->file, &n0);
        CHECK(before && n0 > 0);
        long limit = c->limit;
        plume_frames_info info0 = {0};
        plume_err err = {{0}};
        if (k == 4) { /* appending: room for what is there and a little more */
            limit = (long)n0 + 512;
            CHECK(plume_frames_info_read(c->file, &info0, &err) == PLUME_OK);
        }
        rc = run_limited(dir, c->app, c->args_full, limit, errs, sizeof errs);
        unsigned char *after = slurp(c->file, &n1);
        int intact;
        if (k == 4) { /* the frames written before are all still there and readable */
            plume_frames_info info1 = {0};
            intact = plume_frames_info_read(c->file, &info1, &err) == PLUME_OK && info1.count >= info0.count;
            for (long i = 0; intact && i < info1.count; i++) {
                plume_frame fr;
                intact = plume_frames_read(c->file, i, &fr, &err) == PLUME_OK;
                plume_frame_free(&fr);
            }
        } else {
            intact = after && n1 == n0 && memcmp(before, after, n0) == 0;
        }
        const char *base = strrchr(c->file, '/') + 1;
        int named = strstr(errs, base) != NULL || strstr(errs, "frames.h5") != NULL || strstr(errs, "too large") != NULL;
        fprintf(stderr, "    full disk during %-24s exit %d, previous file %s, message: %.*s\n", c->what, rc,
                intact ? "intact" : "DAMAGED", (int)strcspn(errs, "\n"), errs);
        CHECK(rc != 0 && rc != -1);
        CHECK(intact);
        CHECK(named);
        free(before);
        free(after);
    }
    remove_tree(dir);
}

/* Kills at random moments: apps/traction -o leaves either the previous results file or the new
 * one, never a damaged one; apps/feather leaves frames.h5 readable and a restart from it goes on
 * to the end, from the last frame it committed. */
void test_robustness_kills(void)
{
    char dir[64];
    if (!scratch_dir(dir, "kill")) {
        CHECK(0);
        return;
    }
    rng64 r = {20261125};
    char args[600], path[300], errs[8192];
    int trials = 0, survived = 0;
    for (int t = 0; t < 8; t++) { /* traction: the curve file */
        snprintf(args, sizeof args, "exec ../apps/traction --steps 4 --edge 0.03 -o %s/t.h5 --quiet >/dev/null 2>&1", dir);
        pid_t pid = fork();
        if (pid == 0) {
            execl("/bin/sh", "sh", "-c", args, (char *)NULL);
            _exit(127);
        }
        struct timespec ts = {0, (long)(urange(&r, 0.0, 0.6) * 1e9)};
        nanosleep(&ts, NULL);
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        trials++;
        snprintf(path, sizeof path, "%s/t.h5", dir);
        plume_curve c;
        plume_err err = {{0}};
        struct stat st;
        int ok = stat(path, &st) != 0 || plume_curve_read(path, "macro", "tilted", &c, &err) == PLUME_OK;
        if (stat(path, &st) == 0 && ok)
            plume_curve_free(&c);
        survived += ok;
    }
    for (int t = 0; t < 6; t++) { /* feather: frames.h5, then a restart to the end */
        snprintf(path, sizeof path, "%s/f%d", dir, t);
        snprintf(args, sizeof args, "exec ../apps/feather ../data/shell/strip_scene.json -o %s --frames 8 --quiet "
                                    ">/dev/null 2>&1", path);
        pid_t pid = fork();
        if (pid == 0) {
            execl("/bin/sh", "sh", "-c", args, (char *)NULL);
            _exit(127);
        }
        struct timespec ts = {0, (long)(urange(&r, 0.05, 0.5) * 1e9)};
        nanosleep(&ts, NULL);
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        trials++;
        char h5[400];
        snprintf(h5, sizeof h5, "%s/frames.h5", path);
        plume_frames_info info;
        plume_err err = {{0}};
        struct stat st;
        if (stat(h5, &st) != 0) { /* killed before the file existed: nothing to lose */
            survived++;
            continue;
        }
        int ok = plume_frames_info_read(h5, &info, &err) == PLUME_OK;
        long committed = ok ? info.count : -1;
        for (long i = 0; ok && i < committed; i++) {
            plume_frame fr;
            ok = plume_frames_read(h5, i, &fr, &err) == PLUME_OK;
            plume_frame_free(&fr);
        }
        if (ok && committed >= 1 && committed < 9) { /* the restart takes it to frame 8 */
            snprintf(args, sizeof args, "../data/shell/strip_scene.json --restart %s --frames %ld --quiet", h5,
                     9 - committed);
            ok = run_limited(dir, "feather", args, 0, errs, sizeof errs) == 0 &&
                 plume_frames_info_read(h5, &info, &err) == PLUME_OK && info.count == 9;
        }
        if (!ok)
            fprintf(stderr, "    feather killed: %s (committed %ld): %s%s\n", h5, committed, err.msg, errs);
        survived += ok;
    }
    fprintf(stderr, "    kills: %d trials, %d survived (outputs readable, restarts complete)\n", trials, survived);
    CHECK(survived == trials);
    remove_tree(dir);
}

/* Kills at every file write, not at random moments: apps/feather (the strip scene, 9 frames) under
 * a preload that SIGKILLs it at its k-th write (tests/data/kill_at_write.c), for every second k of
 * the run. After each kill frames.h5 is absent or readable with all its committed frames, and from
 * every fifth a restart reaches frame 8. Random kills hit the append of frame 8 too rarely to see
 * that HDF5's default group layout lost the frames' links there (its name heap moved and its
 * B-tree leaf split: lib/io/frames.c); this walks every write. */
void test_robustness_kill_every_write(void)
{
    char dir[64], cmd[1400], shim[300], count_file[300], h5[400], errs[8192];
    if (!scratch_dir(dir, "killw")) {
        CHECK(0);
        return;
    }
    snprintf(shim, sizeof shim, "%s/kill_at_write.so", dir);
    snprintf(cmd, sizeof cmd, "cc -shared -fPIC -O1 -o %s data/kill_at_write.c -ldl", shim);
    if (system(cmd) != 0) {
        fprintf(stderr, "    cannot build the preload (%s); skipped\n", cmd);
        CHECK(!"the kill-at-write preload builds");
        remove_tree(dir);
        return;
    }
    snprintf(count_file, sizeof count_file, "%s/writes", dir);
    snprintf(h5, sizeof h5, "%s/run/frames.h5", dir);
    const char *run = "../apps/feather ../data/shell/strip_scene.json --frames 8 --quiet";
    snprintf(cmd, sizeof cmd, "rm -rf %s/run && KILL_COUNT=%s LD_PRELOAD=%s %s -o %s/run >/dev/null 2>&1", dir,
             count_file, shim, run, dir);
    CHECK(system(cmd) == 0);
    long total = 0;
    FILE *f = fopen(count_file, "r");
    CHECK(f && fscanf(f, "%ld", &total) == 1 && total > 50);
    if (f)
        fclose(f);
    int trials = 0, survived = 0, restarts = 0;
    for (long k = 1; k <= total; k += 2) {
        snprintf(cmd, sizeof cmd, "rm -rf %s/run && KILL_AT=%ld LD_PRELOAD=%s %s -o %s/run >/dev/null 2>&1", dir, k,
                 shim, run, dir);
        int rc = system(cmd);
        (void)rc;
        trials++;
        struct stat st;
        if (stat(h5, &st) != 0) { /* killed before the file existed */
            survived++;
            continue;
        }
        plume_frames_info info;
        plume_err err = {{0}};
        int ok = plume_frames_info_read(h5, &info, &err) == PLUME_OK;
        long committed = ok ? info.count : -1;
        for (long i = 0; ok && i < committed; i++) {
            plume_frame fr;
            ok = plume_frames_read(h5, i, &fr, &err) == PLUME_OK;
            plume_frame_free(&fr);
        }
        if (ok && committed >= 1 && committed < 9 && trials % 5 == 0) {
            char args[600];
            snprintf(args, sizeof args, "../data/shell/strip_scene.json --restart %s --frames %ld --quiet", h5,
                     9 - committed);
            ok = run_limited(dir, "feather", args, 0, errs, sizeof errs) == 0 &&
                 plume_frames_info_read(h5, &info, &err) == PLUME_OK && info.count == 9;
            restarts++;
        }
        if (!ok)
            fprintf(stderr, "    killed at write %ld of %ld: committed %ld: %s%s\n", k, total, committed, err.msg, errs);
        survived += ok;
    }
    fprintf(stderr, "    kills at every second write: %d trials (%ld writes), %d survived, %d restarts to the end\n",
            trials, total, survived, restarts);
    CHECK(survived == trials);
    remove_tree(dir);
}

