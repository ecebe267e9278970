#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/ and runs each for
# SECONDS (default 600) on its corpus in fuzz/corpus/<target> (new inputs go to
# build-fuzz/corpus/<target>; crashes to build-fuzz/crashes/). The targets run at once.
#   scripts/fuzz.sh [SECONDS] [pcd|estimator ...]      (default: both)
# A crash input belongs in fuzz/corpus/<target>/ once fixed: CTest replays that corpus.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(pcd estimator)
command -v clang++ >/dev/null || { echo "fuzz: needs clang (apt-get install clang)" >&2; exit 1; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Release -DFACYL_BUILD_FUZZERS=ON \
  -DFACYL_BUILD_APPS=OFF -DFACYL_BUILD_TESTS=OFF -DFACYL_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_pcd fuzz_estimator
mkdir -p build-fuzz/crashes
export ASAN_OPTIONS=alloc_dealloc_mismatch=0:detect_leaks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
pids=()
for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t"
  "build-fuzz/fuzz/fuzz_$t" "build-fuzz/corpus/$t" "fuzz/corpus/$t" -max_total_time="$seconds" \
    -rss_limit_mb=4096 -max_len=65536 -timeout=30 -artifact_prefix="build-fuzz/crashes/${t}-" \
    -print_final_stats=1 >"build-fuzz/fuzz_$t.log" 2>&1 &
  pids+=($!)
done
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || status=1
done
for t in "${targets[@]}"; do
  echo "== fuzz_$t"
  grep -E "stat::number_of_executed_units|stat::new_units_added|stat::peak_rss_mb|ERROR|SUMMARY" \
    "build-fuzz/fuzz_$t.log" || true
done
exit $status
