#!/usr/bin/env bash
# A classifier model on the real sets (never trained on): the rgbd frames (score_frames.py's
# line and the AUC of the labelled and of all output objects), mOSD learn33-44 (the detection
# table at the defaults; AUC with every object fitted, --reject-below 0) and the UW crops;
# with REPORT_DIR (train_classifier.py's OUT) also its held-out simulated test split.
#   recognition/training/evaluate_model.sh MODEL.onnx|default OUT [REPORT_DIR] [BUILD]
# Writes OUT/rgbd.jsonl, OUT/mosd.md, OUT/mosd.csv, OUT/uw/, OUT/summary.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
model=${1:?usage: evaluate_model.sh MODEL OUT [REPORT_DIR] [BUILD]}
out=${2:?usage: evaluate_model.sh MODEL OUT [REPORT_DIR] [BUILD]}
report=${3:-}
build=${4:-build}
real=${FACYL_REAL_DATA_DIR:-../shared/data/real}
tools=${FACYL_TOOLS_DIR:-../shared/tools}
mkdir -p "$out/uw"
"$build/apps/facyl_detect" --model "$model" "$real"/rgbd/*/*.pcd > "$out/rgbd.jsonl" 2> /dev/null || true
"$build/apps/facyl_tabletop_eval" --model "$model" --mosd "$real/mosd" > "$out/mosd.md" 2>&1
"$build/apps/facyl_tabletop_eval" --model "$model" --mosd "$real/mosd" --reject-below 0 \
  --csv "$out/mosd.csv" > /dev/null 2>&1
"$build/apps/facyl_crops" --uw "$real/uw_objects" --model "$model" "$out/uw" > /dev/null
sim=()
[ -n "$report" ] && [ -f "$report/test_predictions.csv" ] && sim=(--sim "$report/test_predictions.csv")
{
  echo "rgbd: $(/usr/bin/python3 "$tools/score_frames.py" "$real/rgbd/labels.csv" "$out/rgbd.jsonl")"
  echo "mOSD: $(grep -A12 'Positives = `cylinder` and' "$out/mosd.md" | grep '(default)')"
  /usr/bin/python3 recognition/training/evaluate_classifier.py "${sim[@]}" --mosd "$out/mosd.csv" \
    --uw "$out/uw/objects.csv" --rgbd "$out/rgbd.jsonl" --rgbd-labels "$real/rgbd/labels.csv"
} | tee "$out/summary.md"
