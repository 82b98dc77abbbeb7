#!/usr/bin/env python3
"""A seeded sample of cargo-mutants mutants, as `--re` arguments.

Reads `cargo mutants --list` output (one mutant name a line) on stdin,
drops the proof harnesses' own mutants (`verification::`), picks `N`
names with `random.Random(SEED).sample` over the list in its printed
order, and prints them (`--names`) or one `--re '^name$'` argument per
line (default) for `xargs`/`$(...)`.

    cargo mutants -p gaze-lidar-core --list -f 'crates/core/src/eye_safety/bound/*.rs' \
        | python3 scripts/mutants_sample.py 120 29 > /tmp/sample.re
"""
import random
import re
import sys


def main() -> None:
    n = int(sys.argv[1])
    seed = int(sys.argv[2])
    names_only = "--names" in sys.argv[3:]
    names = [l.rstrip("\n") for l in sys.stdin if l.strip()]
    names = [l for l in names if "verification::" not in l]
    picked = random.Random(seed).sample(names, min(n, len(names)))
    picked.sort(key=names.index)
    for name in picked:
        print(name if names_only else "--re=^" + re.escape(name) + "$")


if __name__ == "__main__":
    main()
