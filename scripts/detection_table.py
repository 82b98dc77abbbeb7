#!/usr/bin/env python3
"""Markdown table of scripts/detection_table.sh's per-trial CSVs.

Median TTA of the car from the right (undetected trials count as 0 s: no
warning) per (model, fog) for the closed forms and each config's optimized
variant (objective.kind sqrt / detection), each with a 95 % percentile
bootstrap interval of the median (2000 resamples of the trials, Python's
`random.Random(20261127)`, the same resampled trial indices for every
variant: a paired bootstrap), and the paired bootstrap interval of
`median(detection) − median(best closed form)`.
"""
import csv
import glob
import os
import random
import statistics
import sys

RESAMPLES = 2000
SEED = 20261127
CLOSED = ["baseline", "range", "resolution", "joint"]

# Which of simulate's closed forms (the paper preset's: angle accounting, no
# spin, slew or acceleration limit) a config's optimized variant can be held
# to, and why the others cannot (each reason checked by hand against the
# profiles: `gaze-lidar profile --preset paper --mode M --gaze-deg 90`).
ARGUS_CODE = ("argus", {"resolution", "joint"},
              "argus resolution/joint are the paper code's variant: 27.5 Hz at 687,500 points/s, "
              "37.5 % more points per second than the sensor's 500,000")
NOT_ON_SENSOR = {
    "smooth": ({"range", "resolution", "joint"},
               "smooth's sensor: the closed forms step the power by 0.6 mW at a bin edge "
               "(slew limit 2e-5 W/deg) and resolution/joint spin at 586 rad/s (spin_rad_s_max 200)"),
    "multi_level": ({"resolution", "joint"},
                    "multi_level is mode = \"range\": resolution/joint move the spin, which it does not"),
}


def feasible(cfg, model):
    """Closed forms the config's optimized variant is held to."""
    out = set(CLOSED)
    if model == ARGUS_CODE[0]:
        out -= ARGUS_CODE[1]
    if cfg in NOT_ON_SENSOR:
        out -= NOT_ON_SENSOR[cfg][0]
    return out


def load(path):
    """{(model, fog, variant): [tta by trial index]}"""
    out = {}
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
    closed = load(os.path.join(out_dir, "closed.csv"))
    n = len(next(iter(closed.values())))
    rng = random.Random(SEED)
    idx_sets = [[rng.randrange(n) for _ in range(n)] for _ in range(RESAMPLES)]
    configs = sorted({os.path.basename(p).split(".")[0] for p in glob.glob(os.path.join(out_dir, "*.sqrt.toml"))})
    print("| config | model | fog % | best closed form: median [95 % CI] | best on the config's sensor and mode | optimized sqrt | optimized detection | detection − best on sensor [95 % CI] | ≥ best on sensor | ≥ best |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    failures = []
    for cfg in configs:
        runs = {}
        for kind in ("sqrt", "detection"):
            p = os.path.join(out_dir, f"{cfg}.{kind}.csv")
            failed = os.path.join(out_dir, f"{cfg}.{kind}.failed")
            if os.path.exists(failed):
                failures.append(open(failed).read().strip())
            elif os.path.exists(p):
                runs[kind] = load(p)
        if not runs:
            continue
        for model in ("argus", "physical"):
            for fog in (0, 25, 50):
                cf = {v: closed[(model, fog, v)] for v in CLOSED if (model, fog, v) in closed}
                best = max(cf, key=lambda v: statistics.median(cf[v]))
                fcf = {v: cf[v] for v in cf if v in feasible(cfg, model)}
                fbest = max(fcf, key=lambda v: statistics.median(fcf[v]))
                named = {best: cf[best], fbest: cf[fbest]}
                for kind, r in runs.items():
                    named[kind] = r[(model, fog, "optimized")]
                ci = boot(named, idx_sets)
                cell = lambda name: f"{statistics.median(named[name]):.2f} [{ci[name][0]:.2f}, {ci[name][1]:.2f}]"
                row = [cfg, model, str(fog), f"{best} {cell(best)}", f"{fbest} {cell(fbest)}",
                       cell("sqrt") if "sqrt" in named else "—",
                       cell("detection") if "detection" in named else "—"]
                if "detection" in named:
                    d, b = named["detection"], named[fbest]
                    raw = statistics.median(d) - statistics.median(named[best])
                    diffs = sorted(statistics.median([d[i] for i in idx]) - statistics.median([b[i] for i in idx]) for idx in idx_sets)
                    delta = statistics.median(d) - statistics.median(b)
                    row.append(f"{delta:+.2f} [{diffs[int(0.025 * RESAMPLES)]:+.2f}, {diffs[int(0.975 * RESAMPLES) - 1]:+.2f}]")
                    row.append("yes" if delta >= 0 else "**no**")
                    row.append("yes" if raw >= 0 else f"no ({raw:+.2f})")
                else:
                    row += ["—", "—", "—"]
                print("| " + " | ".join(row) + " |")
    print("\nClosed forms left out of \"best on the config's sensor and mode\":")
    print(f"- {ARGUS_CODE[2]};")
    for cfg, (_, why) in NOT_ON_SENSOR.items():
        print(f"- {why}.")
    for f in failures:
        print(f"\nNot run: {f}")


if __name__ == "__main__":
    main(sys.argv[1])
