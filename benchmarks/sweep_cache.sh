#!/usr/bin/env bash
# Camera-only sweeps render once: scenes/sweeps/filter_edge.json (20 levels of the
# emission long-pass edge, 450-500 nm, on the demo scene) run with the render cache and again with
# --no-render-cache. Prints the wall time of both runs, how many renders each made, and whether
# every point's metrics agree bit for bit.
# Usage: benchmarks/sweep_cache.sh [build-dir] [out-dir] [width spp]   (docs/sweep-format.md)
set -euo pipefail
build=${1:-build}
out=${2:-out/sweep_cache}
w=${3:-160}; spp=${4:-16}
root=$(cd "$(dirname "$0")/.." && pwd)
sweep="$root/scenes/sweeps/filter_edge.json"
rm -rf "$out/cached" "$out/uncached"
mkdir -p "$out"
run() {  # run <dir> [flags...]: wall seconds of one whole sweep
  local dir=$1; shift
  local t0 t1
  t0=$(date +%s.%N)
  "$build/oralfluor" sweep "$sweep" -o "$dir" --width "$w" --spp "$spp" --json "$@" > "$dir.summary.json" 2> "$dir.log"
  t1=$(date +%s.%N)
  python3 -c "print(f'{$t1 - $t0:.1f}')"
}
cached_s=$(run "$out/cached")
uncached_s=$(run "$out/uncached" --no-render-cache)
python3 - "$out" "$cached_s" "$uncached_s" "$w" "$spp" <<'PY'
import json, sys, glob, os
out, cached_s, uncached_s, w, spp = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4], sys.argv[5]
def points(d):
    return {p["key"]: p for p in (json.load(open(f)) for f in glob.glob(f"{out}/{d}/points/*.json"))}
c, u = points("cached"), points("uncached")
renders_c = sum(not p["render_cached"] for p in c.values())
renders_u = sum(not p["render_cached"] for p in u.values())
exr = len(glob.glob(f"{out}/cached/renders/*.exr"))
same = all(c[k]["metrics"] == u[k]["metrics"] for k in c) and c.keys() == u.keys()
render_s = sum(p["render"]["seconds"] for p in u.values()) / max(1, len(u))
print(f"| run | points | renders | wall time |")
print(f"|---|---|---|---|")
print(f"| render cache (default) | {len(c)} | {renders_c} ({exr} EXR in renders/) | {cached_s:.1f} s |")
print(f"| --no-render-cache | {len(u)} | {renders_u} | {uncached_s:.1f} s |")
print()
print(f"{w} px wide, {spp} spp; {uncached_s / cached_s:.1f}x faster with the cache; a render takes {render_s:.1f} s on average "
      f"(render.seconds, uncached run); metrics of every point equal bit for bit: {'yes' if same else 'NO'}.")
PY
