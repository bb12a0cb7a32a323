#!/usr/bin/env bash
# The Modbus TCP server against a bare libmodbus server, and the start jitter
# of a 1 ms task with and without Modbus load (docs/benchmarks.md, "Modbus
# TCP server"). Builds nothing: expects the build directory.
#
# Usage: bench/modbus_bench.sh [throughput|jitter|all]      (default all)
#
# throughput: starts bench_modbus_bare_server and
#   `syncplc run bench/projects/modbus_bench.yaml --no-status --modbus-port 0`
#   side by side (both on 127.0.0.1, ports chosen by the kernel), then for each
#   client count runs bench_modbus_load (FC 3, 125 holding registers from 1024)
#   against each server in turn, ROUNDS times: bare, syncplc, syncplc, bare,
#   bare, syncplc, ... (the order swaps every round), so that drift in the
#   background load affects both. Prints per-run lines and a table of medians:
#   clients, bare req/s, syncplc req/s, ratio (of the medians; the min..max
#   ratio of the rounds paired in time is printed too).
# jitter: `syncplc run ... -d JITTER_S` (same project, server on) with no
#   client, then with each count of JITTER_CLIENTS clients loading it for the
#   whole run, JITTER_ROUNDS times in that order; the task's start jitter
#   (p99, max) is syncplc's own statistics output. Prints a table.
#
# Environment:
#   BUILD_DIR       build directory (default build)
#   PROJECT         project (default bench/projects/modbus_bench.yaml)
#   CLIENTS         client counts for throughput (default "1 8 64")
#   ROUNDS          rounds per client count (default 5)
#   DURATION        measured seconds per load run (default 5), WARMUP seconds before it (default 1)
#   JITTER_S        seconds per jitter run (default 30)
#   JITTER_CLIENTS  loads of the jitter runs (default "8 64"; no load always comes first);
#                   bN: N clients loading a bare libmodbus server instead, while syncplc runs
#                   with its server idle (a control: Modbus traffic on the machine, not syncplc's server)
#   JITTER_ROUNDS   (default 2)
#   LOAD_PREFIX     command put before every bench_modbus_load (e.g. "taskset -c 1"); default none
#   ISOLATE         1: the task on CPU 1, the load on CPU 0 (the server thread keeps off CPU 1; see below)
#
# Client and server share the machine's CPUs: on a 2-CPU machine the load
# generator's threads compete with the server thread (and the 1 ms task) for
# the same two cores, so req/s measures the pair, not the server alone. The
# same is true of both servers, which is what makes the ratio meaningful.
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-all}
build=${BUILD_DIR:-build}
project=${PROJECT:-bench/projects/modbus_bench.yaml}
clients=${CLIENTS:-1 8 64}
rounds=${ROUNDS:-5}
duration=${DURATION:-5}
warmup=${WARMUP:-1}
jitter_s=${JITTER_S:-30}
jitter_clients=${JITTER_CLIENTS:-8 64}
jitter_rounds=${JITTER_ROUNDS:-2}
read -r -a load_prefix <<<"${LOAD_PREFIX:-}"

# ISOLATE=1: the deployment layout on 2 CPUs. The 1 ms task is pinned to CPU 1
# (task `cpu: 1`); the Modbus server thread then keeps off it by itself (no
# `cpus` setting: it avoids the pinned tasks' CPUs), and the load generator
# runs on CPU 0 (taskset), standing in for remote clients whose network
# interrupts are steered away from the real-time CPU.
if [ "${ISOLATE:-0}" = 1 ]; then
  isolated=$(mktemp --suffix=.yaml)  # removed by cleanup below
  sed 's/^  - {name: main, period: 1ms, priority: 80}$/  - {name: main, period: 1ms, priority: 80, cpu: 1}/' "$project" >"$isolated"
  grep -q 'cpu: 1}' "$isolated" || { echo "modbus_bench.sh: ISOLATE=1 expects the task line of $project" >&2; exit 2; }
  project=$isolated
  [ ${#load_prefix[@]} -eq 0 ] && load_prefix=(taskset -c 0)
fi

syncplc=$build/syncplc
load=$build/bench/bench_modbus_load
bare=$build/bench/bench_modbus_bare_server
for b in "$syncplc" "$load" "$bare"; do
  [ -x "$b" ] || { echo "modbus_bench.sh: $b not found; build first (bash scripts/build.sh $build)" >&2; exit 1; }
done
case $mode in throughput|jitter|all) ;; *) echo "usage: bench/modbus_bench.sh [throughput|jitter|all]" >&2; exit 2 ;; esac

