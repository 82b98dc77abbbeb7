#!/usr/bin/env bash
# Whole-process timing of `gaze-lidar profile --config C --gaze-deg 90
# --format json` for the shipped optimizer configs, as ratios against a
# baseline binary measured in the same run (old and new runs alternate, so
# load from other processes falls on both alike).
#
#   scripts/bench-profile.sh [BASE_REV] [RUNS]
#
# BASE_REV (default `main`) is checked out in a temporary git worktree and
# built with this repository's target directory (only the workspace crates
# rebuild; HiGHS is reused), its binary kept as target/bench/gaze-lidar-base;
# then the working tree is rebuilt (its sources touched, see below, so
# target/ holds this tree's build afterwards) as target/bench/gaze-lidar-new.
# OLD=path / NEW=path skip the builds. RUNS (default 21) runs per binary and
# config; the table gives the medians of the child's CPU time (user +
# system, `os.wait4`) and of the wall time, in ms.
# Outputs of both binaries are compared byte for byte (reported, not
# required: a new formulation may move the last bits).
set -euo pipefail
cd "$(dirname "$0")/.."
BASE_REV="${1:-main}"
RUNS="${2:-21}"
CONFIGS="${CONFIGS:-paper multi_level vls128_eye smooth}"
mkdir -p target/bench
if [[ -z "${OLD:-}" ]]; then
    wt="$(mktemp -d)"
    trap 'git worktree remove --force "$wt" >/dev/null 2>&1 || true' EXIT
    git worktree add --detach "$wt" "$BASE_REV" >/dev/null
    (cd "$wt" && cargo build --release --bin gaze-lidar --target-dir "$OLDPWD/target" >&2)
    cp target/release/gaze-lidar target/bench/gaze-lidar-base
    OLD=target/bench/gaze-lidar-base
fi
if [[ -z "${NEW:-}" ]]; then
    # The worktree's build wrote its own gaze-lidar and gaze-lidar-core
    # artifacts under the same names (cargo hashes path packages relative
    # to the workspace root), and this tree's older sources would read as
    # fresh: touch them so cargo rebuilds both crates from this tree.
    find src crates/core/src -name '*.rs' -exec touch {} +
    cargo build --release --bin gaze-lidar >&2
    cp target/release/gaze-lidar target/bench/gaze-lidar-new
    NEW=target/bench/gaze-lidar-new
fi
python3 - "$OLD" "$NEW" "$RUNS" $CONFIGS <<'EOF'
import os, statistics, subprocess, sys, time
old, new, runs, configs = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4:]
def once(binary, config):
    args = [binary, "profile", "--config", f"examples/configs/{config}.toml",
            "--gaze-deg", "90", "--format", "json"]
    t0 = time.perf_counter()
    p = subprocess.Popen(args, stdout=subprocess.PIPE)
    out = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    if status != 0:
        sys.exit(f"{binary} on {config}: exit status {status}")
    # CPU of the child (user + system): the measure under load; wall is
    # several times it on a shared machine.
    return time.perf_counter() - t0, usage.ru_utime + usage.ru_stime, out
print(f"baseline {old}, new {new}, {runs} runs each, alternated; ms, medians")
print(f"{'config':<12} {'base cpu':>9} {'new cpu':>9} {'ratio':>7} {'base wall':>10} {'new wall':>9}  outputs")
for c in configs:
    wall = {old: [], new: []}
    cpu = {old: [], new: []}
    outs = {}
    for _ in range(runs):
        for b in (old, new):
            dt, dc, out = once(b, c)
            wall[b].append(dt * 1e3)
            cpu[b].append(dc * 1e3)
            outs[b] = out
    co, cn = statistics.median(cpu[old]), statistics.median(cpu[new])
    wo, wn = statistics.median(wall[old]), statistics.median(wall[new])
    same = "identical" if outs[old] == outs[new] else "differ"
    print(f"{c:<12} {co:9.1f} {cn:9.1f} {co / cn:6.2f}× {wo:10.1f} {wn:9.1f}  {same}")
EOF
