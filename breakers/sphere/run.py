#!/usr/bin/env python3
"""Driver: head -> uniform profile scaled so `check` gives ~target -> sphere oracle.
usage: run.py NAME 'HEADJSON' [--target 0.97] [--frame 1000]"""
import argparse, json, subprocess, sys, os, math
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "head"))
from mk import profile
G = os.environ.get("GAZE_LIDAR", "/work/targets/break-sphere/release/gaze-lidar")
PY = os.environ.get("PY", sys.executable)
HERE = os.path.dirname(os.path.abspath(__file__))

def check(path):
    p = subprocess.run([G, "check", path, "--format", "json"], capture_output=True, text=True)
    if p.returncode not in (0, 1):
        return p.returncode, None, p.stderr.strip()
    d = json.loads(p.stdout)
    return p.returncode, d, None

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("name"); ap.add_argument("head")
    ap.add_argument("--target", type=float, default=0.97)
    ap.add_argument("--frame", type=float, default=1000.0)
    ap.add_argument("--ne", type=int, default=3601)
    ap.add_argument("--nth", type=int, default=72000)
    ap.add_argument("--outdir", default="/tmp/sph")
    ap.add_argument("--extra", default="")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    head = json.loads(a.head)
    head.setdefault("cycle_s", 1e-6); head.setdefault("aperture_distance_mm", 100.0)
    head.setdefault("origin_height_mm", 0.0)
    for i, c in enumerate(head["channels"]):
        c.setdefault("id", i); c.setdefault("slot_s", 0.0); c.setdefault("azimuth_offset_deg", 0.0)
    path = os.path.join(a.outdir, a.name + ".json")
    P = 0.01
    json.dump(profile(head, P, a.frame, 4), open(path, "w"), indent=1)
    rc, d, err = check(path)
    if d is None:
        print(json.dumps({"name": a.name, "rc": rc, "err": err})); return
    r1 = d["eye_safety"]["worst_ratio"]
    P2 = P * a.target / r1
    json.dump(profile(head, P2, a.frame, 4), open(path, "w"), indent=1)
    rc, d, err = check(path)
    es = d["eye_safety"]
    o = subprocess.run([PY, os.path.join(HERE, "sph.py"), path, "--ne", str(a.ne), "--nth", str(a.nth)] + a.extra.split(),
                       capture_output=True, text=True)
    try:
        orc = json.loads(o.stdout)
    except Exception:
        orc = {"oracle_err": o.stderr[-500:]}
    res = {"name": a.name, "rc": rc, "check": es["worst_ratio"], "rule": es["binding_rule"],
           "surface": es.get("head", {}).get("figures", {}).get("surface"),
           "Wv": es.get("head", {}).get("figures", {}).get("weight_vertical"),
           "pass": es.get("head", {}).get("figures", {}).get("pass_angle_deg"), "P": P2}
    res.update(orc)
    tr = max(orc.get("pulse_ratio", 0), orc.get("measure_ratio", 0))
    res["truth/check"] = tr / es["worst_ratio"] if es["worst_ratio"] else None
    flag = " <<<<<< BUG" if (rc == 0 and tr > 1.0) else ""
    print(json.dumps(res) + flag)

if __name__ == "__main__":
    main()