tmp=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$tmp"
  [ -n "${isolated:-}" ] && rm -f "$isolated"
  return 0
}
trap cleanup EXIT

# The port a server printed ("... listening on 127.0.0.1:PORT ..."), waiting up to 10 s.
port_of() {
  local file=$1 pid=$2 port=""
  for _ in $(seq 100); do
    port=$(sed -n 's/.*listening on 127\.0\.0\.1:\([0-9]*\).*/\1/p' "$file" | head -1)
    [ -n "$port" ] && { echo "$port"; return 0; }
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  echo "modbus_bench.sh: no port from $file:" >&2
  cat "$file" >&2
  return 1
}

# On-CPU time (ns, from /proc/PID/task/TID/schedstat) of a server's thread:
# the bare server's only thread, or syncplc's Modbus thread (named "modbus";
# the task threads carry their task's name).
server_tid() {
  local pid=$1 t
  [ "$(ls /proc/"$pid"/task | wc -l)" -eq 1 ] && { echo "$pid"; return; }
  for t in /proc/"$pid"/task/*; do
    [ "$(cat "$t"/comm)" = modbus ] && { echo "${t##*/}"; return; }
  done
}
cpu_ns() { awk '{ print $1 }' /proc/"$1"/task/"$2"/schedstat; }

# Runs the load against the server of process PID; prints "rps p50_us p99_us
# fail server_us_per_request" (the server thread's CPU time over the whole load
# run, warm-up included, divided by every request answered in it).
run_load() {
  local port=$1 n=$2 dur=$3 warm=$4 pid=${5:-} tid="" c0=0 c1=0 out all
  [ -n "$pid" ] && { tid=$(server_tid "$pid"); c0=$(cpu_ns "$pid" "$tid"); }
  out=$("${load_prefix[@]}" "$load" --port "$port" --clients "$n" --duration "$dur" --warmup "$warm")
  [ -n "$pid" ] && c1=$(cpu_ns "$pid" "$tid")
  grep -v '^RESULT' <<<"$out" | sed 's/^/    /' >&2
  all=$(sed -n 's/^RESULT .* all_ok=\([0-9]*\).*/\1/p' <<<"$out")
  sed -n 's/^RESULT .* fail=\([0-9]*\) .* rps=\([0-9.]*\) p50_us=\([0-9.]*\) p99_us=\([0-9.]*\) .*/\2 \3 \4 \1/p' <<<"$out" |
    awk -v c="$(( c1 - c0 ))" -v a="$all" '{ printf "%s %s %s %s %.2f\n", $1, $2, $3, $4, (a > 0 ? c / a / 1000 : 0) }'
}

