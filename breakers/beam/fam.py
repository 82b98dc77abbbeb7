#!/usr/bin/env python3
"""Families of heads for run.py (end-to-end: check scaled to 0.97, oracle truth, firmware).
usage: fam.py FAMILY COUNT SEED  -> one run.py JSON line per head (stdout)
families:
  A  one strongly diverging channel (5-1000 mrad), thin or wide exit, r0 0-99, steep/down,
     large offsets; 100 kHz, 1000 Hz (time base or pass train binds on the footprint)
  B  2-6 diverging channels stacked in elevation (their boxes meet near the edges of their
     heights), shared or distinct slots, power scales
  C  whole turn: beam wider than R - r0 (crossing point within reach), 1-3 channels
  D  a declared aperture distance other than 100 mm (four surfaces), 1-4 channels, diverging
  E  heads whose sphere footprints equal the cylinder's (flat channels, r0 = 0) at R = 100
     and at another R
"""
import json, math, os, random, subprocess, sys

CYC = 1.0 / 150000.0  # 150 pulses per turn at 1000 Hz; > T_i apart
HERE = os.path.dirname(os.path.abspath(__file__))
PY = os.environ.get("PY", sys.executable)


def ch(el, az, slot=0.0, s=1.0):
    return {"elevation_deg": el, "azimuth_offset_deg": az, "slot_s": slot, "power_scale": s}


def fam_A(rng):
    r0 = rng.choice([0.0, rng.uniform(0, 20), rng.uniform(40, 90), rng.uniform(90, 99)])
    el = rng.choice([rng.uniform(-20, 20), rng.uniform(30, 80), -rng.uniform(30, 80)])
    az = rng.choice([0.0, rng.uniform(-89, 89), rng.choice([-1, 1]) * rng.uniform(60, 89)])
    exit_ = rng.choice([rng.uniform(0.05, 1.0), rng.uniform(1, 10), rng.uniform(10, 30)])
    div = math.exp(rng.uniform(math.log(5), math.log(1000)))
    return {"cycle_s": CYC, "origin_radius_mm": r0, "origin_height_mm": rng.uniform(-20, 20),
            "exit_diameter_mm": exit_, "divergence_mrad": div, "channels": [ch(el, az)]}


def fam_B(rng):
    n = rng.randint(2, 6)
    r0 = rng.choice([0.0, rng.uniform(10, 60), rng.uniform(60, 95)])
    base = rng.uniform(-60, 60)
    gap = rng.uniform(2, 25)
    az0 = rng.uniform(-60, 60)
    spread_az = rng.choice([0.0, rng.uniform(0, 20)])
    slots = rng.choice(["same", "distinct", "two"])
    cyc = CYC
    chans = []
    for i in range(n):
        slot = 0.0 if slots == "same" else (i * cyc / n if slots == "distinct" else (i % 2) * cyc / 2)
        chans.append(ch(max(-89, min(89, base + i * gap)), az0 + rng.uniform(-spread_az, spread_az),
                        slot, rng.choice([1.0, 1.0, rng.uniform(0.2, 2.0)])))
    return {"cycle_s": cyc, "origin_radius_mm": r0, "origin_height_mm": 0.0,
            "exit_diameter_mm": rng.uniform(0.2, 8), "divergence_mrad": math.exp(rng.uniform(math.log(5), math.log(600))),
            "channels": chans}


def fam_C(rng):
    r0 = rng.uniform(50, 99.5)
    need = 2 * (100 - r0) - 7          # exit + div*t >= need somewhere near the crossing point
    exit_ = max(0.05, need * rng.uniform(0.3, 1.3))
    n = rng.randint(1, 3)
    chans = [ch(rng.uniform(-70, 70), rng.uniform(-80, 80), i * CYC / 3 if rng.random() < 0.5 else 0.0)
             for i in range(n)]
    return {"cycle_s": CYC, "origin_radius_mm": r0, "origin_height_mm": rng.uniform(-10, 10),
            "exit_diameter_mm": exit_, "divergence_mrad": rng.choice([0.0, rng.uniform(5, 300)]),
            "channels": chans}


def fam_D(rng):
    R = rng.choice([rng.uniform(20, 99), rng.uniform(101, 400), 99.999, 100.001])
    r0 = rng.uniform(0, 0.9 * min(R, 100))
    n = rng.randint(1, 4)
    chans = [ch(rng.uniform(-70, 70), rng.uniform(-70, 70), rng.choice([0.0, CYC / 2])) for _ in range(n)]
    return {"cycle_s": CYC, "origin_radius_mm": r0, "origin_height_mm": rng.uniform(-20, 20),
            "exit_diameter_mm": rng.uniform(0.2, 15), "divergence_mrad": rng.choice([0.0, math.exp(rng.uniform(math.log(5), math.log(500)))]),
            "aperture_distance_mm": R, "channels": chans}


def fam_E(rng):
    R = rng.choice([100.0, rng.uniform(30, 99), rng.uniform(101, 300)])
    n = rng.randint(1, 3)
    chans = [ch(0.0, 0.0, i * CYC / 3) for i in range(n)]
    return {"cycle_s": CYC, "origin_radius_mm": 0.0, "origin_height_mm": 0.0,
            "exit_diameter_mm": rng.uniform(0.5, 20), "divergence_mrad": rng.choice([0.0, rng.uniform(5, 300)]),
            "aperture_distance_mm": R, "channels": chans}


FAMS = {"A": fam_A, "B": fam_B, "C": fam_C, "D": fam_D, "E": fam_E}


def main():
    fam, count, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    extra = sys.argv[4:]
    rng = random.Random(seed)
    for i in range(count):
        head = FAMS[fam](rng)
        name = f"{fam}{seed}_{i}"
        p = subprocess.run([PY, os.path.join(HERE, "run.py"), name, json.dumps(head)] + extra,
                           capture_output=True, text=True)
        line = p.stdout.strip() or json.dumps({"name": name, "err": p.stderr[-300:]})
        print(line.replace('{"name"', '{"head": ' + json.dumps(head) + ', "name"', 1), flush=True)




def hot_main():
    """fam.py hot FAMILY COUNT SEED: the family's heads (cycle 1e-5 s) on 10 Hz hot-sector
    profiles (36 bins, one to three hot bins, 10-100x) through hot.py."""
    fam, count, seed = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    rng = random.Random(seed)
    for i in range(count):
        head = FAMS[fam](rng)
        head["cycle_s"] = 1e-5
        for c in head["channels"]:
            c["slot_s"] = min(c["slot_s"] * 1.5, 0.9e-5)
        i0 = rng.randrange(36); i1 = min(35, i0 + rng.randrange(3))
        name = f"H{fam}{seed}_{i}"
        p = subprocess.run([PY, os.path.join(HERE, "hot.py"), name, json.dumps(head), "--frame", "10",
                            "--bins", "36", "--hot", f"{i0},{i1}", "--ratio", str(rng.choice([10, 30, 100])),
                            "--oracle-args", "--top 3 --phases 2"], capture_output=True, text=True)
        line = p.stdout.strip() or json.dumps({"name": name, "err": p.stderr[-300:]})
        print(line.replace('{"name"', '{"head": ' + json.dumps(head) + ', "name"', 1), flush=True)


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "hot":
    hot_main()
    sys.exit(0)


if __name__ == "__main__":
    main()
