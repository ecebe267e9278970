#!/usr/bin/env bash
# New user, step 2 (and CI): install what is needed, build everything with the tests, and run
# them (unit and accuracy tests, the tools, and a downstream project using find_package(facyl)).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFACYL_BUILD_TESTS=ON >/dev/null
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
