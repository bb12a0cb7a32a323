#!/usr/bin/env bash
# Installs what is needed, builds, and runs every test three times:
#   1. the release build (RelWithDebInfo), all tests;
#   2. AddressSanitizer + UndefinedBehaviorSanitizer (clang), all tests but
#      those in which none of syncplc's C++ runs (label "no_cxx");
#   3. ThreadSanitizer, the tests of threaded parts (label "threaded": the real-time
#      runner, the store, the modbus_client driver's device threads, the HTTP server), the CLI
#      tests and the peer tests (label "peers": pymodbus, mbpoll and the
#      simulated drives against the real `syncplc run`), "no_cxx" left out;
#   4. the libFuzzer harnesses of the Modbus server's request path, the
#      modbus_client driver's reply path, the HTTP server's request path and
#      the Structured Text parser, checker and engines, 90 s side by side
#      beside the TSan tests, under ASan + UBSan: built in the ASan tree of
#      stage 2 (scripts/fuzz.sh --prebuilt).
# Any failure stops the script with a non-zero status.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build_hmi.sh --browser  # the HMI and chromium for its browser tests (label hmi)
jobs=$(nproc)

# The builds after the first run in the background at nice 19 beside the
# tests of the stage before: the tests mostly wait (ctest -j2 of the release
# stage uses about 70 % of one core), and a niced compiler takes only the CPU
# they leave (docs/benchmarks.md section 13, "Overlapping builds and tests").
# bg LOG CMD...: runs CMD in the background; its status lands in LOG.rc.
logs=$(mktemp -d)
bg_pids=()
declare -A bg_pid_of
bg() {
  local log=$1
  shift
  (set +e; nice -n 19 "$@" >"$log" 2>&1; echo $? >"$log.rc") &
  bg_pids+=($!)
  bg_pid_of[$log]=$!
}
# bg_wait LOG: waits for it; its log's last lines, or all of it and a stop on failure.
bg_wait() {
  local log=$1
  while [ ! -f "$log.rc" ]; do
    if ! kill -0 "${bg_pid_of[$log]}" 2>/dev/null && [ ! -f "$log.rc" ]; then
      echo "background build ended without a status: $log"
      exit 1
    fi
    sleep 1
  done
  local rc
  rc=$(cat "$log.rc")
  if [ "$rc" != 0 ]; then
    cat "$log"
    echo "background build failed: $log (status $rc)"
    exit "$rc"
  fi
  tail -n 3 "$log"
}
kill_tree() {
  local child
  for child in $(pgrep -P "$1" 2>/dev/null); do kill_tree "$child"; done
  kill "$1" 2>/dev/null || true
}
# A failing stage stops the script; the builds still running beside it stop too.
trap 'for p in "${bg_pids[@]}"; do kill_tree "$p"; done; rm -rf "$logs" "${supp:-}"' EXIT

echo "== release build"
# Every build here is from scratch, so in unity batches (-DSYNCPLC_UNITY=ON:
# half the compile time, docs/benchmarks.md section 13).
# Line tables only (-g1): stack traces keep their lines, the build takes 30 %
# less time than with full debug information.
bash scripts/build.sh build -DSYNCPLC_UNITY=ON -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"

# Beside the release tests: the ASan + UBSan build, with clang (a quarter
# less compile time than g++ at -O1 -g1 under the sanitizers) and the fuzz
# targets in the same tree (libFuzzer needs clang; one sanitizer build
# fewer: docs/benchmarks.md section 13, run 12).
asan_args=(-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DSYNCPLC_FUZZ=ON -DSYNCPLC_UNITY=ON
           -DSYNCPLC_SANITIZE=address,undefined -DSYNCPLC_BENCH=OFF)
bg "$logs/asan.log" bash scripts/build.sh build-asan "${asan_args[@]}"
# SYNCPLC_TEST_INSTALL=1: the package test (tests/package) installs the
# Debian package it builds with apt-get, runs its unit's ExecStart line as
# the unit's user, and purges it (only where no syncplc is installed already).
(cd build && SYNCPLC_TEST_INSTALL=1 ctest --output-on-failure -j "$jobs")

echo "== AddressSanitizer + UndefinedBehaviorSanitizer"
bg_wait "$logs/asan.log"
# Beside the ASan tests: the ThreadSanitizer build (only what the threaded
# and CLI tests need: the target threaded_and_cli_tests, tests/CMakeLists.txt;
# the other suites do not run there).
bg "$logs/tsan.log" env SYNCPLC_TARGETS="threaded_and_cli_tests" \
  bash scripts/build.sh build-tsan -DSYNCPLC_UNITY=ON -DSYNCPLC_SANITIZE=thread -DSYNCPLC_BENCH=OFF
# Not the tests labelled no_cxx (the HMI's JavaScript alone, the simulated
# drive alone): none of syncplc's C++ runs in them, the release stage ran them.
(cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
   ctest --output-on-failure -j "$jobs" -LE no_cxx)

echo "== ThreadSanitizer"
bg_wait "$logs/tsan.log"
# The fuzz targets (built in the ASan tree) run 90 s side by side beside the
# TSan tests: at nice 19 they take the CPU those tests leave.
bg "$logs/fuzz.log" bash scripts/fuzz.sh 90 build-asan --prebuilt
# tests/tsan.supp: Cyclone DDS's library, not built with TSan (its own
# atomics are invisible to it). Copied where every user can read it: some
# tests run syncplc as another user, and a clone in a private directory
# (mktemp -d) would hide it from them (TSan then refuses to start).
supp=$(mktemp /tmp/syncplc-tsan-XXXXXX.supp)
cp tests/tsan.supp "$supp"
chmod 644 "$supp"
(cd build-tsan && TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$supp" \
   ctest --output-on-failure -j "$jobs" -L 'threaded|cli|peers' -LE no_cxx)

echo "== libFuzzer: the Modbus request and reply paths, the HTTP request path, the ST front end, the ST engines"
bg_wait "$logs/fuzz.log"
grep -E '^(fuzz_.*: no failure|stat::number_of_executed_units)' "$logs/fuzz.log"
echo "== all test runs passed"
