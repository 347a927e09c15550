/* libFuzzer: apps/homogenize's flag parser (parse_args). */
#include "fuzz_cli.h"
#define main app_main
#include "../../apps/homogenize.c"
#undef main

FUZZ_CLI_HARNESS(options, (void)0)
