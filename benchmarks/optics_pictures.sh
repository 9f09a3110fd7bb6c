#!/usr/bin/env bash
# Pictures of the camera's optical-image stage for docs/camera.md ("Optical image"), made by the tool:
#   - the lens PSF kernels at 450 and 650 nm (f/8, 0.5 um grid) and a defocused one (camera_bench psf);
#   - the demo scene (scenes/oraleye_385.json, rendered smaller) through the OralEye-like camera
#     without the stage (sensor = render grid), with a 160x120 sensor of its own, and focused too near.
# Usage: benchmarks/optics_pictures.sh [build-dir] [work-dir] [width height spp]
# Writes docs/images/camera/*.png and prints the camera summaries' optics lines and the tongue's
# chromaticity on each raw (run from the repository root: raw.json names the EXR relative to it).
set -euo pipefail
build=${1:-build}
work=${2:-out/optics_pictures}
w=${3:-320}; h=${4:-240}; spp=${5:-64}
root=$(cd "$(dirname "$0")/.." && pwd)
img="$root/docs/images/camera"
mkdir -p "$work" "$img"

"$build/camera_bench" psf "$img" 8 0.5

if [ ! -f "$work/radiance.exr" ]; then
  "$build/oralfluor" render "$root/scenes/oraleye_385.json" -o "$work" --width "$w" --height "$h" --spp "$spp"
fi

# The OralEye-like camera with a lens whose field of view is the render's (48 deg vertical):
# a 160x120 sensor of 6 um pixels is 0.72 mm tall, f = 0.36 mm / tan(24 deg) = 0.8086 mm.
python3 - "$root" "$work" "$h" <<'PY'
import json, sys, os
root, work = sys.argv[1], sys.argv[2]
cam = json.load(open(f"{root}/scenes/cameras/oraleye.json"))
cam["sensor"]["qe"]["file"] = f"{root}/assets/sensors/MT9V024_RGB.csv"
cam["noise"] = False
cam["lens"]["focal_length_mm"] = 0.8086
def write(name, optics):
    c = json.loads(json.dumps(cam))
    if optics is not None:
        c["optics"] = optics
    else:  # no stage: one sensor pixel per render pixel, pitch so that the field of view is the same 0.72 mm
        c["sensor"]["pixel_pitch_um"] = 720.0 / int(sys.argv[3])
    json.dump(c, open(f"{work}/{name}.json", "w"), indent=1)
write("render_grid", None)
write("sensor_160x120", {"sensor_pixels": [160, 120], "focus_distance_mm": 40})
write("sensor_160x120_near_focus", {"sensor_pixels": [160, 120], "focus_distance_mm": 6})
PY

for c in render_grid sensor_160x120 sensor_160x120_near_focus; do
  "$build/oralfluor" camera "$work/radiance.exr" --camera "$work/$c.json" -o "$work/$c" --no-dng --wb gray | grep -E "optics|camera \"" || true
  cp "$work/$c/camera_preview.png" "$img/demo_$c.png"
  # The tongue's chromaticity on each raw (the table in docs/camera.md).
  "$build/oralfluor" chroma "$work/$c/raw.tiff" --roi-material tongue --name chroma_tongue --json > "$work/$c/chroma.json"
  python3 -c "import json,sys; s=json.load(open(sys.argv[1]))['stats']; c=s['covariance']; print(sys.argv[2], s['cells_used'], 'cells, r %.4f g %.4f, s.d. %.3f %.3f, mean RGB DN' % (s['mean']['r'], s['mean']['g'], c['rr']**0.5, c['gg']**0.5), [round(x, 1) for x in s['mean_rgb_dn']])" "$work/$c/chroma.json" "$c"
done
echo "pictures in $img"
