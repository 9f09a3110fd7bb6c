#!/usr/bin/env bash
# The main job on the default scene, run by `make demo`: render the OralEye-like 385 nm scene,
# simulate the camera, and plot the chromaticity of the tongue.
# Usage: scenes/demo.sh <oralfluor binary> <output folder>
set -euo pipefail
bin=${1:-build/oralfluor}
out=${2:-out/demo}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
echo "== 1/3 render scenes/oraleye_385.json (480x360, 256 samples per pixel; Ctrl-C keeps the finished passes)"
"$bin" render "$here/oraleye_385.json" -o "$out"
echo "== 2/3 camera scenes/cameras/oraleye.json (475 nm long-pass, RGB CMOS, EMVA 1288 noise)"
"$bin" camera "$out/radiance.exr" --camera "$here/cameras/oraleye.json" -o "$out"
echo "== 3/3 chromaticity of the pixels that see the tongue"
"$bin" chroma "$out/raw.tiff" --roi-material tongue -o "$out" --name chroma_tongue
cat <<TXT

pictures:
  $out/preview.png          rendered spectral radiance as sRGB (what the eye would see, violet light included)
  $out/preview_fluorescence.png  the fluorescence alone (auto-exposed on its own: a few % of the light above)
  $out/camera_preview.png   what the fluorescence camera records (demosaiced raw, 475 nm long-pass)
  $out/chroma_tongue.png    r,g chromaticity of the tongue with the fluorophore reference lines (also .svg)
data:
  $out/radiance.exr         spectral radiance, W sr^-1 m^-2 nm^-1 (spectral EXR layout; fluorescence layer, aov planes)
  $out/raw.tiff, raw.dng    16-bit Bayer mosaic with its metadata (raw.json)
  $out/electrons.exr        noise-free expected electrons per channel
TXT
