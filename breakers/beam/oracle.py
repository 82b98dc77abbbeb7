#!/usr/bin/env python3
"""break-beam oracle: the truth (a lower bound of it: concrete aperture positions and clock
phases) for a constant-spin profile@1 with a head, on the cylinder and on the sphere.

GEOMETRY (written from the definition, not from the checker's code): an aperture of diameter
a = 7 mm centred at P is hit by channel c at head angle h iff the 3-D distance from P, turned
into the head frame by -h, to the half-line O + t*u (t >= 0, O = (r0, 0, z0), u from the
channel's elevation and azimuth offset) is <= (a + w(t))/2, w(t) = exit + divergence*t at the
nearest point t. Positions: the cylinder of radius R around the spin axis (height z), the
sphere of radius R around C = (0, 0, z0) (elevation e seen from C). R = 100 mm, and also the
declared aperture_distance_mm when it differs (the verdict covers both).

For one position the reached head-frame angles of each channel are found on a grid of
--nth angles and every edge refined by bisection (to ~1e-12 rad).

RULES (700-1050 nm; AEL code checked against the design card's section 5 (outside this repository), as breakers/sphere/full.py):
 - AEL(T) = 7.7e-8*C4 J (T < 5 us), 7e-4*C4*T^0.75 J (5 us .. 10 s), 3.9e-4*C4*T J (> 10 s);
   a window of pulses spanning s is compared with the smallest AEL over [s + tau, s + tau + gap)
   (gap: to the next received pulse; the table steps down at 5 us and 10 s).
 - Rule 1: each T_i (5 us) group's energy <= C5 * 7.7e-8*C4, C5 = 1 (N <= 600) else
   max(0.4, 5 N^-0.25), N = groups in 10 s (a lower count: whole turns only).
 - within a pass: windows of k consecutive received pulses (all k <= 64, geometric beyond, the
   whole pass), vectorised over starts;
 - over n turns (periodic: the profile must have an integer number of cycles per turn): the
   window from a pass's first pulse to the n-th pass's last, n = 2 .. 100 s, and the n around 10 s;
 - time base: pulses per turn x turns in 100 s against 3.9e-4*C4*100.
Clock phases: --phases values of the pulse clock's phase within one cycle.
Positions: a coarse grid ranked by sum_c s_c*(reached fraction) and by the most channels
reached at one head angle, then the best --top refined locally.

usage: oracle.py PROFILE [--surface cylinder|sphere|both] [--zmin --zmax --nz] [--top 6]
prints one JSON line: per surface and distance the worst ratio per rule and where.
"""
import argparse, json, math, sys
import numpy as np

A_MM = 7.0


def c4(lam):
    return 10 ** (0.002 * (lam - 700.0)) if 700 <= lam <= 1050 else float("nan")


def ael(T, lam):
    k = c4(lam)
    T = np.asarray(T, float)
    return np.where(T < 5e-6, 7.7e-8 * k, np.where(T <= 10.0, 7e-4 * k * T ** 0.75, 3.9e-4 * k * T))


def ael_inf(T1, T2, lam):
    """smallest AEL over [T1, T2]."""
    a = ael(T1, lam)
    T1 = np.asarray(T1, float); T2 = np.asarray(T2, float)
    for edge in (5e-6, 10.0):
        e = ael(np.full_like(T1, edge), lam)
        a = np.where((T1 <= edge) & (edge <= T2), np.minimum(a, e), a)
    return a


