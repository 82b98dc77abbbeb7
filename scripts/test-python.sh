#!/usr/bin/env bash
# The Python package: build `pip install ./python` into a fresh venv (as a
# user would), then run its pytest suite (hypothesis property tests
# included), `mypy.stubtest` on the installed package, `mypy --strict` on
# the tests and examples, and print the apply_profile benchmark. The wheel's
# Rust build shares the workspace's target/ (python/.cargo/config.toml; the
# python crate uses the root's release profile), so HiGHS is not rebuilt
# and nothing lands in python/target/; a CARGO_TARGET_DIR already set is
# used instead. Also keeps the binding crate fmt- and clippy-clean (it is
# its own workspace, outside `cargo … --workspace`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
PY=${PYTHON:-python3}

echo "== python: fmt + clippy (binding crate)"
cargo fmt --check --manifest-path python/Cargo.toml
cargo clippy --release --manifest-path python/Cargo.toml --all-targets -- -D warnings

venv=$(mktemp -d "${TMPDIR:-/tmp}/gaze-lidar-venv.XXXXXX")
trap 'rm -rf "$venv"' EXIT
echo "== python: pip install ./python into a fresh venv ($venv)"
"$PY" -m venv "$venv"
"$venv/bin/pip" install -q ./python   # exactly what a user runs
"$venv/bin/python" -m pip install -q pytest hypothesis mypy
# pandas (optional for users): the to_pandas() tests and push_many's
# nullable-type cases (pandas "boolean", "Float64") run with it.
"$venv/bin/python" -m pip install -q pandas
# Independent MCAP writers and readers for the replay tests (mcap,
# mcap-ros2-support, rosbags), and
# dask.distributed for examples/python/replay_many.py (pure Python, ~15 s).
"$venv/bin/python" -m pip install -q mcap mcap-ros2-support rosbags "dask[distributed]"

echo "== python: pytest"
# From outside the source tree, so the installed package is what is tested.
(cd "$venv" && "$venv/bin/python" -m pytest -q -p no:cacheprovider "$OLDPWD/python/tests" "$@")

echo "== python: mypy.stubtest (runtime vs stubs) and mypy --strict (tests, examples)"
(cd "$venv" && "$venv/bin/python" -m mypy.stubtest gaze_lidar)
"$venv/bin/python" -m mypy --strict --no-incremental --python-executable "$venv/bin/python" \
  python/tests examples/python

echo "== python: benchmark (apply_profile, 100k points)"
"$venv/bin/python" python/benchmarks/apply_profile.py --repeat 100
