#!/usr/bin/env bash
# Regenerates docs/scenarios.md byte for byte: every scenario file under
# examples/scenarios/ (the paper's four variants, physical model, every fog
# level) and `simulate --gaze` on recorded traces and on each named gaze
# behaviour (paper scene, clear air), with bootstrap intervals, TTA modes and
# paired tests (examples/scenarios_doc.rs). TRIALS per cell (default 100), seed 1.
#   bash scripts/scenarios.sh
set -euo pipefail
cd "$(dirname "$0")/.."
TRIALS=${TRIALS:-100}
cargo run --release --quiet --example scenarios_doc -- "$TRIALS" >docs/scenarios.md.tmp
mv docs/scenarios.md.tmp docs/scenarios.md
echo "wrote docs/scenarios.md" >&2
