#!/bin/sh
# Rewrites tests/data/optimizer_golden/ with BIN (default: the release
# binary of CARGO_TARGET_DIR or target/): the four shipped configs at gazes
# 0, 90 and 200, profile + certificate folder. Only for a change meant to
# move the optimizer's answers (tests/it/optimizer/golden.rs compares them).
set -eu
cd "$(dirname "$0")/.."
BIN=${BIN:-${CARGO_TARGET_DIR:-target}/release/gaze-lidar}
D=tests/data/optimizer_golden
rm -rf "$D"
mkdir -p "$D"
for c in paper multi_level smooth vls128_eye; do
  for g in 0 90 200; do
    "$BIN" profile --config "examples/configs/$c.toml" --gaze-deg "$g" \
      --certificate "$D/${c}_g$g" --out "$D/${c}_g$g.json"
    # The detection bound's certificate (several MB on smooth) is checked
    # when written; the golden test compares the profile and certificate.json.
    rm -f "$D/${c}_g$g/detection_bound.json"
  done
done
