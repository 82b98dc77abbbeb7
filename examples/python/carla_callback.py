"""Gaze-aware LiDAR in a CARLA client: GazeStream + apply_profile in a
`sensor.lidar.ray_cast` listen callback.

CARLA records what a *uniform* LiDAR would see. Each LiDAR frame, this
callback asks the gaze stream for the certified profile the adaptive sensor
runs (fail-safe baseline when the gaze is stale or lost) and keeps only the
points that sensor would return: the per-azimuth range from the profile's
power, the per-azimuth density from its spin.

Frames: CARLA's sensor frame is left-handed (x forward, y right, z up);
gaze-lidar's azimuths are ISO 8855 (y left), counter-clockwise from ahead,
so a gaze of 90 degrees looks left and a CARLA point (x, y) has azimuth
atan2(-y, x). `apply_profile(..., frame="carla")` (the default) does that.
Mount the LiDAR with yaw 0 (its x axis the car's forward), or rotate the
points first.

In CARLA (not installable here, so these lines are the only CARLA-specific
ones):

    bp = world.get_blueprint_library().find("sensor.lidar.ray_cast")
    bp.set_attribute("rotation_frequency", "20")      # the profile's frame rate
    bp.set_attribute("points_per_second", "500000")
    bp.set_attribute("range", "200")                  # record beyond the rated range
    lidar = world.spawn_actor(bp, carla.Transform(carla.Location(z=2.0)), attach_to=ego)
    adaptive = AdaptiveLidar(gaze_source=eye_tracker.latest)  # your tracker
    lidar.listen(lambda m: adaptive.on_measurement(m.timestamp, m.raw_data))

Run this file to try the same code on a synthetic cloud: it prints what the
adaptive sensor keeps per region while the driver looks left, then after the
tracker loses the eyes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

import gaze_lidar as gl


def points_from_raw(raw_data: bytes | memoryview) -> npt.NDArray[np.float32]:
    """CARLA's LidarMeasurement.raw_data → N x 4 float32 (x, y, z, intensity), no copy."""
    return np.frombuffer(raw_data, dtype=np.float32).reshape(-1, 4)


class AdaptiveLidar:
    """Turns each uniform CARLA sweep into what the gaze-adaptive sensor returns.

    gaze_source: a callable returning the newest tracker samples as a list of
    (t_s, gaze_deg, valid) since the last call, timestamps on the simulation
    clock (or an empty list when the tracker is silent).
    """

    def __init__(
        self,
        gaze_source: Callable[[], Sequence[tuple[float, float, bool]]],
        *,
        mode: Any = "range",
        rated_range_m: float = 100.0,
        fog_mor_m: float | None = None,
        seed: int = 0,
    ) -> None:
        self.gaze_source = gaze_source
        self.stream = gl.GazeStream(preset="paper", mode=mode, timeout_ms=100)
        self.rated_range_m = rated_range_m
        self.fog_mor_m = fog_mor_m
        self.seed = seed
        self.frame: gl.Frame | None = None  # the gaze_lidar.Frame in force

    def on_measurement(self, timestamp_s: float, raw_data: bytes | memoryview) -> npt.NDArray[np.float32]:
        """The listen callback: returns the kept points (N' x 4 float32)."""
        for t_s, gaze_deg, valid in self.gaze_source():
            for frame in self.stream.push(t_s, gaze_deg, valid):
                self.frame = frame
        # The frame clock runs whether or not the tracker speaks.
        for frame in self.stream.tick(timestamp_s):
            self.frame = frame
        points = points_from_raw(raw_data)
        if self.frame is None:  # before the first frame: nothing certified yet
            return points[:0]
        keep = gl.apply_profile(
            self.frame.profile,
            points,
            rated_range_m=self.rated_range_m,
            fog_mor_m=self.fog_mor_m,
            seed=self.seed,
        )
        self.seed += 1  # fresh thinning draws each sweep, still reproducible
        return points[keep]


def synthetic_sweep(rng: np.random.Generator, n: int = 100_000) -> bytes:
    """A uniform sweep around the car, as CARLA's raw_data bytes (y to the right)."""
    az = np.radians(rng.uniform(0.0, 360.0, n))
    r = rng.uniform(2.0, 150.0, n)
    pts = np.empty((n, 4), dtype=np.float32)
    pts[:, 0] = r * np.cos(az)
    pts[:, 1] = -r * np.sin(az)
    pts[:, 2] = rng.uniform(-1.5, 1.0, n)
    pts[:, 3] = np.exp(-0.004 * r)
    return pts.tobytes()


def demo(sweeps: int = 12, seed: int = 0) -> list[dict[str, Any]]:
    """Runs the callback on synthetic sweeps at 20 Hz: the driver looks left
    (90°) for 0.3 s, then the tracker loses the eyes. One summary per sweep."""
    rng = np.random.default_rng(seed)
    clock = {"t": 0.0}

    def tracker() -> list[tuple[float, float, bool]]:
        # 200 Hz samples over the last 50 ms; valid while t < 0.3 s.
        t1 = clock["t"]
        return [(float(t), 90.0, bool(t < 0.3)) for t in np.arange(max(t1 - 0.05, 0.0), t1, 0.005)]

    lidar = AdaptiveLidar(tracker)
    rows = []
    for k in range(sweeps):
        clock["t"] = k * 0.05
        raw = synthetic_sweep(rng)
        kept = lidar.on_measurement(clock["t"], raw)
        az = gl.azimuth_deg(kept)
        r = np.linalg.norm(kept[:, :3], axis=1)
        left = (az > 60) & (az < 120)
        rows.append(
            {
                "t_s": round(clock["t"], 3),
                "state": lidar.frame.state if lidar.frame else None,
                "kept": int(kept.shape[0]),
                "max_range_left_m": float(r[left].max()) if left.any() else 0.0,
                "max_range_right_m": float(r[(az > 240) & (az < 300)].max()),
            }
        )
    return rows


if __name__ == "__main__":
    for row in demo():
        print(
            f"t={row['t_s']:5.2f} s  {str(row['state']):9}  kept {row['kept']:6d}  "
            f"max range left {row['max_range_left_m']:6.1f} m  right {row['max_range_right_m']:6.1f} m"
        )
