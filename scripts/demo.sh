#!/usr/bin/env bash
# New user, step 1: install what is needed, build (Release), and fit the cylinder of the
# bundled scene. Any arguments are passed to facyl_fit instead of the default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFACYL_BUILD_TESTS=OFF -DFACYL_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build -j"$(nproc)" --target facyl_fit
if [ $# -eq 0 ]; then
  set -- data/default_cylinder.pcd
fi
echo "facyl_fit $*"
./build/apps/facyl_fit "$@"
