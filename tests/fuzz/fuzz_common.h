/* Shared by the libFuzzer harnesses (tests/fuzz/README.md): a private scratch directory per
 * process, made once, into which each input is written as the file a user would hand in. */
#ifndef PLUME_FUZZ_COMMON_H
#define PLUME_FUZZ_COMMON_H

#define _DEFAULT_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char fuzz_dir[64];

/* the scratch directory (made on first use; removed at exit) */
static void fuzz_cleanup(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", fuzz_dir);
    if (fuzz_dir[0] && system(cmd) != 0)
        fprintf(stderr, "fuzz: could not remove %s\n", fuzz_dir);
}

static const char *fuzz_scratch(void)
{
    if (!fuzz_dir[0]) {
        /* in memory when the machine offers it: every input is written to a file */
        strcpy(fuzz_dir, access("/dev/shm", W_OK) == 0 ? "/dev/shm/plume-fuzz-XXXXXX" : "/tmp/plume-fuzz-XXXXXX");
        if (!mkdtemp(fuzz_dir))
            abort();
        atexit(fuzz_cleanup);
    }
    return fuzz_dir;
}

/* writes data to <scratch>/name and returns its path (static buffer) */
static const char *fuzz_write(const char *name, const uint8_t *data, size_t size)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", fuzz_scratch(), name);
    FILE *f = fopen(path, "wb");
    if (!f)
        abort();
    if (size && fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
    return path;
}

/* writes a text to <scratch>/name */
static void fuzz_write_text(const char *name, const char *text)
{
    fuzz_write(name, (const uint8_t *)text, strlen(text));
}

/* copies a file of the source tree (relative to the harness's working directory, tests/, or to
 * PLUME_SRC) into the scratch directory */
static void fuzz_copy(const char *src, const char *name)
{
    char path[512];
    const char *root = getenv("PLUME_SRC");
    snprintf(path, sizeof path, "%s/%s", root ? root : "..", src);
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "fuzz: cannot read %s (run from tests/ or set PLUME_SRC)\n", path);
        abort();
    }
    char *buf = malloc(1 << 22);
    size_t n = fread(buf, 1, 1 << 22, f);
    fclose(f);
    fuzz_write(name, (const uint8_t *)buf, n);
    free(buf);
}

#endif
