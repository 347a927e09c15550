/* Running an app as a user does, for the app tests: ../apps/NAME ARGS with stdout and stderr
 * captured through files in a scratch directory. */
#ifndef PLUME_TEST_APP_RUNNER_H
#define PLUME_TEST_APP_RUNNER_H

#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

static inline void app_slurp(const char *path, char *buf, size_t n)
{
    FILE *f = fopen(path, "r");
    buf[0] = 0;
    if (!f)
        return;
    size_t got = fread(buf, 1, n - 1, f);
    buf[got] = 0;
    fclose(f);
}

/* Returns the exit code (-1 if the app did not exit normally). */
static inline int app_run(const char *scratch, const char *app, const char *args, char *out, size_t nout, char *err,
                          size_t nerr)
{
    char cmd[4096], path[256];
    snprintf(cmd, sizeof cmd, "../apps/%s %s >%s/out.txt 2>%s/err.txt", app, args, scratch, scratch);
    int rc = system(cmd);
    snprintf(path, sizeof path, "%s/out.txt", scratch);
    app_slurp(path, out, nout);
    snprintf(path, sizeof path, "%s/err.txt", scratch);
    app_slurp(path, err, nerr);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

#endif
