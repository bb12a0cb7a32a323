#!/usr/bin/env bash
# The worst loss window of 10,000 retained variables under kill -9
# (docs/benchmarks.md section 8): the kill test's project
# (tests/store/retain_kill.yaml) plus a 10 ms task with 10,000 retained
# counters (UNIT_DELAY + ADD), all changing between two store cycles, so every
# cycle writes 10,001 values. Usage: bench/retain_kill_10k.sh [BUILD_DIR] [KILLS]
set -euo pipefail
cd "$(dirname "$0")/.."
project=$(mktemp /tmp/retain_kill_10k.XXXXXX.yaml)
trap 'rm -f "$project"' EXIT
/usr/bin/python3 - "$project" <<'PY'
import sys
n = 10000
text = open("tests/store/retain_kill.yaml").read()
text = text.replace("tasks: [{name: fast, period: 1ms}]", "tasks: [{name: fast, period: 1ms}, {name: bulk, period: 10ms}]")
blocks = "".join("  - {name: d%d, type: UNIT_DELAY, datatype: DINT, retain: true, task: bulk}\n"
                 "  - {name: a%d, type: ADD, datatype: DINT, task: bulk, inputs: {IN2: 1}}\n" % (i, i) for i in range(n))
conns = "".join("  - d%d.OUT -> a%d.IN1\n  - a%d.OUT -> d%d.IN\n" % (i, i, i, i) for i in range(n))
text = text.replace("blocks:\n", "blocks:\n" + blocks, 1).replace("connections:\n", "connections:\n" + conns, 1)
open(sys.argv[1], "w").write(text)
PY
RETAIN_KILL_PROJECT="$project" exec /usr/bin/python3 tests/store/test_retain_kill.py "${1:-build}/syncplc" "${2:-20}"
