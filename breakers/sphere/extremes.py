#!/usr/bin/env python3
"""Extreme heads through `check` (profile and firmware table): no panic, exit 0/1 (2 for refused input)."""
import json, subprocess, sys, os, time, itertools
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "head"))
from mk import profile
G = os.environ.get("GAZE_LIDAR", "/work/targets/break-sphere/release/gaze-lidar")
PY = os.environ.get("PY", sys.executable)
HERE = os.path.dirname(os.path.abspath(__file__))
os.makedirs("/tmp/sph/x", exist_ok=True)
def head(**k):
    h = {"cycle_s": 1e-6, "origin_radius_mm": 0.0, "origin_height_mm": 0.0, "exit_diameter_mm": 10.0,
         "divergence_mrad": 0.0, "aperture_distance_mm": 100.0,
         "channels": [{"id": 0, "elevation_deg": 75.0, "azimuth_offset_deg": 0.0, "slot_s": 0.0}]}
    ch = k.pop("ch", None)
    h.update(k)
    if ch: h["channels"] = ch
    return h
cases = []
for el in (89.9999999, -89.9999999, 89.999999999999, 0.0, 1e-300 * 0 + 5e-324 * 0 + 1e-12):
    for r0 in (0.0, 1e-12, 1e-6, 50.0, 99.999999999):
        for az in (0.0, 89.9999999, -89.9999999):
            cases.append(head(origin_radius_mm=r0, ch=[{"id": 0, "elevation_deg": el, "azimuth_offset_deg": az, "slot_s": 0.0}]))
cases += [head(exit_diameter_mm=999.0), head(divergence_mrad=1000.0), head(origin_height_mm=1e4), head(origin_height_mm=-1e4),
          head(origin_radius_mm=99.9, exit_diameter_mm=0.1), head(aperture_distance_mm=1e-3, origin_radius_mm=0.0),
          head(aperture_distance_mm=1e4, origin_radius_mm=99.0), head(aperture_distance_mm=50, origin_radius_mm=49.9999),
          head(aperture_distance_mm=150, origin_radius_mm=120.0),
          head(ch=[{"id": i, "elevation_deg": 89.9 - 0.001 * i, "azimuth_offset_deg": -89.9 + 0.35 * i, "slot_s": 0.0} for i in range(512)], origin_radius_mm=70.0),
          head(ch=[{"id": i, "elevation_deg": -85 + i * 0.33, "azimuth_offset_deg": 0, "slot_s": (i % 7) * 1e-7, "power_scale": 1000.0 if i % 2 else 0.0} for i in range(512)], divergence_mrad=300.0, origin_radius_mm=30.0, origin_height_mm=-5000.0),
          head(ch=[{"id": 0, "elevation_deg": 75, "azimuth_offset_deg": 120.0, "slot_s": 0.0}], origin_radius_mm=40.0),
          head(cycle_s=1.0), head(cycle_s=1e-12)]
bad = 0
for i, h in enumerate(cases):
    p = f"/tmp/sph/x/x{i}.json"
    try:
        json.dump(profile(h, 1e-3, 1000.0 if h["cycle_s"] < 1e-3 else 0.5, 4), open(p, "w"))
    except Exception as e:
        print(i, "mk fail", e); continue
    for path in (p,) + ((p + ".fw.json",) if subprocess.run([PY, os.path.join(HERE, "fw.py"), p, p + ".fw.json", "--code", "100"], capture_output=True).returncode == 0 else ()):
        t0 = time.time()
        r = subprocess.run([G, "check", path, "--format", "json"], capture_output=True, text=True, timeout=120)
        dt = time.time() - t0
        ok = r.returncode in (0, 1, 2) and "panick" not in r.stderr
        wr = None
        try:
            d = json.loads(r.stdout); wr = d.get("eye_safety", {}).get("worst_ratio")
            if wr is None:
                wr = [v.get("detail", {}).get("ratio_ppm") for v in d.get("violations", [])]
        except Exception:
            pass
        if not ok: bad += 1
        print(i, os.path.basename(path), "rc", r.returncode, "%.2fs" % dt, "ratio", wr, r.stderr.strip()[:160].replace("\n", " | "), "" if ok else "<<< BAD", flush=True)
print("bad", bad)
