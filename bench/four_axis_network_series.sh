#!/usr/bin/env bash
# The four-axis table over Modbus TCP (docs/four-axis-network.md), ROUNDS
# rounds of every combination of the devices' timing (TIMING, default "cycle
# free") and the Taylor compensation (on, off), alternating within a round so
# every combination sees the same load; then the sim_table version's metrics
# for comparison. One scripts/four_axis_network.py run per line: Track-RSME,
# Sync-RSME (rad), the mean share of repeated position samples and the mean
# data age over the four drives, the load average at the end.
#
# PRIO=N runs each launcher, so the four drive processes and all of
# syncplc's threads but the servo task (SCHED_FIFO 80), under SCHED_FIFO N
# (chrt, as root): on a machine loaded by others, the drives (in reality
# hardware of their own) and the device threads then do not wait behind the
# load, and the runs measure the bus's timing rather than the load.
#
# Builds nothing: expects BUILD_DIR/syncplc (default build).
# Environment: BUILD_DIR, ROUNDS (6), TIMING, PRIO.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
rounds=${ROUNDS:-6}
timings=${TIMING:-cycle free}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=()
[ -n "${PRIO:-}" ] && prefix=(chrt -f "$PRIO")
off_sets=(--set ax2.compensation=FALSE --set ax3.compensation=FALSE --set ax4.compensation=FALSE)

echo "== machine: $(nproc) CPUs, kernel $(uname -r); load before: $(cat /proc/loadavg); ${PRIO:+SCHED_FIFO $PRIO}"
printf "%-6s %-6s %-4s %10s %10s %9s %9s  %s\n" round timing comp track sync repeated age_ms load
for ((r = 1; r <= rounds; r++)); do
  combos=()
  for t in $timings; do combos+=("$t on" "$t off"); done
  # Every other round in reverse order.
  if ((r % 2 == 0)); then
    rev=()
    for ((i = ${#combos[@]} - 1; i >= 0; i--)); do rev+=("${combos[i]}"); done
    combos=("${rev[@]}")
  fi
  for c in "${combos[@]}"; do
    read -r t comp <<<"$c"
    sets=()
    for k in 1 2 3 4; do sets+=(--set "bus.devices.d$k.timing=$t"); done
    [ "$comp" = off ] && sets+=("${off_sets[@]}")
    if ! "${prefix[@]}" /usr/bin/python3 scripts/four_axis_network.py --syncplc "$build/syncplc" "${sets[@]}" \
        --metrics "$tmp/m.json" >"$tmp/out" 2>&1; then
      echo "run failed:"; tail -20 "$tmp/out"; exit 1
    fi
    /usr/bin/python3 - "$tmp/m.json" "$r" "$t" "$comp" "$(cut -d' ' -f1 /proc/loadavg)" <<'EOF' | tee -a "$tmp/res.txt"
import json, sys
m = json.load(open(sys.argv[1]))
rep = sum(s["repeated"] for s in m["position_sampling"].values()) / 4
age = sum(s["mean_ms"] for s in m["data_age"].values()) / 4
print("%-6s %-6s %-4s %10.4f %10.4f %8.1f%% %9.3f  %s" % (sys.argv[2], sys.argv[3], sys.argv[4], m["track_rsme"],
                                                         m["sync_rsme"], 100 * rep, age, sys.argv[5]))
EOF
  done
done
echo "-- medians over $rounds rounds"
for t in $timings; do
  for comp in on off; do
    awk -v t="$t" -v c="$comp" '$2 == t && $3 == c { tr[++n] = $4; sy[n] = $5; rp[n] = $6 + 0; ag[n] = $7 }
      function med(a, n,   i, j, x) { for (i = 2; i <= n; i++) { x = a[i]; for (j = i - 1; j >= 1 && a[j] > x; j--) a[j + 1] = a[j]; a[j + 1] = x }
        return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
      END { printf "%-6s comp %-3s  Track-RSME %.4f  Sync-RSME %.4f  repeated %.1f %%  age %.3f ms  (%d runs)\n",
            t, c, med(tr, n), med(sy, n), med(rp, n), med(ag, n), n }' "$tmp/res.txt"
  done
done
for comp in on off; do
  sets=()
  [ "$comp" = off ] && sets+=("${off_sets[@]}")
  "$build/syncplc" sim projects/four_axis_table/sync.yaml -d 6.283185s --metrics "$tmp/sim.json" "${sets[@]}" >/dev/null
  /usr/bin/python3 -c 'import json, sys; m = json.load(open(sys.argv[1]))["metrics"];
print("sim_table comp %-3s  Track-RSME %.4f  Sync-RSME %.4f" % (sys.argv[2], m["track_rsme"], m["sync_rsme"]))' \
    "$tmp/sim.json" "$comp"
done
echo "== load after: $(cat /proc/loadavg)"