steal() { awk '/^cpu / { print $9 }' /proc/stat; }
echo "== machine: $(nproc) CPUs ($(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)), kernel $(uname -r), $(uname -v)"
echo "== load before: $(cat /proc/loadavg)"
[ "$(id -u)" -eq 0 ] || echo "modbus_bench.sh: warning: not root: the 1 ms task gets no SCHED_FIFO" >&2
[ ${#load_prefix[@]} -gt 0 ] && echo "== load generator run under: ${load_prefix[*]}"
steal0=$(steal); t0=$(date +%s)

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
minmax() { sort -g | awk 'NR == 1 { lo = $1 } { hi = $1 } END { printf "%s..%s", lo, hi }'; }

if [ "$mode" != jitter ]; then
  n_clients=$(wc -w <<<"$clients")
  long=$(awk -v n="$n_clients" -v r="$rounds" -v d="$duration" -v w="$warmup" 'BEGIN { printf "%d", n * r * 2 * (d + w + 3) + 60 }')
  "$bare" --port 0 --address 1024 --count 125 >"$tmp/bare.out" 2>&1 &
  bare_pid=$!; pids+=("$bare_pid")
  "$syncplc" run "$project" --no-status --modbus-port 0 -d "${long}s" >"$tmp/plc.out" 2>"$tmp/plc.err" &
  plc_pid=$!; pids+=("$plc_pid")
  bare_port=$(port_of "$tmp/bare.out" "$bare_pid")
  plc_port=$(port_of "$tmp/plc.err" "$plc_pid")
  echo "== throughput: bare libmodbus server on port $bare_port, syncplc on port $plc_port ($project)"
  echo "== per run: bench_modbus_load --clients N --duration $duration --warmup $warmup (FC 3, 125 registers at 1024)"
  sleep 1
  : >"$tmp/tp.txt"
  for n in $clients; do
    for ((r = 0; r < rounds; r++)); do
      if (( r % 2 == 0 )); then order="bare syncplc"; else order="syncplc bare"; fi
      for side in $order; do
        port=$bare_port; pid=$bare_pid
        [ "$side" = syncplc ] && { port=$plc_port; pid=$plc_pid; }
        echo "  clients $n, round $((r + 1)), $side:" >&2
        read -r rps p50 p99 fail cpu < <(run_load "$port" "$n" "$duration" "$warmup" "$pid")
        echo "    server thread: $cpu us CPU per request" >&2
        echo "$n $r $side $rps $p50 $p99 $fail $cpu" >>"$tmp/tp.txt"
      done
    done
  done
  kill -TERM "$plc_pid" "$bare_pid"
  wait "$plc_pid" "$bare_pid" || true
  echo
  echo "== syncplc's statistics over the whole throughput phase (the 1 ms task ran under the load):"
  sed 's/^/  /' "$tmp/plc.out"
  grep -i 'warning' "$tmp/plc.err" | sed 's/^/  /' || true
  echo "== bare server: $(tail -1 "$tmp/bare.out")"
  echo
  echo "== throughput, FC 3 x 125 registers, $rounds rounds of ${duration} s per cell, medians (min..max)"
  printf "  %7s | %26s | %26s | %6s | %11s | %17s | %17s | %17s | %s\n" clients "bare req/s" "syncplc req/s" ratio \
    "ratio range" "p50 us bare/ours" "p99 us bare/ours" "CPU us/req b/ours" "failed"
  for n in $clients; do
    col() { awk -v n="$n" -v s="$1" -v c="$2" '$1 == n && $3 == s { print $c }' "$tmp/tp.txt"; }
    b_med=$(col bare 4 | median); s_med=$(col syncplc 4 | median)
    ratios=$(awk -v n="$n" '$1 == n { v[$2 " " $3] = $4; r[$2] = 1 }
      END { for (k in r) if (v[k " bare"] > 0) printf "%.3f\n", v[k " syncplc"] / v[k " bare"] }' "$tmp/tp.txt" | minmax)
    fails=$(awk -v n="$n" '$1 == n { f += $7 } END { print f + 0 }' "$tmp/tp.txt")
    printf "  %7s | %8.0f (%15s) | %8.0f (%15s) | %6.3f | %11s | %8s/%-8s | %8s/%-8s | %8s/%-8s | %s\n" "$n" \
      "$b_med" "$(col bare 4 | minmax)" "$s_med" "$(col syncplc 4 | minmax)" \
      "$(awk -v a="$s_med" -v b="$b_med" 'BEGIN { print a / b }')" "$ratios" \
      "$(col bare 5 | median)" "$(col syncplc 5 | median)" "$(col bare 6 | median)" "$(col syncplc 6 | median)" \
      "$(col bare 8 | median)" "$(col syncplc 8 | median)" "$fails"
  done
  echo "  (ratio = syncplc / bare of the medians, aim >= 0.90; ratio range: the rounds' own ratios, each pair run back"
  echo "   to back; CPU us/req: the server thread's on-CPU time per request answered, from /proc/.../schedstat)"
fi

# "p99_ns max_ns scans" of the task's jitter in a syncplc statistics output.
to_ns() { awk '{ v = $1; u = v; sub(/^[-0-9.e+]+/, "", u); sub(/[a-z]+$/, "", v)
  m = (u == "ns") ? 1 : (u == "us") ? 1e3 : (u == "ms") ? 1e6 : 1e9; printf "%.0f\n", v * m }'; }
task_jitter() {
  local line quad
  line=$(awk '$1 == "main" && NF >= 7' "$1" | head -1)
  quad=$(awk '{ print $7 }' <<<"$line")
  IFS=/ read -r _ _ p99 mx <<<"$quad"
  echo "$(to_ns <<<"$p99") $(to_ns <<<"$mx") $(awk '{ print $2 }' <<<"$line")"
}

if [ "$mode" != throughput ]; then
  echo
  echo "== jitter: syncplc run $project --no-status --modbus-port 0 -d ${jitter_s}s, loads: none $jitter_clients"
  : >"$tmp/jit.txt"
  if [[ " $jitter_clients" == *" b"* ]]; then
    "$bare" --port 0 --address 1024 --count 125 >"$tmp/jbare.out" 2>&1 &
    jbare_pid=$!; pids+=("$jbare_pid")
    jbare_port=$(port_of "$tmp/jbare.out" "$jbare_pid")
    echo "== loads bN go to a bare libmodbus server on port $jbare_port"
  fi
  label() { case $1 in 0) echo none ;; b*) echo "${1#b} clients, bare" ;; *) echo "$1 clients" ;; esac; }
  for ((r = 0; r < jitter_rounds; r++)); do
    for n in 0 $jitter_clients; do
      "$syncplc" run "$project" --no-status --modbus-port 0 -d "${jitter_s}s" >"$tmp/j.out" 2>"$tmp/j.err" &
      plc_pid=$!; pids+=("$plc_pid")
      port=$(port_of "$tmp/j.err" "$plc_pid")
      rps=-
      if [ "$n" != 0 ]; then
        # The load covers the whole run: it starts as soon as the server listens and
        # outlasts the run by a second (its last requests fail when the server stops).
        lport=$port; [ "${n:0:1}" = b ] && lport=$jbare_port
        read -r rps _ _ _ < <(run_load "$lport" "${n#b}" "$(awk -v j="$jitter_s" 'BEGIN { print j + 1 }')" 0 2>/dev/null)
      fi
      wait "$plc_pid" || true
      read -r p99 mx scans < <(task_jitter "$tmp/j.out")
      fifo=yes; grep -q 'SCHED_FIFO' "$tmp/j.err" && fifo=no
      echo "  round $((r + 1)), $(label "$n"): scans $scans, jitter p99 $p99 ns, max $mx ns, SCHED_FIFO $fifo, load $rps req/s"
      grep -i 'warning' "$tmp/j.err" | sed 's/^/    /' || true
      echo "$n $r $p99 $mx $rps" >>"$tmp/jit.txt"
    done
  done
  echo
  echo "== start jitter of the 1 ms task, ${jitter_s} s per run, $jitter_rounds round(s): median (min..max) over rounds"
  printf "  %-18s | %22s | %26s | %12s | %s\n" load "p99 us" "max us" "p99 vs none" "load req/s"
  base=$(awk '$1 == 0 { print $3 }' "$tmp/jit.txt" | median)
  for n in 0 $jitter_clients; do
    col() { awk -v n="$n" -v c="$1" '$1 == n { print $c / (c == 5 ? 1 : 1000) }' "$tmp/jit.txt"; }
    p=$(col 3 | median)
    printf "  %-18s | %6.1f (%13s) | %8.1f (%15s) | %+11.0f%% | %s\n" "$(label "$n")" \
      "$p" "$(col 3 | minmax)" "$(col 4 | median)" "$(col 4 | minmax)" \
      "$(awk -v p="$p" -v b="$base" 'BEGIN { print (b > 0 ? 100 * (p * 1000 / b - 1) : 0) }')" \
      "$([ "$n" = 0 ] && echo - || col 5 | median)"
  done
  echo "  (aim: p99 under load at most 10 % above p99 without; syncplc's p99 is a bucket upper bound, 1/32 relative)"
  echo "== per round (p99 us, in run order):"
  awk '{ printf "%s%s=%.1f", (NR == 1 || $2 != last ? (NR > 1 ? "\n" : "") "  round " $2 + 1 ": " : ", "), $1, $3 / 1000; last = $2 } END { print "" }' "$tmp/jit.txt"
fi

echo
echo "== load after: $(cat /proc/loadavg)"
awk -v s="$(( $(steal) - steal0 ))" -v t="$(( $(date +%s) - t0 ))" -v n="$(nproc)" -v hz="$(getconf CLK_TCK)" \
  'BEGIN { printf "== steal time during the run: %.2f s of %d s x %d CPUs (%.2f%%)\n", s / hz, t, n, 100 * s / hz / (t * n) }'
