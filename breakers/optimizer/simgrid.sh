#!/bin/bash
# claim 4: optimized (detection) vs best closed form, per model x fog x seed
B=/work/targets/break-opt/release/gaze-lidar
for cfg in "$@"; do for model in argus physical; do for fog in 0 25 50; do for seed in 1 7; do
  out=$(nice -n 10 $B simulate --variant optimized --optimizer-config $cfg --variant baseline --variant range --variant resolution --variant joint --model $model --fog $fog --trials 100 --seed $seed --format csv 2>/tmp/bo_sim.err)
  rc=$?
  if [ $rc != 0 ]; then echo "$(basename $cfg) $model $fog $seed rc=$rc $(grep -v warning /tmp/bo_sim.err | head -c 300)"; continue; fi
  echo "$out" | python3 -c "
import sys,csv
rows=list(csv.DictReader(sys.stdin))
k='tta_median_s'
m={r['variant']:float(r[k]) for r in rows}
best=max((v,n) for n,v in m.items() if n not in ('optimized',))
flag='  <-- optimized below best closed form' if m['optimized']<best[0]-0.02 else ''
print('$(basename $cfg) $model fog=$fog seed=$seed opt=%.3f best=%s %.3f %s'%(m['optimized'],best[1],best[0],flag))
"
done; done; done; done
