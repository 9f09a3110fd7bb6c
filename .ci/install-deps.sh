#!/usr/bin/env bash
# Installs the Debian 12 packages oralfluor builds and tests with, only those missing.
# Idempotent: a second run does nothing. Needs root (or sudo) when something is missing.
# Python module and its tests: pybind11-dev, python3-numpy, python3-pytest, python3-matplotlib (for
# /usr/bin/python3); python3-venv, python3-pip and python3-build for `pip install .` and
# `python3 -m build` into a virtual environment (python/tests/test_package.py). octave: one test loads an exported ISETCam scene in Octave (measured on the
# 2-core machine: 72 s of apt for octave with its dependencies, 83 s for the Python packages).
set -euo pipefail
pkgs=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libtinygltf-dev libglm-dev
  libopenexr-dev libopenimageio-dev nlohmann-json3-dev libcli11-dev
  libeigen3-dev libmatio-dev libgtest-dev
  openmpi-bin libopenmpi-dev
  chromium
  fonts-dejavu-core dcraw
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
  python3-venv python3-pip python3-build
  octave
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
