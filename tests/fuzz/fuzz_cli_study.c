/* libFuzzer: apps/study's flag parser (parse_args). */
#include "fuzz_cli.h"
#define main app_main
#include "../../apps/study.c"
#undef main

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int argc;
    char *copy;
    char **argv = fuzz_argv(data, size, &argc, &copy);
    study s;
    memset(&s, 0, sizeof s);
    parse_args(argc, argv, &s);
    free(copy);
    return 0;
}
