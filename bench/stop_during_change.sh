#!/usr/bin/env bash
# How long `syncplc run` takes to end on SIGTERM while an online change waits
# for its switch (issue 21: 19 s with a 5 s task before the PLC instance).
# A project with a 5 s task; `syncplc reload` asked in the background; SIGTERM
# 0.5 s later; the time from the signal to the process's exit, ROUNDS times.
# Builds nothing: expects the build directory. BEFORE=path/to/an/older/syncplc
# runs the same rounds with it, alternating, for a side-by-side figure.
#
#   ROUNDS=5 BEFORE=/path/to/old/build/syncplc bash bench/stop_during_change.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${BUILD_DIR:-build}/syncplc")
rounds=${ROUNDS:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/slow.yaml" <<'YAML'
tasks: [{name: slow, period: 5s}]
tags: [{name: n, type: DINT}]
blocks:
  - {name: last, type: UNIT_DELAY, datatype: DINT}
  - {name: inc, type: ADD, datatype: DINT, inputs: {IN2: 1}}
connections: [last.OUT -> inc.IN1, inc.OUT -> n, n -> last.IN]
YAML
one_round() {
  local bin=$1 r=$2 label=$3
  "$bin" run "$tmp/slow.yaml" --no-status --db "$tmp/plc.db" --pid-file "$tmp/run.pid" >/dev/null 2>"$tmp/err" &
  pid=$!
  for _ in $(seq 1 100); do [ -s "$tmp/run.pid" ] && break; sleep 0.05; done
  echo "# round $r" >> "$tmp/slow.yaml"
  "$bin" reload --pid-file "$tmp/run.pid" >/dev/null 2>&1 &
  sleep 0.5
  t0=$(date +%s%N)
  kill -TERM "$pid"
  status=0
  wait "$pid" || status=$?
  t1=$(date +%s%N)
  wait || true
  echo "round $r $label: exit status $status $(( (t1 - t0) / 1000000 )) ms after SIGTERM ($(grep -c 'reload' "$tmp/err" || true) reload lines)"
  rm -f "$tmp/run.pid"
}
for r in $(seq 1 "$rounds"); do
  one_round "$bin" "$r" "this  "
  if [ -n "${BEFORE:-}" ]; then one_round "$(realpath "$BEFORE")" "$r" "before"; fi
done
