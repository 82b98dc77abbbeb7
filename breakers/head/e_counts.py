#!/usr/bin/env python3
"""How many channels of a head can meet one aperture position (alpha, h) during
a sweep (3-D centre distance <= (a + w)/2 at some head angle): the oracle's
count against `check`'s `beams_meeting_worst`.
usage: e_counts.py PROFILE.json H0 H1 STEP [aperture_mm]"""
import json, sys, os
import numpy as np
sys.path.insert(0, os.path.dirname(__file__))
import oracle as o
doc = json.load(open(sys.argv[1]))
head = doc["limits"]["eye_safety"]["head"]
h0, h1, step = map(float, sys.argv[2:5])
a = float(sys.argv[5]) if len(sys.argv) > 5 else 7.0
grid = np.linspace(-40, 40, 16001)
best = (0, None)
for h in np.arange(h0, h1 + 1e-9, step):
    n = 0
    for ch in head["channels"]:
        d, w = o.dist_and_width(head, ch, grid, 0.0, h)
        if np.any(d <= 0.5 * (a + w)):
            n += 1
    if n > best[0]:
        best = (n, float(h))
print(json.dumps({"max_channels_meeting_one_position": best[0], "at_height_mm": best[1]}))
