#!/usr/bin/env bash
# The main job: the paper's experiment end to end.
# Builds the release binary, generates and certifies the paper's profiles.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo build --release --quiet
B=target/release/gaze-lidar
OUT=${OUT:-out}
mkdir -p "$OUT/profiles"
for mode in baseline range resolution joint; do
  $B profile --preset paper --mode "$mode" --gaze-deg 90 --out "$OUT/profiles/paper-$mode.json"
  $B check "$OUT/profiles/paper-$mode.json"
done
