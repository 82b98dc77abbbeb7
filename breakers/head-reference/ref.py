#!/usr/bin/env python3
"""Brute-force eye-safety reference for a multi-beam head, written from the
definitions (outside tester, the head certificate). It does not read or call the project's
bound code.

Model (from specs/eye_safety.md conventions and the Head doc comment):
- head angle theta(t) from the profile's bins (omega^2 linear in angle per bin);
- channel c fires at k*cycle + slot_c + phase, energy s_c * P(bin of theta(t)) * cycle;
- in the head frame its ray leaves O = (r0, 0, z0) with direction
  (cos e cos phi, cos e sin phi, sin e); the lab is the head frame turned by theta;
- an aperture centre A (7 mm disc) receives the pulse, whole, iff the 3-D distance from A to
  the half-line is <= (a + w)/2, w = exit + div*1e-3*t_along (t_along = A's projection);
- surfaces: cylinder (ring radius R at height z) and sphere around (0,0,z0) (ring radius
  R cos e at height z0 + R sin e);
- rules: Rule 1 (each instant's energy vs C5*AEL(t_p); every T_i window's energy vs
  C5*AEL(T_i)), C5 from the most distinct instants in any 10 s window; Rule 2 (every window
  from a pulse to a later pulse vs the smallest AEL over the lengths that hold exactly those
  pulses); the 100 s time base.
The figure is a LOWER bound of the truth (sampled positions, concrete phases, finite horizon).
"""
import json
import math
import sys

import numpy as np

# ---------------- AEL (IEC 60825-1:2014 Class 1) ----------------


class Band:
    def __init__(self, lam, tp):
        self.lam = lam
        self.tp = tp
        if 700 <= lam <= 1050:
            self.kind = "nir"
            self.c4 = 10 ** (0.002 * (lam - 700))
            self.ti = 5e-6
            self.ap = 7.0
        elif 1400 < lam <= 1500 or lam == 1800:  # exact 1500/1800: the stricter (1400-1500) rows
            self.kind = "ir1400"
            self.ti = 1e-3
            self.c4 = 1.0
            self.ap = 3.5571
        elif 1500 < lam < 1800:
            self.kind = "ir1500"
            self.ti = 10.0
            self.c4 = 1.0
            self.ap = 3.5571
        else:
            raise SystemExit("band not modelled: %r" % lam)

    def ael(self, t):
        """AEL (J) at duration t; at a row edge the smaller row."""
        t = np.asarray(t, dtype=float)
        if self.kind == "nir":
            c4 = self.c4
            a = np.where(t < 5e-6, 7.7e-8 * c4, 7e-4 * c4 * np.power(np.maximum(t, 1e-30), 0.75))
            a = np.where(t >= 10.0, np.minimum(a, 3.9e-4 * c4 * t), a)
            a = np.where(t > 10.0, 3.9e-4 * c4 * t, a)
            a = np.where(t == 5e-6, np.minimum(7.7e-8 * c4, 7e-4 * c4 * 5e-6 ** 0.75), a)
            return a
        if self.kind == "ir1400":
            r1 = 8e-4
            r2 = 4.4e-3 * np.power(np.maximum(t, 1e-30), 0.25)
            r3 = 1e-2 * t
            a = np.where(t < 1e-3, r1, np.where(t < 0.35, r2, np.where(t <= 10, r3, 1e-2 * t)))
            a = np.where(t == 1e-3, np.minimum(r1, r2), a)
            a = np.where(t == 0.35, np.minimum(r2, r3), a)
            return a
        r1 = 8e-3
        r2 = 1.8e-2 * np.power(np.maximum(t, 1e-30), 0.75)
        a = np.where(t < 0.35, r1, np.where(t < 10, r2, 1e-2 * t))
        a = np.where(t == 0.35, np.minimum(r1, r2), a)
        a = np.where(t == 10, np.minimum(r2, 0.1), a)
        return a

    def edges(self):
        if self.kind == "nir":
            return [5e-6, 10.0]
        if self.kind == "ir1400":
            return [1e-3, 0.35, 10.0]
        return [0.35, 10.0]

    def ael_inf(self, lo, hi):
        """min AEL over [lo, hi] (vectorized): ends and row edges between."""
        lo = np.asarray(lo, float)
        hi = np.maximum(np.asarray(hi, float), lo)
        m = np.minimum(self.ael(lo), self.ael(hi))
        for e in self.edges():
            inside = (lo <= e) & (e <= hi)
            m = np.where(inside, np.minimum(m, self.ael(np.full_like(lo, e))), m)
        return m

    def c5(self, n):
        if self.kind != "nir" or self.tp > self.ti:
            return 1.0
        if n <= 600:
            return 1.0
        return max(0.4, min(1.0, 5.0 * n ** -0.25))


