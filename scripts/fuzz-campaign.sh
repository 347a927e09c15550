#!/usr/bin/env bash
# A fuzzing campaign (docs/robustness.md): every harness of tests/fuzz/ (or those named) for RUNS
# executions or SECONDS_MAX seconds, whichever ends first, JOBS harnesses at a time, on a scratch copy of
# its corpus. Prints one line per harness: executions, executions per second, new corpus inputs,
# and the crash/timeout/leak artifacts it left in build-fuzz/campaign/ (none means none found).
# RESUME=1 continues a harness stopped by a finding (once it is fixed) from the corpus it had grown;
# its earlier log and artifacts move to build-fuzz/campaign/<harness>/run-<n>/.
# TIMEOUT (seconds, default 20) is wall time: a process paused (SIGSTOP) that long times out, so a
# machine where others pause it needs more; the slowest input over 10 s is still kept (slow-unit-*).
#   scripts/fuzz-campaign.sh [harness ...]      RUNS=1000000 SECONDS_MAX=3600 JOBS=2 RESUME=0 TIMEOUT=20
set -uo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-1000000} SECS=${SECONDS_MAX:-3600} JOBS=${JOBS:-2} RESUME=${RESUME:-0} TIMEOUT=${TIMEOUT:-20}
make -s fuzz-build >/dev/null || exit 1
out=build-fuzz/campaign
mkdir -p "$out"
harnesses=("$@")
[ ${#harnesses[@]} -eq 0 ] && harnesses=($(ls tests/fuzz/fuzz_*.c | sed 's|tests/fuzz/fuzz_||; s|\.c$||'))
run_one() {
    local h=$1 dir="$out/$1"
    if [ "$RESUME" = 1 ] && [ -f "$dir/log.txt" ]; then
        local k=1
        while [ -e "$dir/run-$k" ]; do k=$((k + 1)); done
        mkdir "$dir/run-$k" && mv "$dir/log.txt" "$dir/run-$k/" &&
            find "$dir" -maxdepth 1 -type f -regex ".*/\(crash\|timeout\|leak\|oom\|slow-unit\)-.*" -exec mv {} "$dir/run-$k/" \;
    else
        rm -rf "$dir"
    fi
    mkdir -p "$dir/corpus"
    (cd tests && PLUME_SRC=.. "../build-fuzz/fuzz_$h" -runs="$RUNS" -max_total_time="$SECS" -timeout="$TIMEOUT" \
        -rss_limit_mb=2560 -print_final_stats=1 -artifact_prefix="../$dir/" "../$dir/corpus" "fuzz/corpus/$h" \
        >"../$dir/log.txt" 2>&1)
    local rc=$?
    local n rate found arts
    n=$(grep -o "stat::number_of_executed_units: [0-9]*" "$dir/log.txt" | awk '{print $2}')
    rate=$(grep -o "stat::average_exec_per_sec: *[0-9]*" "$dir/log.txt" | awk '{print $2}')
    found=$(ls "$dir/corpus" | wc -l)
    arts=$(ls "$dir" | grep -E "^(crash|timeout|leak|oom|slow-unit)-" | tr '\n' ' ')
    printf "%-22s exit %d  executions %10s  per second %7s  corpus +%s  artifacts: %s\n" "$h" "$rc" "${n:-?}" \
        "${rate:-?}" "$found" "${arts:-none}"
}
export -f run_one
export RUNS SECS RESUME TIMEOUT out
printf "%s\n" "${harnesses[@]}" | xargs -P "$JOBS" -I{} bash -c 'run_one {}'
