#!/usr/bin/env bash
# Runs the libFuzzer targets for a bounded time each (default 60 s), under
# AddressSanitizer and UndefinedBehaviorSanitizer, from the committed seed
# corpus (copied: libFuzzer adds what it finds to its first corpus folder).
# Usage: scripts/fuzz.sh [SECONDS] [BUILD_DIR] [CMAKE_ARGS...] (the extra
# arguments go to the configure step, e.g. -DSYNCPLC_UNITY=ON). A crash, leak,
# sanitizer report or failed check stops with a non-zero status and leaves the
# input in BUILD_DIR/fuzz-artifacts/ (rerun it: BUILD_DIR/fuzz/<target> <file>).
# SECONDS 0 only builds the targets. CMAKE_ARGS --prebuilt: BUILD_DIR holds
# the targets already (scripts/test.sh builds them in its ASan tree, with
# the tests), only run them.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
dir=${2:-build-fuzz}
shift $(( $# < 2 ? $# : 2 ))
if [ "${1:-}" != --prebuilt ]; then
  SYNCPLC_TARGETS="fuzz_modbus_request fuzz_modbus_reply fuzz_http_request fuzz_st_parse fuzz_st_engines" bash scripts/build.sh "$dir" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DSYNCPLC_FUZZ=ON -DSYNCPLC_SANITIZE=address,undefined -DSYNCPLC_TESTS=OFF -DSYNCPLC_BENCH=OFF "$@"
fi
[ "$seconds" = 0 ] && exit 0
mkdir -p "$dir/fuzz-artifacts"
# The Modbus server's request path, the client driver's reply path, the
# HTTP server's request path, the Structured Text front end (parser and
# type checker) and compiled ST's two engines side by side: a fuzzer is one
# process, five share two cores in the same wall time as one target alone.
fuzz() {
  local target=$1 corpus status=0 dict=()
  corpus=$(mktemp -d)
  cp "fuzz/corpus/$target"/* "$corpus/"
  if [ -f "fuzz/$target.dict" ]; then dict=(-dict="fuzz/$target.dict"); fi
  if [ "$target" = st_engines ]; then dict=(-dict=fuzz/st_parse.dict); fi  # the same language
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$dir/fuzz/fuzz_$target" "${dict[@]}" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$dir/fuzz-artifacts/fuzz_$target-" -print_final_stats=1 "$corpus" \
    >"$dir/fuzz-artifacts/fuzz_$target.log" 2>&1 || status=$?
  rm -rf "$corpus"
  return "$status"
}
targets=(modbus_request modbus_reply http_request st_parse st_engines)
pids=()
for target in "${targets[@]}"; do
  fuzz "$target" &
  pids+=($!)
done
failed=0
for i in "${!targets[@]}"; do
  target=${targets[$i]}
  log="$dir/fuzz-artifacts/fuzz_$target.log"
  status=0
  wait "${pids[$i]}" || status=$?
  if [ "$status" -ne 0 ]; then
    cat "$log"
    echo "fuzz_$target failed (status $status); the input is in $dir/fuzz-artifacts/"
    failed=$status
    continue
  fi
  grep -E '^(INFO: Seed|#[0-9]+[[:space:]]+DONE|stat::)' "$log"
  echo "fuzz_$target: no failure in $seconds s"
done
exit "$failed"
