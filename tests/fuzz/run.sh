#!/bin/sh
# Builds the libFuzzer harnesses with clang (build-fuzz/) and runs each for SECONDS (default 60),
# corpora seeded from the shipped files, findings in build-fuzz/findings/<entry>/, the whole
# libFuzzer log (with the final stats) in build-fuzz/findings/<entry>.log.
#   tests/fuzz/run.sh [SECONDS] [entry ...]
# A finding is fixed, then its input is copied to tests/fuzz/regressions/<entry>/ so that the
# normal build's test (tests/test_fuzz_regressions.cpp) keeps running it.
set -eu
cd "$(dirname "$0")/../.."
SECONDS_EACH=${1:-60}
[ $# -gt 0 ] && shift
ENTRIES=${*:-"scene_json camera_json sweep_json spectrum_csv eem_csv mat diagnose_model diagnose_index gltf glb obj ies spectral_exr image_png diagnose_selection iset_export iset_import"}
B=build-fuzz
cmake -S . -B $B -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DOFL_FUZZ=ON > $B.configure.log 2>&1 || { cat $B.configure.log; exit 1; }
for e in $ENTRIES; do cmake --build $B -j "${JOBS:-$(nproc)}" --target fuzz_$e; done
for e in $ENTRIES; do
  mkdir -p $B/corpus/$e $B/findings/$e
  OFL_FUZZ_SEED_DIR=$B/corpus/$e $B/fuzz_$e
  [ -d tests/fuzz/regressions/$e ] && cp tests/fuzz/regressions/$e/* $B/corpus/$e/ 2>/dev/null || true
  echo "== fuzz_$e for $SECONDS_EACH s"
  ASAN_OPTIONS=detect_leaks=0 $B/fuzz_$e $B/corpus/$e -max_total_time=$SECONDS_EACH -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix=$B/findings/$e/ -print_final_stats=1 > $B/findings/$e.log 2>&1 || true
  tail -15 $B/findings/$e.log
done
