/* A preload for test_robustness_kill_every_write: SIGKILLs the process at its KILL_AT-th file
 * write (write to a descriptor above 2, pwrite, pwrite64), or with KILL_AT unset or 0 counts the
 * writes into the file KILL_COUNT at exit. Built by the test with cc -shared. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/types.h>
#include <unistd.h>

static long writes, kill_at = -1;

static void tick(void)
{
    if (kill_at < 0) {
        const char *e = getenv("KILL_AT");
        kill_at = e ? atol(e) : 0;
    }
    if (++writes == kill_at)
        raise(SIGKILL);
}

__attribute__((destructor)) static void report(void)
{
    const char *path = getenv("KILL_COUNT");
    FILE *f = path && kill_at <= 0 ? fopen(path, "w") : NULL;
    if (f) {
        fprintf(f, "%ld\n", writes);
        fclose(f);
    }
}

ssize_t pwrite64(int fd, const void *b, size_t n, off_t at)
{
    static ssize_t (*real)(int, const void *, size_t, off_t);
    if (!real)
        real = (ssize_t(*)(int, const void *, size_t, off_t))dlsym(RTLD_NEXT, "pwrite64");
    tick();
    return real(fd, b, n, at);
}

ssize_t pwrite(int fd, const void *b, size_t n, off_t at)
{
    static ssize_t (*real)(int, const void *, size_t, off_t);
    if (!real)
        real = (ssize_t(*)(int, const void *, size_t, off_t))dlsym(RTLD_NEXT, "pwrite");
    tick();
    return real(fd, b, n, at);
}

ssize_t write(int fd, const void *b, size_t n)
{
    static ssize_t (*real)(int, const void *, size_t);
    if (!real)
        real = (ssize_t(*)(int, const void *, size_t))dlsym(RTLD_NEXT, "write");
    if (fd > 2)
        tick();
    return real(fd, b, n);
}
