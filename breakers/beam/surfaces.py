#!/usr/bin/env python3
"""Is the declared distance's surface evaluated by both checkers? For each run.py line of a
family log (heads declaring aperture_distance_mm != 100): the profile's float figure, the same
profile with the head at 100 mm (the 100 mm surfaces alone), and the integer figure of the
firmware table (run.py's). Where the declared surface binds (float > 100-mm-only), the integer
figure must follow the float one, not the 100 mm one.
usage: surfaces.py LOG..."""
import json, os, sys
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from run import check, fw_ratio  # noqa: E402

for fn in sys.argv[1:]:
    for l in open(fn):
        d = json.loads(l.split(" <<<<<<")[0])
        if "check" not in d:
            continue
        R = d["head"].get("aperture_distance_mm", 100.0)
        if R == 100.0:
            continue
        path = f"/tmp/bb/runs/{d['name']}.json"
        doc = json.load(open(path))
        doc["limits"]["eye_safety"]["head"]["aperture_distance_mm"] = 100.0
        p100 = path.replace(".json", "_at100.json")
        json.dump(doc, open(p100, "w"))
        rc, d100, _ = check(p100)
        f100 = d100["eye_safety"]["worst_ratio"]
        fw = d["fw"][0]
        binds = d["check"] > f100 * (1 + 1e-9)
        print(json.dumps({"name": d["name"], "R": round(R, 3), "float": d["check"], "float_100_only": f100,
                          "declared_binds": binds, "int": fw["ratio"], "int_rc": fw["rc"],
                          "int_follows": None if fw["ratio"] is None else fw["ratio"] >= d["check"] * (1 - 1e-6)}))
