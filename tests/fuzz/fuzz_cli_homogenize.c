/* libFuzzer: apps/homogenize's flag parser (parse_args). */
#include "fuzz_cli.h"
#define main app_main
#include "../../apps/homogenize.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int argc;
    char *copy;
    char **argv = fuzz_argv(data, size, &argc, &copy);
    options o;
    parse_args(argc, argv, &o);
    free(copy);
    return 0;
}
