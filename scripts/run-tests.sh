#!/usr/bin/env bash
# `make test`: the C suite (tests/run_tests), then the Python package's suite (tests/python/run.py,
# against the library just built), then the commands README.md and docs/ mark runnable
# (scripts/doc-commands.py), then the benchmark tables of docs/benchmarks.md against the bench
# programs (scripts/bench-tables.py check). Each prints "N passed, N failed"; the last line here adds
# them up, and the exit status is non-zero when anything failed. TESTS=substring runs the C tests
# whose names contain it, the Python suite only when it contains "python", the documented commands
# only when it contains "docs", the benchmark tables when it contains "docs" or "bench".
set -uo pipefail
build=${1:-build}
filter=${TESTS:-}
cd "$(dirname "$0")/../tests"
# the build directory as seen from tests/: BUILD may be relative to the top (build) or absolute
case $build in
    /*) ;;
    *) build=../$build ;;
esac
summary='^[0-9]+ passed, [0-9]+ failed$'
log=$(mktemp)
trap 'rm -f "$log"' EXIT

passed=0 failed=0
count() { # adds the last summary line of the log; a suite that printed none counts as one failure
    local line
    line=$(grep -E "$summary" "$log" | tail -n 1)
    if [ -z "$line" ]; then
        echo "run-tests: $1 printed no summary line" >&2
        failed=$((failed + 1))
        return
    fi
    passed=$((passed + ${line%% passed*}))
    local f=${line#*, }
    failed=$((failed + ${f%% failed*}))
}

"$build/run_tests" $filter 2>&1 | tee "$log"
count "the C suite"

if [ -z "$filter" ] || [[ "$filter" == *python* ]]; then
    # the distribution's interpreter first: that is where python3-numpy is installed
    py=""
    for cand in /usr/bin/python3 python3; do
        if command -v "$cand" >/dev/null 2>&1 && "$cand" -c "import numpy" >/dev/null 2>&1; then
            py=$cand
            break
        fi
    done
    if [ -z "$py" ]; then
        echo "run-tests: no python3 with numpy (make deps installs python3-numpy): the Python suite did not run" >&2
        failed=$((failed + 1))
    else
        # the file the build's libplume.so names (an older version's file may still lie beside it)
        lib=$(readlink -f "$build/libplume.so" 2>/dev/null)
        PLUME_LIBRARY="${lib:-$build/libplume.so}" PYTHONPATH=../python MPLBACKEND=Agg \
            "$py" python/run.py 2>&1 | tee "$log"
        count "the Python suite"
    fi
fi
# the commands README.md and docs/ mark runnable (scripts/doc-commands.py), run with this build
if [ -z "$filter" ] || [[ "$filter" == *docs* ]]; then
    case $build in
        /*) abs_build=$build ;;
        *) abs_build=$(cd "$build" && pwd) ;;
    esac
    BUILD="$abs_build" python3 ../scripts/doc-commands.py 2>&1 | tee "$log"
    count "the documented commands"
fi
# the benchmark tables of docs/benchmarks.md against the bench programs' headers
# (scripts/bench-tables.py check: runs `bench_NAME --header`, not the benchmarks)
if [ -z "$filter" ] || [[ "$filter" == *docs* ]] || [[ "$filter" == *bench* ]]; then
    python3 ../scripts/bench-tables.py check "$build" 2>&1 | tee "$log"
    count "the benchmark tables"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
