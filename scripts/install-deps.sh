#!/usr/bin/env bash
# Installs the Debian 12 packages kmbvh builds with, if any is missing. Needs root (or sudo).
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libembree-dev libtbb-dev
  libtinygltf-dev libstb-dev nlohmann-json3-dev libtinyobjloader-dev
  libglm-dev libopenimageio-dev
  libthrust-dev
  libcli11-dev libfmt-dev libspdlog-dev
  libgtest-dev
  embree-tools openimageio-tools
  clang libclang-rt-14-dev libomp-14-dev
  python3-matplotlib
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "kmbvh: all Debian packages present"
  exit 0
fi

echo "kmbvh: installing ${missing[*]}"
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
