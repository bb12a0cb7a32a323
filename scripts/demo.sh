#!/usr/bin/env bash
# Installs what is needed, builds, and runs the demo project in real time.
# Usage: scripts/demo.sh [DURATION]   (default 20s; Ctrl-C stops earlier)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh build
bash scripts/build_hmi.sh
exec build/syncplc run projects/four_axis_table/sync.yaml --duration "${1:-20s}"
