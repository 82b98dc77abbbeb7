#!/usr/bin/env python3
"""Extreme but valid heads through `check`: looks for panics, exit codes other
than 0/1/2, NaN or infinite figures, and very slow checks."""
import json, subprocess, sys, time, os
sys.path.insert(0, os.path.dirname(__file__))
from mk import profile
B = os.environ.get("B", "/work/targets/break-head/release/gaze-lidar")

def ch(i, el=0.0, az=0.0, slot=0.0, ps=1.0):
    return {"id": i, "elevation_deg": el, "azimuth_offset_deg": az, "slot_s": slot, "power_scale": ps}

def head(chs, cycle=1e-5, r0=0.0, z0=0.0, exit_=5.0, div=0.0, R=100.0):
    return {"cycle_s": cycle, "origin_radius_mm": r0, "origin_height_mm": z0, "exit_diameter_mm": exit_,
            "divergence_mrad": div, "aperture_distance_mm": R, "channels": chs}

cases = {
 "grazing": head([ch(0, 0, 89.999)], r0=99.999),
 "grazing_elev": head([ch(0, 89.999, 89.999)], r0=99.999),
 "steep": head([ch(0, 89.9999999, 0)]),
 "huge_beam": head([ch(0)], exit_=999.0, div=1000.0),
 "tiny_R": head([ch(0)], R=1e-300 * 1e292, exit_=1e-3),
 "tiny_R_r0": head([ch(0, 10, 45)], R=1e-3, r0=0.9999e-3, exit_=1e-3),
 "far_R": head([ch(0, 1, 1)], R=1e4, r0=9999.0),
 "tiny_beam": head([ch(0)], exit_=1e-300),
 "512_same": head([ch(i) for i in range(512)]),
 "512_spread": head([ch(i, -80 + 160 * i / 511, -80 + 160 * ((i * 37) % 512) / 511, slot=(i % 7) * 1e-6) for i in range(512)], r0=50, div=3),
 "ps_1000": head([ch(0, ps=1000.0), ch(1, ps=0.0), ch(2, 0.05, ps=5e-324 * 0 + 1e-300)]),
 "all_zero_scale": head([ch(0, ps=0.0), ch(1, ps=0.0)]),
 "slot_edge": head([ch(0, slot=0.0), ch(1, slot=1e-5 * (1 - 2**-52))]),
 "cycle_1s": head([ch(0), ch(1, slot=0.999999)], cycle=1.0),
 "cycle_tiny": head([ch(0), ch(1, slot=5e-13)], cycle=1e-12),
 "origin_high": head([ch(0, -89, 0)], z0=1e4),
}
for name, h in cases.items():
    for frame in (10.0, 1e-6):
        doc = profile(h, 1e-4, frame, 4)
        path = f"/tmp/bh_c_{name}_{frame}.json"
        json.dump(doc, open(path, "w"))
        t0 = time.time()
        try:
            r = subprocess.run([B, "check", path, "--format", "json"], capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            print(f"{name} frame={frame}: TIMEOUT >120 s"); continue
        dt = time.time() - t0
        fig = None
        try:
            j = json.loads(r.stdout); e = j.get("eye_safety") or {}
            fig = (j["certified"], e.get("worst_ratio"), e.get("binding_rule"))
        except Exception:
            pass
        err = r.stderr.strip().splitlines()
        print(f"{name} frame={frame}: rc={r.returncode} {dt:.2f}s {fig} {err[:1]}")
