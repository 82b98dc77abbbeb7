#!/usr/bin/env bash
# The Python package: build `pip install ./python` into a fresh venv (as a
# user would), then run its pytest suite and print the apply_profile
# benchmark. The wheel's Rust build shares the workspace's target/ (the
# python crate uses the root's release profile), so HiGHS is not rebuilt.
# Also keeps the binding crate fmt- and clippy-clean (it is its own
# workspace, outside `cargo … --workspace`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export CARGO_TARGET_DIR="$PWD/target"
PY=${PYTHON:-python3}

echo "== python: fmt + clippy (binding crate)"
cargo fmt --check --manifest-path python/Cargo.toml
cargo clippy --release --manifest-path python/Cargo.toml --all-targets -- -D warnings

venv=$(mktemp -d "${TMPDIR:-/tmp}/gaze-lidar-venv.XXXXXX")
trap 'rm -rf "$venv"' EXIT
echo "== python: pip install ./python into a fresh venv ($venv)"
"$PY" -m venv "$venv"
"$venv/bin/pip" install -q ./python   # exactly what a user runs
"$venv/bin/python" -m pip install -q pytest

echo "== python: pytest"
# From outside the source tree, so the installed package is what is tested.
(cd "$venv" && "$venv/bin/python" -m pytest -q -p no:cacheprovider "$OLDPWD/python/tests" "$@")

echo "== python: benchmark (apply_profile, 100k points)"
"$venv/bin/python" python/benchmarks/apply_profile.py --repeat 100
