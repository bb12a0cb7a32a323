#!/usr/bin/env bash
# The Modbus TCP client driver at 1 ms (docs/benchmarks.md, "Modbus TCP
# client"): four devices on 127.0.0.1, a project with a 1 ms SCHED_FIFO task
# (priority 80) whose modbus_client driver polls every device every scan, run
# with the driver in each of the TIMING modes (default "cycle free": the
# devices' `timing:`, docs/modbus-client.md) and the same project without it
# ("off"), alternately (off, cycle, free, then free, cycle, off, ...), RUN_S
# seconds each, in one invocation. The devices run through the whole series,
# so "off" differs from the others only by the client traffic, and cycle from
# free only by when the exchanges run.
#
# Per run: the 1 ms task's start jitter p99 and max (`run`'s own statistics),
# and with the driver, per device (`run`'s driver counters at exit): requests/s,
# the round trip from sending a request to the scan that latched its reply
# ("latched", p50/p99/max) and to the reply alone ("reply"), errors; the
# driver threads' CPU (the mb:* threads of the run, on-CPU time from
# /proc/PID/task/TID/schedstat between 5 s and RUN_S - 2 s into the run) and
# the four device processes' CPU over the same window.
#
# Series (SERIES, default "pymodbus syncplc"):
#   pymodbus  the devices are tests/peers/mb_device.py (Debian's pymodbus
#             server, one Python process each); one FC 23 request a scan per
#             device: read 10 holding registers, write 10.
#   syncplc   the devices are four `syncplc run` instances (their Modbus
#             servers are C++); one FC 3 read of 10 registers and one FC 16
#             write of 10 a scan per device (FC 23 is answered by syncplc's
#             server only once the device's task has published the write,
#             docs/modbus.md, which would measure the device's scan period).
#
# Builds nothing: expects BUILD_DIR/syncplc (default build).
# Environment: BUILD_DIR, RUN_S (30), ROUNDS (2), SERIES, TIMING, BASE_PORT (15800).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
run_s=${RUN_S:-30}
rounds=${ROUNDS:-2}
series=${SERIES:-pymodbus syncplc}
timings=${TIMING:-cycle free}
base_port=${BASE_PORT:-15800}
syncplc=$build/syncplc
py=/usr/bin/python3
tmp=$(mktemp -d)
device_pids=()
stop_devices() {
  local p
  for p in "${device_pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${device_pids[@]}"; do wait "$p" 2>/dev/null || true; done
  device_pids=()
}
trap 'stop_devices; rm -rf "$tmp"' EXIT

# The client project. $1: off or a timing (cycle, free), $2: the series, $3: first device port.
project() {
  echo "project: {name: modbus_client_bench}"
  echo "tasks:"
  echo "  - {name: main, period: 1ms, priority: 80}"
  echo "tags:"
  echo "  - {name: pos, type: LREAL}"
  for i in 1 2 3 4; do
    echo "  - {name: in$i, type: \"ARRAY[0..9] OF INT\"}"
    echo "  - {name: out$i, type: \"ARRAY[0..9] OF INT\"}"
  done
  echo "blocks:"
  echo "  - {name: ref, type: COSINE_TRAJECTORY, task: main, params: {amplitude: 10, omega: 3, cycles: 0}, inputs: {enable: TRUE}}"
  echo "connections:"
  echo "  - ref.x -> pos"
  [ "$1" != off ] || return 0
  echo "drivers:"
  echo "  - name: io"
  echo "    type: modbus_client"
  echo "    devices:"
  for i in 1 2 3 4; do
    echo "      - {name: d$i, port: $(($3 + i - 1)), response_timeout: 100ms, reconnect_min: 50ms, reconnect_max: 500ms, timing: $1}"
  done
  echo "    groups:"
  local bind=""
  for i in 1 2 3 4; do
    if [ "$2" = pymodbus ]; then
      echo "      - {name: x$i, device: d$i, function: 23, address: 0, count: 10, write_address: 100, write_count: 10}"
      bind+="x$i: in$i, x${i}_write: out$i, "
    else
      # syncplc's server: %MW0.. are holding registers 1024.. (docs/modbus.md)
      echo "      - {name: r$i, device: d$i, function: 3, address: 1024, count: 10}"
      echo "      - {name: w$i, device: d$i, function: 16, address: 1034, count: 10}"
      bind+="r$i: in$i, w$i: out$i, "
    fi
  done
  echo "    bind: {${bind%, }}"
}

