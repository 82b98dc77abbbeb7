#!/bin/bash
# cmp.sh HEAD.json POWER_W FRAME_HZ [oracle args...]: check's figure vs the oracle's at check's worst position
B=${B:-/work/targets/break-head/release/gaze-lidar}
head=$1; p=$2; f=$3; shift 3
out=/tmp/bh_cmp_$(basename $head .json).json
python3 "$(dirname $0)/mk.py" $out --power-w $p --frame-hz $f --bins 4 --head $head
$B check $out --format json 2>/dev/null | python3 -c "
import json,sys;d=json.load(sys.stdin);e=d['eye_safety'];h=e['head']
print('check', d['certified'], e['worst_ratio'], e['binding_rule'], 'az', e['worst_azimuth_deg'], 'h', h['worst_height_mm'], 'pass', h['figures']['pass_angle_deg'])
open('/tmp/bh_pos','w').write('%r %r'%(e['worst_azimuth_deg'],h['worst_height_mm']))"
read az hh < /tmp/bh_pos
al=$(python3 -c "print(','.join(str($az+d) for d in [-2,-1,0,1,2]))")
hs=$(python3 -c "print(','.join(str($hh+d) for d in [-3,0,3]))")
python3 "$(dirname $0)/oracle.py" $out --alphas=$al --heights=$hs "$@"
