#!/usr/bin/env python3
"""For fwscan.py lines (tables the integer check accepts while the float check rejects, or
integer figures below the float one): the oracle's truth of the profile and truth / integer
(the truth when the integer check is exactly at its limit; > 1 would be an unsafe table).
usage: fwtruth.py FWSCAN-LOG... [--max-pulses 400000]"""
import json, os, subprocess, sys
HERE = os.path.dirname(os.path.abspath(__file__))
PY = os.environ.get("PY", sys.executable)
maxp = 400000
args = [a for a in sys.argv[1:]]
if "--max-pulses" in args:
    i = args.index("--max-pulses"); maxp = int(args[i + 1]); del args[i:i + 2]
seen = set()
for fn in args:
    for l in open(fn):
        if "<<<" not in l:
            continue
        d = json.loads(l.split(" <<<")[0])
        if d["name"] in seen:
            continue
        seen.add(d["name"])
        if d["int_rc"] != 0 and d["int"] >= d["float"]:
            continue
        h = d["head"]
        per_turn = len(h["channels"]) / (d["frame"] * h["cycle_s"])
        if per_turn > maxp:
            print(json.dumps({"name": d["name"], "skipped": "pulses per turn", "n": per_turn}), flush=True)
            continue
        p = subprocess.run([PY, os.path.join(HERE, "oracle.py"), f"/tmp/bb/fwscan/{d['name']}.json",
                            "--top", "4", "--phases", "2", "--all", "150"], capture_output=True, text=True)
        try:
            o = json.loads(p.stdout)
        except Exception:
            print(json.dumps({"name": d["name"], "err": p.stderr[-300:]}), flush=True); continue
        r = {"name": d["name"], "R": d["R"], "float": d["float"], "int": d["int"], "int_rc": d["int_rc"],
             "truth": o["truth"], "truth/int": o["truth"] / d["int"]}
        print(json.dumps(r) + (" <<<<<< FW-BUG" if o["truth"] / d["int"] > 1 else ""), flush=True)
