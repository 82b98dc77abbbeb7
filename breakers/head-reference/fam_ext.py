#!/usr/bin/env python3
"""fam_ext.py: extreme timing regimes (huge/tiny cycles, very slow/fast frames, few/many bins)
on small heads; check scaled to 0.97, ref.py at the channels' hit heights."""
import json, math, subprocess, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hits import hit
D = os.path.dirname(os.path.abspath(__file__)); PY = "/tmp/bhv/bin/python"
B = "/work/targets/break-head/release/gaze-lidar"
def chk(p):
    r = subprocess.run([B, "check", p, "--format", "json"], capture_output=True, text=True)
    j = json.loads(r.stdout); e = j["eye_safety"]
    if e is None: return None
    return j["certified"], e["worst_ratio"], e["binding_rule"], e["worst_azimuth_deg"], (e.get("head") or {}).get("worst_height_mm")
def head2(cyc, slots, offs=(0, 0), els=(0, 0), r0=0.0, ex=3.0, dv=0.0):
    return {"cycle_s": cyc, "origin_radius_mm": r0, "origin_height_mm": 0.0, "exit_diameter_mm": ex, "divergence_mrad": dv,
            "channels": [{"id": i, "elevation_deg": els[i], "azimuth_offset_deg": offs[i], "slot_s": slots[i]} for i in range(len(slots))]}
cases = [
    ("cyc1s_f1000", head2(1.0, [0, 0.5]), 1000.0, 4, 1e-7, 905, None),
    ("cyc1s_f0.1", head2(1.0, [0, 0.5]), 0.1, 4, 1e-7, 905, None),
    ("cyc0.1_f10", head2(0.1, [0, 3e-6]), 10.0, 8, 1e-7, 905, None),
    ("cyc1e-6_f10", head2(1e-6, [0, 5e-7]), 10.0, 8, 1e-8, 905, None),
    ("f0.01_cyc1e-4", head2(1e-4, [0, 2e-6]), 0.01, 8, 5e-9, 905, None),
    ("f0.01_hot", head2(1e-4, [0, 2e-6], offs=(0, 3)), 0.01, 36, 5e-9, 905, "3,3,20"),
    ("f200_cyc1e-3", head2(1e-3, [0, 4e-6]), 200.0, 8, 5e-9, 905, None),
    ("f1000_cyc1e-5", head2(1e-5, [0, 4e-6]), 1000.0, 360, 5e-9, 905, "10,10,5"),
    ("ti_twice", head2(2e-6, [0, 1e-6], ex=1.0), 10.0, 8, 1e-9, 905, None),
    ("wide_beam_slow", head2(1e-4, [0, 3e-6], ex=150.0, r0=0.0), 1.0, 8, 5e-9, 905, None),
    ("bins3600_hot", head2(5e-5, [0, 2.5e-6], offs=(0, 0.2)), 10.0, 3600, 5e-9, 905, "100,100,50"),
]
skip = set(sys.argv[1:])
for name, head, frame, bins, tp, lam, hot in cases:
    if name in skip: continue
    p = "/tmp/r5/ext_%s.json" % name
    g = [sys.executable, D + "/gen.py", p, json.dumps(head), "--power", "1e-4", "--frame", str(frame), "--bins", str(bins), "--tp", str(tp), "--lam", str(lam)]
    if hot: g += ["--hot", hot]
    subprocess.run(g, check=True); c = chk(p)
    if c is None or not (c[1] > 0): print(name, "check", c); continue
    g[g.index("--power") + 1] = repr(1e-4 * 0.97 / c[1]); subprocess.run(g, check=True); c = chk(p)
    best = (0, "")
    for surf in ("cylinder", "sphere"):
        hs = sorted(set(round(hit(head, ch, surf) + d, 4) for ch in head["channels"] for d in (-1, 0, 1)))
        if c[4] is not None and math.isfinite(c[4]) and abs(c[4]) < 99: hs.append(c[4])
        al = [c[3], c[3] + 0.3]
        if hot:
            i0 = int(hot.split(",")[0]); al += [(i0 + 0.5) * 360 / bins + o for o in (0, 0.1, 3)]
        hor = ["--horizon", "101"] if frame <= 0.1 else []
        r = subprocess.run([PY, D + "/ref.py", p, "--surface", surf, "--heights=" + ",".join("%.6g" % h for h in hs),
                            "--alphas=" + ",".join("%.6g" % (a % 360) for a in al), "--top", "4", "--phases", "0,0.5"] + hor, capture_output=True, text=True)
        line = [l for l in r.stdout.splitlines() if l.startswith("REFERENCE")]
        if not line: print(name, surf, "ref failed", r.stderr[-300:]); continue
        v = float(line[0].split()[1])
        if v > best[0]: best = (v, surf + " " + line[0][:140])
    print("%-16s check=%s ref=%.6f ref/check=%.5f %s %s" % (name, c[:3], best[0], best[0] / c[1], "BUG" if best[0] > c[1] * (1 + 1e-9) and c[0] else "", best[1]), flush=True)
