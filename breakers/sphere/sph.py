#!/usr/bin/env python3
"""Sphere oracle (written from the definitions, independent of the checker's code).

For a uniform-power, constant-spin profile with a head: every aperture position P on the
sphere of radius R=100 mm around C=(0,0,z0) (and on the cylinder r=100), parameterised by
its elevation e seen from C. In the head frame P turns on a horizontal circle of radius
r=R cos e at height z0+R sin e. Channel c reaches P at head angle theta iff the 3-D distance
from P to the half-line O + t u (t>=0) is <= (a + w)/2, w = exit + div*t (t = the
projection; --wdist slant uses |P-O|, the larger reading).

Time base (100 s), exact pulse count: pulses of channel c at theta_k = omega (k cycle +
slot_c + phase); energy over 100 s = sum_c s_c * #(k in one turn reaching P) * P/f * turns.
Also reports the angular measure version (phase-free). Ratio against AEL(100 s) = 3.9e-4*C4*100.
"""
import argparse, json, math
import numpy as np

def c4(lam):
    return 10 ** (0.002 * (lam - 700.0)) if 700 <= lam <= 1050 else 1.0

def reach_mask(head, ch, Px, Py, Pz, a_mm, wdist):
    r0 = head["origin_radius_mm"]; z0 = head.get("origin_height_mm", 0.0)
    el = math.radians(ch["elevation_deg"]); az = math.radians(ch["azimuth_offset_deg"])
    u = np.array([math.cos(el)*math.cos(az), math.cos(el)*math.sin(az), math.sin(el)])
    vx, vy, vz = Px - r0, Py, Pz - z0
    t = vx*u[0] + vy*u[1] + vz*u[2]
    tp = np.maximum(t, 0.0)
    dx, dy, dz = vx - tp*u[0], vy - tp*u[1], vz - tp*u[2]
    d = np.sqrt(dx*dx + dy*dy + dz*dz)
    L = np.sqrt(vx*vx+vy*vy+vz*vz) if wdist == "slant" else tp
    w = head["exit_diameter_mm"] + head["divergence_mrad"]*1e-3*L
    return d <= 0.5*(a_mm + w)

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("profile")
    ap.add_argument("--a", type=float, default=7.0)
    ap.add_argument("--ne", type=int, default=3601, help="elevation samples over (-90,90)")
    ap.add_argument("--emin", type=float, default=-89.99)
    ap.add_argument("--emax", type=float, default=89.99)
    ap.add_argument("--nth", type=int, default=72000, help="angle samples per turn for the measure")
    ap.add_argument("--phases", type=int, default=4)
    ap.add_argument("--rule1", action="store_true")
    ap.add_argument("--wdist", default="proj", choices=["proj", "slant"])
    ap.add_argument("--surface", default="sphere", choices=["sphere", "cylinder"])
    ap.add_argument("--zmin", type=float, default=-1200); ap.add_argument("--zmax", type=float, default=1200)
    args = ap.parse_args()
    doc = json.load(open(args.profile))
    es = doc["limits"]["eye_safety"]; head = es["head"]; lam = es["wavelength_nm"]
    bins = doc["bins"]
    P = bins[0]["power_w"]; om = bins[0]["spin_start_rad_s"]
    assert all(abs(b["power_w"] - P) <= 1e-15 and b["spin_start_rad_s"] == om == b["spin_end_rad_s"] for b in bins), "uniform only"
    f = doc["pulse_rate_hz"]; cyc = head["cycle_s"]
    Tf = 2*math.pi/om
    R = 100.0; z0 = head.get("origin_height_mm", 0.0)
    if args.surface == "sphere":
        e = np.radians(np.linspace(args.emin, args.emax, args.ne))
        rr = R*np.cos(e); zz = z0 + R*np.sin(e); lab = np.degrees(e)
    else:
        zz = np.linspace(args.zmin, args.zmax, args.ne); rr = np.full_like(zz, R); lab = zz
    ael100 = 3.9e-4*c4(lam)*100.0
    # measure per channel per elevation
    th = np.linspace(0, 2*math.pi, args.nth, endpoint=False)
    tot_meas = np.zeros(len(zz))
    chunk = max(1, 4_000_000 // args.nth)
    for ch in head["channels"]:
        s = ch.get("power_scale", 1.0)
        for i0 in range(0, len(zz), chunk):
            r = rr[i0:i0+chunk, None]; z = zz[i0:i0+chunk, None]
            m = reach_mask(head, ch, r*np.cos(th), r*np.sin(th), np.broadcast_to(z, (len(r), len(th))), args.a, args.wdist)
            tot_meas[i0:i0+chunk] += s*m.mean(axis=1)
    wsim_top = None
    if args.rule1:
        # simultaneous weight per elevation: max over head angle of the channels reaching (coarse theta)
        thc = np.linspace(0, 2*math.pi, 7200, endpoint=False)
        wsim = np.zeros(len(zz))
        for i0 in range(0, len(zz), max(1, 2_000_000 // len(thc))):
            r = rr[i0:i0+2_000_000//len(thc), None]; z = zz[i0:i0+2_000_000//len(thc), None]
            acc = np.zeros((len(r), len(thc)))
            for ch in head["channels"]:
                acc += ch.get("power_scale", 1.0)*reach_mask(head, ch, r*np.cos(thc), r*np.sin(thc), np.broadcast_to(z, (len(r), len(thc))), args.a, args.wdist)
            wsim[i0:i0+len(r)] = acc.max(axis=1)
        wsim_top = np.argsort(-wsim)[:4]
        out_w = float(wsim.max())
    ratio_meas = tot_meas*P*100.0/ael100   # fraction of time * P * 100 s / AEL(100)
    k = int(np.argmax(ratio_meas))
    out = {"wsim": out_w if args.rule1 else None, "measure_ratio": float(ratio_meas[k]), "at_elev_deg_or_z": float(lab[k]),
           "r_mm": float(rr[k]), "z_mm": float(zz[k])}
    # exact pulse count at the top few positions (phases)
    npr = Tf/cyc
    order = np.argsort(-ratio_meas)[:5]
    best = 0.0; bat = None
    n_turn = round(npr)
    if abs(npr - n_turn) < 1e-6 and n_turn < 5_000_000:
        for idx in order:
            r = rr[idx]; z = zz[idx]
            for p in range(args.phases):
                ph = cyc*p/args.phases
                E = 0.0
                for ch in head["channels"]:
                    kk = np.arange(n_turn)
                    ang = om*(kk*cyc + ch["slot_s"] + ph)
                    # aperture at lab azimuth 0; head at angle ang: P in head frame at -ang
                    m = reach_mask(head, ch, r*np.cos(-ang), r*np.sin(-ang), np.full(n_turn, z), args.a, args.wdist)
                    E += ch.get("power_scale", 1.0)*m.sum()*P/f
                turns = math.floor(100.0/Tf + 1e-9)
                rt = E*turns/ael100
                if rt > best: best, bat = rt, (float(lab[idx]), p)
        out["pulse_ratio"] = best; out["pulse_at"] = bat
    if args.rule1 and abs(npr - n_turn) < 1e-6:
        # Rule 1 (700-1050 nm): every T_i window's energy <= AEL_single * C5(N10), at the
        # positions where the most channels' reach overlaps (weight of reach sets, max over angle)
        ael_s = 7.7e-8*c4(lam)
        T_I = 5e-6
        # candidate elevations: top by measure and top by simultaneous weight (coarse)
        cand = list(np.argsort(-ratio_meas)[:3])
        if wsim_top is not None: cand += list(wsim_top)
        best1 = 0.0; at1 = None
        for idx in dict.fromkeys(cand):
            r = rr[idx]; z = zz[idx]
            for p in range(args.phases):
                ph = cyc*p/args.phases
                ts = []; es_ = []
                for ch in head["channels"]:
                    kk = np.arange(n_turn)
                    tt = kk*cyc + ch["slot_s"] + ph
                    ang = om*tt
                    m = reach_mask(head, ch, r*np.cos(-ang), r*np.sin(-ang), np.full(n_turn, z), args.a, args.wdist)
                    ts.append(tt[m]); es_.append(np.full(m.sum(), ch.get("power_scale", 1.0)*P/f))
                t = np.concatenate(ts); e = np.concatenate(es_)
                if len(t) == 0: continue
                o = np.argsort(t); t = t[o]; e = e[o]
                n_in_turn = np.unique(np.round(t/cyc*1e6)).size  # distinct instants
                t2 = np.concatenate([t, t + Tf]); e2 = np.concatenate([e, e])
                j = np.searchsorted(t2, t + T_I, side="left")
                ce = np.concatenate([[0.0], np.cumsum(e2)])
                grp = ce[j] - ce[:len(t)]
                N10 = len(np.unique(np.round(t/cyc*1e6)))*math.floor(10.0/Tf)  # distinct instants (lower bound)
                c5 = 1.0 if N10 <= 600 else max(0.4, 5*N10**-0.25)
                r1 = grp.max()/(ael_s*c5)
                if r1 > best1: best1, at1 = float(r1), (float(lab[idx]), p, int(N10), float(c5))
        out["rule1_ratio"] = best1; out["rule1_at"] = at1
    print(json.dumps(out))

if __name__ == "__main__":
    main()
