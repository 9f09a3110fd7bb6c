#!/usr/bin/env bash
# oralfluor against pbrt-v4, side by side on the same work: the scene pairs of
# benchmarks/scenes/peers/ (README.md there), rendered in interleaved rounds at the same samples
# per pixel and thread count. The tongue in the mouth (pbrt's four spot lights in both, 47 bands of
# 10 nm, path depth 5) also gets one reference of many samples per renderer, and
# benchmarks/peer_compare turns the files into camera samples per second, rays per camera sample,
# and the time each renderer needs to reach the same relative RMS error against its own reference
# (total radiance and per 10 nm band). The flat patch is timed only (camera samples per second).
#
# usage: benchmarks/vs_pbrt.sh <build dir> [out dir] [rounds]
#   PBRT     the pbrt-v4 executable (default: `pbrt` on PATH)
#   THREADS  threads for both renderers (default 2)
#   SPP      samples per pixel of each round (default 64: below that pbrt's spectral film leaves
#            buckets without a sample, benchmarks/scenes/peers/README.md)
#   REF_SPP  samples per pixel of the references (default 1024); REUSE_REF=1 keeps each reference
#            already in the out dir (render again after changing a renderer: delete its reference)
#
# pbrt-v4 is not part of this project and is never committed to it: it is public (github.com/mmp/pbrt-v4,
# with its submodules). Build its CPU renderer in Release outside this repository as its own README
# describes and point PBRT at the `pbrt` it produces. Without it this script says so and exits 0.
set -euo pipefail
build=${1:?usage: benchmarks/vs_pbrt.sh <build dir> [out dir] [rounds]}
out=${2:-out/vs_pbrt}
rounds=${3:-5}
threads=${THREADS:-2}
spp=${SPP:-64}
ref_spp=${REF_SPP:-1024}
here=$(cd "$(dirname "$0")" && pwd)
peers=$here/scenes/peers
pbrt=${PBRT:-$(command -v pbrt || true)}

if [[ -z "$pbrt" || ! -x "$pbrt" ]]; then
  echo "vs_pbrt: skipped: no pbrt-v4 executable (set PBRT=/path/to/pbrt). pbrt-v4 is public at" \
       "github.com/mmp/pbrt-v4; build its CPU renderer (Release) outside this repository, never commit it."
  exit 0
fi
for b in oralfluor peer_compare; do
  [[ -x "$build/$b" ]] || { echo "vs_pbrt: $build/$b is missing: cmake --build $build --target oralfluor peer_compare" >&2; exit 2; }
done

mkdir -p "$out"
out=$(cd "$out" && pwd)
# pbrt reads PLY meshes written by the scene pair's generator (the same vertices as tongue_mouth.glb).
cp "$peers"/*.pbrt "$peers/gen_tongue_mouth.py" "$out/"
[[ -s "$out/geometry/tongue.ply" && -s "$out/geometry/mouth.ply" ]] || /usr/bin/python3 "$out/gen_tongue_mouth.py" > /dev/null

# Each run also writes <stem>.time: wall, user and system seconds of the whole process (bash's
# `time`), from which peer_compare takes CPU time (robust to other processes on a shared machine).
TIMEFORMAT='%R %U %S'
run_oralfluor() {  # <scene> <dir> <spp> <seed>
  { time "$build/oralfluor" render "$peers/$1_matched.json" -o "$2" --spp "$3" --seed "$4" --threads "$threads" > "$2.log" 2>&1; } 2> "$2.time"
}
run_pbrt() {  # <scene> <file stem> <spp> <seed>
  { time (cd "$out" && "$pbrt" --nthreads "$threads" --spp "$3" --seed "$4" --stats --outfile "$2.exr" "$out/$1.pbrt" > "$2.log" 2>&1); } 2> "$2.time"
}

# <scene> <rounds> <with references: 1|0>
compare_scene() {
  local scene=$1 n=$2 refs=$3 d=$out/$1 loads=()
  mkdir -p "$d"
  if ((refs)); then
    if [[ "${REUSE_REF:-0}" == 1 && -s "$d/oralfluor_ref/radiance.exr" ]]; then
      echo "$scene: oralfluor reference kept from $d"
    else
      echo "$scene: oralfluor reference ($ref_spp spp) ..."
      run_oralfluor "$scene" "$d/oralfluor_ref" "$ref_spp" 1000
    fi
    if [[ "${REUSE_REF:-0}" == 1 && -s "$d/pbrt_ref.exr" ]]; then
      echo "$scene: pbrt-v4 reference kept from $d"
    else
      echo "$scene: pbrt-v4 reference ($ref_spp spp) ..."
      run_pbrt "$scene" "$d/pbrt_ref" "$ref_spp" 1000
    fi
  fi
  printf '{"spp": %d, "round_spp": %d}\n' "$ref_spp" "$spp" > "$d/pbrt_ref.json"
  # Loading and building cost CPU time too: runs of 1 spp (three each, interleaved) measure it.
  for ((i = 1; i <= 3; ++i)); do
    run_oralfluor "$scene" "$d/oralfluor_setup_$i" 1 "$i"
    run_pbrt "$scene" "$d/pbrt_setup_$i" 1 "$i"
  done
  for ((i = 1; i <= n; ++i)); do
    # Interleaved, the order alternating, so that both see the same load on average.
    if ((i % 2)); then
      run_oralfluor "$scene" "$d/oralfluor_$i" "$spp" "$i"; loads+=("$(load)")
      run_pbrt "$scene" "$d/pbrt_$i" "$spp" "$i"; loads+=("$(load)")
    else
      run_pbrt "$scene" "$d/pbrt_$i" "$spp" "$i"; loads+=("$(load)")
      run_oralfluor "$scene" "$d/oralfluor_$i" "$spp" "$i"; loads+=("$(load)")
    fi
  done
  echo "$scene: load average (1 min) after each render: ${loads[*]}"
  local mode=()
  ((refs)) || mode=(--speed-only)
  "$build/peer_compare" "$d" "$n" "${mode[@]}" | tee "$d/summary.md"
  "$build/peer_compare" "$d" "$n" "${mode[@]}" --json > "$d/summary.json"
}

load() { cut -d' ' -f1 /proc/loadavg; }
echo "vs_pbrt: pbrt-v4 at $pbrt; $threads threads each; $rounds rounds of $spp spp; references of $ref_spp spp"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg) ($(nproc) cores)"
compare_scene tongue_mouth "$rounds" 1
compare_scene flat_patch "$rounds" 0
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
