#!/usr/bin/env bash
# Installs what is needed, builds, and runs the demo project in real time
# with its web HMI served on http://127.0.0.1:8080/ (reads need no login;
# writes and forces need a user: build/syncplc user add NAME --role engineer).
# Usage: scripts/demo.sh [DURATION]   (default 5m; Ctrl-C stops earlier)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh build
bash scripts/build_hmi.sh
echo "The HMI: http://127.0.0.1:8080/ (open it in a browser while the demo runs)"
exec build/syncplc run projects/four_axis_table/sync.yaml --duration "${1:-5m}"
