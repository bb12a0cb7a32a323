#!/usr/bin/env bash
# The retain soak (issue 12): `syncplc run` killed with SIGKILL at 100 random
# moments in a row; after each, the database is intact and the counter lost
# at most one store interval (tests/store/test_retain_kill.py says exactly what
# is checked). Usage: scripts/retain_soak.sh [BUILD_DIR] [KILLS]
set -euo pipefail
cd "$(dirname "$0")/.."
exec /usr/bin/python3 tests/store/test_retain_kill.py "${1:-build}/syncplc" "${2:-100}"
