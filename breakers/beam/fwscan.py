#!/usr/bin/env python3
"""Float `check` against the integer `check` of the same profile written as a firmware@1 table
(fine codes: the table runs the profile's power), on random multi-channel heads at 100 mm and at
other declared distances (four surfaces), scaled so the float figure is TARGET (default just
above 1: the float check rejects). Flags every table the integer check accepts while the float
check rejects, and every integer figure below the float one.
usage: fwscan.py COUNT SEED [--target 1.0005] [--frame 1000]
"""
import argparse, json, math, os, random, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "head"))
sys.path.insert(0, HERE)
from mk import profile  # noqa: E402
from run import check, fw_table, fw_ratio, fw_why  # noqa: E402


def rand_head(rng, cyc):
    n = rng.choice([1, 2, 3, 4, 6, 8, 16])
    R = rng.choice([100.0, 100.0, rng.uniform(30, 99), rng.uniform(101, 300)])
    r0 = rng.uniform(0, 0.9 * min(R, 100.0)) * rng.choice([0, 1, 1])
    groups = rng.choice([1, 2, n])
    el0 = rng.uniform(-30, 30); gap = rng.choice([0.0, rng.uniform(0.2, 3), rng.uniform(3, 15)])
    chans = []
    for i in range(n):
        chans.append({"id": i, "elevation_deg": max(-85, min(85, el0 + gap * i + rng.uniform(-0.3, 0.3))),
                      "azimuth_offset_deg": rng.choice([0.0, rng.uniform(-10, 10), rng.uniform(-60, 60)]),
                      "slot_s": (i % groups) * cyc / groups, "power_scale": rng.choice([1.0, rng.uniform(0.3, 1.5)])})
    return {"cycle_s": cyc, "origin_radius_mm": r0, "origin_height_mm": rng.uniform(-10, 10),
            "exit_diameter_mm": rng.uniform(0.3, 12),
            "divergence_mrad": rng.choice([0.0, 3.0, rng.uniform(5, 100), rng.uniform(100, 600)]),
            "aperture_distance_mm": R, "channels": chans}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("count", type=int); ap.add_argument("seed", type=int)
    ap.add_argument("--target", type=float, default=1.0005)
    ap.add_argument("--outdir", default="/tmp/bb/fwscan")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    rng = random.Random(a.seed)
    stats = {"n": 0, "both_reject": 0, "int_accepts_float_rejects": 0, "int_below_float": 0,
             "int_refused_other": 0, "min_int_over_float": 9.9, "max_int_over_float": 0.0}
    for i in range(a.count):
        frame = rng.choice([10.0, 100.0, 1000.0])
        cyc = rng.choice([1e-6, 2e-6, 1e-5, 5.55e-5 if frame == 10.0 else 1e-5])
        if abs(round(1 / frame / cyc) - 1 / frame / cyc) > 1e-6:
            cyc = 1e-5
        head = rand_head(rng, cyc)
        name = f"S{a.seed}_{i}"
        path = os.path.join(a.outdir, name + ".json")
        json.dump(profile(head, 0.01, frame, 8), open(path, "w"))
        rc, d, err = check(path)
        if d is None or not d.get("eye_safety"):
            continue
        P = 0.01 * a.target / d["eye_safety"]["worst_ratio"]
        json.dump(profile(head, P, frame, 8), open(path, "w"))
        rc, d, err = check(path)
        fl = d["eye_safety"]["worst_ratio"]
        fwp = os.path.join(a.outdir, name + "_fw.json")
        try:
            fw_table(path, fwp, code=60000)
        except AssertionError:
            continue
        frc, fd, ferr = check(fwp)
        stats["n"] += 1
        ir = fw_ratio(fd)
        if ir is None:
            stats["int_refused_other"] += 1
            print(json.dumps({"name": name, "int_refused": fw_why(fd), "err": ferr}), flush=True)
            continue
        q = ir / fl
        stats["min_int_over_float"] = min(stats["min_int_over_float"], q)
        stats["max_int_over_float"] = max(stats["max_int_over_float"], q)
        line = {"name": name, "float": fl, "float_rc": rc, "int": ir, "int_rc": frc,
                "rule": d["eye_safety"]["binding_rule"], "int_rule": (fd.get("eye_safety") or {}).get("binding_rule"),
                "R": head["aperture_distance_mm"], "head": head, "frame": frame}
        if q < 1 - 2e-6:
            stats["int_below_float"] += 1
            print(json.dumps(line) + " <<< int<float", flush=True)
        if frc == 0 and rc != 0:
            stats["int_accepts_float_rejects"] += 1
            print(json.dumps(line) + " <<<<<< INT-ACCEPTS", flush=True)
        elif frc != 0 and rc != 0:
            stats["both_reject"] += 1
    print(json.dumps(stats), flush=True)


if __name__ == "__main__":
    main()
