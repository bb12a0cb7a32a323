#!/usr/bin/env bash
# Online change in real time (docs/benchmarks.md, "Online change"): the
# four-axis demo's 1 ms servo task, side by side in one script, ROUNDS times:
#   plain:   `syncplc run projects/four_axis_table/sync.yaml` for as long as
#            the reload run took, with a pymodbus client reading throughout;
#   reloads: tests/reload/test_reloads.py, RELOADS online changes of it
#            (`syncplc reload` after each edit) with the client reading.
# Prints each run's servo statistics line (scans, overruns, skipped, watchdog
# trips, exec and start-jitter min/mean/p99/max): a reload that made a scan
# late or missed shows as a larger jitter max or a skipped count there.
# Builds nothing: expects the build directory.
#
# Environment: BUILD_DIR (default build), RELOADS (default 100), ROUNDS (default 3),
# MIXED=1 for issue 21's mixed changes (wiring, period, driver) instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BUILD_DIR:-build}/syncplc
reloads=${RELOADS:-100}
rounds=${ROUNDS:-3}
if [ "${MIXED:-0}" != 1 ]; then
for r in $(seq 1 "$rounds"); do
  start=$(date +%s)
  out=$(/usr/bin/python3 tests/reload/test_reloads.py "$bin" "$reloads")
  secs=$(( $(date +%s) - start ))
  echo "round $r reloads ($reloads, $secs s): $(echo "$out" | grep '^servo:')"
  echo "round $r           $(echo "$out" | grep '^reads:')"
  echo "round $r           $(echo "$out" | grep '^switches:')"
  plain=$(/usr/bin/python3 tests/reload/test_reloads.py "$bin" 0 "$secs")
  echo "round $r plain   (0, $secs s): $(echo "$plain" | grep '^servo:')"
done
fi
# The mixed changes of issue 21 (MIXED=1): 100 online changes of three kinds
# in turn beside the servo task (tests/reload/test_mixed_changes.py), then the
# same setup's servo statistics without a change for as long.
if [ "${MIXED:-0}" = 1 ]; then
  for r in $(seq 1 "$rounds"); do
    start=$(date +%s)
    out=$(/usr/bin/python3 tests/reload/test_mixed_changes.py "$bin" "$reloads")
    secs=$(( $(date +%s) - start ))
    echo "round $r mixed   ($reloads, $secs s): $(echo "$out" | grep '^servo:')"
    echo "round $r           $(echo "$out" | grep '^switches:')"
    echo "round $r           $(echo "$out" | grep '^sockets:')"
    echo "round $r           $(echo "$out" | grep '^retain:')"
    plain=$(/usr/bin/python3 tests/reload/test_reloads.py "$bin" 0 "$secs")
    echo "round $r plain   (0, $secs s): $(echo "$plain" | grep '^servo:')"
  done
fi
