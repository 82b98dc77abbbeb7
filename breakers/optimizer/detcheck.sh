#!/bin/bash
# claim 7: byte-identical outputs and certificates with RAYON_NUM_THREADS=1/2/3 on fuzz members
B=/work/targets/break-opt/release/gaze-lidar
n=0; bad=0
for d in fuzz_out/m00{0,1,2,3,4}?; do
  g=$(python3 -c "import json;[print(r['gaze']) for r in map(json.loads,open('fuzz_out/log.jsonl')) if r['k']==int('$d'[-4:])]")
  rc0=$(python3 -c "import json;[print(r['rc']) for r in map(json.loads,open('fuzz_out/log.jsonl')) if r['k']==int('$d'[-4:])]")
  [ "$rc0" = 0 ] || continue
  n=$((n+1))
  for t in 1 2 3; do rm -rf /tmp/bo_dt$t; mkdir -p /tmp/bo_dt$t; RAYON_NUM_THREADS=$t nice -n 10 $B profile --config $d/c.toml --gaze-deg $g --out /tmp/bo_dt$t/p.json --certificate /tmp/bo_dt$t/cert 2>/dev/null; done
  for t in 2 3; do diff -r /tmp/bo_dt1 /tmp/bo_dt$t >/dev/null || { echo "DIFF $d t1 vs t$t"; bad=$((bad+1)); }; done
  cmp -s /tmp/bo_dt1/p.json $d/p.json || { echo "DIFF vs earlier run $d"; bad=$((bad+1)); }
done
echo "members $n bad $bad"
