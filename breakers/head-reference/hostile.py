#!/usr/bin/env python3
"""hostile.py: malformed/extreme head fields through `check` (profile@1 JSON) and `check --sensor`
(TOML). Prints exit code, stderr line count and first line; flags panics / multi-line / wrong codes."""
import json, os, subprocess, copy
B = os.environ.get("B", "/work/targets/break-head/release/gaze-lidar")
D = "/tmp/r5/hostile"; os.makedirs(D, exist_ok=True)
base = json.load(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "cases/ti_closed_three_slots.json")))
def run(args, inp=None):
    p = subprocess.run([B] + args, capture_output=True, text=True, input=inp)
    return p.returncode, p.stderr.strip().splitlines(), p.stdout
cases = []
def hc(name, f):
    d = copy.deepcopy(base); f(d["limits"]["eye_safety"]["head"]); cases.append((name, json.dumps(d)))
def raw(name, old, new):
    s = json.dumps(base); assert old in s, old; cases.append((name, s.replace(old, new, 1)))
H = base["limits"]["eye_safety"]["head"]
raw("cycle 1e999", '"cycle_s": 0.0001', '"cycle_s": 1e999')
raw("cycle NaN", '"cycle_s": 0.0001', '"cycle_s": NaN')
raw("elev -1e999", '"elevation_deg": 0', '"elevation_deg": -1e999')
raw("slot string", '"slot_s": 0', '"slot_s": "0"')
raw("slot null", '"slot_s": 0', '"slot_s": null')
hc("cycle 0", lambda h: h.update(cycle_s=0.0))
hc("cycle neg", lambda h: h.update(cycle_s=-1e-4))
hc("cycle 5e-324", lambda h: h.update(cycle_s=5e-324))
hc("cycle 2", lambda h: h.update(cycle_s=2.0))
hc("no channels", lambda h: h.update(channels=[]))
hc("513 channels", lambda h: h.update(channels=[dict(H["channels"][0], id=i) for i in range(513)]))
hc("512 channels", lambda h: h.update(channels=[dict(H["channels"][0], id=i, slot_s=0.0) for i in range(512)]))
hc("dup id", lambda h: h["channels"][1].update(id=0))
hc("slot = cycle", lambda h: h["channels"][1].update(slot_s=1e-4))
hc("slot > cycle", lambda h: h["channels"][1].update(slot_s=2e-4))
hc("slot neg", lambda h: h["channels"][1].update(slot_s=-1e-9))
hc("slot -0.0", lambda h: h["channels"][1].update(slot_s=-0.0))
hc("elev 90", lambda h: h["channels"][1].update(elevation_deg=90.0))
hc("elev 89.99999999", lambda h: h["channels"][1].update(elevation_deg=89.99999999))
hc("off 90", lambda h: h["channels"][1].update(azimuth_offset_deg=90.0))
hc("off -180", lambda h: h["channels"][1].update(azimuth_offset_deg=-180.0))
hc("off 89.999999", lambda h: h["channels"][1].update(azimuth_offset_deg=89.999999))
hc("scale neg", lambda h: h["channels"][1].update(power_scale=-1.0))
hc("scale 1001", lambda h: h["channels"][1].update(power_scale=1001.0))
hc("scale 1000", lambda h: h["channels"][1].update(power_scale=1000.0))
hc("scale 0 all", lambda h: [c.update(power_scale=0.0) for c in h["channels"]])
hc("r0 = R", lambda h: h.update(origin_radius_mm=100.0))
hc("r0 neg", lambda h: h.update(origin_radius_mm=-1.0))
hc("r0 99.999", lambda h: h.update(origin_radius_mm=99.999))
hc("exit 0", lambda h: h.update(exit_diameter_mm=0.0))
hc("exit 1000", lambda h: h.update(exit_diameter_mm=1000.0))
hc("div neg", lambda h: h.update(divergence_mrad=-1.0))
hc("div 1000", lambda h: h.update(divergence_mrad=1000.0))
hc("R 0", lambda h: h.update(aperture_distance_mm=0.0))
hc("R 1e-300", lambda h: h.update(aperture_distance_mm=1e-300))
hc("R 10001", lambda h: h.update(aperture_distance_mm=10001.0))
hc("R 3 (r0 0)", lambda h: h.update(aperture_distance_mm=3.0))
hc("z0 1e5", lambda h: h.update(origin_height_mm=1e5))
hc("unknown key", lambda h: h.update(foo=1))
hc("id neg", lambda h: h["channels"][1].update(id=-1))
hc("id 2^32", lambda h: h["channels"][1].update(id=2**32))
hc("id float", lambda h: h["channels"][1].update(id=1.5))
hc("missing slot", lambda h: h["channels"][1].pop("slot_s"))
def rate(d):
    d["pulse_rate_hz"] = 1.0 / 1e-4 * (1 + 1e-6)
cases.append(("rate != 1/cycle", json.dumps(dict(base, pulse_rate_hz=1e4 * (1 + 1e-6)))))
bad = 0
for name, s in cases:
    p = os.path.join(D, name.replace(" ", "_").replace("/", "_") + ".json")
    open(p, "w").write(s)
    rc, err, out = run(["check", p])
    panic = any("panick" in l or "RUST_BACKTRACE" in l for l in err)
    flag = "PANIC" if panic or rc not in (0, 1, 2) else ("MULTI" if len(err) > 1 else "")
    if flag: bad += 1
    print("%-20s rc=%d %s | %s" % (name, rc, flag, (err[0] if err else out.splitlines()[0] if out else "")[:170]))
print("flagged", bad)
