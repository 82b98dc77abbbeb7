#!/usr/bin/env bash
# Type-checks the core library and its Kani harnesses as `cargo kani -p
# gaze-lidar-core` would build them (`--cfg kani`, no dev-dependencies),
# and the root crate's fail-safe harnesses as `cargo kani --tests
# --no-default-features` would (the library under `--cfg kani`, without the
# solver), against a stub of the `kani` API (scripts/kani-stub). It proves
# nothing: it catches harnesses that would not even resolve under Kani (e.g.
# a harness naming bolero, a dev-dependency). Kani itself:
# specs/verification.md.
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
# The root crate: `--cfg kani` on it alone (`cargo rustc`), since some of
# its dependencies (zerocopy) carry Kani contracts of their own that the stub
# does not model; the harness macros expand in this crate, so its cfg is
# the one that matters.
CARGO_TARGET_DIR="${KANI_CHECK_TARGET:-target/kani-typecheck}" \
    cargo rustc -p gaze-lidar --lib --no-default-features --profile check -- \
    --cfg kani --extern kani="$stub/libkani.rlib" -L "$stub" -A dead_code
echo "kani-typecheck: gaze-lidar-core, gaze-lidar (no solver) and their harnesses resolve under --cfg kani"
