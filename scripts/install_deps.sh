#!/usr/bin/env bash
# Installs the Debian 12 packages detslam needs. Idempotent: does nothing when they are present.
set -euo pipefail
PACKAGES=(build-essential cmake ninja-build pkg-config
  libopencv-dev libeigen3-dev libceres-dev libcli11-dev libspdlog-dev libfmt-dev
  nlohmann-json3-dev libyaml-cpp-dev libbz2-dev liblz4-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3-numpy
  libcpp-httplib-dev libjs-three  # the viewer: its web server, three.js for its 3-D view
  chromium-headless-shell)        # the viewer's browser tests (tests/viewer_browser_test.cc)
missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PACKAGES[@]} Debian packages present"
  exit 0
fi
echo "[deps] installing: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
