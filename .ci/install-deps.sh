#!/usr/bin/env bash
# Installs the Debian 12 packages oralfluor builds and tests with, only those missing.
# Idempotent: a second run does nothing. Needs root (or sudo) when something is missing.
set -euo pipefail
pkgs=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libtinygltf-dev libglm-dev
  libopenexr-dev libopenimageio-dev nlohmann-json3-dev libcli11-dev
  libeigen3-dev libmatio-dev libgtest-dev
  openmpi-bin libopenmpi-dev
  chromium
  fonts-dejavu-core dcraw
)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing missing Debian packages: ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
