#!/usr/bin/env bash
# Start jitter of an empty syncplc task (RealtimeRunner) next to cyclictest
# (rt-tests) at the same period and priority, on the same machine, in one run.
#
# The two never run at the same time (they would share the cores): the run is
# cut into SLICES slices, and each slice of the syncplc task is followed by a
# slice of cyclictest of the same length (bench_rt_jitter runs cyclictest
# between its slices), so both see the same background load. The syncplc side
# is Task::stats.jitter accumulated over its slices; the cyclictest side is the
# sum of its histograms (-h, 1 us buckets), and its percentiles are taken the
# same way (first bucket whose cumulative count exceeds floor(q * n)) and
# reported as the bucket's upper bound, like Histogram::summary() does.
#
# Usage: sudo bench/rt_jitter.sh [DURATION_S]      (default 60 s for each side)
# Environment:
#   BUILD_DIR  build directory (default build)
#   SLICES     number of interleaved slices (default 30, i.e. 2 s each for 60 s;
#              1 = one after the other)
#   PERIOD_US  period (default 1000)      PRIORITY  SCHED_FIFO priority (default 80)
#   CPU        pin both to this CPU (syncplc task key cpu:, cyclictest -a)
#   PM_QOS     /dev/cpu_dma_latency request of the syncplc side, in us (default 0,
#              as RealtimeRunner and cyclictest both hold by default; -1 leaves
#              it alone; see docs/benchmarks.md)
#   CT_EXTRA   extra cyclictest arguments (e.g. --laptop: leave /dev/cpu_dma_latency alone)
#   BARE=1     syncplc side replaced by bench_rt_jitter --bare: a minimal
#              clock_nanosleep loop in the same process (a control, not the runtime)
#   BARE=2     the same plus Task::scan/publish/account each cycle (bench_rt_jitter --bare-work)
#   CONTROL=1  no syncplc: cyclictest against itself in the same interleaving, to
#              see how far two identical measurements differ on this machine
set -euo pipefail
cd "$(dirname "$0")/.."

duration=${1:-60}
slices=${SLICES:-30}
period=${PERIOD_US:-1000}
prio=${PRIORITY:-80}
bin=${BUILD_DIR:-build}/bench/bench_rt_jitter

[ -x "$bin" ] || { echo "rt_jitter.sh: $bin not found; build first (bash scripts/build.sh build)" >&2; exit 1; }
command -v cyclictest >/dev/null || { echo "rt_jitter.sh: cyclictest not found (apt-get install rt-tests)" >&2; exit 1; }
[ "$(id -u)" -eq 0 ] || echo "rt_jitter.sh: warning: not root: no SCHED_FIFO, no mlockall" >&2

loops=$(( duration * 1000000 / period / slices ))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

plc_args=(--duration "$duration" --slices "$slices" --period-us "$period" --priority "$prio")
ct_cmd="cyclictest -m -p $prio -i $period -l $loops -t 1 -h 2000 -q"
if [ -n "${CPU:-}" ]; then
  plc_args+=(--cpu "$CPU")
  ct_cmd+=" -a $CPU"
fi
[ -n "${PM_QOS:-}" ] && plc_args+=(--pm-qos "$PM_QOS")
[ -n "${CT_EXTRA:-}" ] && ct_cmd+=" $CT_EXTRA"
[ "${BARE:-0}" = 1 ] && plc_args+=(--bare)
[ "${BARE:-0}" = 2 ] && plc_args+=(--bare-work)

steal() { awk '/^cpu / { print $9 }' /proc/stat; }
echo "== machine: $(nproc) CPUs, kernel $(uname -r), $(uname -v)"
echo "== load before: $(cat /proc/loadavg)"
steal0=$(steal); t0=$(date +%s)
if [ "${CONTROL:-0}" = 1 ]; then
  left="cyclictest A"
  echo "== control run: $ct_cmd, twice per slice (A then B)"
  for ((s = 0; s < slices; s++)); do
    $ct_cmd >> "$tmp/a.txt" 2>&1
    $ct_cmd >> "$tmp/ct.txt" 2>&1
  done
else
  left="syncplc RealtimeRunner"
  [ "${BARE:-0}" = 1 ] && left="bare loop (control)"
  [ "${BARE:-0}" = 2 ] && left="bare loop + task work"
  echo "== syncplc: $bin ${plc_args[*]}"
  echo "== cyclictest (after each syncplc slice): $ct_cmd"
  "$bin" "${plc_args[@]}" --between "$ct_cmd >> $tmp/ct.txt 2>&1" | tee "$tmp/plc.txt"
