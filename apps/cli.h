/* Small helpers shared by the apps' flag parsers (header-only: apps are single files). */
#ifndef PLUME_APPS_CLI_H
#define PLUME_APPS_CLI_H

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "../include/plume/scene.h"

/* What an app's parse_args returns after printing --help (main then exits 0): a flag parser
 * never exits by itself, so it can be fuzzed (tests/fuzz/fuzz_cli_*.c). */
#define CLI_HELP (-1)

/* Prints j on stdout (json_dumps with flags, then a newline) and releases it: an app's --json. */
static inline void cli_print_json(json_t *j, size_t flags)
{
    char *text = j ? json_dumps(j, flags) : NULL;
    if (text)
        puts(text);
    free(text);
    json_decref(j);
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

/* Whether a new file can be created in the existing directory dir: a probe file made and removed
 * (access() is not enough: it says yes to root on a read-only file system). 0, or -1 with errno. */
static inline int cli_dir_writable(const char *dir)
{
    char probe[4200];
    snprintf(probe, sizeof probe, "%s/.plume-probe.%ld", dir, (long)getpid());
    int fd = open(probe, O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0)
        return -1;
    close(fd);
    unlink(probe);
    return 0;
}

/* Outputs are prepared before anything is solved, so that a run never ends by failing to write
 * its result. The output directory dir of `flag`, created with its parents, and writable: 0, or
 * the exit code of bad input after a message naming the flag and the path. */
static inline int cli_output_dir(const char *app, const char *flag, const char *dir)
{
    if (plume_make_dirs(dir) != 0)
        return cli_fail(app, "%s %s: cannot create the directory: %s", flag, dir, strerror(errno));
    if (cli_dir_writable(dir) != 0)
        return cli_fail(app, "%s %s: cannot write in the directory: %s", flag, dir, strerror(errno));
    return 0;
}

/* The same for the output file `path` of `flag`: its folder created with its parents and
 * writable (files are written beside their final name, then renamed), path not a directory. */
static inline int cli_output_file(const char *app, const char *flag, const char *path)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!*path)
        return cli_fail(app, "%s expects a file name", flag);
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else if (snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path) >= (int)sizeof dir)
        return cli_fail(app, "%s %s: the path is too long", flag, path);
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return cli_fail(app, "%s %s: a directory, not a file", flag, path);
    if (plume_make_dirs(dir) != 0)
        return cli_fail(app, "%s %s: cannot create the directory '%s': %s", flag, path, dir, strerror(errno));
    if (cli_dir_writable(dir) != 0)
        return cli_fail(app, "%s %s: cannot write in the directory '%s': %s", flag, path, dir, strerror(errno));
    return 0;
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

/* The scene's description (plume_scene_describe), parsed (the caller json_decref's it); NULL with
 * a message on stderr. */
static inline json_t *cli_describe(const char *app, const plume_scene *scene)
{
    plume_err err = {{0}};
    char *text = NULL;
    json_t *j = NULL;
    if (plume_scene_describe(scene, &text, &err) != PLUME_OK)
        fprintf(stderr, "%s: %s\n", app, err.msg);
    else if (!(j = json_loads(text, 0, NULL)))
        fprintf(stderr, "%s: the scene's description is not JSON\n", app);
    plume_free(text);
    return j;
}

#endif
