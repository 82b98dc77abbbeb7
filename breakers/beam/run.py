#!/usr/bin/env python3
"""Driver: head -> uniform profile@1 scaled so that `check` gives ~TARGET -> oracle.py (both
surfaces, 100 mm and the declared distance) -> the same profile as firmware@1 (fw.py) -> the
integer check. Prints one JSON line; flags
  BUG        certified (exit 0) and the oracle's truth > 1
  FW-BUG     the integer check accepts a table the float check rejects (or truth > 1)
  FW-SAFE    the integer check rejects a table the float check certifies (safe side)
usage: run.py NAME 'HEAD-JSON' [--frame HZ] [--target 0.97] [--bins 8] [--oracle-args '...']
"""
import argparse, json, os, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "head"))
from mk import profile  # noqa: E402

G = os.environ.get("GAZE_LIDAR", "/work/targets/break-beam/release/gaze-lidar")
PY = os.environ.get("PY", sys.executable)


def check(path):
    p = subprocess.run([G, "check", path, "--format", "json"], capture_output=True, text=True)
    try:
        d = json.loads(p.stdout)
    except Exception:
        d = None
    return p.returncode, d, p.stderr.strip()[-300:]


def fw_table(prof, out, code=4000, bins=8, tick_hz=80_000_000):
    p = json.load(open(prof))
    P = p["bins"][0]["power_w"]; fr = p["frame_rate_hz"]
    ft = round(tick_hz / fr)
    assert ft % bins == 0
    doc = {"format": "gaze-lidar/firmware@1", "tick_hz": tick_hz, "frame_ticks": ft,
           "power_w_per_code": P / code, "power_accounting": "time",
           "pulse_rate_hz": p["pulse_rate_hz"], "eye_safety": p["limits"]["eye_safety"],
           "limits": {"power_code_min": 0, "power_code_max": 65535, "energy_budget": 65535 * ft,
                      "window_bins": 1, "window_energy_max": 18446744073709551615},
           "bins": [{"start_deg": 360.0 * i / bins, "width_mdeg": 360000 // bins,
                     "dwell_ticks": ft // bins, "power_code": code, "dwell_ticks_min": ft // bins,
                     "dwell_ticks_max": ft // bins, "power_code_cap": 65535} for i in range(bins)]}
    json.dump(doc, open(out, "w"), indent=1)


def fw_ratio(d):
    """the integer check's worst ratio: the certified report's, or the eye-safety violation's."""
    if d is None:
        return None
    es = d.get("eye_safety") or {}
    if "worst_ratio" in es:
        return es["worst_ratio"]
    r = [v["detail"]["ratio_ppm"] / 1e6 for v in d.get("violations", [])
         if isinstance(v.get("detail"), dict) and v["detail"].get("kind") == "eye_safety"
         and "ratio_ppm" in v["detail"]]
    return max(r) if r else None


def fw_why(d):
    if d is None:
        return None
    return [v.get("message", v.get("limit", str(v)))[:160] for v in d.get("violations", [])]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("name"); ap.add_argument("head")
    ap.add_argument("--target", type=float, default=0.97)
    ap.add_argument("--frame", type=float, default=1000.0)
    ap.add_argument("--bins", type=int, default=8)
    ap.add_argument("--outdir", default="/tmp/bb/runs")
    ap.add_argument("--oracle-args", default="")
    ap.add_argument("--no-oracle", action="store_true")
    ap.add_argument("--fw-codes", default="4000", help="codes to write the table at (comma list)")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    head = json.loads(a.head)
    head.setdefault("cycle_s", 1e-6); head.setdefault("aperture_distance_mm", 100.0)
    head.setdefault("origin_height_mm", 0.0)
    for i, c in enumerate(head["channels"]):
        c.setdefault("id", i); c.setdefault("slot_s", 0.0); c.setdefault("azimuth_offset_deg", 0.0)
    path = os.path.join(a.outdir, a.name + ".json")
    P = 0.01
    json.dump(profile(head, P, a.frame, a.bins), open(path, "w"), indent=1)
    rc, d, err = check(path)
    if d is None or "eye_safety" not in d or d["eye_safety"] is None:
        print(json.dumps({"name": a.name, "rc": rc, "err": err})); return
    r1 = d["eye_safety"]["worst_ratio"]
    P2 = P * a.target / r1
    json.dump(profile(head, P2, a.frame, a.bins), open(path, "w"), indent=1)
    rc, d, err = check(path)
    es = d["eye_safety"]
    hf = (es.get("head") or {}).get("figures", {})
    res = {"name": a.name, "rc": rc, "check": es["worst_ratio"], "rule": es["binding_rule"],
           "surface": hf.get("surface"), "Wv": hf.get("weight_vertical"),
           "pass": hf.get("pass_angle_deg"), "width": hf.get("footprint_max_mm"), "P": P2}
    flags = []
    # firmware
    fws = []
    for code in [int(x) for x in a.fw_codes.split(",")]:
        fwp = os.path.join(a.outdir, f"{a.name}_fw{code}.json")
        fw_table(path, fwp, code=code)
        frc, fd, ferr = check(fwp)
        fr = fw_ratio(fd)
        fws.append({"code": code, "rc": frc, "ratio": fr, "err": None if fd else ferr,
                    "why": fw_why(fd) if frc else None})
        if frc == 0 and rc != 0:
            flags.append("FW-BUG(float rejects)")
        if frc != 0 and rc == 0:
            flags.append("FW-SAFE")
    res["fw"] = fws
    if not a.no_oracle:
        o = subprocess.run([PY, os.path.join(HERE, "oracle.py"), path] + a.oracle_args.split(),
                           capture_output=True, text=True)
        try:
            orc = json.loads(o.stdout)
            res["truth"] = orc["truth"]
            res["truth_by"] = {k: round(v["worst"], 6) for k, v in orc.items() if isinstance(v, dict)}
            res["truth/check"] = orc["truth"] / es["worst_ratio"]
            if rc == 0 and orc["truth"] > 1.0:
                flags.append("BUG")
            if any(f["rc"] == 0 for f in fws) and orc["truth"] > 1.0:
                flags.append("FW-BUG(truth)")
        except Exception:
            res["oracle_err"] = o.stderr[-400:]
    res["flags"] = flags
    print(json.dumps(res, default=float) + (" <<<<<< " + ",".join(flags) if flags else ""))


if __name__ == "__main__":
    main()
