#!/usr/bin/env python3
"""A hot-sector constant-spin profile with a head, scaled so that `check` gives ~TARGET, then
oracle.py (both surfaces) and the firmware@1 table's integer check (one table bin per profile
bin, codes in proportion).
usage: hot.py NAME 'HEAD-JSON' --frame HZ --bins N --hot I0,I1 --ratio K [--target 0.97]
"""
import argparse, json, os, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "head"))
from mk import profile  # noqa: E402
from run import check, fw_ratio, fw_why, G, PY  # noqa: E402


def fw_table(doc, out, code_hot=60000, tick_hz=72_000_000):
    fr = doc["frame_rate_hz"]; ft = round(tick_hz / fr); n = len(doc["bins"])
    assert ft % n == 0, (ft, n)
    pmax = max(b["power_w"] for b in doc["bins"])
    step = pmax / code_hot
    bins = []
    for i, b in enumerate(doc["bins"]):
        code = int(round(b["power_w"] / step))
        bins.append({"start_deg": b["start_deg"], "width_mdeg": 360000 // n, "dwell_ticks": ft // n,
                     "power_code": code, "dwell_ticks_min": ft // n, "dwell_ticks_max": ft // n,
                     "power_code_cap": 65535})
    d = {"format": "gaze-lidar/firmware@1", "tick_hz": tick_hz, "frame_ticks": ft,
         "power_w_per_code": step, "power_accounting": "time", "pulse_rate_hz": doc["pulse_rate_hz"],
         "eye_safety": doc["limits"]["eye_safety"],
         "limits": {"power_code_min": 0, "power_code_max": 65535, "energy_budget": 65535 * ft,
                    "window_bins": 1, "window_energy_max": 18446744073709551615},
         "bins": bins}
    json.dump(d, open(out, "w"), indent=1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("name"); ap.add_argument("head")
    ap.add_argument("--frame", type=float, default=10.0)
    ap.add_argument("--bins", type=int, default=36)
    ap.add_argument("--hot", default="0,0")
    ap.add_argument("--ratio", type=float, default=100.0)
    ap.add_argument("--target", type=float, default=0.97)
    ap.add_argument("--outdir", default="/tmp/bb/hot")
    ap.add_argument("--oracle-args", default="")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    head = json.loads(a.head)
    head.setdefault("aperture_distance_mm", 100.0); head.setdefault("origin_height_mm", 0.0)
    for i, c in enumerate(head["channels"]):
        c.setdefault("id", i); c.setdefault("slot_s", 0.0); c.setdefault("azimuth_offset_deg", 0.0)
    i0, i1 = (int(x) for x in a.hot.split(","))
    base = [1.0 if i0 <= i <= i1 else 1.0 / a.ratio for i in range(a.bins)]
    path = os.path.join(a.outdir, a.name + ".json")
    s = 0.01
    json.dump(profile(head, None, a.frame, a.bins, powers=[s * x for x in base]), open(path, "w"), indent=1)
    rc, d, err = check(path)
    if d is None or not d.get("eye_safety"):
        print(json.dumps({"name": a.name, "rc": rc, "err": err})); return
    s *= a.target / d["eye_safety"]["worst_ratio"]
    doc = profile(head, None, a.frame, a.bins, powers=[s * x for x in base])
    json.dump(doc, open(path, "w"), indent=1)
    rc, d, err = check(path)
    es = d["eye_safety"]; hf = (es.get("head") or {}).get("figures", {})
    res = {"name": a.name, "rc": rc, "check": es["worst_ratio"], "rule": es["binding_rule"],
           "pass": hf.get("pass_angle_deg"), "Wv": hf.get("weight_vertical")}
    fwp = os.path.join(a.outdir, a.name + "_fw.json")
    fw_table(doc, fwp)
    frc, fd, ferr = check(fwp)
    res["fw"] = {"rc": frc, "ratio": fw_ratio(fd), "why": fw_why(fd) if frc else None}
    o = subprocess.run([PY, os.path.join(HERE, "oracle.py"), path] + a.oracle_args.split(),
                       capture_output=True, text=True)
    flags = []
    try:
        orc = json.loads(o.stdout)
        res["truth"] = orc["truth"]
        res["truth_by"] = {k: (round(v["worst"], 6), {r: round(v[r], 6) for r in ("rule1", "pass", "multi", "time_base")})
                           for k, v in orc.items() if isinstance(v, dict)}
        res["truth/check"] = orc["truth"] / es["worst_ratio"]
        if rc == 0 and orc["truth"] > 1:
            flags.append("BUG")
        if frc == 0 and orc["truth"] > 1:
            flags.append("FW-BUG(truth)")
    except Exception:
        res["oracle_err"] = o.stderr[-400:]
    if frc == 0 and rc != 0:
        flags.append("FW-BUG(float rejects)")
    if frc != 0 and rc == 0:
        flags.append("FW-SAFE")
    res["flags"] = flags
    print(json.dumps(res, default=float) + (" <<<<<< " + ",".join(flags) if flags else ""))


if __name__ == "__main__":
    main()
