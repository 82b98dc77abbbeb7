#!/bin/bash
# chk.sh PROFILE: prints certified, ratio, rule, az, height
B=${B:-/work/targets/break-head/release/gaze-lidar}
$B check "$1" --format json 2>/dev/null | python3 -c "
import json,sys;d=json.load(sys.stdin);e=d['eye_safety'];h=e.get('head') or {}
print('CHECK', d['certified'], repr(e['worst_ratio']), e['binding_rule'], 'az', e['worst_azimuth_deg'], 'h', h.get('worst_height_mm'), 'meet', h.get('beams_meeting_worst'))"
