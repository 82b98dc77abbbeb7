#!/usr/bin/env python3
"""Whole turn for real: a head whose every channel reaches every aperture position at every
head angle (r0 = 0, flat channels, exit >= 2R - 7 + margin: rho >= R on the cylinder and the
sphere), so the truth is the emission itself, whatever the geometry: every pulse enters.
Profiles with steps of spin and power (no acceleration limit), 905 nm, the truth from explicit
pulses (time from the spin per bin), against `check` scaled to TARGET.
Rules: each pulse vs C5*AEL_single (N = pulses in 10 s, T_i groups when cycle < 5 us), every
window of k consecutive pulses (k <= 64 and geometric to two frames), n frames, the time base.
usage: wholeturn.py COUNT SEED [--target 0.97]
"""
import argparse, json, math, os, random, sys
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from run import check  # noqa: E402
import importlib.util  # noqa: E402
_spec = importlib.util.spec_from_file_location("beam_oracle", os.path.join(HERE, "oracle.py"))
_o = importlib.util.module_from_spec(_spec); _spec.loader.exec_module(_o)
ael, ael_inf, c4 = _o.ael, _o.ael_inf, _o.c4


def make(rng, scale):
    n = 36
    omega0 = 2 * math.pi * rng.choice([5.0, 10.0, 20.0])
    spins = [omega0 * rng.choice([1.0, 1.0, 0.3, 0.5, 2.0]) for _ in range(n)]
    pw = [rng.choice([1.0, 1.0, 0.1, 3.0, 10.0]) for _ in range(n)]
    nch = rng.choice([1, 2, 4])
    cyc = rng.choice([1e-5, 2e-5, 5.5e-6])
    head = {"cycle_s": cyc, "origin_radius_mm": 0.0, "origin_height_mm": 0.0,
            "exit_diameter_mm": rng.uniform(195.5, 400.0), "divergence_mrad": rng.choice([0.0, 3.0]),
            "aperture_distance_mm": 100.0,
            "channels": [{"id": i, "elevation_deg": 0.0, "azimuth_offset_deg": 0.0,
                          "slot_s": (i * cyc / nch) if rng.random() < 0.5 else 0.0, "power_scale": 1.0}
                         for i in range(nch)]}
    return head, spins, pw


def profile(head, spins, pw, scale):
    n = len(spins); w = 360.0 / n
    T = sum(math.radians(w) / s for s in spins)
    return {"format": "gaze-lidar/profile@1", "frame_rate_hz": 1.0 / T, "pulse_rate_hz": 1.0 / head["cycle_s"],
            "average_power_w": sum(scale * p * math.radians(w) / s for p, s in zip(pw, spins)) / T,
            "power_accounting": "time", "gaze_deg": None,
            "limits": {"power_w_min": 0.0, "power_w_max": scale * max(pw), "spin_rad_s_min": min(spins),
                       "spin_rad_s_max": max(spins), "spin_accel_rad_s2_max": None,
                       "power_slew_w_per_deg_max": None,
                       "eye_safety": {"wavelength_nm": 905.0, "pulse_duration_s": 5e-9,
                                      "beam_diameter_mm": head["exit_diameter_mm"], "head": head}},
            "bins": [{"start_deg": i * w, "width_deg": w, "power_w": scale * pw[i],
                      "spin_start_rad_s": spins[i], "spin_end_rad_s": spins[i]} for i in range(n)]}


def truth(doc):
    es = doc["limits"]["eye_safety"]; head = es["head"]; lam = 905.0; tau = 5e-9
    bins = doc["bins"]
    edges_t = [0.0]
    for b in bins:
        edges_t.append(edges_t[-1] + math.radians(b["width_deg"]) / b["spin_start_rad_s"])
    T = edges_t[-1]; edges_t = np.array(edges_t)
    cyc = head["cycle_s"]; f = 1.0 / cyc
    pw = np.array([b["power_w"] for b in bins])
    ts = []
    for c in head["channels"]:
        ts.append(np.arange(0.0, 2 * T, cyc) + c["slot_s"])
    t = np.sort(np.concatenate(ts)); t = t[t < 2 * T]
    k = np.clip(np.searchsorted(edges_t, np.mod(t, T), side="right") - 1, 0, len(bins) - 1)
    E = pw[k] / f
    ce = np.concatenate([[0.0], np.cumsum(E)])
    n = len(t)
    res = {}
    # rule 1 (T_i = 5 us groups)
    j = np.searchsorted(t, t + 5e-6 - 1e-15, side="left")
    g = (ce[j] - ce[:-1]).max()
    groups = 1 + np.count_nonzero(np.diff(t[t < T]) >= 5e-6)
    N = groups * math.floor(10.0 / T)
    C5 = 1.0 if N <= 600 else max(0.4, 5 * N ** -0.25)
    res["rule1"] = g / (C5 * 7.7e-8 * c4(lam))
    best = 0.0
    half = n // 2
    ks = sorted(set(list(range(1, 65)) + [int(x) for x in np.geomspace(65, half, 200)]))
    for kk in ks:
        i = np.arange(0, n - kk)
        jj = i + kk - 1
        span = t[jj] - t[i]
        gap = t[jj + 1] - t[jj]
        r = (ce[jj + 1] - ce[i]) / ael_inf(span + tau, span + tau + gap, lam)
        best = max(best, float(r.max()))
    res["windows"] = best
    Ef = E[t < T].sum()
    multi = 0.0
    for nn in sorted(set(int(x) for x in np.geomspace(2, math.floor(100 / T), 60)) | {int(10 / T), int(10 / T) + 1}):
        span = nn * T
        multi = max(multi, nn * Ef / float(ael_inf(span - cyc + tau, span + tau, lam)))
    res["multi"] = multi
    res["time_base"] = Ef * math.floor(100 / T) / (3.9e-4 * c4(lam) * 100)
    res["truth"] = max(res.values())
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("count", type=int); ap.add_argument("seed", type=int)
    ap.add_argument("--target", type=float, default=0.97)
    ap.add_argument("--outdir", default="/tmp/bb/whole")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    rng = random.Random(a.seed)
    for i in range(a.count):
        head, spins, pw = make(rng, 1.0)
        path = os.path.join(a.outdir, f"W{a.seed}_{i}.json")
        json.dump(profile(head, spins, pw, 1e-3), open(path, "w"))
        rc, d, err = check(path)
        if d is None or not d.get("eye_safety"):
            print(json.dumps({"name": path, "rc": rc, "err": err})); continue
        s = 1e-3 * a.target / d["eye_safety"]["worst_ratio"]
        doc = profile(head, spins, pw, s)
        json.dump(doc, open(path, "w"))
        rc, d, err = check(path)
        es = d["eye_safety"]
        tr = truth(doc)
        flag = " <<<<<< BUG" if rc == 0 and tr["truth"] > 1 else ""
        print(json.dumps({"name": os.path.basename(path), "rc": rc, "check": es["worst_ratio"],
                          "rule": es["binding_rule"],
                          "pass": (es.get("head") or {}).get("figures", {}).get("pass_angle_deg"),
                          "truth": tr, "truth/check": tr["truth"] / es["worst_ratio"]}) + flag, flush=True)


if __name__ == "__main__":
    main()
