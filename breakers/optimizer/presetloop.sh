#!/bin/bash
# claim 8: every preset x mode x gaze x bins x accounting with --optimize: certified or one line
B=/work/targets/break-opt/release/gaze-lidar
n=0; bad=0
for p in paper vls128 vlp16 os1-128; do for m in range resolution joint; do for g in 0 33.3 180 359.99; do for nb in 36 360 1440; do for a in time angle; do
  out=/tmp/bo_pl.json; rm -f $out; n=$((n+1))
  s=$(date +%s%N); nice -n 10 $B profile --preset $p --mode $m --gaze-deg $g --bins $nb --accounting $a --optimize --out $out 2>/tmp/bo_pl.err; rc=$?; e=$(( ($(date +%s%N)-s)/1000000 ))
  if [ $rc = 0 ]; then $B check $out >/dev/null 2>&1 || { echo "CHECKFAIL $p $m $g $nb $a"; bad=$((bad+1)); }
     python3 -c "import json,sys;sys.exit(0 if 'optimality' in json.load(open('$out')) else 1)" || { echo "NOOPT $p $m $g $nb $a"; bad=$((bad+1)); }
  else l=$(grep -vc warning /tmp/bo_pl.err); echo "rc=$rc $p $m $g $nb $a ${e}ms lines=$l $(grep -v warning /tmp/bo_pl.err | head -c 300)"; fi
  [ $e -gt 2000 ] && echo "SLOW ${e}ms $p $m $g $nb $a rc=$rc"
done; done; done; done; done
echo "total $n bad $bad"
