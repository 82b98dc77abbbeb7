#!/usr/bin/env python3
"""Every rule (700-1050 nm) by explicit pulses at positions of the 100 mm sphere around the
scan centre (or the cylinder), for uniform constant-spin profiles with a head, any pulse rate.

Positions: sphere elevations e (seen from C) ranked on a grid by the time-base proxy
(sum of s_c x reach measure) and by the simultaneous weight; the top --top ones get the full
rules for --phases clock phases (a lab-azimuth shift of the aperture is a phase shift):
 - Rule 1: every T_i window's energy <= C5(N10) * AEL(single), N10 = distinct instants
   reaching the aperture in 10 s (turn count x instants per turn);
 - every window from a pulse to a later one (span s, up to --span-max s): E <= AEL(s + tau);
 - time base: pulses of one turn x turns in 100 s (from --turns simulated turns, per turn).
Lower bound of the truth (concrete positions, phases).
usage: full.py PROFILE [--surface sphere|cylinder] [--e0 -40 --e1 40 --de 0.05] [--top 6]
"""
import argparse, json, math, sys, os
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sph import reach_mask, c4

def ael_vec(t, lam):
    k = c4(lam); t = np.asarray(t, float)
    return np.where(t < 5e-6, 7.7e-8*k, np.where(t <= 10.0, 7e-4*k*t**0.75, 3.9e-4*k*t))

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("profile"); ap.add_argument("--surface", default="sphere")
    ap.add_argument("--e0", type=float, default=-40); ap.add_argument("--e1", type=float, default=40)
    ap.add_argument("--de", type=float, default=0.05); ap.add_argument("--top", type=int, default=6)
    ap.add_argument("--phases", type=int, default=4); ap.add_argument("--turns", type=int, default=2)
    ap.add_argument("--span-max", type=float, default=0.02); ap.add_argument("--nth", type=int, default=7200)
    ap.add_argument("--a", type=float, default=7.0)
    ap.add_argument("--alphas", default="0", help="lab azimuths of the aperture, deg (non-uniform profiles)")
    a = ap.parse_args()
    doc = json.load(open(a.profile)); es = doc["limits"]["eye_safety"]; head = es["head"]
    lam = es["wavelength_nm"]; tau = es["pulse_duration_s"]
    P = doc["bins"][0]["power_w"]; om = doc["bins"][0]["spin_start_rad_s"]
    assert all(b["spin_start_rad_s"] == om == b["spin_end_rad_s"] for b in doc["bins"]), "constant spin only"
    starts = np.array([b["start_deg"] for b in doc["bins"]]); pows = np.array([b["power_w"] for b in doc["bins"]])
    def power_at(tt):  # head (encoder) angle = omega t from 0 deg at t = 0
        th = np.mod(np.degrees(om*tt), 360.0)
        return pows[np.clip(np.searchsorted(starts, th, side="right") - 1, 0, len(pows) - 1)]
    P = float(pows.mean())
    f = doc["pulse_rate_hz"]; cyc = head["cycle_s"]; Tf = 2*math.pi/om; R = 100.0
    z0 = head.get("origin_height_mm", 0.0)
    if a.surface == "sphere":
        e = np.radians(np.arange(a.e0, a.e1 + 1e-9, a.de)); rr = R*np.cos(e); zz = z0 + R*np.sin(e); lab = np.degrees(e)
    else:
        zz = np.arange(a.e0, a.e1 + 1e-9, a.de); rr = np.full_like(zz, R); lab = zz
    th = np.linspace(0, 2*math.pi, a.nth, endpoint=False)
    meas = np.zeros(len(zz)); wsim = np.zeros(len(zz))
    slots = sorted(set(c["slot_s"] for c in head["channels"]))
    for i in range(len(zz)):
        X = rr[i]*np.cos(th); Y = rr[i]*np.sin(th); Z = np.full_like(th, zz[i])
        bys = {}
        for c in head["channels"]:
            m = reach_mask(head, c, X, Y, Z, a.a, "proj")
            s = c.get("power_scale", 1.0)
            meas[i] += s*m.mean()
            bys[c["slot_s"]] = bys.get(c["slot_s"], 0) + s*m
        wsim[i] = max(v.max() for v in bys.values())
    cand = list(dict.fromkeys(list(np.argsort(-meas)[:a.top]) + list(np.argsort(-wsim)[:a.top//2])))
    ael_s = 7.7e-8*c4(lam); T_I = 5e-6
    best = {"rule1": (0, None), "window": (0, None), "time_base": (0, None)}
    nk = int(math.ceil(a.turns*Tf/cyc)) + 1
    for idx in cand:
        r = rr[idx]; z = zz[idx]
        for alpha in [math.radians(float(x)) for x in a.alphas.split(",")]:
          a.alpha = alpha
          for p in range(a.phases):
            ph = cyc*p/a.phases
            ts = []; en = []
            for c in head["channels"]:
                tt = np.arange(nk)*cyc + c["slot_s"] + ph
                tt = tt[tt < a.turns*Tf]
                ang = om*tt
                m = reach_mask(head, c, r*np.cos(a.alpha - ang), r*np.sin(a.alpha - ang), np.full(len(tt), z), a.a, "proj")
                ts.append(tt[m]); en.append(c.get("power_scale", 1.0)*power_at(tt[m])/f)
            t = np.concatenate(ts); E = np.concatenate(en)
            if len(t) == 0: continue
            o = np.argsort(t, kind="stable"); t = t[o]; E = E[o]
            ce = np.concatenate([[0.0], np.cumsum(E)])
            inst = np.unique(np.round(t/cyc*1e3)).size / a.turns   # distinct instants per turn
            N10 = inst*(10.0/Tf)
            c5 = 1.0 if N10 <= 600 else max(0.4, 5*N10**-0.25)
            j = np.searchsorted(t, t + T_I, side="left")
            g = (ce[j] - ce[:-1]).max()/(ael_s*c5)
            if g > best["rule1"][0]: best["rule1"] = (float(g), (float(lab[idx]), round(math.degrees(a.alpha), 3), p, int(N10), round(c5, 4)))
            # windows from pulse i to pulse j (span <= span_max)
            n = len(t); wbest = 0; wat = None
            jmax = np.searchsorted(t, t + a.span_max, side="right")
            for i0 in range(n):
                jj = np.arange(i0, jmax[i0])
                if len(jj) == 0: continue
                rat = (ce[jj + 1] - ce[i0])/ael_vec(t[jj] - t[i0] + tau, lam)
                k = int(np.argmax(rat))
                if rat[k] > wbest: wbest, wat = float(rat[k]), (float(t[jj[k]] - t[i0]), int(jj[k] - i0 + 1))
            if wbest > best["window"][0]: best["window"] = (wbest, (float(lab[idx]), round(math.degrees(a.alpha), 3), p) + wat)
            tb = E.sum()/a.turns*math.floor(100.0/Tf)/(3.9e-4*c4(lam)*100)
            if tb > best["time_base"][0]: best["time_base"] = (float(tb), (float(lab[idx]), round(math.degrees(a.alpha), 3), p))
    out = {k: v for k, v in best.items()}
    out["worst"] = max(v[0] for v in best.values())
    out["proxy_top"] = [(float(lab[i]), float(meas[i]), float(wsim[i])) for i in cand[:4]]
    print(json.dumps(out))

if __name__ == "__main__":
    main()
