#!/usr/bin/env bash
# Counts, over the integration tests (tests/ and crates/core/tests/, every .rs
# file below them, data dirs included if they hold .rs) and the fixtures and
# references they share (crates/core/src/testing/):
#   tests      = `#[test]` attributes (proptest fns inside `proptest!` carry one)
#   assertions = calls of assert!, assert_eq!, assert_ne!, prop_assert!,
#                prop_assert_eq!, prop_assert_ne!, assert_relative_eq!,
#                assert_abs_diff_eq!, assert_ulps_eq!, debug_assert*!
#   panics     = panic!( calls (explicit failure paths)
#   expects    = .expect( calls
#   ignored    = #[ignore] attributes
# Comments (// ...) are excluded from every count.
set -euo pipefail
cd "$(dirname "$0")/.."
files=$(find tests crates/core/tests crates/core/src/testing -name '*.rs' | sort)
strip() { sed -E 's#//.*$##' $files; }
echo "files:      $(echo "$files" | wc -l)"
echo "tests:      $(strip | grep -oE '#\[test\]' | wc -l)"
echo "assertions: $(strip | grep -oE '\b(prop_)?(debug_)?assert(_eq|_ne|_relative_eq|_abs_diff_eq|_ulps_eq)?!' | wc -l)"
echo "panics:     $(strip | grep -oE '\bpanic!\(' | wc -l)"
echo "expects:    $(strip | grep -oE '\.expect\(' | wc -l)"
echo "ignored:    $(strip | grep -oE '#\[ignore' | wc -l)"
