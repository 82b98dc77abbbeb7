#!/usr/bin/env python3
"""Markdown table of scripts/detection_table.sh's per-trial CSVs.

Median TTA of the car from the right (undetected trials count as 0 s: no
warning) per (config, model, fog) for the closed forms on the config's own
sensor, limits and driver model and for the config's optimized variant
(objective.kind sqrt / detection), each with a 95 % percentile bootstrap
interval of the median (2000 resamples of the trials, Python's
`random.Random(20261127)`, the same resampled trial indices for every
variant: a paired bootstrap), and the paired bootstrap interval of
`median(detection) - median(best closed form on the sensor and mode)`.

A closed form the sensor's limits reject has no cells: simulate's own
message (the first violated limit and how many more) is listed under the
table. Of the closed forms the sensor runs, "on the sensor and mode" also
leaves out
- `argus` resolution/joint: the paper code's variant, which spins and fires
  27.5/20 times the sensor's rates (more points per second than the sensor);
- the blocks the config's `objective.mode` does not move (range: the spin;
  resolution: the power).
"""
import csv
import glob
import os
import random
import statistics
import sys
import tomllib

RESAMPLES = 2000
SEED = 20261127
CLOSED = ["baseline", "range", "resolution", "joint"]
MODELS = ["argus", "physical"]
FOGS = [0, 25, 50]
# The closed forms whose blocks an objective mode moves.
IN_MODE = {
    "baseline": {"baseline"},
    "range": {"baseline", "range"},
    "resolution": {"baseline", "resolution"},
    "joint": set(CLOSED),
}
ARGUS_CODE = {"resolution", "joint"}


def load(paths):
    """{(model, fog, variant): [tta by trial index]} over the CSVs."""
    out = {}
    for path in paths:
        with open(path) as f:
            for row in csv.DictReader(f):
                key = (row["model"], int(row["fog_pct"]), row["variant"])
                v = row["tta_right_s"]
                out.setdefault(key, {})[int(row["trial"])] = float(v) if v not in ("", "nan") else 0.0
    return {k: [d[i] for i in sorted(d)] for k, d in out.items()}


def boot(samples_by_name, idx_sets):
    """Percentile 95 % interval of the median of each named sample."""
    res = {}
    for name, xs in samples_by_name.items():
        meds = sorted(statistics.median([xs[i] for i in idx]) for idx in idx_sets)
        res[name] = (meds[int(0.025 * len(meds))], meds[int(0.975 * len(meds)) - 1])
    return res


def main(out_dir):
    configs = sorted({os.path.basename(p).split(".")[0] for p in glob.glob(os.path.join(out_dir, "*.sqrt.toml"))})
    print("| config (mode) | model | fog % | best closed form on the sensor: median [95 % CI] | best on the sensor and mode | optimized sqrt | optimized detection | detection − best on sensor and mode [95 % CI] | ≥ best on sensor and mode | ≥ best on sensor |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    failures, rejected_lines, idx_sets = [], [], None
    for cfg in configs:
        with open(os.path.join(out_dir, f"{cfg}.sqrt.toml"), "rb") as f:
            mode = tomllib.load(f).get("objective", {}).get("mode", "range")
        closed = load(sorted(glob.glob(os.path.join(out_dir, f"{cfg}.closed*.csv"))))
        rejected = {}
        rej_path = os.path.join(out_dir, f"{cfg}.closed.rejected")
        if os.path.exists(rej_path):
            for line in open(rej_path):
                v, m, why = line.rstrip("\n").split("\t", 2)
                rejected[(v, m)] = why
                rejected_lines.append(f"- {cfg}, {v}, {m}: {why.removeprefix('gaze-lidar: error: ')}")
        runs = {}
        for kind in ("sqrt", "detection"):
            p = os.path.join(out_dir, f"{cfg}.{kind}.csv")
            failed = os.path.join(out_dir, f"{cfg}.{kind}.failed")
            if os.path.exists(failed):
                failures.append(open(failed).read().strip())
            elif os.path.exists(p):
                runs[kind] = load([p])
        for model in MODELS:
            for fog in FOGS:
                cf = {v: closed[(model, fog, v)] for v in CLOSED if (model, fog, v) in closed}
                named = {k: r[(model, fog, "optimized")] for k, r in runs.items()}
                if idx_sets is None:
                    some = next(iter(cf.values()), None) or next(iter(named.values()), None)
                    if some is None:
                        continue
                    n = len(some)
                    rng = random.Random(SEED)
                    idx_sets = [[rng.randrange(n) for _ in range(n)] for _ in range(RESAMPLES)]
                best = max(cf, key=lambda v: statistics.median(cf[v])) if cf else None
                fcf = {v: cf[v] for v in cf
                       if v in IN_MODE[mode] and not (model == "argus" and v in ARGUS_CODE)}
                fbest = max(fcf, key=lambda v: statistics.median(fcf[v])) if fcf else None
                for v in (best, fbest):
                    if v is not None:
                        named[v] = cf[v]
                ci = boot(named, idx_sets)
                cell = lambda name: f"{statistics.median(named[name]):.2f} [{ci[name][0]:.2f}, {ci[name][1]:.2f}]"
                row = [f"{cfg} ({mode})", model, str(fog),
                       f"{best} {cell(best)}" if best else "— (all rejected)",
                       f"{fbest} {cell(fbest)}" if fbest else "— (all rejected)",
                       cell("sqrt") if "sqrt" in named else "—",
                       cell("detection") if "detection" in named else "—"]
                if "detection" in named and fbest:
                    d, b = named["detection"], named[fbest]
                    diffs = sorted(statistics.median([d[i] for i in idx]) - statistics.median([b[i] for i in idx]) for idx in idx_sets)
                    delta = statistics.median(d) - statistics.median(b)
                    raw = statistics.median(d) - statistics.median(named[best])
                    row.append(f"{delta:+.2f} [{diffs[int(0.025 * RESAMPLES)]:+.2f}, {diffs[int(0.975 * RESAMPLES) - 1]:+.2f}]")
                    row.append("yes" if delta >= 0 else f"**no** ({delta:+.2f})")
                    row.append("yes" if raw >= 0 else f"no ({raw:+.2f}, {best})")
                else:
                    row += ["—", "—", "—"]
                print("| " + " | ".join(row) + " |")
    print("\nClosed forms the config's sensor rejects (simulate's message: the first violated limit, at the scene's gaze):")
    for line in rejected_lines or ["- none"]:
        print(line)
    print("\nOf the closed forms the sensor runs, \"on the sensor and mode\" leaves out `argus` resolution/joint "
          "(the paper code's variant: 27.5/20 times the sensor's spin and point rate) and the closed forms that "
          "move a block the config's mode does not (range: the spin).")
    for f in failures:
        print(f"\nNot run: {f}")


if __name__ == "__main__":
    main(sys.argv[1])
