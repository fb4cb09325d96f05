#!/usr/bin/env bash
# Runs every libFuzzer harness built in BUILD_DIR/fuzz for SECONDS each, starting from its seed corpus
# fuzz/corpus/<harness>/ (copied: what a run finds stays in BUILD_DIR/fuzz-corpus, not in the repository),
# JOBS harnesses at a time (default: the number of cores), and prints one line per harness: executions,
# executions per second, corpus size, and whether it found anything.
# Usage: fuzz/run.sh BUILD_DIR SECONDS [JOBS] [SEED]. SEED (default 1) makes a run repeatable: the same
# binaries, corpus and seed try the same inputs in the same order, so what CI finds a local run finds too
# (up to the number of executions the time allows); SEED 0 lets libFuzzer pick one, to explore further.
# Exit status 1 when any harness found a crash, leak or hang (or
# did not run); the input that did it is kept in BUILD_DIR/fuzz-findings/<harness>/.
set -euo pipefail
build=${1:?build directory}
seconds=${2:?seconds per harness}
jobs=${3:-$(nproc)}
seed=${4:-1}
here=$(cd "$(dirname "$0")" && pwd)

run_one() {  # NAME: fuzzes one harness; its exit status goes to BUILD/fuzz-findings/NAME.status
  local name=$1 binary="$build/fuzz/$1" corpus="$build/fuzz-corpus/$1" findings="$build/fuzz-findings/$1"
  mkdir -p "$corpus" "$findings"
  rm -f "$findings"/*  # what an earlier run found is in its own report, not this one's
  [ -d "$here/corpus/$name" ] && cp -n "$here/corpus/$name"/* "$corpus"/ 2>/dev/null || true
  local status=0
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$binary" "$corpus" -max_total_time="$seconds" -seed="$seed" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -print_final_stats=1 -artifact_prefix="$findings/" >"$build/fuzz-findings/$name.log" 2>&1 || status=$?
  echo "$status" >"$build/fuzz-findings/$name.status"
}

names=()
for source in "$here"/*_fuzz.cpp; do
  name=$(basename "$source" .cpp)
  if [ ! -x "$build/fuzz/$name" ]; then
    # A harness of an optional part (MuJoCo: mujoco_*, fuzz/CMakeLists.txt) is not built where that part is
    # off: said, not fatal.
    if [[ $name == mujoco_* ]]; then
      echo "fuzz: $name skipped (its optional part is not built)" >&2
      continue
    fi
    echo "fuzz: $build/fuzz/$name was not built" >&2
    exit 1
  fi
  names+=("$name")
done
mkdir -p "$build/fuzz-findings"
rm -f "$build"/fuzz-findings/*.status
running=0
for name in "${names[@]}"; do
  run_one "$name" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait || true

status=0
printf '%-22s %12s %10s %8s  %s\n' harness executions exec/s corpus result
for name in "${names[@]}"; do
  log="$build/fuzz-findings/$name.log"
  code=$(cat "$build/fuzz-findings/$name.status" 2>/dev/null || echo missing)
  result=ok
  if [ "$code" != 0 ]; then
    result="FOUND (exit $code; see $log and $build/fuzz-findings/$name/)"
    status=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  printf '%-22s %12s %10s %8s  %s\n' "$name" "${runs:-?}" "${rate:-?}" "$(ls "$build/fuzz-corpus/$name" | wc -l)" \
    "$result"
done
# What each finding was, here and not only in its log: where CI keeps nothing but what was printed, the cause,
# the frames that matter and the input itself (base64) are enough to reproduce it.
for name in "${names[@]}"; do
  code=$(cat "$build/fuzz-findings/$name.status" 2>/dev/null || echo missing)
  [ "$code" = 0 ] && continue
  log="$build/fuzz-findings/$name.log"
  echo
  echo "== $name (exit $code)"
  grep -E "ERROR:|SUMMARY:|runtime error|error contract broken|Assertion|terminate called|what\(\)" "$log" | head -8
  grep -E "^ +#[0-9]+ " "$log" | grep -v -E "libFuzzer|fuzzer::|libc\.so|compiler-rt|sanitizer_common" | head -12
  for input in "$build/fuzz-findings/$name"/*; do
    [ -f "$input" ] || continue
    echo "input $(basename "$input") ($(wc -c <"$input") bytes, base64 of the first 3000):"
    head -c 3000 "$input" | base64 -w 120
  done
done
exit $status
