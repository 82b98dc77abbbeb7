#!/usr/bin/env python3
"""Wide beams close to R - r0, large divergence, off-axis origin, heights."""
import json, subprocess, os, sys
PY = os.environ.get("PY", sys.executable)
cases = []
for r0 in (20, 60, 85):
    rho_max = 100 - r0
    for frac in (0.6, 0.97):
        exit_ = 2*frac*rho_max - 7
        if exit_ <= 0: continue
        for az in (0, 60, 88):
            for el in (0, 35, 70, -60):
                cases.append(("B_r%d_f%.2f_az%d_el%d" % (r0, frac, az, el),
                              {"origin_radius_mm": r0, "origin_height_mm": 12.5, "exit_diameter_mm": exit_, "divergence_mrad": 0,
                               "channels": [{"elevation_deg": el, "azimuth_offset_deg": az}]}))
for r0 in (0, 50, 90):
    for div in (200, 1000):
        for az in (0, 80):
            for el in (40, 80, -75):
                cases.append(("D_r%d_div%d_az%d_el%d" % (r0, div, az, el),
                              {"origin_radius_mm": r0, "origin_height_mm": -20, "exit_diameter_mm": 2, "divergence_mrad": div,
                               "channels": [{"elevation_deg": el, "azimuth_offset_deg": az}]}))
for name, head in cases:
    p = subprocess.run([PY, "run.py", name, json.dumps(head), "--ne", "1201", "--nth", "36000", "--extra", "--phases 2"], capture_output=True, text=True)
    print(p.stdout.strip() or p.stderr[-400:], flush=True)