class Ray:
    def __init__(self, head, ch):
        el = math.radians(ch["elevation_deg"]); az = math.radians(ch["azimuth_offset_deg"])
        self.u = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
        self.r0 = head["origin_radius_mm"]
        self.exit = head["exit_diameter_mm"]; self.div = head["divergence_mrad"] * 1e-3
        self.s = ch.get("power_scale", 1.0); self.slot = ch["slot_s"]

    def reached(self, th, r, Z):
        """position at head-frame angle th, distance r from the axis, height Z above O."""
        px = r * np.cos(th) - self.r0; py = r * np.sin(th); pz = Z
        t = np.maximum(px * self.u[0] + py * self.u[1] + pz * self.u[2], 0.0)
        dx = px - t * self.u[0]; dy = py - t * self.u[1]; dz = pz - t * self.u[2]
        return np.sqrt(dx * dx + dy * dy + dz * dz) <= 0.5 * (A_MM + self.exit + self.div * t)

    def arcs(self, r, Z, nth):
        """reached head-frame angles as a sorted list of [lo, hi] in [0, 2pi) (may wrap)."""
        th = np.linspace(0.0, 2 * math.pi, nth, endpoint=False)
        m = self.reached(th, r, Z)
        if m.all():
            return np.array([[0.0, 2 * math.pi]])
        if not m.any():
            return np.zeros((0, 2))
        # transitions i -> i+1 (cyclic)
        nxt = np.roll(m, -1)
        ups = np.nonzero(~m & nxt)[0]    # edge between th[i] (out) and th[i+1] (in)
        dns = np.nonzero(m & ~nxt)[0]    # edge between th[i] (in) and th[i+1] (out)
        step = 2 * math.pi / nth

        def refine(idx, rising):
            lo = th[idx].copy(); hi = lo + step
            for _ in range(45):
                mid = 0.5 * (lo + hi)
                inside = self.reached(mid, r, Z)
                if rising:
                    hi = np.where(inside, mid, hi); lo = np.where(inside, lo, mid)
                else:
                    lo = np.where(inside, mid, lo); hi = np.where(inside, hi, mid)
            return hi if rising else lo   # the reached side
        starts = np.mod(refine(ups, True), 2 * math.pi)
        ends = np.mod(refine(dns, False), 2 * math.pi)
        starts.sort(); ends.sort()
        # pair each start with the next end (cyclically)
        out = []
        for s in starts:
            k = np.searchsorted(ends, s)
            e = ends[k % len(ends)]
            if e < s:
                e += 2 * math.pi
            out.append([s, e])
        return np.array(out)


def in_arcs(theta, arcs):
    theta = np.mod(theta, 2 * math.pi)
    m = np.zeros(theta.shape, bool)
    for lo, hi in arcs:
        if hi - lo >= 2 * math.pi - 1e-15:
            return np.ones(theta.shape, bool)
        d = np.mod(theta - lo, 2 * math.pi)
        m |= d <= (hi - lo)
    return m


def measure(arcs):
    return sum(min(hi - lo, 2 * math.pi) for lo, hi in arcs) / (2 * math.pi)


