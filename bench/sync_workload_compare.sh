#!/usr/bin/env bash
# TRANSIENT_SYNC of this tree against an earlier commit's, side by side, on
# issue 15's workload: builds bench_sync_workload from BASE (a git worktree of
# it with this tree's bench/sync_workload.{cpp,hpp} copied in) and from this
# tree, then runs the two binaries in alternation, ROUNDS times, on the same
# CPU, and prints every round's RESULT lines with the tree they came from.
#
# Usage: bench/sync_workload_compare.sh [BASE] [ROUNDS] [-- bench options]
#   BASE    default 76b0376 (the last commit before issue 15's changes)
#   ROUNDS  default 3
#   bench options default: --axes 6,100,1000 --seconds 60 --cpu 1 --no-floor
# Needs: scripts/build.sh build (this tree's build directory).
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:-76b0376}
rounds=${2:-3}
shift $(( $# >= 2 ? 2 : $# )) || true
[ "${1:-}" = "--" ] && shift
opts=("$@")
[ ${#opts[@]} -eq 0 ] && opts=(--axes 6,100,1000 --seconds 60 --cpu 1 --no-floor)

work=$(mktemp -d /tmp/syncplc-sync-base.XXXXXX)
cleanup() { git worktree remove --force "$work/src" >/dev/null 2>&1 || true; rm -rf "$work"; }
trap cleanup EXIT

git worktree add --detach -q "$work/src" "$base"
cp bench/sync_workload.cpp bench/sync_workload.hpp "$work/src/bench/"
if ! grep -q bench_sync_workload "$work/src/bench/CMakeLists.txt"; then
  printf '\nadd_executable(bench_sync_workload sync_workload.cpp)\ntarget_link_libraries(bench_sync_workload PRIVATE syncplc_project)\n' \
    >> "$work/src/bench/CMakeLists.txt"
fi
echo "== building bench_sync_workload at $base"
cmake -S "$work/src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSYNCPLC_TESTS=OFF >/dev/null
cmake --build "$work/build" -j "$(nproc)" --target bench_sync_workload >/dev/null
echo "== building bench_sync_workload here ($(git rev-parse --short HEAD))"
cmake --build build -j "$(nproc)" --target bench_sync_workload >/dev/null

for r in $(seq 1 "$rounds"); do
  for side in base here; do
    bin=build/bench/bench_sync_workload
    [ "$side" = base ] && bin=$work/build/bench/bench_sync_workload
    "$bin" "${opts[@]}" | sed -n "s/^RESULT /RESULT round=$r tree=$side /p"
  done
done
