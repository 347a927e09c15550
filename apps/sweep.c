/* apps/sweep — a parameter sweep (macro/sweep.h): expands a sweep file into runs, executes them
 * serially or over MPI ranks with dynamic scheduling, and gathers every curve, its parameters and
 * its outcome into one HDF5 file, with a summary table. A killed sweep resumes from that file.
 * Built with MPI when mpicc is found (PLUME_MPI); the same binary then runs serially or under
 * mpirun/srun. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef PLUME_MPI
#include <mpi.h>
#endif

#include "../lib/plume.h"
#include "../macro/sweep.h"
#include "cli.h"

#define APP "sweep"

/* OpenBLAS's thread count, when the BLAS is OpenBLAS (a weak reference: NULL otherwise) */
extern void openblas_set_num_threads(int n) __attribute__((weak));

static const char usage[] =
    "usage: sweep SWEEP.json -o FILE.h5 [options]\n"
    "Runs a parameter sweep (the format is in macro/sweep.h): every run's curve, parameters and outcome go to\n"
    "FILE.h5 (/sweep/runs/<k>), a summary table to FILE.md. Runs already in FILE.h5 are not redone (resume).\n"
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

/* writes run k's record; returns 0, or 1 after saying why */
static int record(const char *out, const plume_sweep *s, int k, const char *rec, int *written, int total, int quiet)
{
    plume_err err = {{0}};
    if (!rec || plume_sweep_results_add(out, s, k, rec, &err) != PLUME_OK) {
        fprintf(stderr, "%s: %s\n", APP, rec ? err.msg : "out of memory");
        return 1;
    }
    (*written)++;
    if (!quiet)
        fprintf(stderr, "%s: run %d recorded (%d of %d this session)\n", APP, k, *written, total);
    return 0;
}

#ifdef PLUME_MPI
enum { TAG_WORK = 1, TAG_RECORD = 2 };

/* ranks > 0: run what rank 0 sends until it sends -1; each record goes back to rank 0 */
static void worker(const plume_sweep *s)
{
    for (;;) {
        int k;
        MPI_Recv(&k, 1, MPI_INT, 0, TAG_WORK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (k < 0)
            return;
        char *rec = plume_sweep_execute(s, k);
        const char *text = rec ? rec : "";
        MPI_Send(text, (int)strlen(text) + 1, MPI_CHAR, 0, TAG_RECORD, MPI_COMM_WORLD);
        free(rec);
    }
}

/* receives one record (from any worker) into the file and gives that worker its next run */
static int receive(const char *out, const plume_sweep *s, const int *todo, int ntodo, int *next, int *outstanding,
                   int *written, int quiet)
{
    MPI_Status stt;
    MPI_Probe(MPI_ANY_SOURCE, TAG_RECORD, MPI_COMM_WORLD, &stt);
    int len;
    MPI_Get_count(&stt, MPI_CHAR, &len);
    char *text = malloc((size_t)len + 1);
    MPI_Recv(text, len, MPI_CHAR, stt.MPI_SOURCE, TAG_RECORD, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    text[len] = '\0';
    int w = stt.MPI_SOURCE, rc = 0;
    outstanding[w]--;
    if (*next < ntodo) { /* keep the worker busy: its next run */
        MPI_Send(&todo[(*next)++], 1, MPI_INT, w, TAG_WORK, MPI_COMM_WORLD);
        outstanding[w]++;
    } else if (outstanding[w] == 0) {
        int stop = -1;
        MPI_Send(&stop, 1, MPI_INT, w, TAG_WORK, MPI_COMM_WORLD);
    }
    /* which run: the record says */
    const char *p = strstr(text, "\"run\":");
    int k = p ? atoi(p + 6) : -1;
    if (k < 0 || record(out, s, k, text, written, ntodo, quiet))
        rc = 1;
    free(text);
    return rc;
}
#endif

int main(int argc, char **argv)
{
    plume_openmp_serial();
    /* the runs are the parallelism: one BLAS thread per process. Measured on 2 cores, the 24 runs of
     * data/sweeps/mesh_angles.json took 13.6 s serially with OpenBLAS's 2 threads and 6.2 s with 1 */
    if (openblas_set_num_threads && !getenv("OPENBLAS_NUM_THREADS"))
        openblas_set_num_threads(1);
    int rank = 0, size = 1;
#ifdef PLUME_MPI
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
#endif
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc) {
#ifdef PLUME_MPI
        MPI_Finalize();
#endif
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
#ifdef PLUME_MPI
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD); /* a bad input stops every rank */
#endif
    double t0 = plume_wall_seconds();
    int written = 0;
    if (!rc && size == 1) {
        for (int i = 0; i < ntodo && !rc; i++) {
            char *rec = plume_sweep_execute(s, todo[i]);
            rc = record(o.out, s, todo[i], rec, &written, ntodo, o.quiet);
            free(rec);
        }
    }
#ifdef PLUME_MPI
    else if (!rc && rank > 0) {
        worker(s);
    } else if (!rc) {
        /* rank 0 schedules and computes too: every worker holds two runs (one running, one queued),
         * so that it does not wait while rank 0 is busy with a run of its own */
        int next = 0, *outstanding = calloc((size_t)size, sizeof *outstanding), total = 0;
        for (int w = 1; w < size; w++) {
            for (int q = 0; q < 2 && next < ntodo; q++, outstanding[w]++, total++)
                MPI_Send(&todo[next++], 1, MPI_INT, w, TAG_WORK, MPI_COMM_WORLD);
            if (!outstanding[w]) {
                int stop = -1;
                MPI_Send(&stop, 1, MPI_INT, w, TAG_WORK, MPI_COMM_WORLD);
            }
        }
        for (;;) {
            int flag = 1, pending = 0;
            while (flag) {
                MPI_Iprobe(MPI_ANY_SOURCE, TAG_RECORD, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
                if (flag)
                    rc |= receive(o.out, s, todo, ntodo, &next, outstanding, &written, o.quiet);
            }
            for (int w = 1; w < size; w++)
                pending += outstanding[w];
            if (next < ntodo) {
                int k = todo[next++];
                char *rec = plume_sweep_execute(s, k);
                rc |= record(o.out, s, k, rec, &written, ntodo, o.quiet);
                free(rec);
            } else if (pending > 0) {
                rc |= receive(o.out, s, todo, ntodo, &next, outstanding, &written, o.quiet);
            } else {
                break;
            }
        }
        free(outstanding);
    }
#endif
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
            fprintf(stderr, "%s: %d runs in %.2f s on %d rank%s; results %s, summary %s\n", APP, written,
                    plume_wall_seconds() - t0, size, size == 1 ? "" : "s", o.out, md);
    }
    free(done);
    free(todo);
    plume_sweep_destroy(&s);
#ifdef PLUME_MPI
    MPI_Finalize();
#endif
    return rc;
}
