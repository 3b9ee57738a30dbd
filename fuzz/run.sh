#!/usr/bin/env bash
# Run one fuzz target in the background-friendly way: `fuzz/run.sh TARGET SECONDS [EXTRA SEEDS...]`
# (FUZZ_TOOLCHAIN=nightly uses `cargo +nightly`; FUZZ_NICE sets the niceness, default 19).
# The working corpus and the crashes go to ${FUZZ_WORK:-/tmp/robodyn-fuzz}/TARGET (outside the
# repository); the seeds are read in place: robots/ (robot-file targets), fuzz/seeds/TARGET and any
# directories given.
set -euo pipefail
cd "$(dirname "$0")/.."
target=$1; secs=$2; shift 2
work=${FUZZ_WORK:-/tmp/robodyn-fuzz}/$target
mkdir -p "$work/corpus" "$work/artifacts"
seeds=()
case $target in toml|par|urdf) seeds+=(robots) ;; esac
[ -d "fuzz/seeds/$target" ] && seeds+=("fuzz/seeds/$target")
dict=()
[ -f "fuzz/dicts/$target.dict" ] && dict=(-dict="fuzz/dicts/$target.dict")
exec nice -n "${FUZZ_NICE:-19}" cargo ${FUZZ_TOOLCHAIN:+"+$FUZZ_TOOLCHAIN"} fuzz run -s none "$target" "$work/corpus" "${seeds[@]}" "$@" -- \
  -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
  -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
  -artifact_prefix="$work/artifacts/" "${dict[@]}"
