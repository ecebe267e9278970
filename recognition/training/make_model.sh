#!/usr/bin/env bash
# The shipped classifier from scratch, seeded: renders the training data with facyl_crops
# (2 x SCENES simulated scenes, seeds 50000.. and 60000.., in parallel), trains
# train_classifier.py (depth channels, 24 epochs, seed 0) and writes OUT/cylinder_net.onnx,
# .cfg, curves.png, report.json. About 10 minutes on 2 cores.
#   recognition/training/make_model.sh OUT [SCENES (default 1200)] [BUILD (default build)]
# Then: cp OUT/cylinder_net.onnx OUT/cylinder_net.cfg recognition/models/
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: make_model.sh OUT [SCENES] [BUILD]}
scenes=${2:-1200}
build=${3:-build}
crops="$build/apps/facyl_crops"
[ -x "$crops" ] || { echo "make_model: build facyl first ($crops is missing)" >&2; exit 1; }
mkdir -p "$out/data/a" "$out/data/b"
"$crops" --sim "$scenes" --seed 50000 "$out/data/a" &
a=$!
"$crops" --sim "$scenes" --seed 60000 "$out/data/b" &
b=$!
wait $a
wait $b
/usr/bin/python3 recognition/training/train_classifier.py --data "$out/data/a" "$out/data/b" \
  --out "$out" --channels depth --epochs 24 --seed 0
