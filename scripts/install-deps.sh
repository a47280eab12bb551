#!/usr/bin/env bash
# Installs photonvr's build and test dependencies from Debian 12's packages.
# Idempotent and non-interactive: packages already present are not touched. Extra packages a
# script needs beyond the build's (scripts/fuzz.sh: clang) come as arguments.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libassimp-dev libcgal-dev
  libcli11-dev nlohmann-json3-dev libstb-dev libopenexr-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libvulkan-dev glslc mesa-vulkan-drivers libopenxr-dev libglfw3-dev libimgui-dev
  xvfb xauth assimp-testmodels
  "$@"
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing: ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
