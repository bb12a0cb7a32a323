#!/usr/bin/env bash
# The historian's cost (docs/benchmarks.md, "The historian"): a project with a
# 1 ms task (a cosine reference) and a 10 ms task owning TAGS LREAL tags,
# run with every tag trended at 10 ms ("on") and with the same project
# without trend keys ("off"), alternately (off, on, on, off, ...), RUN_S
# seconds each. Per run it reports the 1 ms task's start jitter (p99, max;
# syncplc's own statistics), the store thread's on-CPU time (from
# /proc/PID/task/TID/schedstat, between 5 s and RUN_S - 2 s into the run) and
# the trend tables' size at the end (SQLite's dbstat through the sqlite3 shell)
# as growth per hour, and the 10 ms task's execution time (mean, p99: with the
# historian each scan folds every tag into its bucket). Builds nothing:
# expects the build directory.
#
# Environment: BUILD_DIR (default build), TAGS (1000), RUN_S (30), ROUNDS (2).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
tags=${TAGS:-1000}
run_s=${RUN_S:-30}
rounds=${ROUNDS:-2}
syncplc=$build/syncplc
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

project() {  # $1: on|off
  echo "project: {name: historian_bench}"
  echo "tasks:"
  echo "  - {name: main, period: 1ms, priority: 80}"
  echo "  - {name: hist, period: 10ms, priority: 40}"
  echo "tags:"
  echo "  - {name: pos, type: LREAL}"
  for ((i = 1; i <= tags; i++)); do
    if [ "$1" = on ]; then printf '  - {name: h%04d, type: LREAL, task: hist, init: %d, trend: {rate: 10ms}}\n' "$i" "$i"
    else printf '  - {name: h%04d, type: LREAL, task: hist, init: %d}\n' "$i" "$i"; fi
  done
  echo "blocks:"
  echo "  - {name: ref, type: COSINE_TRAJECTORY, task: main, params: {amplitude: 10, omega: 3, cycles: 0}, inputs: {enable: TRUE}}"
  echo "connections:"
  echo "  - ref.x -> pos"
}
project on >"$tmp/on.yaml"
project off >"$tmp/off.yaml"

to_ns() { awk '{ v = $1; u = v; sub(/^[-0-9.e+]+/, "", u); sub(/[a-z]+$/, "", v)
  m = (u == "ns") ? 1 : (u == "us") ? 1e3 : (u == "ms") ? 1e6 : 1e9; printf "%.0f\n", v * m }'; }
task_jitter() {  # "p99_ns max_ns scans" of task main in a statistics output
  local line quad
  line=$(awk '$1 == "main" && NF >= 7' "$1" | head -1)
  quad=$(awk '{ print $7 }' <<<"$line")
  IFS=/ read -r _ _ p99 mx <<<"$quad"
  echo "$(to_ns <<<"$p99") $(to_ns <<<"$mx") $(awk '{ print $2 }' <<<"$line")"
}
store_cpu_ns() {  # on-CPU ns of the thread named "store" of process $1
  local t
  for t in /proc/"$1"/task/*; do
    [ "$(cat "$t"/comm 2>/dev/null)" = store ] && { awk '{ print $1 }' "$t"/schedstat; return; }
  done
  echo 0
}
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "== machine: $(nproc) CPUs, kernel $(uname -r); load before: $(cat /proc/loadavg)"
echo "== $tags tags at 10 ms in a 10 ms task, a 1 ms task beside it; ${run_s} s per run, $rounds round(s)"
: >"$tmp/res.txt"
for ((r = 0; r < rounds; r++)); do
  order="off on"; [ $((r % 2)) = 1 ] && order="on off"
  for mode in $order; do
    rm -f "$tmp/h.db" "$tmp/h.db-wal" "$tmp/h.db-shm"
    "$syncplc" run "$tmp/$mode.yaml" --no-status -d "${run_s}s" --db "$tmp/h.db" >"$tmp/out" 2>"$tmp/err" &
    pid=$!
    sleep 5
    c0=$(store_cpu_ns "$pid")
    sleep $((run_s - 7))
    c1=$(store_cpu_ns "$pid")
    wait "$pid"
    read -r p99 mx scans < <(task_jitter "$tmp/out")
    bytes=0 points=0
    if [ "$mode" = on ]; then
      bytes=$(sqlite3 "$tmp/h.db" "SELECT sum(pgsize) FROM dbstat WHERE name LIKE 'trend%'")
      points=$(sqlite3 "$tmp/h.db" "SELECT count(*) FROM trend_point")
    fi
    cpu=$(awk -v c=$((c1 - c0)) -v s=$((run_s - 7)) 'BEGIN { printf "%.2f", 100 * c / (s * 1e9) }')
    per_hour=$(awk -v b="$bytes" -v s="$run_s" 'BEGIN { printf "%.0f", b * 3600 / s / 1e6 }')
    # Constant values and no deadband: every finished bucket is stored (the
    # 10 ms task's scans minus the one in progress at the stop, per tag).
    hist_scans=$(awk '$1 == "hist" && NF >= 7 { print $2 }' "$tmp/out" | head -1)
    # The 10 ms task's exec time: with the historian it folds 1000 values per scan.
    IFS=/ read -r _ hist_mean hist_p99 _ <<<"$(awk '$1 == "hist" && NF >= 7 { print $6 }' "$tmp/out" | head -1)"
    kept=$(awk -v p="$points" -v t="$tags" -v s="$hist_scans" 'BEGIN { printf "%.1f", (s > 1 ? 100 * p / (t * (s - 1)) : 0) }')
    echo "  round $((r + 1)) $mode: scans $scans, jitter p99 $((p99 / 1000)) us, max $((mx / 1000)) us, 10 ms task exec mean $hist_mean p99 $hist_p99, store thread CPU $cpu %, points $points ($kept % of the buckets), trend tables $bytes B (~$per_hour MB/h)"
    echo "$mode $p99 $mx $cpu $per_hour $points $kept" >>"$tmp/res.txt"
  done
done
echo
echo "== medians over $rounds round(s)"
for mode in off on; do
  col() { awk -v m="$mode" -v c="$1" '$1 == m { print $c }' "$tmp/res.txt" | median; }
  printf "  %-4s p99 %7.1f us  max %9.1f us  store CPU %6s %%  growth %6s MB/h  buckets kept %s %%\n" "$mode" \
    "$(awk -v v="$(col 2)" 'BEGIN { print v / 1000 }')" "$(awk -v v="$(col 3)" 'BEGIN { print v / 1000 }')" "$(col 4)" "$(col 5)" "$(col 7)"
done
echo "== load after: $(cat /proc/loadavg)"
