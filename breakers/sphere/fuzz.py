#!/usr/bin/env python3
"""Random heads (1-6 channels; steep, down-pointing, off-axis, offsets, wide/diverging beams, heights),
scaled to check ~0.97 at 1000 Hz, truth by sph.py (time base + Rule 1 on the sphere)."""
import json, subprocess, random, sys, os
PY = os.environ.get("PY", sys.executable)
rng = random.Random(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
n_cases = int(sys.argv[2]) if len(sys.argv) > 2 else 40
for k in range(n_cases):
    r0 = rng.choice([0, rng.uniform(10, 90), rng.uniform(0, 30)])
    rmax = 100 - r0
    exit_ = rng.choice([rng.uniform(2, 12), rng.uniform(0.3, 0.97)*2*rmax - 7, rng.uniform(10, 40)])
    exit_ = max(0.5, min(exit_, 999))
    div = rng.choice([0, 0, rng.uniform(0, 20), rng.uniform(100, 600)])
    nch = rng.randint(1, 6)
    chs = []
    base_el = rng.uniform(30, 85) * rng.choice([1, -1])
    for i in range(nch):
        chs.append({"elevation_deg": max(-89.5, min(89.5, base_el + rng.uniform(-8, 8))),
                    "azimuth_offset_deg": rng.uniform(-89, 89) if rng.random() < 0.7 else rng.uniform(-10, 10),
                    "slot_s": rng.choice([0.0, 0.0, rng.uniform(0, 9.9e-7)]),
                    "power_scale": rng.choice([1.0, rng.uniform(0.2, 2.0)])})
    head = {"origin_radius_mm": r0, "origin_height_mm": rng.uniform(-60, 60), "exit_diameter_mm": exit_,
            "divergence_mrad": div, "channels": chs}
    p = subprocess.run([PY, "run.py", "F%s_%d" % (sys.argv[1] if len(sys.argv) > 1 else "7", k), json.dumps(head), "--ne", "1201", "--nth", "14400", "--extra", "--rule1 --phases 2"], capture_output=True, text=True)
    print(p.stdout.strip() or p.stderr[-400:], flush=True)
