#!/bin/bash
# single channel: steep, off-axis crossing point, azimuth offsets, heights
PY=${PY:-python3}
for r0 in 10 45 90; do for az in -85 -45 0 45 85; do for el in 30 60 75 85 -50 -80; do
 z0=$(( (r0 % 20) * 3 ))
 $PY run.py A_r${r0}_az${az}_el${el} "{\"origin_radius_mm\":$r0,\"origin_height_mm\":$z0,\"exit_diameter_mm\":10,\"divergence_mrad\":0,\"channels\":[{\"elevation_deg\":$el,\"azimuth_offset_deg\":$az}]}" --ne 1801 --nth 36000
done; done; done
