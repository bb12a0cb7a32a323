#!/usr/bin/env bash
# Installs everything syncplc needs to build, test and benchmark on Debian 12.
# Run as root (or with sudo). Safe to run again: apt-get skips what is there.
set -euo pipefail
# The HMI's Node.js and npm (when npm is missing) and the browser tests'
# chromium are installed by scripts/build_hmi.sh, called by demo.sh and test.sh.
PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libyaml-dev libcli11-dev libfmt-dev libspdlog-dev nlohmann-json3-dev
  libeigen3-dev libnlopt-dev libmodbus-dev libsqlite3-dev libsqlitecpp-dev sqlite3 libsodium-dev
  libboost1.81-dev libssl-dev  # the HTTP server (runtime/web: Boost.Beast); OpenSSL for its TLS
  libcpp-httplib-dev  # the CLI's HTTP client (runtime/cli/api_client)
  cyclonedds-dev cyclonedds-tools  # the dds driver (runtime/io/dds) and its peer tests (ddsperf)
  libxbyak-dev  # native code for compiled ST on x86-64 (runtime/st/vm/native_x64.cpp)
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-pymodbus python3-serial-asyncio mbpoll  # Modbus peer tests; pymodbus's client needs serial-asyncio
  python3-cvxopt  # tests/plcopen/test_jerk_lp.py: the jerk-limited profiles against GLPK's LP (python3-scipy would pull libboost1.74-dev, which conflicts with 1.81)
  rt-tests
  openssl  # tests/peers/test_http_tls.py makes a certificate
  curl  # the HTTP API's examples (docs/http-api.md) run as written
  dpkg-dev file systemd  # the Debian package (packaging/): cpack's dpkg-shlibdeps and file, systemd-analyze verify on its unit
  clang libclang-rt-14-dev
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
