#!/usr/bin/env bash
# Runs every libFuzzer harness built in BUILD_DIR/fuzz for SECONDS each, starting from its seed corpus
# fuzz/corpus/<harness>/ (copied: what a run finds stays in BUILD_DIR/fuzz-corpus, not in the repository),
# and prints one line per harness: executions, corpus size, and whether it found anything.
# Usage: fuzz/run.sh BUILD_DIR SECONDS. Exit status 1 when any harness found a crash, leak or hang; the
# input that did it is kept in BUILD_DIR/fuzz-findings/<harness>/.
set -euo pipefail
build=${1:?build directory}
seconds=${2:?seconds per harness}
here=$(cd "$(dirname "$0")" && pwd)
status=0
printf '%-22s %12s %10s %8s  %s\n' harness executions exec/s corpus result
for source in "$here"/*_fuzz.cpp; do
  name=$(basename "$source" .cpp)
  binary="$build/fuzz/$name"
  [ -x "$binary" ] || { echo "fuzz: $binary was not built" >&2; exit 1; }
  corpus="$build/fuzz-corpus/$name"
  findings="$build/fuzz-findings/$name"
  mkdir -p "$corpus" "$findings"
  [ -d "$here/corpus/$name" ] && cp -n "$here/corpus/$name"/* "$corpus"/ 2>/dev/null || true
  log="$build/fuzz-findings/$name.log"
  result=ok
  if ! ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "$binary" "$corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
      -print_final_stats=1 -artifact_prefix="$findings/" >"$log" 2>&1; then
    result="FOUND (see $log and $findings)"
    status=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  printf '%-22s %12s %10s %8s  %s\n' "$name" "${runs:-?}" "${rate:-?}" "$(ls "$corpus" | wc -l)" "$result"
done
exit $status
