#!/bin/sh
# Runs fuzz targets one after another, each for SECONDS, with the limits
# docs/robustness.md gives, and prints a summary line per target
# (executions, coverage, corpus size, findings).
# Usage: fuzz/run.sh SECONDS target...   (build first: cargo +nightly fuzz build)
# The hdf5 target reads through hdf5-pure (pure Rust) like the others.
# EXTRA adds libFuzzer flags, e.g. EXTRA=-detect_leaks=0.
set -u
here=$(cd "$(dirname "$0")" && pwd)
cd "$here"
secs=$1
shift
bin=target/x86_64-unknown-linux-gnu/release
mkdir -p logs
for t in "$@"; do
    [ -d "corpus/$t" ] || ./seed.sh "$t"
    mkdir -p "artifacts/$t"
    "$bin/$t" "corpus/$t" -artifact_prefix="artifacts/$t/" -max_total_time="$secs" \
        -rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=10 -print_final_stats=1 ${EXTRA:-} \
        >"logs/$t.log" 2>&1
    rc=$?
    rm -rf /dev/shm/volray-fuzz-"$t"-*
    execs=$(grep -o 'number_of_executed_units: [0-9]*' "logs/$t.log" | tail -1 | cut -d' ' -f2)
    last=$(grep -E '^#[0-9]+' "logs/$t.log" | tail -1)
    cov=$(echo "$last" | grep -o 'cov: [0-9]*' | cut -d' ' -f2)
    corp=$(echo "$last" | grep -o 'corp: [0-9]*/[0-9A-Za-z]*' | cut -d' ' -f2)
    echo "$t rc=$rc secs=$secs execs=${execs:-?} cov=${cov:-?} corpus=${corp:-?} artifacts=$(ls "artifacts/$t" | wc -l)"
done
