/* Independent runs spread over MPI ranks as they free up (apps/sweep, apps/fit --starts,
 * apps/study): every rank can execute any run; rank 0 hands them out, computes too, and receives
 * every run's record. A run's cost may vary by 100x, so nothing is split statically: rank 0 keeps
 * each other rank two runs deep (one running, one queued). Rank 0 computes its own runs in a second
 * thread while its main thread keeps handing out work (polling every millisecond, so it costs no
 * core): the full study has one run of 142 s among 150, and a rank 0 busy with it in its only
 * thread left rank 1 idle — 2 ranks took 298 s against 316 s for one. Only the main thread calls
 * MPI (MPI_THREAD_FUNNELED) and keeps the records. Built without PLUME_MPI (no mpicc), the runs
 * execute in order on the one process. Header-only: each app is a single file. */
#ifndef PLUME_APPS_SCHEDULE_H
#define PLUME_APPS_SCHEDULE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef PLUME_MPI
#include <mpi.h>
#include <pthread.h>
#include <time.h>
#endif

/* executes run k on any rank: its record (malloc'ed text; NULL when memory runs out) */
typedef char *(*schedule_execute)(void *ctx, int k);
/* rank 0: keeps run k's record; nonzero on failure (the schedule goes on and reports it) */
typedef int (*schedule_record)(void *ctx, int k, const char *record);

#ifdef PLUME_MPI
/* 1 once MPI is initialised (the process was started by an MPI launcher) */
static int schedule_mpi_on;
#endif

/* 1 when an MPI launcher started this process: Open MPI's mpirun, MPICH's Hydra, a PMI or PMIx
 * launcher such as Slurm's srun each set one of these. */
static inline int schedule_launched(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") || getenv("PMI_RANK") || getenv("PMIX_RANK");
}

/* MPI is initialised only under a launcher: started alone, the app runs its runs in order as one
 * process. MPI_Init without a launcher would make Open MPI fork its singleton daemon (orted) and
 * handshake with it through PMIx: that costs time on every plain run, and on a loaded machine the
 * handshake was seen to hang for good (the daemon died, PMIx_Init waited on it), stalling the
 * test suite for 15-22 minutes. */
static inline void schedule_init(int *argc, char ***argv, int *rank, int *size)
{
    *rank = 0, *size = 1;
#ifdef PLUME_MPI
    if (!schedule_launched())
        return;
    int provided;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    schedule_mpi_on = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
#else
    (void)argc, (void)argv;
#endif
}

static inline void schedule_finalize(void)
{
#ifdef PLUME_MPI
    if (schedule_mpi_on)
        MPI_Finalize();
#endif
}

