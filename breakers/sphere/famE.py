#!/usr/bin/env python3
"""Dome-like heads: many steep channels (up and down), azimuth offsets, slots, overlapping sphere footprints."""
import json, subprocess, os, sys
PY = os.environ.get("PY", sys.executable)
cases = []
for r0, z0 in ((0, 0), (30, 40), (70, -25)):
    for kind in ("up", "updown", "fan"):
        chs = []
        for i in range(24):
            if kind == "up":
                el, az = 50 + 38*i/23, (-1)**i * (i*3.5 % 80)
            elif kind == "updown":
                el, az = (1 if i % 2 else -1)*(40 + 48*(i//2)/11), (i*7.3 % 160) - 80
            else:
                el, az = 78 + (i % 3)*3, -86 + 172*i/23
            chs.append({"elevation_deg": el, "azimuth_offset_deg": az, "slot_s": (i % 4)*2e-7, "power_scale": 0.5 + (i % 3)*0.25})
        head = {"origin_radius_mm": r0, "origin_height_mm": z0, "exit_diameter_mm": 12, "divergence_mrad": 5, "channels": chs}
        cases.append(("E_%s_r%d" % (kind, r0), head))
for name, head in cases:
    p = subprocess.run([PY, "run.py", name, json.dumps(head), "--ne", "901", "--nth", "14400", "--extra", "--rule1 --phases 2"], capture_output=True, text=True)
    print(p.stdout.strip() or p.stderr[-400:], flush=True)
