#!/usr/bin/env python3
"""Non-uniform (hot sector) constant-spin profiles with a given head, scaled so check ~ target.
usage: nonuni.py OUT.json 'HEAD-JSON' --frame HZ --bins N --hot I0,I1 --ratio K"""
import argparse, json, subprocess, sys, os
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "head"))
from mk import profile
G = os.environ.get("GAZE_LIDAR", "/work/targets/break-sphere/release/gaze-lidar")
ap = argparse.ArgumentParser(); ap.add_argument("out"); ap.add_argument("head")
ap.add_argument("--frame", type=float, default=1000.0); ap.add_argument("--bins", type=int, default=36)
ap.add_argument("--hot", default="0,1"); ap.add_argument("--ratio", type=float, default=50.0)
ap.add_argument("--target", type=float, default=0.97)
a = ap.parse_args()
head = json.loads(a.head)
head.setdefault("cycle_s", 1e-6); head.setdefault("aperture_distance_mm", 100.0); head.setdefault("origin_height_mm", 0.0)
for i, c in enumerate(head["channels"]):
    c.setdefault("id", i); c.setdefault("slot_s", 0.0); c.setdefault("azimuth_offset_deg", 0.0)
i0, i1 = map(int, a.hot.split(","))
def mkp(s):
    pw = [s if i0 <= i < i1 else s / a.ratio for i in range(a.bins)]
    return profile(head, None, a.frame, a.bins, powers=pw)
def chk():
    d = json.loads(subprocess.run([G, "check", a.out, "--format", "json"], capture_output=True, text=True).stdout)
    return d
json.dump(mkp(0.01), open(a.out, "w"), indent=1)
r = chk()["eye_safety"]["worst_ratio"]
json.dump(mkp(0.01 * a.target / r), open(a.out, "w"), indent=1)
d = chk(); e = d["eye_safety"]
print(json.dumps({"certified": d["certified"], "ratio": e["worst_ratio"], "rule": e["binding_rule"],
                  "surface": e.get("head", {}).get("figures", {}).get("surface"),
                  "pass": e.get("head", {}).get("figures", {}).get("pass_angle_deg"),
                  "worst_az": e.get("worst_azimuth_deg")}))
