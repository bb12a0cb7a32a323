#!/usr/bin/env bash
# The HTTP API's live stream under HMI load (docs/benchmarks.md, "HTTP live
# streams"; issue 14): CLIENTS Server-Sent Events streams of the 20 values of
# bench/projects/http_stream_bench.yaml at RATE updates/s, against one
# `syncplc run` whose 1 ms task (SCHED_FIFO 80) is pinned to CPU 1 by the
# project (`cpu: 1`) while the rest of the process (HTTP workers, main and
# store threads) and the load generator are held on CPU 0 with taskset.
#
# One `syncplc run` for the whole series; rounds of RUN_S seconds alternate
# without the load (off) and with it (on): off on, on off, off on, ... (PAIRS
# pairs). Per round, from two snapshots of GET /api/v1/status?histograms=full
# (the task's own jitter histogram, 32 buckets per power of two) taken RUN_S
# apart, the 1 ms task's start jitter p50/p99/max of that round alone (the
# difference of the two histograms; percentiles are bucket upper bounds, as
# `run` reports them); over the same window the syncplc process's CPU (utime +
# stime of /proc/PID/stat), its task thread's on-CPU time
# (/proc/PID/task/TID/schedstat), each CPU's busy share (/proc/stat: what
# else ran there) and the load average; with the load, the generator's
# events/s and latencies (bench_http_stream_load: scan release -> client,
# release -> server t_ns, t_ns -> client) over its own window, which starts
# 2 s after its last client has connected (the status snapshots are taken
# then too), and the listen queue overflows (/proc/net/netstat) of the round.
#
# Builds nothing: expects BUILD_DIR/syncplc and BUILD_DIR/bench/bench_http_stream_load.
# Environment: BUILD_DIR (build), RUN_S (20), PAIRS (3), CLIENTS (50), RATE (20),
#              PORT (18080), LOAD_CPU (0: the CPU of the HTTP threads and the generator).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
run_s=${RUN_S:-20}
pairs=${PAIRS:-3}
clients=${CLIENTS:-50}
rate=${RATE:-20}
port=${PORT:-18080}
load_cpu=${LOAD_CPU:-0}
warmup=2
syncplc=$build/syncplc
load=$build/bench/bench_http_stream_load
project=bench/projects/http_stream_bench.yaml
py=/usr/bin/python3
refs=release_ms,scan_count,tripled,limited,position,velocity,acceleration,position2,velocity2,sum_xy,error_xy,scaled,clamped,above,pulse,setpoint1,setpoint2,setpoint3,gain,mode
for f in "$syncplc" "$load"; do
  [ -x "$f" ] || { echo "http_stream_bench.sh: $f not found; build first (SYNCPLC_TARGETS=\"syncplc bench_http_stream_load\" bash scripts/build.sh build)" >&2; exit 1; }
done
[ "$(id -u)" -eq 0 ] || echo "http_stream_bench.sh: warning: not root: no SCHED_FIFO, no mlockall" >&2

tmp=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; [ -n "$pid" ] && wait "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT

status_url="http://127.0.0.1:$port/api/v1/status?histograms=full"
rounds=$((2 * pairs))
# A safety net: run ends by itself even if this script is killed.
total_s=$((rounds * (run_s + warmup + 4) + 60))
echo "== machine: $(nproc) CPUs, kernel $(uname -r) ($(uname -v)); load before: $(cat /proc/loadavg)"
echo "== $clients streams x 20 refs at $rate/s; $rounds rounds of ${run_s} s (off/on alternating); port $port"
echo "== syncplc run on CPU $load_cpu (taskset), its task main pinned to CPU 1 by the project"
XDG_STATE_HOME=$tmp/state taskset -c "$load_cpu" "$syncplc" run "$project" --no-status --http "127.0.0.1:$port" \
  --db "$tmp/plc.db" --pid-file "$tmp/run.pid" -d "${total_s}s" >"$tmp/run.out" 2>"$tmp/run.err" &
pid=$!
for _ in $(seq 100); do
  curl -sf "http://127.0.0.1:$port/api/v1/status" >/dev/null 2>&1 && break
  sleep 0.1
done
curl -sf "http://127.0.0.1:$port/api/v1/status" >"$tmp/first.json" || { echo "syncplc run did not answer:"; cat "$tmp/run.err"; exit 1; }
# The task thread: named after the task.
tid=""
for t in /proc/"$pid"/task/*; do
  [ "$(cat "$t"/comm)" = main ] && tid=${t##*/}
