#!/usr/bin/env bash
# Installs the Debian 12 packages photonbound needs to build, test and run its tools.
# Idempotent: packages already present are not touched, and apt is not called at all
# when nothing is missing. Runs as root, or through sudo when that is available.
# Extra package names given as arguments are installed too (tools/fuzz.sh asks for clang).
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config
  libembree-dev libopenimageio-dev libopenexr-dev libdeflate-dev libjpeg-dev libglm-dev libtinygltf-dev
  libdraco-dev libmeshoptimizer-dev nlohmann-json3-dev
  libtbb-dev libboost-dev libgtest-dev
  libopenmpi-dev openmpi-bin
  python3-numpy python3-matplotlib python3-openimageio
  python3
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi

echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
