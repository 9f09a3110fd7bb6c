#!/usr/bin/env bash
# Writes benchmarks/results.d/42_lesions.md: lesion discs of one preset inside lateral_tongue, lit
# uniformly and rendered through the spatial transport (`spatial_lesion_*`, "transport": "spatial")
# or the volume walk (`volume_lesion_*`, "transport": "volume"), against the 3D forward Monte Carlo's
# radiance along the normal (docs/layered-tissue.md, "How it was checked").
# Usage: benchmarks/lesion_results.sh [build-dir] [case ...]
#   cases default to every lesion disc of both transports (`oralfluor bench --list`);
#   samples: $OFL_LESION_SAMPLES if set, else 1.6e7 for spatial reflectance and 4e6 otherwise;
#   each case's JSON is kept in $OFL_LESION_RUNS (default benchmarks/results.d/lesion_runs, not in
#   git): a case already there is not run again, so an interrupted run resumes where it stopped.
# A spatial reflectance case takes 10-25 minutes on 2 cores at 1.6e7, a volume-walk case 3-10 at 4e6.
set -euo pipefail
build=${1:-build}
shift || true
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/benchmarks/results.d/42_lesions.md"
runs=${OFL_LESION_RUNS:-$root/benchmarks/results.d/lesion_runs}
mkdir -p "$runs"
cases=("$@")
if [ ${#cases[@]} -eq 0 ]; then
  mapfile -t cases < <("$build/oralfluor" bench --list | awk '{print $1}' | grep -E '^(spatial|volume)_lesion_')
fi
for c in "${cases[@]}"; do
  [ -s "$runs/$c.json" ] && continue
  samples=4000000
  case "$c" in spatial_lesion_*_fluorescence) ;; spatial_lesion_*) samples=16000000 ;; esac
  samples=${OFL_LESION_SAMPLES:-$samples}
  echo "$(date -u +%H:%M:%S) $c --samples $samples --seed 7" >&2
  if "$build/oralfluor" bench "$c" --samples "$samples" --seed 7 --json > "$runs/$c.json.part" 2> "$runs/$c.err" ||
     [ -s "$runs/$c.json.part" ]; then  # (a failed check still writes its result; exit 1)
    mv "$runs/$c.json.part" "$runs/$c.json"
  else
    echo "$c: no result ($(tail -1 "$runs/$c.err"))" >&2
  fi
done
python3 "$root/benchmarks/lesion_table.py" "$runs" "$root" "$build" "${cases[@]}" > "$out"
echo "wrote $out"
