/* plume: a one-line progress indicator on stderr for long runs. */
#include "progress.h"

#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* The line is padded to this many columns so a shorter update erases a longer previous one. The
 * struct keeps no previous length (its layout is the public contract), and an ANSI erase code
 * would litter logs when output is forced into a file. */
enum { PROGRESS_WIDTH = 79 };

double plume_wall_seconds(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double plume_cpu_seconds(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void plume_progress_start(plume_progress *p, const char *label, int total, int force)
{
    if (!p)
        return;
    p->label = label ? label : "";
    p->total = total;
    p->enabled = force || isatty(fileno(stderr));
    p->t_start = plume_wall_seconds();
}

void plume_progress_update(plume_progress *p, int k, const char *info)
{
    if (!p || !p->enabled)
        return;
    char line[512];
    double elapsed = plume_wall_seconds() - p->t_start;
    int len;
    if (p->total > 0)
        len = snprintf(line, sizeof line, "\r%s step %d/%d", p->label, k, p->total);
    else
        len = snprintf(line, sizeof line, "\r%s step %d", p->label, k);
    if (info && *info && len >= 0 && (size_t)len < sizeof line)
        len += snprintf(line + len, sizeof line - (size_t)len, " %s", info);
    if (len >= 0 && (size_t)len < sizeof line)
        len += snprintf(line + len, sizeof line - (size_t)len, "  elapsed %.1f s", elapsed);
    if (len >= 0 && (size_t)len < sizeof line) {
        /* Linear extrapolation from the steps done so far; unknown before the first one. */
        if (p->total > 0 && k > 0 && k <= p->total)
            len += snprintf(line + len, sizeof line - (size_t)len, "  eta %.1f s",
                            elapsed * (double)(p->total - k) / (double)k);
        else if (p->total > 0)
            len += snprintf(line + len, sizeof line - (size_t)len, "  eta ? s");
    }
    if (len < 0)
        return;
    if ((size_t)len >= sizeof line)
        len = (int)sizeof line - 1;
    /* Pad (the leading '\r' takes no column) so leftovers of a longer previous line vanish. */
    while (len - 1 < PROGRESS_WIDTH && (size_t)len + 1 < sizeof line)
        line[len++] = ' ';
    line[len] = '\0';
    fputs(line, stderr);
    fflush(stderr);
}

void plume_progress_finish(plume_progress *p)
{
    if (!p || !p->enabled)
        return;
    fputc('\n', stderr);
    fflush(stderr);
    p->enabled = 0; /* a second finish prints nothing */
}
