#!/usr/bin/env python3
"""Uniform profile@1 (with head) -> firmware@1 JSON at the same power (8 bins, constant spin).
usage: fw.py PROFILE.json OUT.json [--code 4000]"""
import json, sys, argparse
ap = argparse.ArgumentParser(); ap.add_argument("prof"); ap.add_argument("out"); ap.add_argument("--code", type=int, default=4000)
ap.add_argument("--bins", type=int, default=8); ap.add_argument("--tick-hz", type=int, default=80_000_000)
a = ap.parse_args()
p = json.load(open(a.prof))
P = p["bins"][0]["power_w"]; fr = p["frame_rate_hz"]
ft = round(a.tick_hz / fr); assert ft % a.bins == 0
q = P / a.code
es = p["limits"]["eye_safety"]
doc = {"format": "gaze-lidar/firmware@1", "tick_hz": a.tick_hz, "frame_ticks": ft, "power_w_per_code": q,
       "power_accounting": "time", "pulse_rate_hz": p["pulse_rate_hz"], "eye_safety": es,
       "limits": {"power_code_min": 0, "power_code_max": 4095, "energy_budget": 4095 * ft, "window_bins": 1,
                  "window_energy_max": 18446744073709551615},
       "bins": [{"start_deg": 360.0 * i / a.bins, "width_mdeg": 360000 // a.bins, "dwell_ticks": ft // a.bins,
                 "power_code": a.code, "dwell_ticks_min": ft // a.bins, "dwell_ticks_max": ft // a.bins,
                 "power_code_cap": 4095} for i in range(a.bins)]}
json.dump(doc, open(a.out, "w"), indent=1)
