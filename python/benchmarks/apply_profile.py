"""Benchmark: apply_profile on 100,000 points (the issue's bar: < 5 ms).

Prints the minimum and median wall time of repeated calls for three
profiles: the paper's range control (two power levels), resolution control
(spin steps) and the optimizer's smooth joint profile (ramps: the exact
azimuth is computed inside ramping bins). Not a test: timings depend on the
machine and its load. Wall time includes the time the thread waits for a
core on a busy machine; thread CPU time (the call runs on the calling
thread, GIL released) is what the call itself costs.

    python python/benchmarks/apply_profile.py [--points N] [--repeat R]
"""

import argparse
import pathlib
import statistics
import time

import numpy as np

import gaze_lidar as gl


def cloud(n, seed=0):
    rng = np.random.default_rng(seed)
    az = np.radians(rng.uniform(0, 360, n))
    r = rng.uniform(1, 150, n)
    pts = np.empty((n, 4), dtype=np.float32)
    pts[:, 0] = r * np.cos(az)
    pts[:, 1] = -r * np.sin(az)
    pts[:, 2] = rng.uniform(-1.5, 1.0, n)
    pts[:, 3] = np.exp(-0.004 * r)
    return pts


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=200)
    a = ap.parse_args()
    pts = cloud(a.points)
    repo = pathlib.Path(__file__).resolve().parents[2]
    profiles = {
        "range (closed form)": gl.profile(mode="range", gaze_deg=90.0),
        "resolution (closed form)": gl.profile(mode="resolution", gaze_deg=90.0),
        "joint (optimizer, ramps)": gl.optimize((repo / "examples/configs/smooth.toml").read_text(), 90.0),
    }
    for name, p in profiles.items():
        gl.apply_profile(p, pts, rated_range_m=100.0)  # warm up
        wall, cpu = [], []
        for _ in range(a.repeat):
            c0, t0 = time.thread_time(), time.perf_counter()
            gl.apply_profile(p, pts, rated_range_m=100.0)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.thread_time() - c0)
        print(
            f"apply_profile {a.points} points, {name:26}: "
            f"wall min {min(wall) * 1e3:6.2f} ms, median {statistics.median(wall) * 1e3:6.2f} ms; "
            f"thread CPU min {min(cpu) * 1e3:6.2f} ms, median {statistics.median(cpu) * 1e3:6.2f} ms "
            f"({1e9 * statistics.median(cpu) / a.points:5.1f} ns/point)"
        )


if __name__ == "__main__":
    main()
