/* libFuzzer: apps/study's flag parser (parse_args). */
#include "fuzz_cli.h"
#define main app_main
#include "../../apps/study.c"
#undef main

FUZZ_CLI_HARNESS(study, memset(&o, 0, sizeof o))
