/* The command-line harnesses: the input, split at NUL bytes, is an app's argv (after its name),
 * handed to the app's own flag parser (the app's source is included with its main renamed). */
#ifndef PLUME_FUZZ_CLI_H
#define PLUME_FUZZ_CLI_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* up to 31 arguments from data, NUL-separated; *argc and argv point into a copy (free *copy) */
static char **fuzz_argv(const uint8_t *data, size_t size, int *argc, char **copy)
{
    static char *argv[33];
    *copy = malloc(size + 1);
    memcpy(*copy, data, size);
    (*copy)[size] = '\0';
    int n = 0;
    argv[n++] = (char *)"app";
    for (size_t i = 0; i <= size && n < 32;) {
        argv[n++] = *copy + i;
        i += strlen(*copy + i) + 1;
    }
    argv[n] = NULL;
    *argc = n;
    return argv;
}

/* The whole harness for an app whose parse_args fills an options_type (the app's source included
 * before this, with its main renamed): one line per app file. */
#define FUZZ_CLI_HARNESS(options_type, init)                                                       \
    int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)                                   \
    {                                                                                               \
        int argc;                                                                                   \
        char *copy;                                                                                 \
        char **argv = fuzz_argv(data, size, &argc, &copy);                                          \
        options_type o;                                                                             \
        init;                                                                                       \
        parse_args(argc, argv, &o);                                                                 \
        free(copy);                                                                                 \
        return 0;                                                                                   \
    }

#endif
