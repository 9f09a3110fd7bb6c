#!/usr/bin/env bash
# Lesion size: how small a dark spot can the OralEye-like camera show, and tell a lesion from a blood
# spot of the same size? Renders scenes/dark_spot_spatial_{385,405,450}.json with the dysplastic
# lesion and the blood spot as discs of 1, 2, 3, 5 and 10 mm diameter, with light travelling
# sideways in the tissue ("spatial") and without ("table", position-free), passes each through
# scenes/cameras/oraleye.json and measures each region with `oralfluor chroma --roi-material`:
# intensity against the healthy tongue, (r, g) chromaticity, and the lesion-vs-blood-spot distance in
# units of the healthy tongue's spread and of the two means' standard errors. Also the fluorescence
# profile across the lesion's edge (image row through its centre) for both transports.
# Usage: benchmarks/dark_spot_sizes.sh [build-dir] [out-dir] [width height spp]
# Writes <out>/sizes.md (the tables of docs/layered-tissue.md "Lesion size") and <out>/*.png.
set -euo pipefail
build=${1:-build}
out=${2:-out/dark_spot_sizes}
w=${3:-480}; h=${4:-360}; spp=${5:-16}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
for nm in 385 405 450; do
  for transport in spatial table; do
    for d in 1 2 3 5 10; do
      dir="$out/$nm/$transport/d$d"
      if [ ! -f "$dir/cam/raw.tiff" ]; then
        mkdir -p "$dir"
        /usr/bin/python3 - "$root/scenes/dark_spot_spatial_$nm.json" "$dir/scene.json" "$transport" "$d" <<'PY'
import json, os, sys
src, dst, transport, d = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
j = json.load(open(src))
base = os.path.dirname(src)
def absolute(x):  # file names in the scene are relative to it
    if isinstance(x, dict):
        return {k: absolute(v) for k, v in x.items()}
    if isinstance(x, list):
        return [absolute(v) for v in x]
    if isinstance(x, str) and not os.path.isabs(x) and os.path.isfile(os.path.join(base, x)):
        return os.path.join(base, x)
    return x
j = absolute(j)
for m in ("tongue_healthy", "dysplasia", "blood_spot"):
    j["materials"][m]["transport"] = transport
for r in j["materials"]["tongue"]["regions"]:
    r["sphere"]["radius_mm"] = d / 2
json.dump(j, open(dst, "w"), indent=1)
PY
        "$build/oralfluor" render "$dir/scene.json" -o "$dir" --width "$w" --height "$h" --spp "$spp" > "$dir/render.log" 2>&1
        "$build/oralfluor" camera "$dir/radiance.exr" --camera "$root/scenes/cameras/oraleye.json" -o "$dir/cam" > /dev/null
      fi
      for m in tongue_healthy dysplasia blood_spot; do
        "$build/oralfluor" chroma "$dir/cam/raw.tiff" --roi-material "$m" --name "chroma_$m" --json > "$dir/chroma_$m.json" 2>/dev/null || true
      done
    done
  done
done
PYTHONPATH="$build/python" /usr/bin/python3 "$root/benchmarks/dark_spot_sizes.py" "$out" "$root"
