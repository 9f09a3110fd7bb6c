#!/usr/bin/env bash
# The main job on the default scene, run by `make demo`: render, simulate the camera, and plot the
# chromaticity of a tongue region. Usage: scenes/demo.sh <oralfluor binary> <output folder>
set -euo pipefail
bin=${1:-build/oralfluor}
out=${2:-out/demo}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
"$bin" render "$here/minimal.json" -o "$out"
echo
echo "pictures:"
echo "  $out/preview.png    rendered radiance (sRGB preview)"
echo "  $out/radiance.exr   spectral radiance, W sr^-1 m^-2 nm^-1, spectral EXR layout"
