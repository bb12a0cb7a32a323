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
# Environment: BUILD_DIR (default build), RELOADS (default 100), ROUNDS (default 3).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BUILD_DIR:-build}/syncplc
reloads=${RELOADS:-100}
rounds=${ROUNDS:-3}
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
