/* apps/sweep — a parameter sweep (drivers/sweep.h): expands a sweep file into runs, executes them
 * serially or over MPI ranks with dynamic scheduling, and gathers every curve, its parameters and
 * its outcome into one HDF5 file, with a summary table. A killed sweep resumes from that file.
 * Built with MPI when mpicc is found (PLUME_MPI); the same binary then runs serially or under
 * mpirun/srun. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/plume.h"
#include "cli.h"
#include "schedule.h"

#define APP "sweep"


static const char usage[] =
    "usage: sweep SWEEP.json -o FILE.h5 [options]\n"
    "Runs a parameter sweep (the format is in drivers/sweep.h): every run's curve (or a scene's per-step measures\n"
    "and final positions), parameters and outcome go to FILE.h5 (/sweep/runs/<k>), a summary table to FILE.md.\n"
    "Runs already in FILE.h5 are not redone (resume).\n"
    "Under mpirun -n N (or srun) the runs are spread over the ranks as they free up; rank 0 writes.\n"
    "  -o FILE.h5          results file (required)\n"
    "  --summary FILE.md   summary table (default: FILE.h5 with .md)\n"
    "  --samples FILE      Table 1 samples for \"vary\": {\"sample\": ...} (default data/samples.json)\n"
    "  --json              print the summary as JSON on stdout\n"
    "  --quiet             no progress line\n"
    "  --help\n"
    "Exit status: 0 every run recorded (failed runs are recorded with their reason), 2 bad input, 1 other errors.\n";

typedef struct {
    const char *sweep, *out, *summary, *samples;
    int json, quiet;
} options;

static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            return CLI_HELP;
        }
        if (strcmp(a, "--json") == 0)
            o->json = 1;
        else if (strcmp(a, "--quiet") == 0)
            o->quiet = 1;
        else if (a[0] != '-') {
            if (o->sweep)
                return cli_fail(APP, "one sweep file only (got '%s' and '%s')", o->sweep, a);
            o->sweep = a;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--summary") || !strcmp(a, "--samples")) {
            if (!v)
                return cli_fail(APP, "%s needs a value (see --help)", a);
            i++;
            if (!strcmp(a, "-o"))
                o->out = v;
            else if (!strcmp(a, "--summary"))
                o->summary = v;
            else
                o->samples = v;
        } else
            return cli_fail(APP, "unknown option '%s' (see --help)", a);
    }
    if (!o->sweep)
        return cli_fail(APP, "no sweep file given (usage: sweep SWEEP.json -o FILE.h5; see --help)");
    if (!o->out)
        return cli_fail(APP, "-o FILE.h5 is required");
    return 0;
}

/* the schedule's callbacks (apps/schedule.h): a run executes on any rank, rank 0 writes records */
typedef struct {
    const plume_sweep *s;
    const char *out;
    int written, total, quiet;
} sweep_ctx;

/* Runs k in a child process, so that a run that crashes (a signal, not an error status) is
 * recorded with its reason and the sweep goes on: the child writes the record to a pipe. The
 * environment variable PLUME_SWEEP_CRASH_RUN=k makes run k's child crash (SIGSEGV), to rehearse it. */