def evaluate_position(doc, rays, r, Z, nth, phases, lam, tau):
    """every rule at one position (lab azimuth 0), max over clock phases."""
    head = doc["limits"]["eye_safety"]["head"]
    om = doc["bins"][0]["spin_start_rad_s"]; Tf = 2 * math.pi / om
    cyc = head["cycle_s"]; f = doc["pulse_rate_hz"]
    npt = Tf / cyc
    assert abs(npt - round(npt)) < 1e-6 * npt, "need an integer number of cycles per turn"
    npt = int(round(npt))
    starts = np.array([b["start_deg"] for b in doc["bins"]]); pows = np.array([b["power_w"] for b in doc["bins"]])
    arcs = [ray.arcs(r, Z, nth) for ray in rays]
    res = {"rule1": 0.0, "pass": 0.0, "multi": 0.0, "time_base": 0.0}
    where = {}
    ael_s = 7.7e-8 * c4(lam)
    # lab azimuths of the aperture: 0 for a uniform profile; otherwise where the hottest bins'
    # encoder angles bring each channel's reached arcs (its ends and middle) over the aperture
    alphas = [0.0]
    if pows.max() > pows.min():
        widths = np.array([b["width_deg"] for b in doc["bins"]])
        hot = np.nonzero(pows >= pows.max() * (1 - 1e-12))[0]
        encs = sorted({math.radians(starts[hb] + 0.5 * widths[hb]) for hb in hot}
                      | {math.radians(starts[hot[0]]), math.radians(starts[hot[-1]] + widths[hot[-1]])})
        for ar in arcs:
            for lo, hi in ar:
                for enc in encs:
                    for x in (lo, 0.5 * (lo + hi), hi):
                        alphas.append(enc + x)
        alphas = sorted(set(round(x % (2 * math.pi), 12) for x in alphas))
    for p, alpha in [(p, al) for p in range(phases) for al in alphas]:
        ph = cyc * p / phases
        ts = []; es = []
        for ray, ar in zip(rays, arcs):
            if len(ar) == 0:
                continue
            tt = np.arange(npt) * cyc + ray.slot + ph
            hang = om * tt                     # encoder angle of the head
            m = in_arcs(alpha - hang, ar)      # position at lab azimuth alpha -> head frame alpha - h
            tt = tt[m]
            if len(tt) == 0:
                continue
            enc = np.mod(np.degrees(om * tt), 360.0)
            P = pows[np.clip(np.searchsorted(starts, enc, side="right") - 1, 0, len(pows) - 1)]
            ts.append(tt); es.append(ray.s * P / f)
        if not ts:
            continue
        t1 = np.concatenate(ts); e1 = np.concatenate(es)
        o = np.argsort(t1, kind="stable"); t1 = t1[o]; e1 = e1[o]
        # two turns (periodic) so that passes across the turn's end are whole
        t = np.concatenate([t1, t1 + Tf]); E = np.concatenate([e1, e1])
        ce = np.concatenate([[0.0], np.cumsum(E)])
        n = len(t)
        Eturn = e1.sum()
        turns100 = math.floor(100.0 / Tf + 1e-9)
        tb = Eturn * turns100 / (3.9e-4 * c4(lam) * 100.0)
        if tb > res["time_base"]:
            res["time_base"] = tb; where["time_base"] = p
        # rule 1: T_i groups
        j = np.searchsorted(t, t + 5e-6 - 1e-15, side="left")
        g = ce[j] - ce[:-1]
        grp = 1 + np.count_nonzero(np.diff(t1) >= 5e-6)  # groups per turn (lower count ok)
        N = grp * math.floor(10.0 / Tf + 1e-9)
        C5 = 1.0 if N <= 600 else max(0.4, 5 * N ** -0.25)
        r1 = g.max() / (C5 * ael_s)
        if r1 > res["rule1"]:
            res["rule1"] = r1; where["rule1"] = (p, int(N), C5)
        # within a pass / a turn: windows of k consecutive pulses
        ks = sorted(set(list(range(1, 65)) + [int(x) for x in np.geomspace(65, max(66, len(t1)), 60)]))
        best = 0.0; bk = None
        for k in ks:
            if k > len(t1):
                break
            i = np.arange(0, len(t1))
            jj = i + k - 1
            span = t[jj] - t[i]
            gap = np.where(jj + 1 < n, t[np.minimum(jj + 1, n - 1)] - t[jj], Tf)
            en = ce[jj + 1] - ce[i]
            rat = en / ael_inf(span + tau, span + tau + gap, lam)
            m = rat.max()
            if m > best:
                best = m; bk = (k, float(span[np.argmax(rat)]))
        if best > res["pass"]:
            res["pass"] = best; where["pass"] = (p,) + bk
        # several turns: from the first pulse of a pass to the last of the n-th pass
        # (every received pulse of the turn x n, span (n - 1)*Tf + the longest in-turn span)
        if len(t1) > 0:
            in_span = t1[-1] - t1[0]
            nmax = turns100
            cand = set(int(x) for x in np.geomspace(2, max(2, nmax), 80))
            n10 = int((10.0 - in_span) / Tf) + 1
            cand |= {n10 - 1, n10, n10 + 1, nmax}
            for nn in sorted(c for c in cand if 2 <= c <= nmax):
                span = (nn - 1) * Tf + in_span
                rr = nn * Eturn / float(ael_inf(span + tau, span + tau + (Tf - in_span), lam))
                if rr > res["multi"]:
                    res["multi"] = rr; where["multi"] = (p, nn)
    res["worst"] = max(res.values())
    res["where"] = where
    res["measure"] = [measure(a) for a in arcs]
    return res


def proxy(rays, r, Z, nth):
    th = np.linspace(0, 2 * math.pi, nth, endpoint=False)
    tot = np.zeros(nth); meas = 0.0
    for ray in rays:
        m = ray.reached(th, r, Z)
        meas += ray.s * m.mean(); tot += ray.s * m
    return meas, tot.max()


def surface_positions(surface, R, z0, zs):
    """(label, r, Z above O) per sample; zs: heights (cylinder) or elevations deg (sphere)."""
    out = []
    for v in zs:
        if surface == "cylinder":
            out.append((float(v), R, float(v) - z0))
        else:
            e = math.radians(v)
            out.append((float(v), R * math.cos(e), R * math.sin(e)))
    return out


