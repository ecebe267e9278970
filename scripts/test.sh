#!/usr/bin/env bash
# New user, step 2 (and CI): install what is needed, build everything with the tests, and run
# them (unit and accuracy tests, the tools, hostile inputs, and a downstream project using
# find_package(facyl)).
#   --sanitize  also build in build-sanitize/ with AddressSanitizer + UndefinedBehaviorSanitizer
#               and run the suite there (all tests but the benchmark smoke test and the
#               Python module's, which an uninstrumented interpreter cannot load, and the
#               viewer's: VTK under xvfb, not checked under the sanitizers)
set -euo pipefail
cd "$(dirname "$0")/.."
sanitize=0
for a in "$@"; do
  case "$a" in
    --sanitize) sanitize=1 ;;
    *) echo "usage: scripts/test.sh [--sanitize]" >&2; exit 2 ;;
  esac
done
bash scripts/setup.sh
bash scripts/check_format.sh # unformatted C++ fails CI (scripts/check_format.sh --fix formats it)
# The same configure as demo.sh (they share build/): the benchmarks on even in a cache made
# without them.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFACYL_BUILD_TESTS=ON -DFACYL_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
if [ "$sanitize" -eq 1 ]; then
  # Debian's Eigen switches to its own aligned allocator under ASan while PCL's libraries
  # free with plain free(): EIGEN_MALLOC_ALREADY_ALIGNED keeps both on malloc. PCL (C++14)
  # and facyl (C++17) disagree on sized delete: alloc_dealloc_mismatch=0.
  flags="-O1 -g1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
  flags="$flags -DEIGEN_MALLOC_ALREADY_ALIGNED=1"
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=None -DFACYL_BUILD_TESTS=ON \
    -DFACYL_BUILD_BENCHMARKS=OFF "-DCMAKE_CXX_FLAGS=$flags" \
    "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" \
    "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined" >/dev/null
  cmake --build build-sanitize -j"$(nproc)"
  ASAN_OPTIONS=alloc_dealloc_mismatch=0:detect_leaks=1:abort_on_error=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" -E "facyl_bench_quick|python_bindings|viewer_screenshots"
fi
