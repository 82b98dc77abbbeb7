#!/usr/bin/env python3
"""mono.py SEED N: the true exposure can only grow when a channel is added or a power_scale
raised; flags when check's ratio FALLS by more than 1e-9 (a hint, not a proof: a bound may be
loose by different amounts) and then the reduced/augmented pair is kept for ref.py."""
import json, math, random, subprocess, sys, os, copy
B = "/work/targets/break-head/release/gaze-lidar"
D = os.path.dirname(os.path.abspath(__file__))
rng = random.Random(int(sys.argv[1])); n = int(sys.argv[2])
def chk(d, p="/tmp/r5/mono.json"):
    json.dump(d, open(p, "w"))
    r = subprocess.run([B, "check", p, "--format", "json"], capture_output=True, text=True)
    j = json.loads(r.stdout); e = j["eye_safety"]
    return e["worst_ratio"] if e else float("nan")
sys.argv = [sys.argv[0]]
exec(open(D + "/fuzz.py").read().split("worst = (0, None)")[0].split("def rand_head():")[1].join(["def rand_head():", ""]) if False else "")
from importlib import util
cnt = 0; drops = []
for case in range(n):
    nch = rng.choice([1, 2, 3, 5, 8])
    cyc = rng.choice([1e-5, 5.5296e-5, 1e-4])
    chs = [{"id": i, "elevation_deg": rng.choice([0.0, rng.uniform(-20, 20), rng.uniform(-80, 80)]), "azimuth_offset_deg": rng.choice([0.0, rng.uniform(-60, 60)]),
            "slot_s": rng.choice([0.0, rng.uniform(0, cyc)]), "power_scale": rng.choice([1.0, rng.uniform(0.2, 2)])} for i in range(nch)]
    head = {"cycle_s": cyc, "origin_radius_mm": rng.choice([0.0, rng.uniform(0, 90)]), "origin_height_mm": rng.choice([0.0, rng.uniform(-10, 10)]),
            "exit_diameter_mm": rng.uniform(1, 15), "divergence_mrad": rng.choice([0.0, rng.uniform(0, 10)]), "channels": chs}
    p = "/tmp/r5/mono_base.json"
    args = [sys.executable, D + "/gen.py", p, json.dumps(head), "--power", "1e-4", "--frame", str(rng.choice([5, 10, 20])), "--bins", str(rng.choice([8, 36])), "--lam", str(rng.choice([905.0, 1550.0, 1450.0]))]
    if rng.random() < 0.5: args += ["--hot", "%d,%d,%g" % (2, 2, rng.choice([3, 20]))]
    if rng.random() < 0.4: args += ["--wave", "0.5"]
    subprocess.run(args, check=True)
    d = json.load(open(p)); r0 = chk(d)
    # variant 1: add a channel copying a random one at a new slot
    d1 = copy.deepcopy(d); h = d1["limits"]["eye_safety"]["head"]; c = copy.deepcopy(rng.choice(h["channels"]))
    c["id"] = 1000; c["slot_s"] = rng.choice([c["slot_s"], rng.uniform(0, cyc)]); h["channels"].append(c)
    r1 = chk(d1)
    # variant 2: raise one power_scale
    d2 = copy.deepcopy(d); h = d2["limits"]["eye_safety"]["head"]; k = rng.randrange(len(h["channels"])); h["channels"][k]["power_scale"] *= 1.5
    r2 = chk(d2)
    cnt += 1
    for name, r, dd in (("add", r1, d1), ("scale", r2, dd2) if False else ("scale", r2, d2)):
        if r < r0 * (1 - 1e-9):
            drops.append((r / r0, name, case))
            json.dump(d, open("/tmp/r5/mono_drop_%d_base.json" % case, "w")); json.dump(dd, open("/tmp/r5/mono_drop_%d_%s.json" % (case, name), "w"))
            print("DROP case %d %s base=%.9g variant=%.9g (%.6f)" % (case, name, r0, r, r / r0), flush=True)
print("cases", cnt, "drops", len(drops), sorted(drops)[:5])
