#!/usr/bin/env bash
# The timing figures the end-to-end tests print but no longer judge (they
# wait for conditions counted in scans or events; a bound a loaded machine
# can break is this benchmark's, docs/benchmarks.md section 14): each test
# run ROUNDS times, its figures collected, min / median / max printed.
#
#   bash bench/reaction_times.sh [build/syncplc] [ROUNDS]
#
# - network.four_axis_kill: a killed drive's group not ok (ms after SIGKILL)
# - network.four_axis_stall: a drive's reply 60 ms late survived (ok/failed)
# - peers.limits: the latency of a client's requests beside two stalled
#   clients (max and median, ms), and when the half frame is closed for
#   idleness (s; idle_timeout 1 s)
# - peers.modbus_client: a killed device's group stale (ms after the kill;
#   response_timeout 200 ms) and its reaction (ms; stale_after 500 ms)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build/syncplc}
rounds=${2:-5}
out=$(mktemp -d /tmp/reaction-times-XXXXXX)
py=/usr/bin/python3

for ((r = 1; r <= rounds; r++)); do
  $py tests/network/test_four_axis_network.py "$bin" kill >"$out/kill.$r" 2>&1 || echo "round $r: kill failed" >&2
  $py tests/network/test_four_axis_network.py "$bin" stall >"$out/stall.$r" 2>&1 || echo "round $r: stall failed" >&2
  $py tests/peers/test_limits.py "$bin" >"$out/limits.$r" 2>&1 || echo "round $r: limits failed" >&2
  $py tests/peers/test_modbus_client.py "$bin" >"$out/client.$r" 2>&1 || echo "round $r: modbus_client failed" >&2
done

# stats NAME FILE_GLOB SED_EXPR: the numbers the expression extracts, one a line
stats() {
  local name=$1 glob=$2 expr=$3
  # shellcheck disable=SC2086
  sed -n "$expr" $glob | sort -g | awk -v name="$name" '
    { v[NR] = $1 }
    END { if (NR == 0) { printf "%-58s (none)\n", name; exit }
          printf "%-58s n %d  min %g  median %g  max %g\n", name, NR, v[1], v[int((NR + 1) / 2)], v[NR] }'
}

echo "rounds: $rounds   load average: $(cut -d' ' -f1-3 /proc/loadavg)"
stats "four_axis_kill: ok2 FALSE after the kill (ms)" "$out/kill.*" 's/^ok2 FALSE \([0-9.]*\) ms after the kill.*/\1/p'
echo "four_axis_stall: passed $(grep -l '^ok$' "$out"/stall.* | wc -l) of $rounds"
stats "limits: third client's max latency (ms)" "$out/limits.*" 's/.*max latency \([0-9.]*\) ms.*/\1/p'
stats "limits: third client's median latency (ms)" "$out/limits.*" 's/.*median \([0-9.]*\) ms$/\1/p'
stats "limits: half frame closed after (s; idle_timeout 1 s)" "$out/limits.*" 's/.*half frame was closed after \([0-9.]*\) s.*/\1/p'
stats "modbus_client: stale after the kill (ms)" "$out/client.*" 's/^killed: stale after \([0-9.]*\) ms.*/\1/p'
stats "modbus_client: reaction after the kill (ms; stale_after 500)" "$out/client.*" 's/^reaction safe after \([0-9.]*\) ms.*/\1/p'
echo "logs in $out"
