#!/usr/bin/env bash
# The main job: the paper's experiment end to end.
#  1. builds the release binary (installing cmake/libclang first if missing);
#  2. generates and certifies the paper's four profiles (gaze 90°, left);
#  3. runs the T-intersection experiment in both return models (planar geometry)
#     (4 variants × 3 fog levels × 100 trials each), prints the table,
#     writes CSV, JSON, the plots and the reproduction report, which adds the
#     paper's pipeline (carla geometry, ARGUS detector and arrival, argus model;
#     PIPELINE_TRIALS per cell, default 100).
# Outputs go to $OUT (default: out/); the report to docs/reproduction.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --release --quiet
B=target/release/gaze-lidar
OUT=${OUT:-out}
TRIALS=${TRIALS:-100}
mkdir -p "$OUT/profiles"
echo "== the paper's profiles (gaze 90°), certified" >&2
for mode in baseline range resolution joint; do
  $B profile --preset paper --mode "$mode" --gaze-deg 90 --out "$OUT/profiles/paper-$mode.json"
  $B check "$OUT/profiles/paper-$mode.json" 2>/dev/null | head -1 | cut -c1-160
done
echo "== the intersection experiment: ${TRIALS} trials per cell" >&2
$B simulate --trials "$TRIALS" --seed 1 --plots "$OUT/plots" --trials-csv "$OUT/trials.csv" \
  --report docs/reproduction.md --paper-pipeline-trials "${PIPELINE_TRIALS:-100}" --export-json "$OUT/results.json" --export-csv "$OUT/results.csv"
echo "results: $OUT/results.json, $OUT/results.csv, $OUT/trials.csv; plots: $OUT/plots/; report: docs/reproduction.md" >&2
