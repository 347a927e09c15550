/* Small helpers shared by the apps' flag parsers (header-only: apps are single files). */
#ifndef PLUME_APPS_CLI_H
#define PLUME_APPS_CLI_H

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* What an app's parse_args returns after printing --help (main then exits 0): a flag parser
 * never exits by itself, so it can be fuzzed (tests/fuzz/fuzz_cli_*.c). */
#define CLI_HELP (-1)

/* mkdir -p: 0, or -1 with errno set (ENOTDIR when the path names something else) */
static inline int cli_make_dirs(const char *path)
{
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return errno = ENAMETOOLONG, -1;
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return -1;
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return -1;
    struct stat st;
    if (stat(buf, &st) != 0 || !S_ISDIR(st.st_mode))
        return errno = ENOTDIR, -1;
    return 0;
}

/* Prints "<app>: <message>" on stderr and returns 2 (the apps' exit code for bad input). */
static inline int cli_fail(const char *app, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s: ", app);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    return 2;
}

/* A finite number for `flag`, or an error naming it. */
static inline int cli_double(const char *app, const char *flag, const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = s ? strtod(s, &end) : 0.0;
    if (!s || end == s || *end || errno || !isfinite(v))
        return cli_fail(app, "%s expects a finite number (got '%s')", flag, s ? s : "");
    *out = v;
    return 0;
}

/* An integer in [1, 1e6] for `flag`. */
static inline int cli_int(const char *app, const char *flag, const char *s, int *out)
{
    char *end;
    errno = 0;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || end == s || *end || errno || v < 1 || v > 1000000)
        return cli_fail(app, "%s expects a positive integer (got '%s')", flag, s ? s : "");
    *out = (int)v;
    return 0;
}

#endif
