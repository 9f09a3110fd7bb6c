#!/bin/sh
# The bookkeeping of a sweep at the design limit (docs/sweep-format.md, "Size"): a Latin hypercube
# of 100000 points over two ranges of the tiny sweep's scene. Times the dry run, then fills the
# points folder with 100000 copies of one real point's result (each under its own key, index and
# parameter values, as a finished run would leave them) and times --report-only, with peak memory
# and the sizes of what the report writes. Needs about 4 GB of free disk in WORK.
#   benchmarks/sweep_size.sh [build] [work folder]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
B=${1:-$root/build}
W=${2:-/tmp/ofl_sweep_size}
rm -rf "$W"
mkdir -p "$W"
python3 - "$root" "$W" <<'PY'
import json, sys
root, w = sys.argv[1], sys.argv[2]
t = json.load(open(root + "/scenes/sweeps/tiny.json"))
t["scene"] = root + "/scenes/lesion_385.json"
t["camera"] = root + "/scenes/cameras/oraleye.json"
for r in t["rois"]:
    if "texture" in r: r["texture"] = root + "/assets/textures/tongue_lesion.png"
t["design"] = {"type": "latin_hypercube", "points": 100000, "seed": 3}
t["parameters"] = [{"name": "distance_m", "generator": "rig_distance", "range": {"min": 0.07, "max": 0.1}},
                   {"name": "half", "generator": "led_half_angle", "range": {"min": 20, "max": 60}}]
json.dump(t, open(w + "/big.json", "w"), indent=1)
PY
echo "== dry run of 100000 points"
/usr/bin/time -f "%e s wall, %M KiB peak" "$B/oralfluor" sweep "$W/big.json" -o "$W/out" --dry-run > "$W/dry.txt"
tail -1 "$W/dry.txt"
echo "== one real point (its result is the template), then SIGINT"
OFL_NO_PROGRESS=1 "$B/oralfluor" sweep "$W/big.json" -o "$W/out" > /dev/null 2> "$W/run.err" &
pid=$!
while ! ls "$W/out/points/"*.json > /dev/null 2>&1; do sleep 0.2; done
kill -INT $pid; wait $pid || true
python3 - "$W" <<'PY'
import json, os, sys, glob
w = sys.argv[1]
manifest = json.load(open(w + "/out/sweep.json"))
template = json.load(open(glob.glob(w + "/out/points/*.json")[0]))
names = [p["name"] for p in manifest["spec"]["parameters"]]
r = dict(template)
r["key"], r["index"], r["label"], r["parameters"] = "@KEY@", -987654321, "@LABEL@", "@PARAMETERS@"
text = json.dumps(r, indent=1) + "\n"
for p in manifest["points"]:
    t = text.replace('"@KEY@"', json.dumps(p["key"])).replace("-987654321", str(p["index"]))
    t = t.replace('"@LABEL@"', json.dumps(p["label"])).replace('"@PARAMETERS@"', json.dumps(dict(zip(names, p["values"]))))
    with open(w + "/out/points/" + p["key"] + ".json", "w") as f:
        f.write(t)
print("wrote", len(manifest["points"]), "point files of", os.path.getsize(glob.glob(w + "/out/points/*.json")[0]), "bytes each")
PY
echo "== report of 100000 finished points"
/usr/bin/time -f "%e s wall, %M KiB peak" "$B/oralfluor" sweep "$W/big.json" -o "$W/out" --report-only
ls -l "$W/out/report.html" "$W/out/results.csv" "$W/out/results.json" | awk '{print $5, $9}'
rm -rf "$W"
