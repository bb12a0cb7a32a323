#!/usr/bin/env bash
# Installs what is needed, builds, and runs the demo project in real time
# with its web HMI served on http://127.0.0.1:8080/ (reads need no login;
# writes and forces need a user: build/syncplc user add NAME --role engineer).
# Usage: scripts/demo.sh [DURATION] [sync|plcopen]   (default 5m, sync; Ctrl-C stops earlier)
#   sync     projects/four_axis_table/sync.yaml: paper 000's synchronous controller
#   plcopen  projects/four_axis_table/plcopen.yaml: the same table driven by PLCopen
#            blocks (MC_Power, MC_Home, MC_GroupMoveAbsolute); the HMI's Motion page
#            shows a faceplate per axis
set -euo pipefail
cd "$(dirname "$0")/.."
case "${2:-sync}" in
  sync) project=projects/four_axis_table/sync.yaml ;;
  plcopen) project=projects/four_axis_table/plcopen.yaml ;;
  *) echo "scripts/demo.sh: the demo is 'sync' or 'plcopen', not '$2'" >&2; exit 2 ;;
esac
bash scripts/setup.sh
bash scripts/build.sh build
bash scripts/build_hmi.sh
echo "The HMI: http://127.0.0.1:8080/ (open it in a browser while the demo runs)"
exec build/syncplc run "$project" --duration "${1:-5m}"
