#!/usr/bin/env bash
# Installs the HMI's npm packages from hmi_web/package-lock.json and builds
# hmi_web/dist, which `syncplc run` serves. Debian's nodejs and npm are
# installed when npm is missing (Debian 12: Node 18, npm 9, enough here).
# Usage: scripts/build_hmi.sh [--browser]
#   --browser  also installs Debian's chromium when it is missing, for the
#              browser tests (tests/hmi); the demo does not need it.
set -euo pipefail
cd "$(dirname "$0")/.."
browser=0
[ "${1:-}" = "--browser" ] && browser=1

apt_install() {
  local SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "$@"
}

# One apt-get run for whatever is missing (each run starts with an update).
missing=()
command -v npm >/dev/null || missing+=(nodejs npm)
[ "$browser" = 1 ] && [ ! -x /usr/bin/chromium ] && missing+=(chromium)
[ ${#missing[@]} -eq 0 ] || apt_install "${missing[@]}"

cd hmi_web
# npm ci starts from an empty node_modules every time: skip it when the
# installed packages are those of the current lockfile.
stamp=node_modules/.syncplc-lock.sha256
want=$(sha256sum package-lock.json | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  npm ci --no-audit --no-fund
  echo "$want" >"$stamp"
fi
npm run --silent build
