#!/usr/bin/env bash
# The detection objective's table (specs/optimizer.md,
# "The detection objective: measured"): for every shipped config
# (examples/configs/), `simulate --variant optimized --optimizer-config C`
# with objective.kind = "sqrt" and = "detection", both return models,
# fog 0/25/50 %, 100 trials, against the closed forms on the same sensor;
# medians with seeded paired-bootstrap 95 % intervals
# (scripts/detection_table.py).
#
# Usage: scripts/detection_table.sh [OUT_DIR]   (binary: $GAZE_LIDAR, or
# target/release/gaze-lidar). Prints the Markdown table on stdout.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN="${GAZE_LIDAR:-${CARGO_TARGET_DIR:-target}/release/gaze-lidar}"
OUT="${1:-$(mktemp -d)}"
TRIALS="${TRIALS:-100}"
mkdir -p "$OUT"
# Closed forms: simulate's closed-form variants run on the paper sensor.
"$BIN" simulate --variant baseline --variant range --variant resolution --variant joint \
  --trials "$TRIALS" --trials-csv "$OUT/closed.csv" >/dev/null
for cfg in examples/configs/*.toml; do
  name="$(basename "$cfg" .toml)"
  for kind in sqrt detection; do
    tmp="$OUT/$name.$kind.toml"
    # [objective] is the last table of every shipped config: set its kind.
    last="$(grep -E '^\[' "$cfg" | tail -1)"
    if [ "$last" != "[objective]" ]; then
      echo "$cfg: [objective] is not the last table" >&2; exit 2
    fi
    grep -vE '^kind *=' "$cfg" >"$tmp"
    printf 'kind = "%s"\n' "$kind" >>"$tmp"
    if ! "$BIN" simulate --variant optimized --optimizer-config "$tmp" \
      --trials "$TRIALS" --trials-csv "$OUT/$name.$kind.csv" >/dev/null 2>"$OUT/$name.$kind.err"; then
      echo "$name ($kind): $(tail -1 "$OUT/$name.$kind.err")" >"$OUT/$name.$kind.failed"
    fi
  done
done
python3 scripts/detection_table.py "$OUT"