def run(doc, surface, R, args):
    es = doc["limits"]["eye_safety"]; head = es["head"]
    lam = es["wavelength_nm"]; tau = es["pulse_duration_s"]
    z0 = head.get("origin_height_mm", 0.0)
    rays = [Ray(head, c) for c in head["channels"]]
    if surface == "cylinder":
        if args.zmin is None:
            # every channel's hit height on this cylinder, +- a generous margin
            zh = []
            r0 = head["origin_radius_mm"]
            for c in head["channels"]:
                ph = math.radians(c["azimuth_offset_deg"]); ep = math.radians(c["elevation_deg"])
                sc = -r0 * math.cos(ph) + math.sqrt(R * R - (r0 * math.sin(ph)) ** 2)
                zh.append(z0 + sc * math.tan(ep))
            lo, hi = min(zh) - 150.0 - R, max(zh) + 150.0 + R
            lo, hi = max(lo, z0 - 3000.0), min(hi, z0 + 3000.0)
        else:
            lo, hi = args.zmin, args.zmax
        zs = np.linspace(lo, hi, args.nz or int(min(4001, max(601, (hi - lo) / 0.5))))
    else:
        zs = np.linspace(-89.99, 89.99, args.nz or 1801)
    pos = surface_positions(surface, R, z0, zs)
    px = [proxy(rays, r, Z, args.nth_coarse) for _, r, Z in pos]
    meas = np.array([p[0] for p in px]); sim = np.array([p[1] for p in px])
    cand = list(dict.fromkeys(list(np.argsort(-meas)[:args.top]) + list(np.argsort(-sim)[:args.top])))
    # local refinement of the best by measure
    step = zs[1] - zs[0]
    best_i = int(np.argmax(meas))
    fine = np.linspace(zs[best_i] - step, zs[best_i] + step, 41)
    if surface == "sphere":
        fine = np.clip(fine, -89.9999, 89.9999)
    fpos = surface_positions(surface, R, z0, fine)
    fmeas = [proxy(rays, r, Z, args.nth_coarse)[0] for _, r, Z in fpos]
    extra = [fpos[int(k)] for k in np.argsort(-np.array(fmeas))[:3]]
    allpos = [pos[i] for i in cand] + extra
    if args.all:
        # every grid position with a reached channel (thinned to --all positions)
        hit = [i for i in range(len(pos)) if meas[i] > 0]
        if len(hit) > args.all:
            hit = [hit[int(k)] for k in np.linspace(0, len(hit) - 1, args.all)]
        allpos += [pos[i] for i in hit]
    best = {"worst": 0.0}
    per_rule = {}
    for lab, r, Z in allpos:
        res = evaluate_position(doc, rays, r, Z, args.nth, args.phases, lam, tau)
        if res["worst"] > best["worst"]:
            best = dict(res); best["at"] = lab
        for k in ("rule1", "pass", "multi", "time_base"):
            if res[k] > per_rule.get(k, (0.0,))[0]:
                per_rule[k] = (res[k], lab)
    best["per_rule_max"] = per_rule
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("profile")
    ap.add_argument("--surface", default="both")
    ap.add_argument("--zmin", type=float, default=None); ap.add_argument("--zmax", type=float, default=None)
    ap.add_argument("--nz", type=int, default=None)
    ap.add_argument("--nth", type=int, default=20000)
    ap.add_argument("--nth-coarse", type=int, default=7200)
    ap.add_argument("--top", type=int, default=5)
    ap.add_argument("--phases", type=int, default=3)
    ap.add_argument("--all", type=int, default=0, help="also every reached grid position (at most N)")
    args = ap.parse_args()
    doc = json.load(open(args.profile))
    head = doc["limits"]["eye_safety"]["head"]
    Rs = sorted({100.0, float(head.get("aperture_distance_mm", 100.0))})
    surfaces = ["cylinder", "sphere"] if args.surface == "both" else [args.surface]
    out = {}
    worst = 0.0
    for R in Rs:
        for s in surfaces:
            b = run(doc, s, R, args)
            out[f"{s}@{R:g}"] = b
            worst = max(worst, b["worst"])
    out["truth"] = worst
    print(json.dumps(out, default=float))


if __name__ == "__main__":
    main()
