#!/usr/bin/env python3
"""gen.py OUT HEAD_JSON_STRING --power W [--frame HZ] [--bins N] [--lam NM] [--tp S] [--hot I0,I1,K]
Writes a constant-spin profile@1 with the head; powers uniform (or bins I0..I1 K x hotter)."""
import argparse, json, math
ap = argparse.ArgumentParser()
ap.add_argument("out"); ap.add_argument("head")
ap.add_argument("--power", type=float, required=True)
ap.add_argument("--frame", type=float, default=10.0)
ap.add_argument("--bins", type=int, default=8)
ap.add_argument("--lam", type=float, default=905.0)
ap.add_argument("--tp", type=float, default=5e-9)
ap.add_argument("--hot", default=None)
ap.add_argument("--wave", type=float, default=0.0, help="spin at bin edges: omega*(1+A*sin(theta+0.7))")
a = ap.parse_args()
head = json.loads(a.head) if a.head.strip().startswith("{") else json.load(open(a.head))
om = 2 * math.pi * a.frame
w = 360.0 / a.bins
pw = [a.power] * a.bins
if a.hot:
    i0, i1, k = a.hot.split(","); 
    for i in range(int(i0), int(i1) + 1): pw[i] = a.power * float(k)
doc = {"format": "gaze-lidar/profile@1", "frame_rate_hz": a.frame, "pulse_rate_hz": 1.0 / head["cycle_s"],
 "average_power_w": sum(pw) / a.bins, "power_accounting": "time", "gaze_deg": None,
 "limits": {"power_w_min": 0.0, "power_w_max": max(pw), "spin_rad_s_min": om, "spin_rad_s_max": om,
  "spin_accel_rad_s2_max": None, "power_slew_w_per_deg_max": None,
  "eye_safety": {"wavelength_nm": a.lam, "pulse_duration_s": a.tp, "beam_diameter_mm": head["exit_diameter_mm"], "head": head}},
 "bins": [{"start_deg": i * w, "width_deg": w, "power_w": pw[i], "spin_start_rad_s": om, "spin_end_rad_s": om} for i in range(a.bins)]}
if a.wave:
    ed = [om * (1 + a.wave * math.sin(math.radians(i * w) + 0.7)) for i in range(a.bins + 1)]
    ed[-1] = ed[0]
    for i, b in enumerate(doc["bins"]):
        b["spin_start_rad_s"] = ed[i]; b["spin_end_rad_s"] = ed[i + 1]
    tf = sum(2 * math.radians(w) / (ed[i] + ed[i + 1]) for i in range(a.bins))
    doc["frame_rate_hz"] = 1 / tf
    doc["limits"]["spin_rad_s_min"] = min(ed); doc["limits"]["spin_rad_s_max"] = max(ed)
    doc["average_power_w"] = sum(pw[i] * 2 * math.radians(w) / (ed[i] + ed[i + 1]) for i in range(a.bins)) / tf
json.dump(doc, open(a.out, "w"), indent=1)
