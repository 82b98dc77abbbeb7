#!/usr/bin/env bash
# Type-checks the core library and its Kani harnesses as `cargo kani -p
# gaze-lidar-core` would build them (`--cfg kani`, no dev-dependencies),
# against a stub of the `kani` API (scripts/kani-stub). It proves nothing: it
# catches harnesses that would not even resolve under Kani (e.g. a harness
# naming bolero, a dev-dependency). Kani itself: specs/verification.md.
set -euo pipefail
cd "$(dirname "$0")/.."
stub="$(mktemp -d)"
trap 'rm -rf "$stub"' EXIT
rustc --edition 2021 --crate-type proc-macro scripts/kani-stub/kani_macros.rs \
    -o "$stub/libkani_macros.so"
rustc --edition 2021 --crate-type rlib scripts/kani-stub/kani.rs \
    --extern kani_macros="$stub/libkani_macros.so" -o "$stub/libkani.rlib"
RUSTFLAGS="--cfg kani --extern kani=$stub/libkani.rlib -L $stub -A dead_code" \
    CARGO_TARGET_DIR="${KANI_CHECK_TARGET:-target/kani-typecheck}" \
    cargo check -p gaze-lidar-core --lib
echo "kani-typecheck: gaze-lidar-core and its harnesses resolve under --cfg kani"
