#!/usr/bin/env bash
# Installs the Debian 12 packages facyl needs; skips apt-get when all are present already.
set -euo pipefail
packages=(g++ make cmake git pkg-config libpcl-dev libeigen3-dev libnanoflann-dev
          libgtest-dev libgmock-dev libbenchmark-dev python3 python3-matplotlib
          libopencv-dnn-dev python3-numpy python3-torch python3-onnx python3-opencv
          python3-dev pybind11-dev python3-pytest python3-open3d xvfb xauth clang-format
          nlohmann-json3-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