# ---------------- kinematics ----------------


class Motion:
    def __init__(self, bins):
        self.s = np.array([math.radians(b["start_deg"]) for b in bins])
        self.w = np.array([math.radians(b["width_deg"]) for b in bins])
        self.o0 = np.array([b["spin_start_rad_s"] for b in bins], float)
        self.o1 = np.array([b["spin_end_rad_s"] for b in bins], float)
        self.p = np.array([b["power_w"] for b in bins], float)
        self.dt = 2 * self.w / (self.o0 + self.o1)
        self.acc = (self.o1 ** 2 - self.o0 ** 2) / (2 * self.w)
        self.t0 = np.concatenate([[0.0], np.cumsum(self.dt)[:-1]])
        self.tf = float(np.sum(self.dt))
        self.th0 = self.s[0]

    def theta(self, t):
        """head angle (rad, unwrapped, from the first bin's start) at times t."""
        t = np.asarray(t, float)
        n = np.floor(t / self.tf)
        r = t - n * self.tf
        i = np.clip(np.searchsorted(self.t0, r, side="right") - 1, 0, len(self.t0) - 1)
        u = r - self.t0[i]
        th = self.s[i] + self.o0[i] * u + 0.5 * self.acc[i] * u * u
        th = np.minimum(th, self.s[i] + self.w[i])
        return th + n * 2 * math.pi, i

    def time_of(self, th):
        """first time >= 0 within a frame at which the head is at angle th (rad, any)."""
        th = np.asarray(th, float)
        rel = np.mod(th - self.th0, 2 * math.pi) + self.th0
        i = np.clip(np.searchsorted(self.s, rel, side="right") - 1, 0, len(self.s) - 1)
        d = rel - self.s[i]
        a = self.acc[i]
        o0 = self.o0[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            om = np.sqrt(np.maximum(o0 * o0 + 2 * a * d, 0.0))
            u = np.where(np.abs(a) > 1e-300, 2 * d / (o0 + om), d / o0)
        return self.t0[i] + u


# ---------------- geometry ----------------


def rays(head):
    ch = head["channels"]
    e = np.radians([c["elevation_deg"] for c in ch])
    f = np.radians([c["azimuth_offset_deg"] for c in ch])
    u = np.stack([np.cos(e) * np.cos(f), np.cos(e) * np.sin(f), np.sin(e)], axis=1)
    return u


def reach_dist(head, u, rxy, z, beta, aperture):
    """excess distance (d - rho) for ring point at head-frame angle beta (array, rad),
    per channel: shape (C, len(beta))."""
    r0 = head["origin_radius_mm"]
    z0 = head.get("origin_height_mm", 0.0)
    ex = head["exit_diameter_mm"]
    dv = head["divergence_mrad"] * 1e-3
    ax = rxy * np.cos(beta)[None, :] - r0
    ay = rxy * np.sin(beta)[None, :]
    az = np.full_like(ax, z - z0)
    ta = ax * u[:, 0:1] + ay * u[:, 1:2] + az * u[:, 2:3]
    tc = np.maximum(ta, 0.0)
    dx = ax - tc * u[:, 0:1]
    dy = ay - tc * u[:, 1:2]
    dz = az - tc * u[:, 2:3]
    d = np.sqrt(dx * dx + dy * dy + dz * dz)
    rho = (aperture + ex + dv * tc) / 2.0
    return d - rho


def arcs(head, u, rxy, z, aperture, step_deg=0.005):
    """per channel, list of closed head-frame angle intervals (rad) where the ring point is reached."""
    beta = np.radians(np.arange(-180.0, 180.0, step_deg))
    g = reach_dist(head, u, rxy, z, beta, aperture)
    ins = g <= 0
    out = []
    st = math.radians(step_deg)
    for c in range(u.shape[0]):
        row = ins[c]
        if not row.any():
            out.append([])
            continue
        if row.all():
            out.append([(-math.pi, math.pi)])
            continue
        # runs (circular)
        idx = np.flatnonzero(np.diff(np.concatenate([[0], row.astype(int), [0]])))
        runs = list(zip(idx[0::2], idx[1::2] - 1))
        # merge wrap
        if row[0] and row[-1] and len(runs) > 1:
            a0, b0 = runs[0]
            a1, b1 = runs[-1]
            runs = runs[1:-1] + [(a1, b0 + len(row))]
        res = []
        for a, b in runs:
            lo = refine(head, u[c:c + 1], rxy, z, aperture, beta_at(a - 1, beta, st), beta_at(a, beta, st))
            hi = refine(head, u[c:c + 1], rxy, z, aperture, beta_at(b + 1, beta, st), beta_at(b, beta, st))
            res.append((lo, hi))
        out.append(res)
    return out


def beta_at(i, beta, st):
    n = len(beta)
    return beta[i % n] + (i // n) * 2 * math.pi


def refine(head, u1, rxy, z, aperture, b_out, b_in, it=60):
    """bisection for the reach edge between an outside and an inside angle; returns the
    outermost inside point (slightly widened outward by 1e-12 rad)."""
    for _ in range(it):
        m = 0.5 * (b_out + b_in)
        g = reach_dist(head, u1, rxy, z, np.array([m]), aperture)[0, 0]
        if g <= 0:
            b_in = m
        else:
            b_out = m
    return b_in


# ---------------- pulses at one aperture position ----------------


def received(prof, head, mo, arcsets, alpha, horizon, phase, scales):
    """pulses received by an aperture at lab azimuth alpha (rad) on the given ring
    within [0, horizon): returns sorted times, energies, slots id (channel index)."""
    cyc = head["cycle_s"]
    slots = np.array([c["slot_s"] for c in head["channels"]])
    T = []
    E = []
    C = []
    nturn = int(math.ceil(horizon / mo.tf)) + 2
    for c, arcl in enumerate(arcsets):
        if scales[c] == 0:
            continue
        for lo, hi in arcl:
            if hi - lo >= 2 * math.pi - 1e-12:
                # whole turn: every pulse
                k = np.arange(0, int(horizon / cyc) + 1)
                t = k * cyc + slots[c] + phase
                t = t[t < horizon]
            else:
                # head angle theta in [alpha - hi, alpha - lo]
                th_lo = alpha - hi
                t_in = float(mo.time_of(np.array([th_lo]))[0])
                # duration of the pass: time from th_lo to th_lo + (hi - lo)
                dth = hi - lo
                t_out_rel = time_between(mo, th_lo, dth)
                starts = t_in + mo.tf * np.arange(-1, nturn)
                ends = starts + t_out_rel
                ks = np.ceil((starts - slots[c] - phase) / cyc - 1e-12)
                ke = np.floor((ends - slots[c] - phase) / cyc + 1e-12)
                # robust: enumerate and test exactly
                ts = []
                for a, b, s0, s1 in zip(ks, ke, starts, ends):
                    if b < a - 1:
                        continue
                    kk = np.arange(a - 1, b + 2)
                    tt = kk * cyc + slots[c] + phase
                    tt = tt[(tt >= s0 - 1e-15) & (tt <= s1 + 1e-15)]
                    ts.append(tt)
                t = np.concatenate(ts) if ts else np.zeros(0)
                t = t[(t >= 0) & (t < horizon)]
            if len(t) == 0:
                continue
            th, bi = mo.theta(t)
            e = scales[c] * mo.p[bi] * cyc
            T.append(t)
            E.append(e)
            C.append(np.full(len(t), c))
    if not T:
        return np.zeros(0), np.zeros(0), np.zeros(0, int)
    T = np.concatenate(T)
    E = np.concatenate(E)
    C = np.concatenate(C)
    o = np.argsort(T, kind="stable")
    return T[o], E[o], C[o]


def time_between(mo, th0, dth):
    """time for the head to turn from th0 by dth (rad), dth < 2 pi."""
    t0 = float(mo.time_of(np.array([th0]))[0])
    t1 = float(mo.time_of(np.array([th0 + dth]))[0])
    d = t1 - t0
    if d < 0:
        d += mo.tf
    return d


# ---------------- rules ----------------


def merge_instants(T, E, tol):
    if len(T) == 0:
        return T, E
    key = np.concatenate([[True], np.diff(T) > tol])
    gid = np.cumsum(key) - 1
    Tm = T[key]
    Em = np.bincount(gid, weights=E)
    return Tm, Em


FRAME = [1.0]


def rules(T, E, band, horizon, long_windows=True):
    """returns dict rule -> (ratio, detail)."""
    res = {}
    if len(T) == 0:
        return {"none": (0.0, "")}
    tp = band.tp
    tol = 1e-13
    Ti, Ei = merge_instants(T, E, tol)
    # C5: most distinct instants in a 10 s window (closed)
    j = np.searchsorted(Ti, Ti + 10.0, side="right")
    n10 = int(np.max(j - np.arange(len(Ti))))
    c5 = band.c5(n10)
    a1 = float(band.ael(np.array([tp]))[0]) if tp > 0 else None
    res["rule1_pulse"] = (float(Ei.max() / (c5 * a1)), "N10=%d C5=%.4f" % (n10, c5))
    if band.kind == "nir" and tp <= band.ti:
        cs = np.concatenate([[0.0], np.cumsum(Ei)])
        j = np.searchsorted(Ti, Ti + band.ti, side="left")  # half-open [t, t+Ti)
        ge = cs[j] - cs[:-1]
        ge = np.where(j - np.arange(len(Ti)) >= 2, ge, 0.0)  # a group needs two pulses (one pulse: AEL(t_p))
        a_ti = float(band.ael(np.array([band.ti]))[0])
        k = int(np.argmax(ge))
        res["rule1_group"] = (float(ge[k] / (c5 * a_ti)), "group of %d instants at t=%.9g" % (j[k] - k, Ti[k]))
    # Rule 2: windows from instant i to instant j (i<=j) up to ~1.2 frames: energy sum,
    # AEL inf over [t_j - t_i + tp, t_{j+1} - t_i) (closed at the lower end)
    n = len(Ti)
    cs = np.concatenate([[0.0], np.cumsum(Ei)])
    best = (0.0, "")
    nxt = np.concatenate([Ti[1:], [np.inf]])
    tf = FRAME[0]
    starts = np.flatnonzero(Ti < Ti[0] + 1.05 * tf)[:3000]
    for i in starts:
        jmax = min(int(np.searchsorted(Ti, Ti[i] + 1.2 * tf, side="right")), i + 4000)
        jj = np.arange(i, jmax)
        en = cs[jj + 1] - cs[i]
        span = Ti[jj] - Ti[i] + tp
        hi = np.maximum(np.minimum(nxt[jj] - Ti[i], 100.0), span)
        r = en / band.ael_inf(span, hi)
        k = int(np.argmax(r))
        if r[k] > best[0]:
            best = (float(r[k]), "window of %d instants, span %.6g s at t=%.9g" % (k + 1, span[k], Ti[i]))
    res["rule2_window"] = best
    maxoff = 0
    if long_windows:
        # longer windows: start at every instant, end at the last instant before t + L for L on a grid
        Ls = np.concatenate([np.geomspace(max(tf, 1e-6), 100.0, 200), [10.0, 100.0, 0.35, 1e-3]])
        b = (0.0, "")
        for L in Ls:
            j = np.searchsorted(Ti, Ti + L - tp, side="right") - 1
            en = cs[j + 1] - cs[np.arange(n)]
            valid = Ti + L <= horizon + 1e-9
            if not valid.any():
                continue
            r = np.where(valid, en / band.ael(np.array([L])), 0.0)
            k = int(np.argmax(r))
            if r[k] > b[0]:
                b = (float(r[k]), "window of %.6g s at t=%.6g" % (L, Ti[k]))
        res["rule2_long"] = b
    return res


def load(path):
    prof = json.load(open(path))
    es = prof["limits"]["eye_safety"]
    head = es.get("head")
    if head is None:
        head = {
            "cycle_s": 1.0 / prof["pulse_rate_hz"],
            "origin_radius_mm": 0.0,
            "origin_height_mm": 0.0,
            "exit_diameter_mm": es["beam_diameter_mm"],
            "divergence_mrad": 0.0,
            "channels": [{"id": 0, "elevation_deg": 0.0, "azimuth_offset_deg": 0.0, "slot_s": 0.0}],
        }
    band = Band(es["wavelength_nm"], es["pulse_duration_s"])
    return prof, head, band


def rings(head, surface, R, zs):
    z0 = head.get("origin_height_mm", 0.0)
    out = []
    for z in zs:
        if surface == "cylinder":
            out.append((R, z, z))
        else:
            # z given as height above C
            if abs(z) >= R:
                continue
            out.append((math.sqrt(R * R - z * z), z0 + z, z))
    return out


def main():
    import argparse

    ap = argparse.ArgumentParser()
    ap.add_argument("profile")
    ap.add_argument("--surface", default="cylinder", choices=["cylinder", "sphere"])
    ap.add_argument("--R", type=float, default=100.0)
    ap.add_argument("--heights", default=None, help="comma list of heights (mm; sphere: above C)")
    ap.add_argument("--hgrid", default=None, help="lo,hi,step")
    ap.add_argument("--alphas", default="0", help="comma list of lab azimuths, deg")
    ap.add_argument("--horizon", type=float, default=None)
    ap.add_argument("--phases", default="0")
    ap.add_argument("--top", type=int, default=4, help="heights given the full rules")
    ap.add_argument("--step", type=float, default=0.005)
    a = ap.parse_args()
    prof, head, band = load(a.profile)
    mo = Motion(prof["bins"])
    FRAME[0] = mo.tf
    u = rays(head)
    scales = np.array([c.get("power_scale", 1.0) for c in head["channels"]], float)
    if a.hgrid:
        lo, hi, st = map(float, a.hgrid.split(","))
        zs = list(np.arange(lo, hi + st / 2, st))
    else:
        zs = [float(x) for x in (a.heights or "0").split(",")]
    if a.heights and a.hgrid:
        zs += [float(x) for x in a.heights.split(",")]
    horizon = a.horizon if a.horizon else min(100.0 + 2 * mo.tf, max(3 * mo.tf, 12.0))
    # screen heights by sum of s_c * pass angle
    scr = []
    for rxy, z, zlab in rings(head, a.surface, a.R, zs):
        ar = arcs(head, u, rxy, z, band.ap, a.step)
        w = sum(scales[c] * sum(h - l for l, h in ar[c]) for c in range(len(ar)))
        scr.append((w, zlab, rxy, z, ar))
    scr.sort(key=lambda x: -x[0])
    overall = (0.0, None)
    for w, zlab, rxy, z, ar in scr[: a.top]:
        nmeet = sum(1 for x in ar if x)
        for al in [math.radians(float(x)) for x in a.alphas.split(",")]:
            for ph in [float(x) for x in a.phases.split(",")]:
                T, E, C = received(prof, head, mo, ar, al, horizon, ph * head["cycle_s"], scales)
                r = rules(T, E, band, horizon)
                m = max(r.items(), key=lambda kv: kv[1][0])
                print("h=%.6g alpha=%.4f phase=%g meet=%d pulses=%d  %s  %s" % (
                    zlab, math.degrees(al), ph, nmeet, len(T), m[0], m[1]), flush=True)
                print("   ", {k: round(v[0], 6) for k, v in r.items()})
                if m[1][0] > overall[0]:
                    overall = (m[1][0], (zlab, math.degrees(al), ph, m[0], m[1][1]))
    print("REFERENCE", overall[0], overall[1])


if __name__ == "__main__":
    main()