done
[ -n "$tid" ] || { echo "no thread 'main' in syncplc run"; exit 1; }
echo "== task thread $tid: $(chrt -p "$tid" | sed 's/.*: //' | paste -sd' '), $(taskset -cp "$tid" | sed 's/.*: /CPUs /'); other threads:" \
  "$(for t in /proc/"$pid"/task/*; do [ "${t##*/}" = "$tid" ] || taskset -cp "${t##*/}" | sed 's/.*: //'; done | sort | uniq -c | awk '{ printf "%s on CPU %s; ", $1, $2 }')"
grep -i warning "$tmp/run.err" | sed 's/^/   /' || true
sleep 3

tck=$(getconf CLK_TCK)
listen_overflows() {  # TcpExt ListenOverflows of this network namespace: SYNs dropped by full accept queues
  awk '$1 == "TcpExt:" { if (!h) { for (i = 2; i <= NF; i++) k[i] = $i; h = 1 } else for (i = 2; i <= NF; i++) if (k[i] == "ListenOverflows") print $i }' /proc/net/netstat
}
snapshot() {  # $1: file prefix
  curl -sf "$status_url" >"$1.json"
  echo "$(date +%s%N) $(awk -v t="$tck" '{ sub(/^.*\) /, ""); printf "%.0f", ($12 + $13) * 1e9 / t }' /proc/"$pid"/stat)" \
    "$(awk '{ print $1 }' /proc/"$pid"/task/"$tid"/schedstat)" >"$1.cpu"
  grep -E '^cpu[0-9]+ ' /proc/stat >"$1.stat"
  cat /proc/loadavg >"$1.load"
  # Other builds beside the run: compilers and linkers at this instant.
  ps -eo comm= | grep -cE '^(cc1plus|cc1|ld|ld.gold|ld.lld|collect2|ninja|make)$' >"$1.builds" || true
}

for ((r = 0; r < rounds; r++)); do
  pair=$((r / 2))
  if [ $((pair % 2)) = 0 ]; then modes=(off on); else modes=(on off); fi
  mode=${modes[$((r % 2))]}
  gen=""
  if [ "$mode" = on ]; then
    lo0=$(listen_overflows)
    taskset -c "$load_cpu" "$load" --port "$port" --clients "$clients" --rate "$rate" --refs "$refs" \
      --release-ref release_ms --warmup "$warmup" --duration "$((run_s + 1))" >"$tmp/gen$r.out" 2>&1 &
    gen=$!
    # Until every client is connected and the generator's warm-up is over.
    for _ in $(seq 1200); do
      grep -q '^bench_http_stream_load: measuring' "$tmp/gen$r.out" && break
      kill -0 "$gen" 2>/dev/null || break
      sleep 0.05
    done
  else
    sleep 1
  fi
  snapshot "$tmp/r$r.a"
  sleep "$run_s"
  snapshot "$tmp/r$r.b"
  if [ -n "$gen" ]; then
    wait "$gen" || { echo "round $((r + 1)): the load generator failed:"; cat "$tmp/gen$r.out"; }
    echo "listen queue overflows during the round: $(($(listen_overflows) - lo0))" >>"$tmp/gen$r.out"
  fi
  echo "$mode" >"$tmp/r$r.mode"
  echo "-- round $((r + 1)) ($mode) done: load $(cut -d' ' -f1-3 "$tmp/r$r.b.load")"
  [ "$mode" = on ] && grep -v '^RESULT\|measuring$' "$tmp/gen$r.out" | sed 's/^/   /'
done
kill "$pid"
wait "$pid" || true
pid=""
echo "== load after: $(cat /proc/loadavg)"
echo "== syncplc run's own statistics at exit (whole run):"
grep -E '^\s*(main|task)' "$tmp/run.out" | sed 's/^/   /' || true

"$py" - "$tmp" "$rounds" "$tck" <<'EOF'
import json, statistics, sys
tmp, rounds, tck = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])

def load(path):
    with open(path) as f:
        return json.load(f)

def task(j):
    return next(t for t in j["tasks"] if t["name"] == "main")

def full(stats):
    return dict(zip(stats["full"]["upper_ns"], stats["full"]["counts"]))

def diff(a, b):
    d = {u: n - a.get(u, 0) for u, n in b.items()}
    return {u: n for u, n in d.items() if n > 0}

def pct(h, q):  # as Histogram::percentile: the first bucket whose cumulative count exceeds floor(q * n)
    n = sum(h.values())
    if n == 0:
        return 0
    rank = min(int(q * n), n - 1)
    acc = 0
    for u in sorted(h):
        acc += h[u]
        if acc > rank:
            return u
    return max(h)

def add(h, g):
    for u, n in g.items():
        h[u] = h.get(u, 0) + n

def result(path):
    for line in open(path):
        if line.startswith("RESULT "):
            return {k: float(v) for k, v in (kv.split("=") for kv in line.split()[1:])}
    return None

def busy(a, b):  # per CPU: busy share between two /proc/stat snapshots
    out = []
    for la, lb in zip(open(a), open(b)):
        va, vb = [int(x) for x in la.split()[1:]], [int(x) for x in lb.split()[1:]]
        d = [y - x for x, y in zip(va, vb)]
        idle = d[3] + d[4]
        out.append(100.0 * (1 - idle / max(1, sum(d[:8]))))
    return out