# A syncplc device: 10 registers to read, 10 to write, a slow task of low priority.
cat >"$tmp/device.yaml" <<'EOF'
project: {name: modbus_client_bench_device}
tasks:
  - {name: main, period: 10ms, priority: 10}
tags:
  - {name: regs, type: "ARRAY[0..9] OF INT", address: "%MW0", hmi: read}
  - {name: cmds, type: "ARRAY[0..9] OF INT", address: "%MW10", hmi: readwrite}
EOF

start_devices() {  # $1: series, $2: first port
  local i port
  for i in 1 2 3 4; do
    port=$(($2 + i - 1))
    if [ "$1" = pymodbus ]; then
      "$py" tests/peers/mb_device.py "$port" >"$tmp/dev$i.out" 2>&1 &
    else
      "$syncplc" run "$tmp/device.yaml" --no-status --modbus-port "$port" --db "$tmp/dev$i.db" -d 3600s \
        >"$tmp/dev$i.out" 2>&1 &
    fi
    device_pids+=($!)
  done
  # Until every device accepts a connection (at most 10 s).
  for i in 1 2 3 4; do
    port=$(($2 + i - 1))
    for _ in $(seq 100); do
      (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null && break
      sleep 0.1
    done
  done
}

to_ns() { awk '{ v = $1; u = v; sub(/^[-0-9.e+]+/, "", u); sub(/[a-z]+$/, "", v)
  m = (u == "ns") ? 1 : (u == "us") ? 1e3 : (u == "ms") ? 1e6 : 1e9; printf "%.0f\n", v * m }'; }
task_exec() {  # "mean p99" of task main's execution time in a statistics output
  awk '$1 == "main" && NF >= 7 { split($6, q, "/"); print q[2], q[3]; exit }' "$1"
}
task_jitter() {  # "p99_ns max_ns scans" of task main in a statistics output
  local line quad
  line=$(awk '$1 == "main" && NF >= 7' "$1" | head -1)
  quad=$(awk '{ print $7 }' <<<"$line")
  IFS=/ read -r _ _ p99 mx <<<"$quad"
  echo "$(to_ns <<<"$p99") $(to_ns <<<"$mx") $(awk '{ print $2 }' <<<"$line")"
}
mb_cpu_ns() {  # on-CPU ns of the threads named mb:* of process $1, summed
  local t sum=0 c
  for t in /proc/"$1"/task/*; do
    case "$(cat "$t"/comm 2>/dev/null)" in mb:*)
      c=$(awk '{ print $1 }' "$t"/schedstat 2>/dev/null || echo 0)
      sum=$((sum + c)) ;;
    esac
  done
  echo "$sum"
}
proc_cpu_ns() {  # on-CPU ns of all threads of processes $@ (utime + stime from stat, ticks)
  local p sum=0 tck
  tck=$(getconf CLK_TCK)
  for p in "$@"; do
    sum=$((sum + $(awk -v t="$tck" '{ sub(/^.*\) /, ""); printf "%.0f", ($12 + $13) * 1e9 / t }' /proc/"$p"/stat)))
  done
  echo "$sum"
}
counter() {  # $1: file, $2: "<what>: " line prefix, $3: key -> value
  awk -v w="$2:" -v k="$3" '$1 == w { for (i = 2; i <= NF; i++) { split($i, kv, "="); if (kv[1] == k) print kv[2] } }' "$1" | head -1
}
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "== machine: $(nproc) CPUs, kernel $(uname -r); load before: $(cat /proc/loadavg)"
echo "== four devices polled every 1 ms scan; ${run_s} s per run, $rounds round(s) of off and $timings per series; series: $series"
window=$((run_s - 7))
for s in $series; do
  port=$base_port
  [ "$s" = syncplc ] && port=$((base_port + 10))
  for t in $timings; do project "$t" "$s" "$port" >"$tmp/$t.yaml"; done
  project off "$s" "$port" >"$tmp/off.yaml"
  start_devices "$s" "$port"
  echo
  echo "== series $s (devices on ports $port..$((port + 3)); load now: $(cut -d' ' -f1-3 /proc/loadavg))"
  : >"$tmp/res.txt"
  for ((r = 0; r < rounds; r++)); do
    order="off $timings"
    [ $((r % 2)) = 1 ] && order=$(tr ' ' '\n' <<<"$order" | tac | tr '\n' ' ')
    for mode in $order; do
      "$syncplc" run "$tmp/$mode.yaml" --no-status -d "${run_s}s" --db "$tmp/client-$s-$r-$mode.db" >"$tmp/out" 2>"$tmp/err" &
      pid=$!
      sleep 5
      c0=$(mb_cpu_ns "$pid"); d0=$(proc_cpu_ns "${device_pids[@]}")
      sleep "$window"
      c1=$(mb_cpu_ns "$pid"); d1=$(proc_cpu_ns "${device_pids[@]}")
      wait "$pid" || { echo "run failed:"; cat "$tmp/err"; exit 1; }
      read -r p99 mx scans < <(task_jitter "$tmp/out")
      read -r exec_mean exec_p99 < <(task_exec "$tmp/out")
      mb_cpu=$(awk -v c=$((c1 - c0)) -v s="$window" 'BEGIN { printf "%.1f", 100 * c / (s * 1e9) }')
      dev_cpu=$(awk -v c=$((d1 - d0)) -v s="$window" 'BEGIN { printf "%.1f", 100 * c / (s * 1e9) }')
      echo "  round $((r + 1)) $mode: scans $scans, 1 ms task jitter p99 $((p99 / 1000)) us, max $((mx / 1000)) us, exec mean $exec_mean p99 $exec_p99; mb:* threads CPU $mb_cpu %, devices CPU $dev_cpu %"
      echo "jitter $mode $p99 $mx" >>"$tmp/res.txt"
      [ "$mode" != off ] || continue
      echo "cpu $mode $mb_cpu $dev_cpu" >>"$tmp/res.txt"
      if [ "$s" = pymodbus ]; then groups="x1 x2 x3 x4"; else groups="r1 w1 r2 w2 r3 w3 r4 w4"; fi
      for g in $groups; do
        line=""
        for k in requests_per_s latched_p50_us latched_p99_us latched_max_us reply_p50_us reply_p99_us reply_max_us errors; do
          v=$(counter "$tmp/out" "$g" "$k"); line+=" ${v:--}"
        done
        read -r rps lp50 lp99 lmax rp50 rp99 rmax errs <<<"$line"
        printf "    %-3s %7.1f req/s  latched p50/p99/max %6s / %6s / %7s us  reply p50/p99/max %6s / %6s / %7s us  errors %s\n" \
          "$g" "$rps" "$lp50" "$lp99" "$lmax" "$rp50" "$rp99" "$rmax" "$errs"
        echo "group $mode:$g $rps $lp50 $lp99 $lmax $rp50 $rp99 $rmax $errs" >>"$tmp/res.txt"
      done
      grep -m3 "modbus_client" "$tmp/err" | sed 's/^/    event: /' || true
    done
  done
  stop_devices
  echo "  -- medians over $rounds round(s), series $s"
  for mode in off $timings; do
    col() { awk -v m="$mode" -v c="$1" '$1 == "jitter" && $2 == m { print $c }' "$tmp/res.txt" | median; }
    printf "  %-5s 1 ms task jitter p99 %7.1f us  max %9.1f us\n" "$mode" \
      "$(awk -v v="$(col 3)" 'BEGIN { print v / 1000 }')" "$(awk -v v="$(col 4)" 'BEGIN { print v / 1000 }')"
  done
  for t in $timings; do
    printf "  %-5s mb:* threads CPU %s %%, devices CPU %s %% (of one core)\n" "$t" \
      "$(awk -v m="$t" '$1 == "cpu" && $2 == m { print $3 }' "$tmp/res.txt" | median)" \
      "$(awk -v m="$t" '$1 == "cpu" && $2 == m { print $4 }' "$tmp/res.txt" | median)"
  done
  for g in $(awk '$1 == "group" { print $2 }' "$tmp/res.txt" | sort -u); do
    gcol() { awk -v g="$g" -v c="$1" '$1 == "group" && $2 == g { print $c }' "$tmp/res.txt" | median; }
    printf "  %-9s %7.1f req/s  latched p50/p99/max %s / %s / %s us  reply p50/p99/max %s / %s / %s us\n" \
      "$g" "$(gcol 3)" "$(gcol 4)" "$(gcol 5)" "$(gcol 6)" "$(gcol 7)" "$(gcol 8)" "$(gcol 9)"
  done
done
echo "== load after: $(cat /proc/loadavg)"
