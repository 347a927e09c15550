/* libFuzzer: apps/traction's flag parser (parse_args). */
#include "fuzz_cli.h"
#define main app_main
#include "../../apps/traction.c"
#undef main

FUZZ_CLI_HARNESS(options, (void)0)
