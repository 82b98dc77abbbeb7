#!/usr/bin/env bash
# The detection objective's table (specs/optimizer.md,
# "Measured: `simulate --variant optimized` against the closed forms"):
# for every shipped config (examples/configs/),
# `simulate --variant optimized --optimizer-config C` with
# objective.kind = "sqrt" and = "detection", both return models,
# fog 0/25/50 %, 100 trials, against the closed forms on the config's own
# sensor, limits and driver model (simulate runs them there when given
# --optimizer-config); a closed form the sensor's limits reject is run
# alone per return model and its first violated limit kept (simulate's own
# message). Medians with seeded paired-bootstrap 95 % intervals
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
CLOSED=(baseline range resolution joint)
for cfg in examples/configs/*.toml; do
  name="$(basename "$cfg" .toml)"
  # [objective] is the last table of every shipped config: set its kind.
  last="$(grep -E '^\[' "$cfg" | tail -1)"
  if [ "$last" != "[objective]" ]; then
    echo "$cfg: [objective] is not the last table" >&2; exit 2
  fi
  for kind in sqrt detection; do
    grep -vE '^kind *=' "$cfg" >"$OUT/$name.$kind.toml"
    printf 'kind = "%s"\n' "$kind" >>"$OUT/$name.$kind.toml"
  done
  rm -f "$OUT/$name".closed*.csv "$OUT/$name.closed.rejected" "$OUT/$name".*.failed
  # The closed forms on the config's sensor (simulate needs the optimized
  # variant with --optimizer-config; its rows are left out of the table).
  closed_args=()
  for v in "${CLOSED[@]}"; do closed_args+=(--variant "$v"); done
  if ! "$BIN" simulate --variant optimized "${closed_args[@]}" \
    --optimizer-config "$OUT/$name.sqrt.toml" --trials "$TRIALS" \
    --trials-csv "$OUT/$name.closed.csv" >/dev/null 2>"$OUT/$name.closed.err"; then
    # One closed form rejected: each alone, per return model.
    for v in "${CLOSED[@]}"; do
      for m in argus physical; do
        if ! "$BIN" simulate --variant optimized --variant "$v" --model "$m" \
          --optimizer-config "$OUT/$name.sqrt.toml" --trials "$TRIALS" \
          --trials-csv "$OUT/$name.closed.$v.$m.csv" >/dev/null 2>"$OUT/$name.closed.err"; then
          printf '%s\t%s\t%s\n' "$v" "$m" "$(tail -1 "$OUT/$name.closed.err")" >>"$OUT/$name.closed.rejected"
        fi
      done
    done
  fi
  for kind in sqrt detection; do
    if ! "$BIN" simulate --variant optimized --optimizer-config "$OUT/$name.$kind.toml" \
      --trials "$TRIALS" --trials-csv "$OUT/$name.$kind.csv" >/dev/null 2>"$OUT/$name.$kind.err"; then
      echo "$name ($kind): $(tail -1 "$OUT/$name.$kind.err")" >"$OUT/$name.$kind.failed"
    fi
  done
done
python3 scripts/detection_table.py "$OUT"
