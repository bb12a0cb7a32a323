#!/usr/bin/env bash
# Reproduces docs/results.md: runs every row's command, prints the tables as
# Markdown, and redraws the figures in docs/figures/ from the traces.
# Usage: scripts/results.sh [OUTDIR]   (traces and metrics land in OUTDIR, default /tmp/syncplc-results)
set -euo pipefail
cd "$(dirname "$0")/.."
if ! /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  apt-get install -y -q python3-matplotlib >/dev/null
fi
[ -x build/syncplc ] || bash scripts/build.sh build
/usr/bin/python3 scripts/results.py tables "${1:-/tmp/syncplc-results}"
# Paper 003 Figs. 7-8: the dropout compensators in the loop of its Fig. 3.
/usr/bin/python3 scripts/results_dropout.py tables "${1:-/tmp/syncplc-results}"
# Paper 002's servo test and paper 003 Figs. 11-15: contour error with and without CCC (set -e: any failure stops it).
/usr/bin/python3 scripts/results_contour.py tables "${1:-/tmp/syncplc-results}"
# Paper 000's table on five DDS nodes: the ring, virtual time and five real processes
# (about 4 minutes: 32 real-time runs; the namespaces column needs root).
/usr/bin/python3 scripts/results_dds.py --runs 3