fi
echo "== load after: $(cat /proc/loadavg)"
awk -v s="$(( $(steal) - steal0 ))" -v t="$(( $(date +%s) - t0 ))" -v n="$(nproc)" -v hz="$(getconf CLK_TCK)" \
  'BEGIN { printf "== steal time during the run: %.2f s of %d s x %d CPUs (%.2f%%)\n", s / hz, t, n, 100 * s / hz / (t * n) }'

# Summed cyclictest histograms of a file: "n p50 p99 max min overflows", in ns.
ct_stats() {
  awk '
  /^[0-9]+ [0-9]+$/ { h[$1 + 0] += $2; n += $2; next }
  /# Histogram Overflows:/ { over += $4; n += $4; next }
  /# Max Latencies:/ { if ($4 + 0 > mx) mx = $4 + 0; next }
  /# Min Latencies:/ { if (mn == "" || $4 + 0 < mn) mn = $4 + 0; next }
  function pct(q,   r, acc, b) {
    r = int(q * n); if (r >= n) r = n - 1
    acc = 0
    for (b = 0; b < 2000; b++) { acc += h[b]; if (acc > r) return (b + 1) * 1000 - 1 }
    return -1   # in the overflow (>= 2000 us)
  }
  END { printf "%d %d %d %d %d %d\n", n, pct(0.50), pct(0.99), mx * 1000, mn * 1000, over }' "$1"
}

if [ "${CONTROL:-0}" = 1 ]; then
  read -r plc_n plc_p50 plc_p99 plc_max plc_min plc_over < <(ct_stats "$tmp/a.txt")
  plc_fifo=1
  [ "$plc_over" -gt 0 ] && echo "  cyclictest A: $plc_over sample(s) beyond its 2000 us histogram"
else
  # syncplc side: the RESULT line.
  result=$(grep '^RESULT ' "$tmp/plc.txt")
  get() { sed -n "s/.* $1=\([0-9-]*\).*/\1/p" <<<"$result"; }
  plc_n=$(get scans); plc_p50=$(get p50_ns); plc_p99=$(get p99_ns); plc_max=$(get max_ns); plc_min=$(get min_ns)
  plc_fifo=$(sed -n 's/.*fifo=\([01]\).*/\1/p' <<<"$result")
fi

# cyclictest side.
read -r ct_n ct_p50 ct_p99 ct_max ct_min ct_over < <(ct_stats "$tmp/ct.txt")

us() { awk -v v="$1" 'BEGIN { if (v < 0) print ">= 2000 us"; else printf "%.1f us", v / 1000 }'; }
echo
echo "== start jitter, ${duration} s each, ${slices} interleaved slice(s), period ${period} us, SCHED_FIFO ${prio}"
printf "  %-10s %24s %24s\n" "" "$left" "cyclictest"
printf "  %-10s %24s %24s\n" "samples" "$plc_n" "$ct_n"
printf "  %-10s %24s %24s\n" "min" "$(us "$plc_min")" "$(us "$ct_min") (trunc.)"
printf "  %-10s %24s %24s\n" "p50" "$(us "$plc_p50")" "$(us "$ct_p50")"
printf "  %-10s %24s %24s\n" "p99" "$(us "$plc_p99")" "$(us "$ct_p99")"
printf "  %-10s %24s %24s\n" "max" "$(us "$plc_max")" "$(us "$ct_max") (trunc.)"
[ "$ct_over" -gt 0 ] && echo "  cyclictest: $ct_over sample(s) beyond its 2000 us histogram"
if [ "${CONTROL:-0}" != 1 ]; then
  [ "$plc_fifo" = 1 ] && echo "  syncplc task: SCHED_FIFO obtained" || echo "  syncplc task: SCHED_FIFO NOT obtained"
fi
awk -v a="$plc_p99" -v b="$ct_p99" 'BEGIN {
  if (b <= 0) { print "  p99 ratio: n/a"; exit }
  r = a / b; printf "  p99 ratio (left / cyclictest): %.2f  (aim <= 1.2: %s)\n", r, r <= 1.2 ? "met" : "NOT met" }'
echo "  (percentiles are bucket upper bounds: syncplc 1/32 relative buckets, cyclictest 1 us buckets;"
echo "   cyclictest min/max are truncated to whole us)"
