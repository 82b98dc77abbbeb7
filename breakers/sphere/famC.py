#!/usr/bin/env python3
"""Clusters of steep channels fired together, whose sphere footprints overlap near the pole."""
import json, subprocess, sys, itertools
PY = os.environ.get("PY", sys.executable)
cases = []
for el in (60, 75, 85, -80):
    for n, spread in ((2, 40), (4, 80), (8, 170), (8, 60)):
        for r0, z0 in ((0, 0), (40, 25), (85, -30)):
            chs = []
            for i in range(n):
                az = -spread/2 + spread*i/(n-1)
                az = max(-89.0, min(89.0, az))
                chs.append({"elevation_deg": el + (i % 2)*1.5, "azimuth_offset_deg": az, "slot_s": 0.0})
            head = {"origin_radius_mm": r0, "origin_height_mm": z0, "exit_diameter_mm": 10, "divergence_mrad": 0, "channels": chs}
            cases.append(("C_el%d_n%d_s%d_r%d" % (el, n, spread, r0), head))
for name, head in cases:
    p = subprocess.run([PY, "run.py", name, json.dumps(head), "--ne", "901", "--nth", "36000", "--extra", "--rule1 --phases 2"], capture_output=True, text=True)
    print(p.stdout.strip() or p.stderr[-400:], flush=True)
