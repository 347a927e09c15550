/* plume: running gnuplot on a script, shared by the chart (plot.c) and render (render.c) code:
 * no shell (posix_spawnp), stdin from /dev/null, stdout and stderr to a log whose last line
 * becomes the error message. */
#define _DEFAULT_SOURCE
#include "gnuplot.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

/* The last non-empty line of gnuplot's output (its error), for the message. */
void plume_gnuplot_log_tail(const char *path, char *out, size_t len)
{
    out[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        size_t n = strlen(line);
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r' || line[n - 1] == ' '))
            line[--n] = '\0';
        if (n > 0)
            snprintf(out, len, "%s", line);
    }
    fclose(f);
}

plume_status plume_gnuplot_run(const char *script, const char *log, const char *who, plume_err *err)
{
    posix_spawn_file_actions_t fa;
    if (posix_spawn_file_actions_init(&fa) != 0)
        return plume_err_set(err, PLUME_ENOMEM, "%s: cannot prepare to run gnuplot", who);
    plume_status st = PLUME_OK;
    if (posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0) != 0 ||
        posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0600) != 0 ||
        posix_spawn_file_actions_adddup2(&fa, 1, 2) != 0) {
        st = plume_err_set(err, PLUME_ENOMEM, "%s: cannot prepare to run gnuplot", who);
        goto cleanup;
    }
    char arg0[] = "gnuplot";
    char *argv[3] = {arg0, (char *)script, NULL};
    pid_t pid;
    int rc = posix_spawnp(&pid, "gnuplot", &fa, NULL, argv, environ);
    if (rc == ENOENT) {
        st = plume_err_set(err, PLUME_EDEP, "%s: gnuplot not found (install gnuplot-nox)", who);
        goto cleanup;
    }
    if (rc != 0) {
        st = plume_err_set(err, PLUME_EDEP, "%s: cannot run gnuplot: %s", who, strerror(rc));
        goto cleanup;
    }
    int status;
    pid_t w;
    do
        w = waitpid(pid, &status, 0);
    while (w < 0 && errno == EINTR);
    if (w < 0) {
        st = plume_err_set(err, PLUME_EDEP, "%s: cannot wait for gnuplot: %s", who, strerror(errno));
        goto cleanup;
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127) {
        /* A libc whose posix_spawnp reports exec failure only through the child's status. */
        st = plume_err_set(err, PLUME_EDEP, "%s: gnuplot not found (install gnuplot-nox)", who);
        goto cleanup;
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        char tail[400];
        plume_gnuplot_log_tail(log, tail, sizeof tail);
        if (WIFEXITED(status))
            st = plume_err_set(err, PLUME_EDEP, "%s: gnuplot failed (exit status %d): %s",
                               who, WEXITSTATUS(status), tail[0] ? tail : "no message");
        else
            st = plume_err_set(err, PLUME_EDEP, "%s: gnuplot killed by signal %d", who,
                               WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    }
cleanup:
    posix_spawn_file_actions_destroy(&fa);
    return st;
}


/* Whether gnuplot's output src is whole: gnuplot exits 0 even when its terminal could not write
 * (a full disk), so a PNG must end with its IEND chunk and an SVG with </svg>. */
static int output_complete(const char *src, const char *dst)
{
    FILE *f = fopen(src, "rb");
    if (!f)
        return 0;
    unsigned char tail[64];
    size_t n = 0;
    if (fseek(f, 0, SEEK_END) == 0) {
        long size = ftell(f);
        long from = size > (long)sizeof tail ? size - (long)sizeof tail : 0;
        if (size > 0 && fseek(f, from, SEEK_SET) == 0)
            n = fread(tail, 1, sizeof tail, f);
    }
    fclose(f);
    size_t len = strlen(dst);
    if (len > 4 && strcmp(dst + len - 4, ".png") == 0) {
        static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
        return n >= 12 && memcmp(tail + n - 12, iend, 12) == 0;
    }
    if (len > 4 && strcmp(dst + len - 4, ".svg") == 0) {
        while (n > 0 && (tail[n - 1] == '\n' || tail[n - 1] == ' ' || tail[n - 1] == '\r'))
            n--;
        return n >= 6 && memcmp(tail + n - 6, "</svg>", 6) == 0;
    }
    return n > 0;
}

plume_status plume_gnuplot_install(const char *src, const char *dst, const char *who, plume_err *err)
{
    plume_status st = PLUME_OK;
    char tmp[4096 + 32];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", dst, (long)getpid());
    if (!output_complete(src, dst))
        return plume_err_set(err, PLUME_EIO, "%s '%s': gnuplot's output is missing or cut short (a full disk?); the "
                                             "previous file is kept", who, dst);
    FILE *in = fopen(src, "rb");
    if (!in)
        return plume_err_set(err, PLUME_EDEP, "%s '%s': gnuplot wrote no output", who, dst);
    FILE *out = fopen(tmp, "wb");
    if (!out) {
        st = plume_err_set(err, PLUME_EIO, "%s '%s': cannot create '%s': %s", who, dst, tmp, strerror(errno));
        fclose(in);
        return st;
    }
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        if (fwrite(buf, 1, n, out) != n)
            break;
    int bad = ferror(in) || ferror(out);
    fclose(in);
    if (fclose(out) != 0 || bad)
        st = plume_err_set(err, PLUME_EIO, "%s '%s': cannot write '%s': %s", who, dst, tmp, strerror(errno));
    else if (rename(tmp, dst) != 0)
        st = plume_err_set(err, PLUME_EIO, "%s '%s': cannot rename '%s' over it: %s", who, dst, tmp, strerror(errno));
    if (st != PLUME_OK)
        unlink(tmp);
    return st;
}

void plume_gnuplot_put_quoted(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '\'')
            fputs("''", f);
        else if (c < 0x20 || c == 0x7f)
            fputc(' ', f);
        else
            fputc(c, f);
    }
    fputc('\'', f);
}