static char *execute(void *vctx, int k)
{
    const sweep_ctx *c = vctx;
    int fd[2];
    if (pipe(fd) != 0)
        return plume_sweep_execute(c->s, k); /* no pipe: in this process */
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid == 0) {
        /* the child keeps only its pipe and the standard streams: an HDF5 file the other thread of
         * rank 0 has open (and its lock) must not live on in a run that lasts minutes */
        long maxfd = sysconf(_SC_OPEN_MAX);
        for (int f = 3; f < (maxfd > 0 && maxfd < 65536 ? maxfd : 1024); f++)
            if (f != fd[1])
                close(f);
        const char *crash = getenv("PLUME_SWEEP_CRASH_RUN");
        if (crash && atoi(crash) == k)
            raise(SIGSEGV);
        char *rec = plume_sweep_execute(c->s, k);
        size_t len = rec ? strlen(rec) : 0, off = 0;
        while (off < len) {
            ssize_t w = write(fd[1], rec + off, len - off);
            if (w <= 0)
                _exit(1);
            off += (size_t)w;
        }
        _exit(rec ? 0 : 1);
    }
    close(fd[1]);
    if (pid < 0) {
        close(fd[0]);
        return plume_sweep_execute(c->s, k);
    }
    size_t cap = 65536, len = 0;
    char *buf = malloc(cap + 1);
    ssize_t r;
    while (buf && (r = read(fd[0], buf + len, cap - len)) > 0) {
        len += (size_t)r;
        if (len == cap) {
            char *nb = realloc(buf, 2 * cap + 1);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb, cap *= 2;
        }
    }
    close(fd[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (buf && WIFEXITED(status) && WEXITSTATUS(status) == 0 && len > 0) {
        buf[len] = '\0';
        return buf;
    }
    free(buf);
    /* the run's process died: a record that says so */
    char *req = NULL, *vals = NULL, why[128];
    plume_err err = {{0}};
    plume_sweep_request(c->s, k, &req, &vals, &err);
    if (WIFSIGNALED(status))
        snprintf(why, sizeof why, "the run's process was killed by signal %d (%s)", WTERMSIG(status),
                 strsignal(WTERMSIG(status)));
    else
        snprintf(why, sizeof why, "the run's process exited with status %d", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    json_t *rec = json_pack("{s:i, s:o, s:s, s:s, s:f}", "run", k, "values",
                            vals ? json_loads(vals, 0, NULL) : json_object(), "outcome", "crashed", "message", why,
                            "seconds", 0.0);
    char *text = json_dumps(rec, JSON_COMPACT | JSON_REAL_PRECISION(17));
    json_decref(rec);
    free(req);
    free(vals);
    return text;
}

static int keep(void *vctx, int k, const char *rec)
{
    sweep_ctx *c = vctx;
    plume_err err = {{0}};
    if (plume_sweep_results_add(c->out, c->s, k, rec, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, err.msg);
        return 1;
    }
    c->written++;
    if (!c->quiet)
        fprintf(stderr, "%s: run %d recorded (%d of %d this session)\n", APP, k, c->written, c->total);
    return 0;
}

int main(int argc, char **argv)
{
    plume_openmp_serial();
    plume_openmp_factor_threads(1); /* the ranks already share the cores */
    /* rank 0 opens the results file for each run's record while its other thread forks the next
     * run: HDF5's file lock, inherited by that child, made the next open fail ("cannot open for
     * writing", 2 times in 3 under mpirun -n 4). One writer, rank 0, needs no lock. */
    setenv("HDF5_USE_FILE_LOCKING", "FALSE", 0);
    int rank, size;
    schedule_init(&argc, &argv, &rank, &size);
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc) {
        schedule_finalize();
        return rc == CLI_HELP ? 0 : rc;
    }
    plume_sweep *s = NULL;
    plume_err err = {{0}};
    char samples[4096];
    if (o.samples)
        snprintf(samples, sizeof samples, "%s", o.samples);
    else {
        const char *env = getenv("PLUME_DATA");
        const char *slash = strrchr(argv[0], '/');
        if (env)
            snprintf(samples, sizeof samples, "%s/samples.json", env);
        else if (slash)
            snprintf(samples, sizeof samples, "%.*s/../data/samples.json", (int)(slash - argv[0]), argv[0]);
        else
            snprintf(samples, sizeof samples, "data/samples.json");
    }
    if (plume_sweep_load(o.sweep, samples, &s, &err) != PLUME_OK)
        rc = rank == 0 ? cli_fail(APP, "%s", err.msg) : 2;
    else if (rank == 0 && ((rc = cli_output_file(APP, "-o", o.out)) == 0) && o.summary)
        rc = cli_output_file(APP, "--summary", o.summary);
    unsigned char *done = NULL;
    int *todo = NULL, ntodo = 0;
    if (!rc && rank == 0) {
        int n = plume_sweep_count(s);
        done = calloc((size_t)n + 1, 1);
        todo = malloc(((size_t)n + 1) * sizeof *todo);
        if (plume_sweep_results_open(o.out, s, &err) != PLUME_OK || plume_sweep_results_done(o.out, s, done, &err) != PLUME_OK)
            rc = 1, fprintf(stderr, "%s: %s\n", APP, err.msg);
        for (int k = 0; k < n; k++)
            if (!done[k])
                todo[ntodo++] = k;
        if (!rc && !o.quiet)
            fprintf(stderr, "%s: %s, %d runs of %s, %d already in %s, %d to run on %d rank%s\n", APP, o.sweep, n,
                    plume_sweep_job(s), n - ntodo, o.out, ntodo, size, size == 1 ? "" : "s");
    }
    rc = schedule_share(rc); /* a bad input stops every rank */
    double t0 = plume_wall_seconds();
    sweep_ctx ctx = {s, o.out, 0, ntodo, o.quiet};
    if (!rc)
        rc = schedule_run(rank, size, todo, ntodo, execute, keep, &ctx);
    if (!rc && rank == 0) {
        char md[4200];
        if (o.summary)
            snprintf(md, sizeof md, "%s", o.summary);
        else {
            snprintf(md, sizeof md, "%s", o.out);
            char *dot = strrchr(md, '.');
            if (dot && !strchr(dot, '/'))
                *dot = '\0';
            strncat(md, ".md", sizeof md - strlen(md) - 1);
        }
        char *json = NULL;
        if (plume_sweep_summary(o.out, s, md, o.json ? &json : NULL, &err) != PLUME_OK)
            rc = 1, fprintf(stderr, "%s: %s\n", APP, err.msg);
        if (json)
            printf("%s\n", json);
        free(json);
        if (!o.quiet)
            fprintf(stderr, "%s: %d runs in %.2f s on %d rank%s; results %s, summary %s\n", APP, ctx.written,
                    plume_wall_seconds() - t0, size, size == 1 ? "" : "s", o.out, md);
    }
    free(done);
    free(todo);
    plume_sweep_destroy(&s);
    schedule_finalize();
    return rc;
}