/* the largest status of every rank (a bad input found on any of them) to all of them */
static inline int schedule_share(int rc)
{
#ifdef PLUME_MPI
    if (schedule_mpi_on) {
        int all = rc;
        MPI_Allreduce(&rc, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        rc = all;
    }
#endif
    return rc;
}

#ifdef PLUME_MPI
enum { SCHEDULE_WORK = 1, SCHEDULE_RECORD = 2 };

/* ranks > 0: run what rank 0 sends until it sends -1; each record goes back as "k\n<record>" */
static inline void schedule_worker(schedule_execute ex, void *ctx)
{
    for (;;) {
        int k;
        MPI_Recv(&k, 1, MPI_INT, 0, SCHEDULE_WORK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (k < 0)
            return;
        char *rec = ex(ctx, k);
        size_t len = rec ? strlen(rec) : 0;
        char *msg = malloc(len + 32);
        int n = snprintf(msg, 32, "%d\n", k);
        if (rec)
            memcpy(msg + n, rec, len + 1);
        else
            msg[n] = '\0';
        MPI_Send(msg, (int)(n + len + 1), MPI_CHAR, 0, SCHEDULE_RECORD, MPI_COMM_WORLD);
        free(msg);
        free(rec);
    }
}

/* rank 0: one record from any worker; that worker gets its next run (or -1 when it has none left) */
static inline int schedule_receive(const int *todo, int ntodo, int *next, int *outstanding, schedule_record rec,
                                   void *ctx)
{
    MPI_Status st;
    MPI_Probe(MPI_ANY_SOURCE, SCHEDULE_RECORD, MPI_COMM_WORLD, &st);
    int len;
    MPI_Get_count(&st, MPI_CHAR, &len);
    char *text = malloc((size_t)len + 1);
    MPI_Recv(text, len, MPI_CHAR, st.MPI_SOURCE, SCHEDULE_RECORD, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    text[len] = '\0';
    int w = st.MPI_SOURCE;
    outstanding[w]--;
    if (*next < ntodo) {
        MPI_Send(&todo[(*next)++], 1, MPI_INT, w, SCHEDULE_WORK, MPI_COMM_WORLD);
        outstanding[w]++;
    } else if (outstanding[w] == 0) {
        int stop = -1;
        MPI_Send(&stop, 1, MPI_INT, w, SCHEDULE_WORK, MPI_COMM_WORLD);
    }
    char *body = strchr(text, '\n');
    int rc = !body || rec(ctx, atoi(text), body + 1);
    free(text);
    return rc;
}
#endif

#ifdef PLUME_MPI
/* rank 0's own run, computed in a second thread */
typedef struct {
    schedule_execute ex;
    void *ctx;
    int k, state; /* state: 0 idle, 1 running, 2 done */
    char *rec;
    pthread_t thread;
} schedule_local;

static void *schedule_local_main(void *arg)
{
    schedule_local *l = arg;
    l->rec = l->ex(l->ctx, l->k);
    __atomic_store_n(&l->state, 2, __ATOMIC_RELEASE);
    return NULL;
}
#endif

/* Executes the runs todo[0..ntodo) on every rank (call it on all of them); rank 0's `rec` gets
 * every record. Returns nonzero on rank 0 when a record could not be kept or a run gave none. */
static inline int schedule_run(int rank, int size, const int *todo, int ntodo, schedule_execute ex, schedule_record rec,
                               void *ctx)
{
    int rc = 0;
    if (size == 1) {
        for (int i = 0; i < ntodo; i++) {
            char *r = ex(ctx, todo[i]);
            rc |= !r || rec(ctx, todo[i], r);
            free(r);
        }
        return rc;
    }
#ifdef PLUME_MPI
    if (rank > 0) {
        schedule_worker(ex, ctx);
        return 0;
    }
    int next = 0, *outstanding = calloc((size_t)size, sizeof *outstanding);
    for (int w = 1; w < size; w++) {
        for (int q = 0; q < 2 && next < ntodo; q++, outstanding[w]++)
            MPI_Send(&todo[next++], 1, MPI_INT, w, SCHEDULE_WORK, MPI_COMM_WORLD);
        if (!outstanding[w]) {
            int stop = -1;
            MPI_Send(&stop, 1, MPI_INT, w, SCHEDULE_WORK, MPI_COMM_WORLD);
        }
    }
    schedule_local local = {ex, ctx, -1, 0, NULL, 0};
    for (;;) {
        int flag = 1, pending = 0, progress = 0;
        while (flag) { /* every record that has arrived */
            MPI_Iprobe(MPI_ANY_SOURCE, SCHEDULE_RECORD, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
            if (flag)
                rc |= schedule_receive(todo, ntodo, &next, outstanding, rec, ctx), progress = 1;
        }
        if (__atomic_load_n(&local.state, __ATOMIC_ACQUIRE) == 2) { /* rank 0's own run is done */
            pthread_join(local.thread, NULL);
            rc |= !local.rec || rec(ctx, local.k, local.rec);
            free(local.rec);
            local.rec = NULL, progress = 1;
            __atomic_store_n(&local.state, 0, __ATOMIC_RELEASE);
        }
        if (__atomic_load_n(&local.state, __ATOMIC_ACQUIRE) == 0 && next < ntodo) { /* rank 0 takes the next run itself */
            local.k = todo[next++], progress = 1;
            __atomic_store_n(&local.state, 1, __ATOMIC_RELEASE);
            if (pthread_create(&local.thread, NULL, schedule_local_main, &local) != 0) {
                local.rec = ex(ctx, local.k); /* no thread: in place */
                local.state = 2;
                rc |= !local.rec || rec(ctx, local.k, local.rec);
                free(local.rec);
                local.rec = NULL, local.state = 0;
            }
        }
        for (int w = 1; w < size; w++)
            pending += outstanding[w];
        if (next >= ntodo && __atomic_load_n(&local.state, __ATOMIC_ACQUIRE) == 0 && pending == 0)
            break;
        if (!progress) {
            struct timespec ms = {0, 1000000};
            nanosleep(&ms, NULL);
        }
    }
    free(outstanding);
#else
    (void)rank;
#endif
    return rc;
}

#endif
