#!/usr/bin/env python3
"""How many channels of a head can meet one aperture position (alpha, h) during
a sweep (3-D centre distance <= (a + w)/2): the oracle's count against `check`'s
`beams_meeting_worst` / `count_vertical`."""
import json, sys, os
import numpy as np
sys.path.insert(0, os.path.dirname(__file__))
import oracle as o
doc = json.load(open(sys.argv[1]))
head = doc["limits"]["eye_safety"]["head"]
a = float(sys.argv[2]) if len(sys.argv) > 2 else 7.0
hs = np.arange(-40, 40.01, 0.25)
best = (0, None)
for h in hs:
    n = 0
    for ch in head["channels"]:
        # quick reject by the elevation: the ray's height at the cylinder
        if o.pass_interval(head, ch, 0.0, h, a) is not None:
            n += 1
    if n > best[0]:
        best = (n, h)
print(json.dumps({"max_channels_meeting_one_position": best[0], "at_height_mm": best[1]}))
