#!/usr/bin/env python3
"""fam_union.py: k channels fired together (one slot), same steep elevation, spread azimuth
offsets, crossing point off the axis: Rule 1's effective-pulse count (S_v x N_union) on both
surfaces. Scales check to 0.97 and runs ref.py on a height grid around the channels."""
import json, math, subprocess, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hits import hit
D = os.path.dirname(os.path.abspath(__file__)); PY = "/tmp/bhv/bin/python"
B = "/work/targets/break-head/release/gaze-lidar"
def chk(p):
    j = json.loads(subprocess.run([B, "check", p, "--format", "json"], capture_output=True, text=True).stdout)
    e = j["eye_safety"]; return j["certified"], e["worst_ratio"], e["binding_rule"], e["worst_azimuth_deg"], (e.get("head") or {}).get("worst_height_mm")
out = []
for (el, r0, offs, cyc, frame, surf) in [
        (60, 40, [-30, 0, 30], 1.6e-4, 10, "sphere"), (60, 40, [-30, 0, 30], 1.6e-4, 10, "cylinder"),
        (70, 80, [-60, -20, 20, 60], 2e-4, 10, "sphere"), (-50, 20, [-10, 0, 10], 1e-4, 10, "sphere"),
        (0, 60, [-45, -15, 15, 45], 1.6e-4, 10, "cylinder"), (45, 90, [-80, -40, 0, 40, 80], 3e-4, 5, "sphere"),
        (80, 10, [-80, 0, 80], 1e-4, 10, "sphere")]:
    head = {"cycle_s": cyc, "origin_radius_mm": r0, "origin_height_mm": 0.0, "exit_diameter_mm": 3.0, "divergence_mrad": 1.0,
            "channels": [{"id": i, "elevation_deg": el, "azimuth_offset_deg": o, "slot_s": 0.0} for i, o in enumerate(offs)]}
    p = "/tmp/r5/fu_%d_%d_%d_%s.json" % (el, r0, len(offs), surf)
    g = [sys.executable, D + "/gen.py", p, json.dumps(head), "--power", "1e-3", "--frame", str(frame), "--bins", "8"]
    subprocess.run(g, check=True); c = chk(p)
    g[g.index("--power") + 1] = repr(1e-3 * 0.97 / c[1]); subprocess.run(g, check=True); c = chk(p)
    hs = sorted(set(round(hit(head, ch, surf) + d, 4) for ch in head["channels"] for d in (-2, -0.7, 0, 0.7, 2)))
    if c[4] is not None and math.isfinite(c[4]): hs.append(c[4])
    hs = ",".join("%.5g" % max(-99.9, min(99.9, h)) if surf == "sphere" else "%.5g" % h for h in hs)
    r = subprocess.run([PY, D + "/ref.py", p, "--surface", surf, "--heights=" + hs, "--alphas=%g,%g" % (c[3], c[3] + 7), "--top", "4", "--phases", "0,0.5"], capture_output=True, text=True)
    line = [l for l in r.stdout.splitlines() if l.startswith("REFERENCE")][0]
    v = float(line.split()[1])
    print("%s check=%s ref=%.6f ref/check=%.5f %s" % (p, c, v, v / c[1], line[:150]), flush=True)
