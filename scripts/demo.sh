#!/usr/bin/env bash
# New user, step 1: install what is needed, build (Release), and find every cylinder on the
# table of the bundled RGB-D frame (data/default_scene.pcd, rendered by facyl_synth --layout cluttered --seed 20).
# Writes build/default_scene_overlay.png. Any arguments are passed to facyl_detect instead.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# build/ is test.sh's too: configured as test.sh does (whichever runs first, the cache is the
# same; CTest scripts_configure_alike), only the demo's tools built.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DFACYL_BUILD_TESTS=ON -DFACYL_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build -j"$(nproc)" --target facyl_detect facyl_fit facyl_synth
if [ $# -eq 0 ]; then
  set -- --overlay build/default_scene_overlay.png data/default_scene.pcd
fi
echo "facyl_detect $*"
./build/apps/facyl_detect "$@"