us = lambda ns: ns / 1000.0
rows, pooled = [], {"off": {}, "on": {}}
print()
print("== per round (jitter: this round's scans only; CPU: % of one core over the round)")
print("round mode  scans   overr  jitter p50 / p99 / max (us)   exec p99  syncplc CPU  task thr  CPU0/CPU1 busy  load1  builds  events/s  latency p50 / p99 / max (us)   age p50/p99   transport p50/p99")
for r in range(rounds):
    mode = open(f"{tmp}/r{r}.mode").read().strip()
    a, b = load(f"{tmp}/r{r}.a.json"), load(f"{tmp}/r{r}.b.json")
    ta, tb = task(a), task(b)
    jit = diff(full(ta["jitter"]), full(tb["jitter"]))
    exe = diff(full(ta["exec"]), full(tb["exec"]))
    add(pooled[mode], jit)
    scans = tb["scans"] - ta["scans"]
    overruns = (tb["overruns"] - ta["overruns"]) + (tb["skipped"] - ta["skipped"])
    ca, cb = [int(x) for x in open(f"{tmp}/r{r}.a.cpu").read().split()], [int(x) for x in open(f"{tmp}/r{r}.b.cpu").read().split()]
    wall = cb[0] - ca[0]
    cpu = 100.0 * (cb[1] - ca[1]) / wall
    thr = 100.0 * (cb[2] - ca[2]) / wall
    bz = busy(f"{tmp}/r{r}.a.stat", f"{tmp}/r{r}.b.stat")
    load1 = float(open(f"{tmp}/r{r}.b.load").read().split()[0])
    builds = max(int(open(f"{tmp}/r{r}.a.builds").read() or 0), int(open(f"{tmp}/r{r}.b.builds").read() or 0))
    g = result(f"{tmp}/gen{r}.out") if mode == "on" else None
    row = dict(mode=mode, p50=pct(jit, .5), p99=pct(jit, .99), max=max(jit) if jit else 0, exec99=pct(exe, .99),
               cpu=cpu, thr=thr, scans=scans, overruns=overruns, bz=bz, load1=load1, builds=builds, g=g)
    rows.append(row)
    gtxt = ""
    if g:
        gtxt = (f"{g['events_per_s']:8.1f}  {us(g['lat_p50_ns']):7.1f} / {us(g['lat_p99_ns']):7.1f} / {us(g['lat_max_ns']):8.1f}"
                f"   {us(g['age_p50_ns']):6.1f}/{us(g['age_p99_ns']):6.1f}   {us(g['tr_p50_ns']):6.1f}/{us(g['tr_p99_ns']):7.1f}")
        if g["disconnects"] or g["bad"] or g["errors"] or g["missing"]:
            gtxt += f"  (disconnects {g['disconnects']:.0f}, bad {g['bad']:.0f}, errors {g['errors']:.0f}, missing {g['missing']:.0f})"
    print(f"{r + 1:5d} {mode:4s} {scans:6d} {overruns:6d}   {us(row['p50']):6.1f} / {us(row['p99']):6.1f} / {us(row['max']):8.1f}"
          f"   {us(row['exec99']):7.1f}   {cpu:9.2f} %  {thr:6.2f} %   {bz[0]:5.1f}/{bz[1]:5.1f} %   {load1:5.2f}  {builds:5d}   {gtxt}")

print()
print("== per mode: jitter from the rounds' histograms added up; the rest, median of the rounds")
for mode in ("off", "on"):
    rs = [x for x in rows if x["mode"] == mode]
    h = pooled[mode]
    med = lambda k: statistics.median(x[k] for x in rs)
    p99s = ", ".join("%.1f" % us(x["p99"]) for x in rs)
    line = (f"  {mode:4s} scans {sum(h.values())}, jitter p50 {us(pct(h, .5)):.1f} us, p99 {us(pct(h, .99)):.1f} us,"
            f" max {us(max(h) if h else 0):.1f} us (round p99s {p99s} us);"
            f" syncplc CPU {med('cpu'):.2f} %, task thread {med('thr'):.2f} %")
    if mode == "on":
        gs = [x["g"] for x in rs if x["g"]]
        if gs:
            gm = lambda k: statistics.median(g[k] for g in gs)
            line += (f"; events/s {gm('events_per_s'):.1f}; scan release -> client p50 {us(gm('lat_p50_ns')):.1f}"
                     f" / p99 {us(gm('lat_p99_ns')):.1f} / max {us(max(g['lat_max_ns'] for g in gs)):.1f} us;"
                     f" generator CPU {gm('cpu_pct'):.2f} %")
    print(line)
off99, on99 = pct(pooled["off"], .99), pct(pooled["on"], .99)
if off99 > 0:
    r = on99 / off99
    print(f"  p99 with / without: {us(on99):.1f} / {us(off99):.1f} us = {r:.3f} (aim <= 1.10: {'met' if r <= 1.10 else 'NOT met'})")
EOF
