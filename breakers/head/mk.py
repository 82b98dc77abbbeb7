#!/usr/bin/env python3
"""Writes a uniform profile@1 (constant power and spin) with a given head.

usage: mk.py OUT.json --power-w P --frame-hz F --bins N --head HEAD.json
             [--wavelength-nm 905] [--tau-s 5e-9] [--power-max W]
HEAD.json holds the `head` object; pulse_rate_hz is 1/cycle_s.
"""
import argparse
import json
import math


def profile(head, power_w, frame_hz, bins, lam=905.0, tau=5e-9, pmax=None, powers=None):
    omega = 2 * math.pi * frame_hz
    width = 360.0 / bins
    pw = powers or [power_w] * bins
    doc = {
        "format": "gaze-lidar/profile@1",
        "frame_rate_hz": frame_hz,
        "pulse_rate_hz": 1.0 / head["cycle_s"],
        "average_power_w": sum(pw) / bins,
        "power_accounting": "time",
        "gaze_deg": None,
        "limits": {
            "power_w_min": 0.0,
            "power_w_max": pmax if pmax is not None else max(pw),
            "spin_rad_s_min": omega,
            "spin_rad_s_max": omega,
            "spin_accel_rad_s2_max": None,
            "power_slew_w_per_deg_max": None,
            "eye_safety": {
                "wavelength_nm": lam,
                "pulse_duration_s": tau,
                "beam_diameter_mm": head["exit_diameter_mm"],
                "head": head,
            },
        },
        "bins": [
            {
                "start_deg": i * width,
                "width_deg": width,
                "power_w": pw[i],
                "spin_start_rad_s": omega,
                "spin_end_rad_s": omega,
            }
            for i in range(bins)
        ],
    }
    return doc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--power-w", type=float, required=True)
    ap.add_argument("--frame-hz", type=float, default=10.0)
    ap.add_argument("--bins", type=int, default=4)
    ap.add_argument("--head", required=True)
    ap.add_argument("--wavelength-nm", type=float, default=905.0)
    ap.add_argument("--tau-s", type=float, default=5e-9)
    a = ap.parse_args()
    head = json.load(open(a.head))
    doc = profile(head, a.power_w, a.frame_hz, a.bins, a.wavelength_nm, a.tau_s)
    with open(a.out, "w") as f:
        json.dump(doc, f, indent=1)


if __name__ == "__main__":
    main()
