#!/usr/bin/env bash
# The test suite: unit, property, integration (through the binary), doctests,
# and every Kani harness body as an ordinary test. One build profile
# (release) so HiGHS is compiled once.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo test --release --workspace --all-targets "$@"
cargo test --release --workspace --doc
